"""Mitsuba 3 references for tests/material_references.rs: one object per
material model on a grey floor under a square area light, 64 x 64.

Each reference is the mean of PASSES independent renders (seeds differ) of
SPP samples per pixel; `<name>_var.exr` holds the per-pixel variance of that
mean (the passes' sample variance / PASSES), which the test's tolerance uses.

The scene is the one `material_scene` in tests/material_references.rs writes
as TOML; keep the two in step. z is up.

Run: pip install mitsuba; python3 tests/data/materials/make_references.py
(Mitsuba 3.9.1, llvm_ad_rgb; needs libllvm19.)
"""
import sys
import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")

SPP = 2048
PASSES = 16
MAX_DEPTH = 9  # segments; tracelab's max_depth 8 (bounces)


def sphere(bsdf):
    return {"type": "sphere", "center": [0, 0, 0.6], "radius": 0.6, "bsdf": bsdf}


def panel(bsdf):
    # A 1.6 m square lying on the floor, normal +z, its tangent +x (the
    # frame tracelab builds for a +z normal), for anisotropic lobes.
    return {
        "type": "rectangle",
        "to_world": mi.ScalarTransform4f().translate([0, 0, 0.01]).scale(0.8),
        "bsdf": bsdf,
    }


def behind(bsdf):
    # The same square turned to face away from the camera (normal +y): its
    # back is what the camera sees.
    return {
        "type": "rectangle",
        "to_world": mi.ScalarTransform4f().translate([0, 0, 0.8]).rotate([1, 0, 0], -90).scale(0.8),
        "bsdf": bsdf,
    }


MATERIALS = {
    "roughconductor_ggx": sphere({"type": "roughconductor", "material": "Cu", "distribution": "ggx", "alpha": 0.2}),
    "roughconductor_beckmann": sphere({"type": "roughconductor", "material": "Cr", "distribution": "beckmann", "alpha": 0.3}),
    "roughconductor_anisotropic": panel({"type": "roughconductor", "material": "Al", "distribution": "ggx", "alpha_u": 0.05, "alpha_v": 0.4}),
    "conductor_gold": sphere({"type": "conductor", "material": "Au"}),
    "roughdielectric": sphere({"type": "roughdielectric", "int_ior": "bk7", "distribution": "ggx", "alpha": 0.15}),
    "thindielectric": sphere({"type": "thindielectric", "int_ior": "bk7"}),
    "plastic": sphere({"type": "plastic", "diffuse_reflectance": {"type": "rgb", "value": [0.7, 0.1, 0.05]}}),
    "roughplastic": sphere({"type": "roughplastic", "distribution": "ggx", "alpha": 0.2,
                            "diffuse_reflectance": {"type": "rgb", "value": [0.1, 0.3, 0.7]}}),
    "roughplastic_nonlinear": sphere({"type": "roughplastic", "distribution": "beckmann", "alpha": 0.3, "nonlinear": True,
                                      "diffuse_reflectance": {"type": "rgb", "value": [0.1, 0.3, 0.7]}}),
    "onesided_back": behind({"type": "roughconductor", "material": "Au", "distribution": "ggx", "alpha": 0.3}),
    "twosided_back": behind({"type": "twosided", "bsdf": {"type": "roughconductor", "material": "Au", "distribution": "ggx", "alpha": 0.3}}),
}


PLASTIC = sphere({"type": "plastic", "diffuse_reflectance": {"type": "rgb", "value": [0.7, 0.1, 0.05]}})
# The plastic sphere again through Mitsuba's tent and Gaussian filters.
FILTERS = {
    "filter_tent": (PLASTIC, {"type": "tent"}),
    "filter_gaussian": (PLASTIC, {"type": "gaussian"}),
}


def checks(scale, c0, c1):
    return {"type": "checkerboard", "to_uv": mi.ScalarTransform3f().scale([scale, scale]),
            "color0": {"type": "rgb", "value": c0}, "color1": {"type": "rgb", "value": c1}}


# Textures: a checkerboard floor (checks of 2 m) under a diffuse sphere with
# a checkerboard of 8 x 8 checks in its (phi / 2 pi, theta / pi) coordinates.
TEXTURED = {
    "textured_diffuse": (
        sphere({"type": "diffuse", "reflectance": checks(8, [0.7, 0.6, 0.1], [0.1, 0.2, 0.6])}),
        {"type": "diffuse", "reflectance": checks(20, [0.6, 0.6, 0.6], [0.1, 0.1, 0.1])},
    ),
}


