#!/usr/bin/env python3
"""Mitsuba 3's `principled` BSDF evaluated at fixed direction pairs, for
the unit test that holds tracelab's model to it
(tests/data/principled_mitsuba.txt).

Each line: parameter set, wo (towards the camera, Mitsuba's si.wi), wi
(towards the light, Mitsuba's wo), and f(wo, wi) in RGB without the
cosine (Mitsuba's eval divided by |wi.z|), all in the local frame.

    pip install mitsuba
    python3 bench/peer/principled_eval.py > tests/data/principled_mitsuba.txt
"""

import math
import os
import random
import sys

# Run where this folder's scripts cannot shadow the package.
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != os.path.dirname(os.path.abspath(__file__))]
import mitsuba as mi  # noqa: E402

mi.set_variant("scalar_rgb")

# The parameter sets, in the order the test builds them.
SETS = [
    {},
    {"base_color": [0.8, 0.3, 0.2], "roughness": 0.3, "metallic": 0.6, "spec_tint": 0.5,
     "sheen": 0.7, "sheen_tint": 0.4, "clearcoat": 0.8, "clearcoat_gloss": 0.6, "specular": 0.7},
    {"base_color": [0.2, 0.6, 0.9], "roughness": 0.4, "anisotropic": 0.6, "flatness": 0.5},
    {"base_color": [0.9, 0.9, 0.6], "roughness": 0.3, "spec_trans": 0.7, "eta": 1.45,
     "metallic": 0.2},
]


def direction(rng, below):
    z = rng.uniform(0.05, 1.0)
    phi = rng.uniform(0, 2 * math.pi)
    s = math.sqrt(1 - z * z)
    return [s * math.cos(phi), s * math.sin(phi), -z if below else z]


def main():
    rng = random.Random(7)
    ctx = mi.BSDFContext()
    for index, params in enumerate(SETS):
        d = {"type": "principled"}
        for key, value in params.items():
            d[key] = {"type": "rgb", "value": value} if isinstance(value, list) else value
        bsdf = mi.load_dict(d)
        transmits = "spec_trans" in params
        for _ in range(40):
            wo_below = transmits and rng.random() < 0.3
            wi_below = transmits and rng.random() < 0.5
            wo, wi = direction(rng, wo_below), direction(rng, wi_below)
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(wo)
            si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
            value = bsdf.eval(ctx, si, mi.Vector3f(wi))
            f = [float(value[c]) / abs(wi[2]) for c in range(3)]
            print(index, *(f"{x:.7g}" for x in wo + wi + f))


if __name__ == "__main__":
    main()
