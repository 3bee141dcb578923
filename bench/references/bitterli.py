#!/usr/bin/env python3
"""References for Bitterli's scenes shipped in scenes/ (veach-mis, veach-bidir,
cornell-box).

Renders each scene.xml with Mitsuba 3 (path tracer, the file's
max_depth and tent filter) at the test's resolution, and
box-downsamples the Tungsten reference that ships with the scene to the same
resolution. Writes tests/data/bitterli/<scene>_{mitsuba,mitsuba_var}.exr (the
variance is that of the mean, from 16 independent passes) and
scenes/<scene>/TungstenRender.exr (downsampled; the viewer loads a reference
it finds beside a scene, and compares it with the image box-downsampled by
the same factor).

    pip install mitsuba numpy      # and apt-get install libllvm19
    python3 bench/references/bitterli.py --tungsten DIR   # DIR/<scene>/TungstenRender.exr
        [--scenes cornell-box,...]                        # only these

The Tungsten renders come with Bitterli's scene archives
(https://benedikt-bitterli.me/resources/); they are not in this repository.
"""

import argparse
import os

import mitsuba as mi
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(REPO, "tests", "data", "bitterli")
# name: (width, height, downsampling factor of the Tungsten render, spp)
SCENES = {
    "veach-mis": (160, 90, 8, 4096),
    "veach-bidir": (128, 128, 8, 4096),
    "cornell-box": (128, 128, 8, 4096),
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tungsten", help="folder with <scene>/TungstenRender.exr")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated")
    args = ap.parse_args()
    mi.set_variant(args.variant)
    os.makedirs(OUT, exist_ok=True)
    for name in args.scenes.split(","):
        w, h, factor, spp = SCENES[name]
        path = os.path.join(REPO, "scenes", name, "scene.xml")
        scene = mi.load_file(path, integrator="path", resx=w, resy=h, spp=spp)
        # Independent passes: their spread gives the variance of the mean.
        passes = 16
        stack = np.stack([np.array(mi.render(scene, spp=spp // passes, seed=k))[..., :3] for k in range(passes)])
        image = stack.mean(axis=0)
        variance = stack.var(axis=0, ddof=1) / passes
        mi.Bitmap(image.astype(np.float32)).write(os.path.join(OUT, f"{name}_mitsuba.exr"))
        mi.Bitmap(variance.astype(np.float32)).write(os.path.join(OUT, f"{name}_mitsuba_var.exr"))
        print(name, "mitsuba mean", image.mean(axis=(0, 1)))
        if args.tungsten:
            t = np.array(mi.Bitmap(os.path.join(args.tungsten, name, "TungstenRender.exr")))[..., :3]
            t = t.reshape(h, factor, w, factor, 3).mean(axis=(1, 3))
            out = os.path.join(REPO, "scenes", name, "TungstenRender.exr")
            mi.Bitmap(t.astype(np.float32)).write(out)
            print(name, "tungsten mean", t.mean(axis=(0, 1)))


if __name__ == "__main__":
    main()
