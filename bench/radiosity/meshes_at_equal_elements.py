#!/usr/bin/env python3
"""Issue 39, Must 3: discontinuity meshing against adaptive subdivision at
equal element count on the Cornell box. Each mesh is solved over a grid of
starting patch sizes, adaptive rounds and tolerances; the lower envelope of
masked RMSE against elements (the configurations no other one beats with as
few elements) is printed per mesh kind, so that neither side is compared at
a configuration chosen for it.

    python3 bench/radiosity/meshes_at_equal_elements.py [--tracelab PATH]

Gauss-Seidel, smooth display, against tests/data/cornell_box_path_ref.exr.
"""
import argparse, itertools, subprocess

parser = argparse.ArgumentParser()
parser.add_argument("--tracelab", default="target/release/tracelab")
parser.add_argument("--sizes", default="0.1,0.12,0.15,0.2")
parser.add_argument("--rounds", default="1,2")
parser.add_argument("--tolerances", default="0.8,1,1.3")
parser.add_argument("--kinds", default="plain,lines,regular",
                    help="plain (adaptive subdivision), lines (discontinuity meshing first), "
                         "regular (its lines on the regular mesh: --lines-on-regular-mesh)")
args = parser.parse_args()

FLAGS = {"plain": [], "lines": ["--discontinuity-meshing"],
         "regular": ["--discontinuity-meshing", "--lines-on-regular-mesh"]}

def solve(size, rounds, tolerance, kind):
    command = [args.tracelab, "radiosity", "scenes/cornell_box.toml",
               "--reference", "tests/data/cornell_box_path_ref.exr",
               "--solver", "gauss-seidel", "--display", "smooth",
               "--patch-size", size, "--adaptive-rounds", rounds,
               "--adaptive-tolerance", tolerance]
    command += FLAGS[kind]
    out = subprocess.run(command, capture_output=True, text=True, check=True).stdout
    row = [l for l in out.splitlines() if l.strip() and l.split()[0].isdigit()][-1].split()
    # Columns: steps, elements, links, rays, bytes, solve s, residual, RMSE, masked RMSE.
    return int(row[1]), float(row[-1]), float(row[5])

def envelope(points):
    best, front = float("inf"), []
    for elements, rmse, config in sorted(points):
        if rmse < best:
            best = rmse
            front.append((elements, rmse, config))
    return front

grid = list(itertools.product(args.sizes.split(","), args.rounds.split(","),
                              args.tolerances.split(",")))
for kind in args.kinds.split(","):
    points = []
    for size, rounds, tolerance in grid:
        elements, rmse, seconds = solve(size, rounds, tolerance, kind)
        config = f"patch {size}, {rounds} rounds, tolerance {tolerance}"
        print(f"{kind}\t{elements}\t{rmse:.5f}\t{seconds:.1f} s\t{config}", flush=True)
        points.append((elements, rmse, config))
    print(f"\nlower envelope, {kind}:")
    for elements, rmse, config in envelope(points):
        print(f"  {elements:6d}  {rmse:.5f}  {config}")
    print(flush=True)