# Light from infinity, beside the area light: a constant environment, and a
# synthetic sky (sky.exr, 64 x 32: a blue gradient, brown ground and a
# 3 x 2-texel sun of radiance 800) lighting a copper sphere.
ENVIRONMENTS = {
    "environment_constant": (
        sphere({"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.6, 0.6, 0.6]}}),
        {"type": "constant", "radiance": {"type": "rgb", "value": [0.3, 0.35, 0.4]}},
    ),
    "environment_map": (
        sphere({"type": "roughconductor", "material": "Cu", "distribution": "ggx", "alpha": 0.2}),
        {"type": "envmap", "filename": "sky.exr", "scale": 0.5},
    ),
}


# Delta lights beside the area light: a spot aimed at the sphere's side and
# parallel light grazing in from the left.
GREY = sphere({"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.6, 0.6, 0.6]}})
LIGHTS = {
    "light_spot": (GREY, {"type": "spot", "intensity": {"type": "rgb", "value": [20, 18, 15]},
                          "cutoff_angle": 25, "beam_width": 15,
                          "to_world": mi.ScalarTransform4f().look_at(origin=[-2, -2, 2], target=[0, 0, 0.3], up=[0, 0, 1])}),
    "light_directional": (GREY, {"type": "directional", "irradiance": {"type": "rgb", "value": [1.5, 1.2, 0.9]},
                                 "direction": [0.8, 0.3, -0.5]}),
}


def write_bumps(path="bumps.exr", size=64):
    """A tangent-space normal map of 4 x 4 bumps: the normal
    normalize(0.15 sin(8 pi u), 0.15 cos(8 pi v), 1), stored as (n + 1) / 2.
    Mild on purpose: where a normal tilts far (0.4 here gave our mean 0.9%
    above Mitsuba's), Mitsuba drops light whose direction lies on different
    sides of the tilted and the untilted normal, and tracelab does not."""
    u = (np.arange(size) + 0.5) / size
    uu, vv = np.meshgrid(u, u)
    n = np.stack([0.15 * np.sin(8 * np.pi * uu), 0.15 * np.cos(8 * np.pi * vv), np.ones_like(uu)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    mi.Bitmap(((n + 1) / 2).astype(np.float32)).write(path)


def write_heights(path="heights.exr", size=64):
    """A height field of 4 x 4 bumps for Mitsuba's bumpmap:
    h = 0.5 + 0.5 sin(8 pi u) sin(8 pi v), grey."""
    u = (np.arange(size) + 0.5) / size
    uu, vv = np.meshgrid(u, u)
    h = 0.5 + 0.5 * np.sin(8 * np.pi * uu) * np.sin(8 * np.pi * vv)
    mi.Bitmap(np.repeat(h[..., None], 3, -1).astype(np.float32)).write(path)


# A normal map (bumps.exr, made by write_bumps) and a bump map (heights.exr,
# scale 0.05: normals tilt by up to about 0.17) on a rough copper sphere.
NORMALMAPS = {
    "bumpmap": sphere({"type": "bumpmap", "scale": 0.05,
                       "heights": {"type": "bitmap", "filename": "heights.exr", "raw": True},
                       "bsdf": {"type": "roughconductor", "material": "Cu", "distribution": "ggx", "alpha": 0.2}}),
    "normalmap": sphere({"type": "normalmap",
                         "normalmap": {"type": "bitmap", "filename": "bumps.exr", "raw": True},
                         "bsdf": {"type": "roughconductor", "material": "Cu", "distribution": "ggx", "alpha": 0.2}}),
}


def scene(obj, rfilter=None, floor_bsdf=None, environment=None):
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": 35,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, -4, 2.5], target=[0, 0, 0.5], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": 64, "height": 64, "rfilter": rfilter or {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": SPP},
        },
        "floor": {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().scale(20),
            "bsdf": floor_bsdf or {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.4, 0.4, 0.4]}},
        },
        # 2 m square at (1.2, -1.2, 3), facing down: large, so that the
        # caustics of Dirac spheres (found by BSDF sampling from the floor)
        # are not rare events that a 256-spp standard error misses.
        "light": {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().translate([1.2, -1.2, 3]).rotate([1, 0, 0], 180),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [3, 3, 3]}},
        },
        "object": obj,
        **({"extra_light": environment} if environment else {}),
    }


def main(names):
    jobs = {name: (obj, None, None) for name, obj in MATERIALS.items()}
    jobs |= {name: (obj, rfilter, None) for name, (obj, rfilter) in FILTERS.items()}
    jobs = {name: (obj, rfilter, floor, None) for name, (obj, rfilter, floor) in jobs.items()}
    jobs |= {name: (obj, None, floor, None) for name, (obj, floor) in TEXTURED.items()}
    jobs |= {name: (obj, None, None, env) for name, (obj, env) in ENVIRONMENTS.items()}
    jobs |= {name: (obj, None, None, light) for name, (obj, light) in LIGHTS.items()}
    jobs |= {name: (obj, None, None, None) for name, obj in NORMALMAPS.items()}
    write_bumps()
    write_heights()
    for name, (obj, rfilter, floor, env) in jobs.items():
        if names and name not in names:
            continue
        s = mi.load_dict(scene(obj, rfilter, floor, env))
        passes = np.stack([np.array(mi.render(s, seed=1000 * k + 7)) for k in range(PASSES)])
        mean = passes.mean(axis=0)
        var = passes.var(axis=0, ddof=1) / PASSES
        mi.Bitmap(mean.astype(np.float32)).write(f"{name}.exr")
        mi.Bitmap(var.astype(np.float32)).write(f"{name}_var.exr")
        print(f"{name}: mean {mean.reshape(-1, 3).mean(axis=0)}, rms se {np.sqrt(var.mean()):.5f}")


if __name__ == "__main__":
    main(sys.argv[1:])
