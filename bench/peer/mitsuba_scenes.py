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

`--rmse` measures time to equal error instead, on the shipped scenes at a
reduced resolution (`--rmse-size`), and on the `--extra` files at their
resolution divided by `--rmse-extra-divisor`: a reference by Mitsuba 3 at
`--reference-spp` (seed 7), then both renderers at 1, 2, 4, ... spp up to
`--max-spp`, each sampler (Mitsuba: independent, multijitter; tracelab:
independent, sobol), RMSE against the reference, and the time to reach
two targets (Mitsuba's independent sampler's RMSE at 16 and 64 spp) by
log-log interpolation between checkpoints, as `bench/peer/mitsuba.py` does
for the Cornell box. Times are render times (Mitsuba after a warm-up;
tracelab's summary line). The reference's own noise is in every RMSE, the
same for both: its floor is printed (the reference against a second one
at a quarter of its spp, scaled down by the square root of 5).
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
SCENES = {"veach-mis": (640, 360), "veach-bidir": (512, 512), "cornell-box": (512, 512)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tracelab", default=os.path.join(REPO, "target/release/tracelab"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--extra", nargs="*", default=[])
    ap.add_argument("--rmse", action="store_true", help="time to equal RMSE instead (see above)")
    ap.add_argument("--rmse-size", default="veach-mis=320x180,veach-bidir=128x128,cornell-box=128x128")
    ap.add_argument("--rmse-extra-divisor", type=int, default=8,
                    help="--rmse on --extra files: their resolution divided by this")
    ap.add_argument("--rmse-exclude", nargs="*", default=[],
                    help="NAME=x0,y0,x1,y1: leave this rectangle (fractions of the image) of "
                         "the file whose path contains NAME out of every RMSE (the kitchen's "
                         "blinds, which Mitsuba's ray offset renders as one layer: docs/validation.md)")
    ap.add_argument("--reference-spp", type=int, default=8192)
    ap.add_argument("--max-spp", type=int, default=1024)
    args = ap.parse_args()
    mi.set_variant(args.variant)
    if args.rmse:
        for item in filter(None, args.rmse_size.split(",")):
            name, size = item.split("=")
            w, h = (int(v) for v in size.split("x"))
            time_to_rmse(args, name, os.path.join(REPO, "scenes", name, "scene.xml"), w, h, True)
        for path in args.extra:
            w, h = mi.load_file(load_copy(path)).sensors()[0].film().size()
            d = args.rmse_extra_divisor
            time_to_rmse(args, path, os.path.abspath(path), w // d, h // d, False)
        return
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


def time_to_rmse(args, name, path, w, h, parameters):
    """`parameters`: the file takes resx, resy and spp as Bitterli's Mitsuba 3
    files do; otherwise (his 0.6 interiors) a copy gets them written in."""

    def mitsuba(spp, seed, sampler="independent", warm_up=True):
        # The files fix their sampler: another is read from a copy beside them.
        file = path
        text = open(load_copy(path)).read()
        if sampler != "independent":
            text = text.replace('<sampler type="independent"', f'<sampler type="{sampler}"')
        if not parameters:
            for key, value in (("width", w), ("height", h), ("sampleCount|sample_count", spp)):
                text = re.sub(rf'(<integer name="(?:{key})" value=")\d+', rf"\g<1>{value}", text)
        if text != open(path).read():
            file = os.path.join(os.path.dirname(path), f".mitsuba3_{sampler}_scene.xml")
            with open(file, "w") as f:
                f.write(text)
        try:
            if parameters:
                scene = mi.load_file(file, integrator="path", resx=w, resy=h, spp=spp)
            else:
                scene = mi.load_file(file)
        finally:
            if file != path:
                os.remove(file)
        if warm_up:  # kernel compilation outside the timed render
            np.array(mi.render(scene, seed=seed + 1000, spp=spp))
        start = time.perf_counter()
        image = np.array(mi.render(scene, seed=seed, spp=spp))[..., :3]
        return image, time.perf_counter() - start

    def tracelab(spp, sampler, filter_sampling="splat"):
        size = (["-D", f"resx={w}", "-D", f"resy={h}"] if parameters
                else ["--width", str(w), "--height", str(h)])
        out = subprocess.run(
            [args.tracelab, "render", path, *size,
             "--integrator", "path", "--sampler", sampler, "--spp", str(spp),
             "--filter-sampling", filter_sampling,
             "--out", "/tmp/mitsuba_scenes_rmse.exr"],
            capture_output=True, text=True, check=True)
        seconds = float(re.search(r"^spp \d+ \| ([0-9.]+) s", out.stdout + out.stderr, re.M).group(1))
        return np.array(mi.Bitmap("/tmp/mitsuba_scenes_rmse.exr"))[..., :3], seconds

    keep = np.ones((h, w), bool)
    for item in args.rmse_exclude:
        key, box = item.split("=")
        if key in path:
            x0, y0, x1, y1 = (float(v) for v in box.split(","))
            keep[int(y0 * h):int(y1 * h), int(x0 * w):int(x1 * w)] = False
            print(f"{name}: RMSE without x {x0}-{x1}, y {y0}-{y1} of the image")

    def rmse(a, b):
        return float(np.sqrt(np.mean(((a - b) ** 2)[keep])))

    reference, seconds = mitsuba(args.reference_spp, 7, warm_up=False)
    quarter, _ = mitsuba(args.reference_spp // 4, 8, warm_up=False)
    # E|q - r|² = σ²(1/n + 4/n) per pixel: the reference's own share is a fifth.
    floor = rmse(quarter, reference) / np.sqrt(5.0)
    print(f"\n{name} {w}x{h}: reference {args.reference_spp} spp in {seconds:.1f} s, its noise (RMSE) {floor:.5f}")
    runs = [("mitsuba independent", lambda n: mitsuba(n, 1)),
            ("mitsuba multijitter", lambda n: mitsuba(n, 1, "multijitter")),
            ("tracelab independent", lambda n: tracelab(n, "independent")),
            ("tracelab sobol", lambda n: tracelab(n, "sobol"))]
    if parameters:
        # The filter importance-sampled, as before 2026-12-06.
        runs += [("tracelab independent, importance", lambda n: tracelab(n, "independent", "importance")),
                 ("tracelab sobol, importance", lambda n: tracelab(n, "sobol", "importance"))]
    curves = {}
    for label, render in runs:
        points, spp = [], 1
        while spp <= args.max_spp:
            image, t = render(spp)
            points.append((spp, t, rmse(image, reference)))
            spp *= 2
        curves[label] = points
        print(f"{label}: " + ", ".join(f"{n} spp {t:.3f} s {e:.5f}" for n, t, e in points))
    by_spp = {n: e for n, _, e in curves["mitsuba independent"]}
    targets = [by_spp[16], by_spp[64]]
    print("| configuration | " + " | ".join(f"time to RMSE {t:.4f}" for t in targets) + " |")
    print("|---|---|---|")
    best = {}
    for label, points in curves.items():
        times = [interpolate([(t, e) for _, t, e in points], target) for target in targets]
        for i, t in enumerate(times):
            key = (label.split()[0], i)
            if t is not None and (key not in best or t < best[key]):
                best[key] = t
        print(f"| {label} | " + " | ".join(f"{t:.3f} s" if t else "not reached" for t in times) + " |")
    for i, target in enumerate(targets):
        if ("tracelab", i) in best and ("mitsuba", i) in best:
            print(f"RMSE {target:.4f}: tracelab's best / Mitsuba's best time = "
                  f"{best[('tracelab', i)] / best[('mitsuba', i)]:.2f} (issue 38 asks at most 0.8)")


def interpolate(points, target):
    """points: [(seconds, rmse)] by increasing spp; log-log between the two
    checkpoints that bracket `target`."""
    import math
    if points and points[0][1] <= target:
        return points[0][0]
    for (ta, ea), (tb, eb) in zip(points, points[1:]):
        if eb <= target < ea:
            f = (math.log(target) - math.log(ea)) / (math.log(eb) - math.log(ea))
            return math.exp(math.log(ta) + f * (math.log(tb) - math.log(ta)))
    return None


def load_copy(path):
    """`path`, or a copy without the film properties Mitsuba 3 refuses as
    unreferenced (see bench/peer/load.py)."""
    sys.path.insert(0, HERE)
    from load import for_mitsuba
    return for_mitsuba(path)


if __name__ == "__main__":
    main()
