"""Probes of Mitsuba plugins: small scenes written as Mitsuba 3 XML, each
rendered by Mitsuba 3 (scalar_rgb) and by tracelab with several
techniques; prints both image means with the standard error over seeds.
Emitter shapes and transforms, furnaces of every BSDF, textures and their
wrap and filter modes, environment maps, masks, normal maps and blends.
The figures of docs/validation.md, "Probes of Mitsuba plugins".

Run: pip install mitsuba numpy; cargo build --release;
python3 bench/peer/plugin_probes.py [--only disk,blend] [--techniques path,bdpt]
    [--seeds 4] [--spp 1024] [--dir /tmp/probes]
"""
import argparse
import os
import subprocess
import sys

import numpy as np

# bench/peer/mitsuba (the Cornell box's meshes) would shadow the package.
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != HERE]
import mitsuba as mi  # noqa: E402

mi.set_variant("scalar_rgb")


def write_scenes():
    HEAD='''<scene version="3.0.0">
      <integrator type="path"><integer name="max_depth" value="{depth}"/></integrator>
      <sensor type="perspective"><float name="fov" value="{fov}"/>
        <transform name="to_world"><lookat origin="{origin}" target="{target}" up="{up}"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="48"/><rfilter type="box"/></film>
      </sensor>
    '''
    FLOOR='''  <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
    '''
    OBL=dict(depth=2,fov=40,origin="0, -6, 3",target="0, 0, 0",up="0, 0, 1")
    scenes={
     'disk': FLOOR+'''  <shape type="disk"><transform name="to_world"><rotate x="1" angle="180"/><translate z="2"/></transform>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>''',
     'disk_squash': FLOOR+'''  <shape type="disk"><transform name="to_world"><scale x="2" y="0.5" z="1"/><rotate x="1" angle="180"/><translate z="2"/></transform>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>''',
     'cylinder': FLOOR+'''  <shape type="cylinder"><point name="p0" x="-1" y="0" z="1"/><point name="p1" x="1" y="0.5" z="1.5"/><float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>''',
     'cylinder_scaled': FLOOR+'''  <shape type="cylinder"><transform name="to_world"><scale x="0.3" y="0.3" z="2"/><rotate y="1" angle="90"/><translate x="-1" z="1"/></transform>
        <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>''',
     'rect_shear': FLOOR+'''  <shape type="rectangle"><transform name="to_world"><matrix value="1 0.6 0 0  0 0.4 0.3 0  0 0 -1 2  0 0 0 1"/></transform>
        <emitter type="area"><rgb name="radiance" value="4"/></emitter></shape>''',
     'cube': FLOOR+'''  <shape type="cube"><transform name="to_world"><scale x="0.5" y="0.3" z="0.2"/><rotate z="1" angle="30"/><translate z="1.5"/></transform>
        <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>''',
     'directional': FLOOR+'''  <emitter type="directional"><vector name="direction" x="0.3" y="0.5" z="-1"/><rgb name="irradiance" value="2"/></emitter>''',
     'point': FLOOR+'''  <emitter type="point"><point name="position" x="0.3" y="0.2" z="1.5"/><rgb name="intensity" value="4"/></emitter>''',
     'sphere_squash': FLOOR+'''  <shape type="sphere"><transform name="to_world"><scale x="0.5" y="0.5" z="0.5"/><translate z="1.5"/></transform>
        <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>''',
     'obj_scaled': FLOOR+'''  <shape type="obj"><string name="filename" value="tri.obj"/><transform name="to_world"><scale x="2" y="0.3" z="1"/><rotate x="1" angle="25"/><translate z="1.5"/></transform>
        <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>''',
    }
    open('tri.obj','w').write('v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n')
    for n,b in scenes.items():
        open(n+'.xml','w').write(HEAD.format(**OBL)+b+'\n</scene>\n')
    # furnace-type: constant env, spheres
    ENV=dict(depth=64,fov=30,origin="0, -5, 0",target="0, 0, 0",up="0, 0, 1")
    env='  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>\n'
    mats={
     'glass_furnace':'<bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>',
     'roughglass':'<bsdf type="roughdielectric"><float name="alpha" value="0.2"/><float name="int_ior" value="1.5"/></bsdf>',
     'plastic':'<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.5"/></bsdf>',
     'roughplastic':'<bsdf type="roughplastic"><float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.5"/></bsdf>',
     'thindielectric':'<bsdf type="thindielectric"><float name="int_ior" value="1.5"/></bsdf>',
     'conductor_au':'<bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.1"/></bsdf>',
     'coated':'<bsdf type="roughplastic"><string name="distribution" value="ggx"/><float name="alpha" value="0.05"/><rgb name="diffuse_reflectance" value="0.8"/></bsdf>',
     'lambert_furnace':'<bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>',
    }
    for n,m in mats.items():
        open(n+'.xml','w').write(HEAD.format(**ENV)+env+'  <shape type="sphere"><float name="radius" value="1"/>'+m+'</shape>\n</scene>\n')

    H,W=64,128
    env=np.full((H,W,3),0.2,np.float32)
    env[:H//2,:,2]+=0.3   # bluer upper half
    env[10:12,40:42,:]=[800,700,500]   # small sun
    mi.Bitmap(env).write('env.exr')
    tex=np.zeros((8,8,3),np.float32)
    for i in range(8):
      for j in range(8): tex[i,j]=[0.8,0.2,0.1] if (i+j)%2 else [0.1,0.6,0.9]
    mi.Bitmap(tex).write('checker.exr')
    grad=np.zeros((16,32,3),np.float32); grad[:,:,0]=np.linspace(0,10,32)[None,:]; grad[:,:,1]=np.linspace(0,5,16)[:,None]; grad[:,:,2]=2
    mi.Bitmap(grad).write('grad.exr')
    # The same head, at the oblique view of the emitter probes.
    HEAD = HEAD.replace("{fov}", "40").replace("{origin}", OBL["origin"]).replace(
        "{target}", OBL["target"]).replace("{up}", OBL["up"])
    TEXFLOOR='''  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
        <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="checker.exr"/>{filt}
          <transform name="to_uv"><scale x="{su}" y="{sv}"/><translate x="0.1"/></transform></texture></bsdf></shape>
    '''
    SUN='''  <shape type="sphere"><point name="center" x="1" y="1" z="3"/><float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="30"/></emitter></shape>
    '''
    S={
     'envmap': HEAD.format(depth=3)+FLOOR+'''  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0" z="0.7"/><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
      <emitter type="envmap"><string name="filename" value="env.exr"/></emitter>''',
     'envmap_rot': HEAD.format(depth=3)+FLOOR+'''  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0" z="0.7"/><bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf></shape>
      <emitter type="envmap"><string name="filename" value="env.exr"/><float name="scale" value="0.5"/><transform name="to_world"><rotate x="1" angle="90"/><rotate z="1" angle="40"/></transform></emitter>''',
     'texfloor_bilinear': HEAD.format(depth=2)+TEXFLOOR.format(filt='',su=3,sv=2)+SUN,
     'texfloor_nearest': HEAD.format(depth=2)+TEXFLOOR.format(filt='<string name="filter_type" value="nearest"/>',su=3,sv=2)+SUN,
     'texfloor_clamp': HEAD.format(depth=2)+TEXFLOOR.format(filt='<string name="wrap_mode" value="clamp"/>',su=1.5,sv=1.2)+SUN,
     'texfloor_mirror': HEAD.format(depth=2)+TEXFLOOR.format(filt='<string name="wrap_mode" value="mirror"/>',su=2.5,sv=1.7)+SUN,
     'texlight': HEAD.format(depth=2)+FLOOR+'''  <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="1"/><rotate x="1" angle="160"/><translate z="1.5"/></transform>
        <emitter type="area"><texture type="bitmap" name="radiance"><string name="filename" value="grad.exr"/></texture></emitter></shape>''',
     'twosided_light': HEAD.format(depth=3)+FLOOR+'''  <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="1"/><rotate x="1" angle="70"/><translate z="1.2"/></transform>
        <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf></bsdf>
        <emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>''',
     'blend': HEAD.format(depth=3)+FLOOR+SUN+'''  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0" z="0.7"/>
        <bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf><bsdf type="roughconductor"><float name="alpha" value="0.1"/></bsdf></bsdf></shape>''',
     'mask': HEAD.format(depth=3)+FLOOR+SUN+'''  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="20"/><translate z="1.5"/></transform>
        <bsdf type="mask"><texture type="bitmap" name="opacity"><string name="filename" value="checker.exr"/><string name="filter_type" value="nearest"/></texture><bsdf type="diffuse"/></bsdf></shape>''',
     'normalmap': HEAD.format(depth=3)+FLOOR+SUN+'''  <shape type="rectangle"><transform name="to_world"><scale value="2"/><translate z="0.01"/></transform>
        <bsdf type="normalmap"><texture type="bitmap" name="normalmap"><string name="filename" value="checker.exr"/><boolean name="raw" value="true"/></texture><bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></bsdf></shape>''',
     'principled': HEAD.format(depth=3)+FLOOR+SUN+'''  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0" z="0.7"/>
        <bsdf type="principled"><rgb name="base_color" value="0.7,0.3,0.2"/><float name="metallic" value="0.3"/><float name="roughness" value="0.4"/></bsdf></shape>''',
     'principled_lobes': HEAD.format(depth=3)+FLOOR+SUN+'''  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0" z="0.7"/>
        <bsdf type="principled"><rgb name="base_color" value="0.2,0.5,0.8"/><float name="roughness" value="0.3"/><float name="anisotropic" value="0.5"/>
        <float name="spec_tint" value="0.5"/><float name="sheen" value="0.8"/><float name="sheen_tint" value="0.5"/><float name="flatness" value="0.4"/>
        <float name="clearcoat" value="1"/><float name="clearcoat_gloss" value="0.7"/><float name="specular" value="0.6"/></bsdf></shape>''',
     'principled_glass': HEAD.format(depth=6)+FLOOR+SUN+'''  <shape type="sphere"><float name="radius" value="0.7"/><point name="center" x="0" y="0" z="0.7"/>
        <bsdf type="principled"><rgb name="base_color" value="0.9,0.8,0.6"/><float name="roughness" value="0.2"/><float name="spec_trans" value="0.9"/><float name="eta" value="1.5"/></bsdf></shape>''',
    }
    for n,b in S.items(): open(n+'.xml','w').write(b+'\n</scene>\n')

    # Blends with a textured weight and with a specular part.
    b = open("blend.xml").read()
    open("blend_tex.xml", "w").write(b.replace(
        '<float name="weight" value="0.3"/>',
        '<texture type="bitmap" name="weight"><string name="filename" value="checker.exr"/>'
        '<string name="filter_type" value="nearest"/></texture>'))
    open("blend_glass.xml", "w").write(b.replace(
        '<bsdf type="roughconductor"><float name="alpha" value="0.1"/></bsdf>', '<bsdf type="dielectric"/>'))
    # A constant normal map tilted 22 degrees under a directional light at
    # 45 degrees: the closed form is 0.7 / pi * cos(23.2 degrees) = 0.20480.
    n = np.array([0.4, 0.0, 1.0]) / np.linalg.norm([0.4, 0.0, 1.0])
    mi.Bitmap(np.tile(((n + 1) / 2).astype(np.float32), (4, 4, 1))).write("tilt.exr")
    open("normalmap_tilt.xml", "w").write('''<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="perspective"><float name="fov" value="20"/>
    <transform name="to_world"><lookat origin="0, 0, 6" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
    <bsdf type="normalmap"><texture type="bitmap" name="normalmap"><string name="filename" value="tilt.exr"/>
      <boolean name="raw" value="true"/></texture><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></bsdf></shape>
  <emitter type="directional"><vector name="direction" value="-1, 0, -1"/><rgb name="irradiance" value="1"/></emitter>
</scene>
''')


def image_mean(path):
    return np.array(mi.Bitmap(path))[:, :, :3].mean()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", default="")
    ap.add_argument("--techniques", default="path,bdpt")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--dir", default="/tmp/tracelab-probes")
    ap.add_argument("--tracelab", default=os.path.join(os.path.dirname(__file__), "../../target/release/tracelab"))
    a = ap.parse_args()
    tracelab = os.path.abspath(a.tracelab)
    os.makedirs(a.dir, exist_ok=True)
    os.chdir(a.dir)
    write_scenes()
    names = a.only.split(",") if a.only else sorted(f[:-4] for f in os.listdir(".") if f.endswith(".xml"))
    for name in names:
        xml = name + ".xml"
        scene = mi.load_file(xml)
        m = [np.array(mi.render(scene, spp=a.spp, seed=s)).mean() for s in range(1, a.seeds + 1)]
        line = "%-20s mitsuba %.5f ± %.5f" % (name, np.mean(m), np.std(m, ddof=1) / np.sqrt(a.seeds))
        for t in a.techniques.split(","):
            v = []
            for s in range(1, a.seeds + 1):
                out = "out_%s_%s.exr" % (name, t)
                r = subprocess.run([tracelab, "render", xml, "--integrator", t, "--spp", str(a.spp),
                                    "--seed", str(s), "--out", out], capture_output=True, text=True)
                if r.returncode:
                    sys.exit(r.stderr)
                v.append(image_mean(out))
            line += " | %s %.5f ± %.5f (%+.2f%%)" % (t, np.mean(v), np.std(v, ddof=1) / np.sqrt(a.seeds),
                                                   100 * (np.mean(v) / np.mean(m) - 1))
        print(line, flush=True)


if __name__ == "__main__":
    main()
