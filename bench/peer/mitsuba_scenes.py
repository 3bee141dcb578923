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
    args = ap.parse_args()
    mi.set_variant(args.variant)
    print("scene | resolution | spp | Mitsuba load s | Mitsuba render s | tracelab load s | tracelab render s | tracelab process s | render ratio")
    for name, (w, h) in SCENES.items():
        path = os.path.join(REPO, "scenes", name, "scene.xml")
        start = time.perf_counter()
        scene = mi.load_file(path, integrator="path", resx=w, resy=h, spp=args.spp)
        load = time.perf_counter() - start
        np.array(mi.render(scene, seed=1))
        start = time.perf_counter()
        np.array(mi.render(scene, seed=2))
        render = time.perf_counter() - start
        start = time.perf_counter()
        out = subprocess.run(
            [args.tracelab, "render", path, "-D", f"resx={w}", "-D", f"resy={h}",
             "--spp", str(args.spp), "--out", "/tmp/mitsuba_scenes.exr"],
            capture_output=True, text=True, check=True)
        process = time.perf_counter() - start
        ours_load = float(re.search(r"scene loaded in ([0-9.]+) s", (out.stdout + out.stderr)).group(1))
        ours_render = float(re.search(r"^spp \d+ \| ([0-9.]+) s", out.stdout + out.stderr, re.M).group(1))
        print(f"{name} | {w}x{h} | {args.spp} | {load:.2f} | {render:.2f} | {ours_load:.2f} | "
              f"{ours_render:.2f} | {process:.2f} | {render / ours_render:.2f}")


if __name__ == "__main__":
    main()
