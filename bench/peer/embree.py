#!/usr/bin/env python3
"""Embree on the rays of `cargo bench --bench scaling`.

Runs the scaling benchmark with `--export` (UV spheres of 10^3..10^6
triangles and 2^20 incoherent and 2^20 coherent rays, written as raw f32),
traces the same rays with Embree through embreex, and prints Embree's rays/s
next to tracelab's, per thread. Not part of `cargo test`.

    pip install embreex numpy
    python3 bench/peer/embree.py            # builds and runs the benchmark
    python3 bench/peer/embree.py --reuse    # reuse an earlier export

embreex calls rtcIntersect1 / rtcOccluded1 ray by ray from one thread, so
its figures are one core's (the CPU-time column checks that); tracelab's
one-thread column is the fair comparison.
"""
import argparse
import csv
import os
import resource
import subprocess
import sys
import time

import numpy as np
from embreex import rtcore as rtc
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def load_rays(path):
    rays = np.fromfile(path, dtype="<f4").reshape(-1, 6)
    return np.ascontiguousarray(rays[:, :3]), np.ascontiguousarray(rays[:, 3:])


def median_rate(scene, origins, directions, query, repeats=3):
    rates, cpu_ratio = [], []
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), cpu_seconds()
        scene.run(origins, directions, query=query)
        wall, cpu = time.perf_counter() - wall, cpu_seconds() - cpu
        rates.append(len(origins) / wall)
        cpu_ratio.append(cpu / wall)
    return float(np.median(rates)), float(np.median(cpu_ratio))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dir", default=os.path.join(ROOT, "target", "ray_workload"))
    parser.add_argument("--reuse", action="store_true", help="skip running the tracelab benchmark")
    args = parser.parse_args()
    tracelab_csv = os.path.join(args.dir, "tracelab.csv")
    if not args.reuse:
        os.makedirs(args.dir, exist_ok=True)
        subprocess.run(
            ["cargo", "bench", "--bench", "scaling", "--", "--export", args.dir, "--csv", tracelab_csv],
            cwd=ROOT,
            check=True,
        )
    ours = {}
    with open(tracelab_csv) as f:
        for row in csv.DictReader(f):
            key = (int(row["triangles"]), row["query"], row["rays"], int(row["threads"]))
            ours[key] = float(row["mrays_per_s"])
    ray_sets = {kind: load_rays(os.path.join(args.dir, f"rays_{kind}.f32")) for kind in ["incoherent", "coherent"]}
    meshes = sorted(
        int(name[len("mesh_") : -len(".f32")]) for name in os.listdir(args.dir) if name.startswith("mesh_")
    )
    print("| triangles | query | rays | Embree Mrays/s (1 core) | Embree CPU/wall | tracelab 1 thread | tracelab / Embree |")
    print("|---:|---|---|---:|---:|---:|---:|")
    for count in meshes:
        vertices = np.fromfile(os.path.join(args.dir, f"mesh_{count}.f32"), dtype="<f4").reshape(-1, 3, 3)
        device = rtc.EmbreeDevice()
        scene = rtcs.EmbreeScene(device)
        TriangleMesh(scene, vertices)
        for query, name in [("INTERSECT", "closest"), ("OCCLUDED", "any")]:
            for kind, (origins, directions) in ray_sets.items():
                rate, cpu_ratio = median_rate(scene, origins, directions, query)
                mine = ours.get((count, name, kind, 1), float("nan"))
                print(
                    f"| {count} | {name} | {kind} | {rate / 1e6:.2f} | {cpu_ratio:.2f} | {mine:.2f} | {mine / (rate / 1e6):.2f} |"
                )
                sys.stdout.flush()


if __name__ == "__main__":
    main()
