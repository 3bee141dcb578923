#!/usr/bin/env python3
"""Where tracelab and Mitsuba 3 differ on one scene file, by blocks of pixels.

Two Mitsuba 3 renders (seeds 7 and 9) give the reference and its own
seed-to-seed noise; one tracelab render is compared with their mean. Printed:
per-pixel RMSE, each channel's mean as a fraction of Mitsuba's, the RMSE of
B × B block means (tracelab's against Mitsuba's seed-to-seed figure), the
share of tracelab's squared error in its worst 1% of pixels, and the blocks'
relative differences, (tracelab − Mitsuba) / (Mitsuba + 0.05), averaged over
channels. A block far outside the rest is a difference in the scene as read,
not noise (living-room's mirrors, read as copper until 1034a10).

    python3 bench/peer/blocks_vs_mitsuba.py living-room/scene.xml --width 160 --height 90 \
        --mitsuba-spp 8192 --tracelab-spp 4096
"""
import argparse
import os
import re
import subprocess
import sys

sys.path.append(os.path.dirname(os.path.abspath(__file__)))
from mitsuba_scenes import REPO, load_copy, mi  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=90)
    ap.add_argument("--mitsuba-spp", type=int, default=8192)
    ap.add_argument("--tracelab-spp", type=int, default=4096)
    ap.add_argument("--sampler", default="sobol", help="tracelab's sampler")
    ap.add_argument("--block", type=int, default=10)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--tracelab", default=os.path.join(REPO, "target/release/tracelab"))
    args = ap.parse_args()
    mi.set_variant(args.variant)
    path = os.path.abspath(args.scene)

    # Resolution and spp written into a copy beside the file (0.6 files
    # take no parameters), as mitsuba_scenes.py does.
    text = open(load_copy(path)).read()
    for key, value in (("width", args.width), ("height", args.height),
                       ("sampleCount|sample_count", args.mitsuba_spp)):
        text = re.sub(rf'(<integer name="(?:{key})" value=")\d+', rf"\g<1>{value}", text)
    copy = os.path.join(os.path.dirname(path), ".blocks_vs_mitsuba.xml")
    with open(copy, "w") as f:
        f.write(text)
    try:
        scene = mi.load_file(copy)
    finally:
        os.remove(copy)
    a, b = (np.array(mi.render(scene, seed=s, spp=args.mitsuba_spp))[..., :3] for s in (7, 9))

    out = "/tmp/blocks_vs_mitsuba.exr"
    subprocess.run([args.tracelab, "render", path, "--width", str(args.width),
                    "--height", str(args.height), "--integrator", "path", "--sampler",
                    args.sampler, "--spp", str(args.tracelab_spp), "--out", out],
                   check=True, capture_output=True)
    t = np.array(mi.Bitmap(out))[..., :3]

    def rmse(x, y):
        return float(np.sqrt(np.mean((x - y) ** 2)))

    def blocks(x):
        k = args.block
        h, w = x.shape[0] // k * k, x.shape[1] // k * k
        return x[:h, :w].reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))

    m = (a + b) / 2
    print(f"Mitsuba seed-to-seed RMSE {rmse(a, b):.5f}; tracelab against their mean {rmse(t, m):.5f}")
    print("means, tracelab / Mitsuba:", np.round(t.mean(axis=(0, 1)) / m.mean(axis=(0, 1)), 5))
    A, B, T = blocks(a), blocks(b), blocks(t)
    print(f"{args.block}x{args.block} block RMSE: Mitsuba seed-to-seed {rmse(A, B):.5f}, "
          f"tracelab against Mitsuba's mean {rmse(T, (A + B) / 2):.5f}")
    err = ((t - m) ** 2).mean(axis=2).ravel()
    worst = np.sort(err)[::-1][: max(1, err.size // 100)].sum() / err.sum()
    print(f"share of tracelab's squared error in its worst 1% of pixels: {worst:.2f}")
    relative = ((T - (A + B) / 2) / ((A + B) / 2 + 0.05)).mean(axis=2)
    np.set_printoptions(precision=3, suppress=True, linewidth=200)
    print("relative block differences:")
    print(relative)


if __name__ == "__main__":
    main()
