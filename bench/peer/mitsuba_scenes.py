#!/usr/bin/env python3
"""Mitsuba 3 and tracelab on the same scene files, in the same run.

For each imported scene of scenes/ (Bitterli's Mitsuba 3 files): load time,
and render time of path tracing at the file's max_depth, same resolution and
spp, for Mitsuba 3's LLVM variant (timed after a warm-up render, so kernel
compilation is not counted; the image is read back to force evaluation) and
for tracelab (the whole process, and the render time of its summary line).
Neither is given a thread count: both use every core.

    pip install mitsuba numpy   # and apt-get install libllvm19
    python3 bench/peer/mitsuba_scenes.py [--tracelab target/release/tracelab] [--spp 64]
        [--extra SCENE.xml ...]

`--extra` adds other files (Bitterli's interiors, see bench/peer/load.py),
rendered at their own resolution and max_depth.
"""

import argparse
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
# This folder's mitsuba.py would shadow the package.
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != HERE]
import mitsuba as mi  # noqa: E402
import numpy as np  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))
SCENES = {"veach-mis": (640, 360), "veach-bidir": (512, 512)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tracelab", default=os.path.join(REPO, "target/release/tracelab"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--extra", nargs="*", default=[])
    args = ap.parse_args()
    mi.set_variant(args.variant)
    print("scene | resolution | spp | Mitsuba load s | Mitsuba render s | tracelab load s | tracelab render s | tracelab process s | render ratio")
    runs = [(name, os.path.join(REPO, "scenes", name, "scene.xml"), size)
            for name, size in SCENES.items()]
    runs += [(path, os.path.abspath(path), None) for path in args.extra]
    for name, path, size in runs:
        start = time.perf_counter()
        if size is None:
            scene = mi.load_file(load_copy(path))
            w, h = scene.sensors()[0].film().size()
        else:
            w, h = size
            scene = mi.load_file(path, integrator="path", resx=w, resy=h, spp=args.spp)
        load = time.perf_counter() - start
        np.array(mi.render(scene, seed=1, spp=args.spp))
        start = time.perf_counter()
        np.array(mi.render(scene, seed=2, spp=args.spp))
        render = time.perf_counter() - start
        start = time.perf_counter()
        size_flags = [] if size is None else ["-D", f"resx={w}", "-D", f"resy={h}"]
        out = subprocess.run(
            [args.tracelab, "render", path, *size_flags, "--integrator", "path",
             "--spp", str(args.spp), "--out", "/tmp/mitsuba_scenes.exr"],
            capture_output=True, text=True, check=True)
        process = time.perf_counter() - start
        ours_load = float(re.search(r"scene loaded in ([0-9.]+) s", (out.stdout + out.stderr)).group(1))
        ours_render = float(re.search(r"^spp \d+ \| ([0-9.]+) s", out.stdout + out.stderr, re.M).group(1))
        print(f"{name} | {w}x{h} | {args.spp} | {load:.2f} | {render:.2f} | {ours_load:.2f} | "
              f"{ours_render:.2f} | {process:.2f} | {render / ours_render:.2f}")


def load_copy(path):
    """`path`, or a copy without the film properties Mitsuba 3 refuses as
    unreferenced (see bench/peer/load.py)."""
    sys.path.insert(0, HERE)
    from load import for_mitsuba
    return for_mitsuba(path)


if __name__ == "__main__":
    main()
