#!/usr/bin/env python3
"""Scene load time and peak memory, tracelab against Mitsuba 3, same files.

Each measurement is its own process, run `--runs` times, the two
renderers alternating (the median is printed, with the range). Mitsuba:
`mi.load_file` timed inside the process (its import and variant set-up
not counted), peak RSS of the process, and
the RSS its import and set-up alone reach (loading the empty scene), so
that what the scene costs can be told from what the library costs.
tracelab: the load time of its render summary (parse, meshes, textures,
BVH) and the process's peak RSS for a 1-spp render at 64 x 64.

    pip install mitsuba   # and apt-get install libllvm19
    python3 bench/peer/load.py SCENE.xml [SCENE.xml ...] [--tracelab target/release/tracelab]

Bitterli's interiors in Mitsuba 0.6 form (staircase, living-room, kitchen;
CC-BY, credits in each folder's LICENSE.txt) come with
github.com/jgarciapueyo/mitsuba2-transient-scenes; Mitsuba 3 reads their
0.5 camelCase names after upgrading them, as tracelab does. That
repository lacks 6 of the kitchen's mesh files (Mesh054, 090, 145, 273,
275, 294): measure a copy of its scene.xml without the shapes that name
them.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))

MITSUBA = r"""
import resource, sys, time
import mitsuba as mi
mi.set_variant(sys.argv[2])
if sys.argv[1] == "-":
    mi.load_dict({"type": "scene"})
    print(0.0, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
else:
    t = time.perf_counter()
    scene = mi.load_file(sys.argv[1])
    seconds = time.perf_counter() - t
    print(seconds, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def for_mitsuba(scene):
    """A copy beside `scene` without the film properties Mitsuba 3 refuses
    as unreferenced (living-room's highQualityEdges, which tracelab reads
    and ignores as an output setting)."""
    text = open(scene).read()
    cleaned = re.sub(r'<boolean name="(highQualityEdges|high_quality_edges)"[^>]*/>', "", text)
    if cleaned == text:
        return scene
    copy = os.path.join(os.path.dirname(scene), ".mitsuba3_" + os.path.basename(scene))
    with open(copy, "w") as f:
        f.write(cleaned)
    return copy


def mitsuba(scene, variant):
    # Run where this folder's mitsuba.py cannot shadow the package.
    out = subprocess.run(
        [sys.executable, "-c", MITSUBA, scene if scene == "-" else for_mitsuba(scene), variant],
        capture_output=True, text=True, check=True, cwd="/",
    ).stdout.split()
    return float(out[-2]), int(out[-1]) / 1024


def tracelab(binary, scene):
    r = subprocess.run(
        ["/usr/bin/time", "-f", "maxrss %M", binary, "render", scene, "--spp", "1",
         "--width", "64", "--height", "64", "--out", "/tmp/load_probe.exr"],
        capture_output=True, text=True, check=True,
    )
    seconds = float(re.search(r"scene loaded in ([0-9.]+) s", r.stderr).group(1))
    rss = int(re.search(r"maxrss (\d+)", r.stderr).group(1)) / 1024
    return seconds, rss


def summary(values):
    return f"{statistics.median(values):.2f} ({min(values):.2f}-{max(values):.2f})"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--tracelab", default=os.path.join(REPO, "target/release/tracelab"))
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    base = [mitsuba("-", args.variant)[1] for _ in range(args.runs)]
    print(f"Mitsuba {args.variant} with an empty scene: peak RSS {summary(base)} MiB")
    print("scene | Mitsuba load s | Mitsuba peak RSS MiB | tracelab load s | tracelab peak RSS MiB")
    for scene in args.scenes:
        scene = os.path.abspath(scene)
        # Alternating, so that a busy or idle spell of the machine falls on both.
        m, t = [], []
        for _ in range(args.runs):
            m.append(mitsuba(scene, args.variant))
            t.append(tracelab(args.tracelab, scene))
        print(f"{scene} | {summary([x[0] for x in m])} | {summary([x[1] for x in m])} | "
              f"{summary([x[0] for x in t])} | {summary([x[1] for x in t])}")


if __name__ == "__main__":
    main()
