#!/usr/bin/env python3
"""Issue 39, Must 3: discontinuity meshing against adaptive subdivision at
equal element count on the Cornell box. Each mesh is solved over a grid of
starting patch sizes, adaptive rounds and tolerances; the lower envelope of
masked RMSE against elements (the configurations no other one beats with as
few elements) is printed per mesh kind, so that neither side is compared at
a configuration chosen for it.

    python3 bench/radiosity/meshes_at_equal_elements.py [--tracelab PATH]

Gauss-Seidel, smooth display, against tests/data/cornell_box_path_ref.exr.
With --max-penumbrae the meshes with lines are also solved with each
--max-penumbra value; the element counts where the lines' envelope (all
their kinds together) is not below the plain one are printed last.
--min-angles sweeps --adaptive-min-angle for every kind alike, and
--min-piece-areas sweeps --min-piece-area for the regular kind.
"""
import argparse, itertools, subprocess

parser = argparse.ArgumentParser()
parser.add_argument("--tracelab", default="target/release/tracelab")
parser.add_argument("--sizes", default="0.1,0.12,0.15,0.2")
parser.add_argument("--rounds", default="1,2")
parser.add_argument("--tolerances", default="0.8,1,1.3")
parser.add_argument("--max-penumbrae", default="all",
                    help="for the kinds with lines: --max-penumbra values to sweep too "
                         "(comma-separated; all: every line)")
parser.add_argument("--min-angles", default="0",
                    help="--adaptive-min-angle values to sweep for every kind (comma-separated)")
parser.add_argument("--min-piece-areas", default="0",
                    help="--min-piece-area values to sweep for the regular kind (comma-separated)")
parser.add_argument("--kinds", default="plain,lines,regular",
                    help="plain (adaptive subdivision), lines (discontinuity meshing first), "
                         "regular (its lines on the regular mesh: --lines-on-regular-mesh)")
args = parser.parse_args()

FLAGS = {"plain": [], "lines": ["--discontinuity-meshing"],
         "regular": ["--discontinuity-meshing", "--lines-on-regular-mesh"]}

def solve(size, rounds, tolerance, kind, max_penumbra, min_angle, min_piece):
    command = [args.tracelab, "radiosity", "scenes/cornell_box.toml",
               "--reference", "tests/data/cornell_box_path_ref.exr",
               "--solver", "gauss-seidel", "--display", "smooth",
               "--patch-size", size, "--adaptive-rounds", rounds,
               "--adaptive-tolerance", tolerance, "--adaptive-min-angle", min_angle]
    command += FLAGS[kind]
    if kind != "plain" and max_penumbra != "all":
        command += ["--max-penumbra", max_penumbra]
    if kind == "regular":
        command += ["--min-piece-area", min_piece]
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

def configurations(kind):
    # Without rounds the tolerance does nothing: one run.
    sizes, rounds = args.sizes.split(","), args.rounds.split(",")
    tolerances = args.tolerances.split(",")
    penumbrae = ["all"] if kind == "plain" else args.max_penumbrae.split(",")
    angles = args.min_angles.split(",")
    pieces = args.min_piece_areas.split(",") if kind == "regular" else ["0"]
    for size, r, tolerance, m, a, piece in itertools.product(
            sizes, rounds, tolerances, penumbrae, angles, pieces):
        # Without rounds neither the tolerance nor the angle does anything.
        if r != "0" or (tolerance == tolerances[0] and a == angles[0]):
            yield size, r, tolerance, m, a, piece

envelopes = {}
for kind in args.kinds.split(","):
    points = []
    for size, rounds, tolerance, max_penumbra, min_angle, piece in configurations(kind):
        elements, rmse, seconds = solve(size, rounds, tolerance, kind, max_penumbra, min_angle,
                                        piece)
        config = f"patch {size}, {rounds} rounds, tolerance {tolerance}"
        if max_penumbra != "all":
            config += f", max penumbra {max_penumbra}"
        if min_angle != "0":
            config += f", min angle {min_angle}"
        if piece != "0":
            config += f", min piece area {piece}"
        print(f"{kind}\t{elements}\t{rmse:.5f}\t{seconds:.1f} s\t{config}", flush=True)
        points.append((elements, rmse, config))
    print(f"\nlower envelope, {kind}:")
    envelopes[kind] = envelope(points)
    for elements, rmse, config in envelopes[kind]:
        print(f"  {elements:6d}  {rmse:.5f}  {config}")
    print(flush=True)

def best_within(front, count):
    """The envelope's RMSE with at most `count` elements (None below its start)."""
    within = [rmse for elements, rmse, _ in front if elements <= count]
    return min(within) if within else None

# Where the meshes with lines lose: the element counts (from the smallest
# mesh either side has to the largest both grids reach) at which the best
# mesh with lines of at most that many elements is not below the best
# plain one.
if "plain" in envelopes and len(envelopes) > 1:
    lines = sorted(p for kind, front in envelopes.items() if kind != "plain" for p in front)
    plain = envelopes["plain"]
    counts = sorted({e for e, _, _ in plain} | {e for e, _, _ in lines})
    losing, start = [], None
    for i, count in enumerate(counts):
        ours, theirs = best_within(lines, count), best_within(plain, count)
        lost = ours is None or (theirs is not None and ours >= theirs)
        end = counts[i + 1] - 1 if i + 1 < len(counts) else count
        if lost:
            losing.append((count, end, ours, theirs))
    print("element counts where the meshes with lines are not below adaptive subdivision:")
    for count, end, ours, theirs in losing:
        print(f"  {count}-{end}: lines {ours}, plain {theirs}")
