#!/usr/bin/env python3
"""Time to equal RMSE: Mitsuba 3 against tracelab, measured in the same run.

Not part of `cargo test`. Needs `pip install mitsuba numpy` and, for the LLVM
variant, `apt-get install libllvm19`. Renders the Cornell box
(cornell_box_mitsuba.xml, the same scene as scenes/cornell_box.toml: 256x256,
up to 8 bounces, box filter) at 1, 2, 4, ... spp with each variant and
sampler, times each render (after a warm-up render, so the LLVM variant's
kernel compilation is not counted), measures RMSE against the reference, and
interpolates the time to reach each target RMSE on the log-log line between
the two checkpoints that bracket it, as `tracelab bench` does. Then runs
`tracelab bench` for tracelab's configurations and prints both tables and the
ratio of tracelab's best time to Mitsuba's best.

    python3 bench/peer/mitsuba.py [--targets 0.01,0.005] [--tracelab target/release/tracelab]
"""

import argparse
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def time_to_rmse(points, target):
    """points: [(seconds, rmse)] in increasing spp. Log-log interpolation."""
    if not points:
        return None
    if points[0][1] <= target:
        return points[0][0]
    for (ta, ea), (tb, eb) in zip(points, points[1:]):
        if eb <= target < ea or (eb <= target and ea > target):
            f = (math.log(target) - math.log(ea)) / (math.log(eb) - math.log(ea))
            return math.exp(math.log(ta) + f * (math.log(tb) - math.log(ta)))
    return None


def mitsuba_points(mi, variant, sampler, reference, targets, max_spp, threads):
    import numpy as np

    mi.set_variant(variant)
    scene_path = os.path.join(HERE, "cornell_box_mitsuba.xml")
    points = []
    spp = 1
    while spp <= max_spp:
        scene = mi.load_file(scene_path, spp=spp, sampler=sampler)
        # Warm-up, evaluated: the LLVM variant records lazily, so an image
        # that is never read would leave kernel compilation to the timed call.
        np.array(mi.render(scene, spp=spp, seed=1))
        start = time.perf_counter()
        image = mi.render(scene, spp=spp, seed=2)
        image = np.array(image)  # forces evaluation
        seconds = time.perf_counter() - start
        rmse = float(np.sqrt(np.mean((image[..., :3] - reference) ** 2)))
        points.append((seconds, rmse, spp))
        if rmse <= min(targets):
            break
        spp *= 2
    return points


def tracelab_times(binary, configs, targets, max_spp, reference, threads):
    args = [
        binary,
        "bench",
        os.path.join(REPO, "scenes/cornell_box.toml"),
        "--reference",
        reference,
        "--max-spp",
        str(max_spp),
        "--until-rmse",
        str(min(targets)),
        "--targets",
        ",".join(str(t) for t in targets),
        "--threads",
        str(threads),
    ]
    for c in configs:
        args += ["--config", c]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    times = {}
    table = out.split("time to reach RMSE", 1)[1].splitlines()[2:]
    for line in table:
        parts = line.split()
        if not parts:
            continue
        name = parts[0]
        rest = line.split(name, 1)[1]
        cells = re.findall(r"([0-9.]+) s|(not reached)", rest)
        times[name] = [float(t) if t else None for t, _ in cells]
    return times, out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--targets", default="0.01,0.005")
    p.add_argument("--variants", default="scalar_rgb,llvm_ad_rgb")
    p.add_argument("--samplers", default="independent,stratified,multijitter")
    p.add_argument("--max-spp", type=int, default=4096)
    p.add_argument("--threads", type=int, default=0, help="tracelab's render threads (0 = all cores); pin both with taskset")
    p.add_argument("--reference", default=os.path.join(REPO, "tests/data/cornell_box_path_ref.exr"))
    p.add_argument("--tracelab", default=os.path.join(REPO, "target/release/tracelab"))
    p.add_argument(
        "--configs",
        default="path:independent,path:stratified,path:multijitter,path:sobol,"
        "mcrt:independent:shadow-rays=1:glossy-rays=1,light:independent",
    )
    args = p.parse_args()
    targets = [float(t) for t in args.targets.split(",")]

    # This file is itself called mitsuba.py: keep its folder off the import
    # path so that `import mitsuba` finds the package.
    sys.path[:] = [d for d in sys.path if os.path.abspath(d or ".") != HERE]
    sys.modules.pop("mitsuba", None)
    try:
        import mitsuba as mi
        import numpy as np
    except ImportError as e:
        sys.exit(f"{e}: pip install mitsuba numpy (and apt-get install libllvm19 for llvm_ad_rgb)")

    mi.set_variant("scalar_rgb")
    reference = np.array(mi.Bitmap(args.reference))[..., :3]
    print(f"machine: {os.cpu_count()} CPUs; targets {targets}; reference {args.reference}")

    rows = []
    for variant in args.variants.split(","):
        for sampler in args.samplers.split(","):
            try:
                pts = mitsuba_points(mi, variant, sampler, reference, targets, args.max_spp, os.cpu_count())
            except Exception as e:  # a variant missing on this machine
                print(f"mitsuba {variant} {sampler}: skipped ({e})")
                continue
            times = [time_to_rmse([(t, e) for t, e, _ in pts], target) for target in targets]
            rows.append((f"mitsuba {variant} {sampler}", times))
            print(f"mitsuba {variant:<12} {sampler:<12} " + "  ".join(
                f"{t:8.3f} s" if t else " not reached" for t in times)
                + "   (spp, s, RMSE: " + ", ".join(f"{s} {t:.3f} {e:.4f}" for t, e, s in pts) + ")")

    tl, _ = tracelab_times(args.tracelab, args.configs.split(","), targets, args.max_spp, args.reference, args.threads)
    for name, times in tl.items():
        rows.append((f"tracelab {name}", times))
        print(f"tracelab {name:<40} " + "  ".join(f"{t:8.3f} s" if t else " not reached" for t in times))

    print("\n| configuration | " + " | ".join(f"time to RMSE {t}" for t in targets) + " |")
    print("|---|" + "---|" * len(targets))
    for name, times in rows:
        print(f"| {name} | " + " | ".join(f"{t:.3f} s" if t else "not reached" for t in times) + " |")

    def best(prefix, i):
        vals = [t[i] for n, t in rows if n.startswith(prefix) and t[i]]
        return min(vals) if vals else None

    for i, target in enumerate(targets):
        ours = best("tracelab path", i)
        llvm = best("mitsuba llvm_ad_rgb", i)
        scalar = best("mitsuba scalar_rgb", i)
        if ours and llvm:
            print(f"RMSE {target}: tracelab best path tracing {ours:.3f} s = {ours / llvm:.2f} x Mitsuba LLVM's best ({llvm:.3f} s)"
                  + (f", {ours / scalar:.2f} x scalar's ({scalar:.3f} s)" if scalar else ""))


if __name__ == "__main__":
    main()
