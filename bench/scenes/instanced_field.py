#!/usr/bin/env python3
"""Writes an instanced Mitsuba 3 scene: one UV sphere of about 100k
triangles (a binary PLY) in a `shapegroup`, placed 10 x 10 times on a
floor by `instance`s (10M triangles drawn), under an area light. What
instancing saves: tracelab and Mitsuba store the sphere once.

    python3 bench/scenes/instanced_field.py OUT_DIR [--side 10] [--segments 224]
    target/release/tracelab render OUT_DIR/field.xml --spp 4 --out field.exr
    python3 bench/peer/load.py OUT_DIR/field.xml   # beside Mitsuba 3
"""

import argparse
import math
import os
import struct


def sphere_ply(path, nu, nv):
    """A unit UV sphere of nu x nv quads (2 nu (nv - 1) triangles, the
    poles' fans single triangles), vertex normals, binary PLY."""
    vertices = []
    for j in range(nv + 1):
        theta = math.pi * j / nv
        for i in range(nu):
            phi = 2.0 * math.pi * i / nu
            n = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))
            vertices.append(n)
    faces = []
    for j in range(nv):
        for i in range(nu):
            a, b = j * nu + i, j * nu + (i + 1) % nu
            c, d = (j + 1) * nu + (i + 1) % nu, (j + 1) * nu + i
            # Rows 0 and nv are the poles: one triangle of each quad there.
            if j < nv - 1:
                faces.append((a, d, c))
            if j > 0:
                faces.append((a, c, b))
    with open(path, "wb") as f:
        f.write(
            (
                "ply\nformat binary_little_endian 1.0\n"
                f"element vertex {len(vertices)}\n"
                "property float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\n"
                f"element face {len(faces)}\n"
                "property list uchar int vertex_indices\nend_header\n"
            ).encode()
        )
        for v in vertices:
            f.write(struct.pack("<6f", *v, *v))
        for face in faces:
            f.write(struct.pack("<B3i", 3, *face))
    return len(faces)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--side", type=int, default=10, help="instances per row")
    parser.add_argument("--segments", type=int, default=320, help="sphere segments around")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    triangles = sphere_ply(os.path.join(args.out, "ball.ply"), args.segments, args.segments // 2)
    side = args.side
    extent = 3.0 * side
    instances = []
    for i in range(side):
        for j in range(side):
            x, z = 3.0 * (i - (side - 1) / 2), 3.0 * (j - (side - 1) / 2)
            scale = 0.8 + 0.4 * ((i * 7 + j * 3) % 5) / 4
            instances.append(
                f'  <shape type="instance"><ref id="ball"/><transform name="to_world">'
                f'<rotate y="1" angle="{(i * 37 + j * 11) % 360}"/>'
                f'<scale value="{scale:.3f}"/><translate x="{x}" y="{scale:.3f}" z="{z}"/>'
                "</transform></shape>"
            )
    xml = f"""<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0, {0.6 * extent}, {1.1 * extent}" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="640"/><integer name="height" value="400"/>
      <rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.6"/></bsdf>
  <shape type="shapegroup" id="ball">
    <shape type="ply"><string name="filename" value="ball.ply"/>
      <bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.5, 0.3, 0.2"/><float name="alpha" value="0.2"/></bsdf>
    </shape>
  </shape>
{chr(10).join(instances)}
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="{extent}"/></transform>
    <ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><scale value="{extent / 4}"/><translate y="{extent}"/></transform>
    <emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
</scene>
"""
    with open(os.path.join(args.out, "field.xml"), "w") as f:
        f.write(xml)
    print(f"{args.out}/field.xml: {side * side} instances of {triangles} triangles "
          f"({side * side * triangles} drawn)")


if __name__ == "__main__":
    main()
