#!/usr/bin/env python3
"""Form factor between two unit spheres whose centres are 3 apart, by Monte
Carlo (uniform points on the first, cosine-weighted directions, the fraction
that hits the second): the reference of src/radiosity/cluster.rs's tests.
Usage: python3 bench/references/sphere_form_factor.py [samples]"""
import sys
import numpy as np

def chunk(rng, n, distance):
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], 1)
    helper = np.where(np.abs(p[:, 0:1]) > 0.9, [[0.0, 1, 0]], [[1.0, 0, 0]])
    t = np.cross(p, helper)
    t /= np.linalg.norm(t, axis=1)[:, None]
    b = np.cross(p, t)
    d = local[:, 0:1] * t + local[:, 1:2] * b + local[:, 2:3] * p
    oc = p - np.array([distance, 0.0, 0.0])
    bb = np.sum(d * oc, 1)
    disc = bb * bb - (np.sum(oc * oc, 1) - 1)
    return np.count_nonzero((disc > 0) & (-bb - np.sqrt(np.maximum(disc, 0)) > 0))

n = int(sys.argv[1]) if len(sys.argv) > 1 else 40_000_000
rng = np.random.default_rng(2026)
hits = sum(chunk(rng, 1_000_000, 3.0) for _ in range(n // 1_000_000))
f = hits / n
print(f"F = {f:.6f} +- {np.sqrt(f * (1 - f) / n):.6f} ({n} samples)")
