//! Mitsuba XML import: a file Mitsuba rendered gives Mitsuba's image, every
//! element the importer reads lands where Mitsuba puts it, and every
//! mistake is an error or a warning naming file, line and column.

use crate::common::{reference, render_adaptive, repo_path, temp_dir};
use glam::Vec3A;
use std::io::Write;
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::sampling::SamplerKind;
use tracelab::scene::{LoadOptions, Scene};

pub(crate) fn load(
    name: &str,
    xml: &str,
    defines: &[(&str, &str)],
    strict: bool,
) -> tracelab::Result<Scene> {
    let dir = temp_dir(name);
    write_assets(&dir);
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    let options = LoadOptions {
        defines: defines
            .iter()
            .map(|(n, v)| (n.to_string(), v.to_string()))
            .collect(),
        strict,
        ..Default::default()
    };
    Scene::load_with(&path, &options)
}

/// A unit quad as ASCII PLY, a one-triangle serialized mesh, an include,
/// an OBJ without faces, an image of 0 bytes.
pub(crate) fn write_assets(dir: &std::path::Path) {
    std::fs::write(dir.join("empty.obj"), "# no faces\nv 0 0 0\n").unwrap();
    std::fs::write(dir.join("empty.hdr"), b"").unwrap();
    std::fs::write(
        dir.join("quad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
    )
    .unwrap();
    // Mitsuba's serialized format, version 4: header, zlib stream, offset table.
    let mut shape = Vec::new();
    shape.extend(0u32.to_le_bytes()); // flags: single precision, no normals or uvs
    shape.extend(b"tri\0");
    shape.extend(3u64.to_le_bytes());
    shape.extend(1u64.to_le_bytes());
    for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        shape.extend(v.to_le_bytes());
    }
    for i in [0u32, 1, 2] {
        shape.extend(i.to_le_bytes());
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&shape).unwrap();
    let mut file = vec![0x1C, 0x04, 4, 0];
    file.extend(z.finish().unwrap());
    file.extend(0u64.to_le_bytes());
    file.extend(1u32.to_le_bytes());
    std::fs::write(dir.join("tri.serialized"), file).unwrap();
    std::fs::write(
        dir.join("light.xml"),
        r##"<scene version="3.0.0">
  <shape type="rectangle">
    <transform name="to_world"><rotate x="1" angle="90"/><translate y="4"/></transform>
    <emitter type="area"><rgb name="radiance" value="$power"/></emitter>
  </shape>
</scene>"##,
    )
    .unwrap();
}

pub(crate) const SENSOR: &str = r##"
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0, 1, 5" target="0, 1, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="16"/></film>
    <sampler type="stratified"><integer name="sample_count" value="$spp"/></sampler>
  </sensor>"##;

#[test]
fn mitsubas_cornell_box_file_matches_mitsubas_render_of_it() {
    // The file that made tests/data/cornell_box_path_ref.exr, read by the
    // importer: the RMSE test of reference.rs (see its comment).
    let scene = Scene::load_with(
        &repo_path("bench/peer/cornell_box_mitsuba.xml"),
        &LoadOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(
        scene.hints.max_depth,
        Some(8),
        "max_depth 9 segments = 8 bounces"
    );
    assert_eq!(scene.hints.spp, Some(64));
    let integrator = PathTracer {
        max_depth: 8,
        ..Default::default()
    };
    let (snapshot, stats) = render_adaptive(
        Integrator::from(integrator),
        SamplerKind::Independent,
        None,
        scene,
        64,
        3,
        0,
        8,
    );
    assert_eq!(stats.non_finite, 0);
    let reference_image = reference("cornell_box_path_ref.exr");
    let variance = reference("cornell_box_path_ref_var.exr");
    let rmse = snapshot.image.compare(&reference_image).unwrap().rmse;
    let mut expected = 0.0f64;
    for (se, v) in snapshot.standard_error.pixels.iter().zip(&variance.pixels) {
        for c in 0..3 {
            expected += (se[c] as f64).powi(2) + v[c] as f64;
        }
    }
    let expected = (expected / (snapshot.image.pixels.len() * 3) as f64).sqrt();
    eprintln!("imported Cornell box: RMSE {rmse:.5}, expected {expected:.5}");
    assert!(rmse <= 1.10 * expected, "RMSE {rmse} against {expected}");
}

#[test]
fn every_element_lands_where_mitsuba_puts_it() {
    let xml = format!(
        r##"<scene version="3.0.0">
  <default name="res" value="24"/>
  <default name="spp" value="4"/>
  <default name="power" value="2"/>
  <integrator type="volpath"><integer name="max_depth" value="-1"/><integer name="rr_depth" value="3"/></integrator>
  {SENSOR}
  <texture type="checkerboard" id="checks">
    <rgb name="color0" value="0.1"/><srgb name="color1" value="#ff0000"/>
    <transform name="to_uv"><scale x="4" y="2"/></transform>
  </texture>
  <bsdf type="twosided" id="floor">
    <bsdf type="diffuse"><ref name="reflectance" id="checks"/></bsdf>
  </bsdf>
  <bsdf type="roughconductor" id="metal">
    <string name="material" value="Au"/><float name="alpha" value="0.2"/>
    <string name="distribution" value="ggx"/>
  </bsdf>
  <include filename="light.xml"/>
  <shape type="ply"><string name="filename" value="quad.ply"/>
    <transform name="to_world"><scale value="2"/><translate x="1"/></transform>
    <ref id="floor"/>
  </shape>
  <shape type="serialized"><string name="filename" value="tri.serialized"/><ref id="metal"/></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.5"/></transform></shape>
  <shape type="sphere"><point name="center" x="0" y="1" z="0"/><float name="radius" value="0.25"/>
    <transform name="to_world"><scale value="2"/></transform>
    <bsdf type="dielectric"><string name="int_ior" value="water"/></bsdf>
  </shape>
  <shape type="shapegroup" id="group">
    <shape type="rectangle"><transform name="to_world"><translate z="-3"/></transform></shape>
  </shape>
  <shape type="instance"><ref id="group"/><transform name="to_world"><translate x="5"/></transform></shape>
  <shape type="instance"><ref id="group"/><transform name="to_world"><translate x="-5"/></transform></shape>
  <emitter type="point"><point name="position" x="0" y="3" z="0"/><spectrum name="intensity" value="5"/></emitter>
</scene>"##
    );
    let scene = load("elements", &xml, &[("res", "32")], false).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // Hints: volpath is path tracing; -1 is unbounded; the sampler's count.
    assert_eq!(scene.hints.integrator.as_deref(), Some("path"));
    assert_eq!(
        scene.hints.max_depth,
        Some(tracelab::scene::UNBOUNDED_DEPTH)
    );
    assert_eq!(scene.hints.rr_depth, Some(3));
    assert_eq!(
        (scene.hints.spp, scene.hints.sampler.as_deref()),
        (Some(4), Some("stratified"))
    );
    // -D wins over <default>; fov is along x (Mitsuba's default axis).
    let camera = &scene.camera;
    assert_eq!((camera.width, camera.height), (32, 16));
    let tan_half_x = 30f32.to_radians().tan();
    assert!((camera.tan_half_fov_y - tan_half_x * 16.0 / 32.0).abs() < 1e-5);
    assert!((camera.eye - Vec3A::new(0.0, 1.0, 5.0)).length() < 1e-5);
    assert!((camera.forward - Vec3A::new(0.0, 0.0, -1.0)).length() < 1e-5);
    // Image right is +x looking down -z with y up.
    assert!(
        (camera.right - Vec3A::X).length() < 1e-5,
        "{:?}",
        camera.right
    );
    // Triangles: light 2 + ply 2 + serialized 1 + cube 12, and two
    // instances of the group's 2, stored once.
    assert_eq!(scene.geometry.triangle_count(), 2 + 2 + 1 + 12);
    assert_eq!(scene.geometry.instance_count(), 2);
    assert_eq!(scene.geometry.triangles_drawn(), 2 + 2 + 1 + 12 + 4);
    // Each instance's rectangle lies at z = -3, facing +z, at x = ±5.
    for x in [5.0, -5.0] {
        let ray = tracelab::math::Ray::new(Vec3A::new(x, 0.0, 0.0), -Vec3A::Z);
        let hit = scene.geometry.intersect(&ray).expect("an instance is hit");
        assert!((hit.t - 3.0).abs() < 1e-5 && (hit.normal - Vec3A::Z).length() < 1e-5);
    }
    // The included light: rotated about x by 90 degrees, then lifted to y = 4,
    // facing down (Mitsuba's rectangle faces +z; +z rotated about x is -y).
    let lights = scene.lights.as_slice();
    let light = lights
        .iter()
        .find_map(|l| match l {
            tracelab::scene::light::Light::Parallelogram(p) => Some(p),
            _ => None,
        })
        .expect("the rectangle is a parallelogram light");
    assert!(
        (light.p0.y - 4.0).abs() < 1e-5 && light.normal.y < -0.999,
        "{light:?}"
    );
    assert!((light.area - 4.0).abs() < 1e-4);
    assert!((light.radiance - Vec3A::splat(2.0)).length() < 1e-6);
    // The sphere: to_world scales its center and radius.
    let sphere = scene.geometry.spheres()[0];
    assert!((sphere.center - Vec3A::new(0.0, 2.0, 0.0)).length() < 1e-5);
    assert!((sphere.radius - 0.5).abs() < 1e-6);
    // Materials: textured twosided diffuse, gold, water, the default.
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert!(
        names.contains(&"floor") && names.contains(&"metal"),
        "{names:?}"
    );
    let floor = scene.materials.iter().find(|m| m.name == "floor").unwrap();
    assert!(floor.textures.diffuse.is_some());
    assert_eq!(scene.textures.len(), 1, "the texture is loaded once");
    let red = scene.textures[0].eval(glam::Vec2::new(0.15, 0.1));
    let dark = scene.textures[0].eval(glam::Vec2::new(0.05, 0.1));
    assert!(
        (red - Vec3A::X).length() < 1e-6 && (dark - Vec3A::splat(0.1)).length() < 1e-6,
        "to_uv scales u by 4: {red:?} {dark:?}"
    );
}

#[test]
fn mitsuba_06_names_read_as_mitsuba_3s() {
    let xml = r##"<scene version="0.6.0">
  <sensor type="perspective">
    <float name="fov" value="40"/><string name="fovAxis" value="y"/>
    <transform name="toWorld"><lookat origin="0, 0, 4" target="0, 0, 0"/></transform>
    <film type="ldrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    <sampler type="ldsampler"><integer name="sampleCount" value="16"/></sampler>
  </sensor>
  <shape type="rectangle">
    <bsdf type="roughplastic"><float name="intIOR" value="1.6"/><srgb name="diffuseReflectance" value="#808080"/><float name="alpha" value="0.3"/></bsdf>
  </shape>
  <emitter type="constant"><spectrum name="radiance" value="400:1, 700:1"/></emitter>
</scene>"##;
    let scene = load("v06", xml, &[], false).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.hints.spp, Some(16));
    assert_eq!(scene.hints.sampler.as_deref(), Some("sobol"));
    assert!((scene.camera.tan_half_fov_y - 20f32.to_radians().tan()).abs() < 1e-6);
    assert!(matches!(
        scene.materials[0].bsdf,
        tracelab::bsdf::Bsdf::RoughPlastic { .. }
    ));
    // Mitsuba 0.x also spells the step `<lookAt>` (its own veach_mi scene).
    let camel = xml.replace("<lookat ", "<lookAt ");
    let camel = load("v06-lookAt", &camel, &[], false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(camel.camera, scene.camera);
}

#[test]
fn mistakes_name_file_line_and_column() {
    let error = |name: &str, xml: &str| -> String {
        match load(name, xml, &[], false) {
            Ok(_) => panic!("{name}: loaded"),
            Err(e) => e.to_string(),
        }
    };
    let e = error(
        "syntax",
        "<scene version=\"3.0.0\">\n  <shape type=\"cube\">\n</scene>",
    );
    assert!(e.contains("scene.xml:3:"), "{e}");
    let e = error(
        "param",
        "<scene version=\"3.0.0\">\n  <integer name=\"x\" value=\"$nope\"/>\n</scene>",
    );
    assert!(e.contains("scene.xml:2:3: `$nope` is not defined"), "{e}");
    let e = error(
        "file",
        "<scene version=\"3.0.0\">\n<shape type=\"obj\"><string name=\"filename\" value=\"none.obj\"/></shape>\n</scene>",
    );
    assert!(
        e.contains("scene.xml:2:1: file `none.obj` not found"),
        "{e}"
    );
    let e = error(
        "ref",
        "<scene version=\"3.0.0\">\n<shape type=\"cube\">\n  <ref id=\"missing\"/>\n</shape>\n</scene>",
    );
    assert!(e.contains("scene.xml:3:3:") && e.contains("missing"), "{e}");
    let e = error("version", "<scene>\n</scene>");
    assert!(e.contains("needs a `version`"), "{e}");
    let e = error("root", "<mesh/>");
    assert!(e.contains("not <scene>"), "{e}");
    let e = error(
        "number",
        "<scene version=\"3.0.0\">\n<shape type=\"sphere\"><float name=\"radius\" value=\"big\"/></shape>\n</scene>",
    );
    assert!(
        e.contains("scene.xml:2:") && e.contains("\"big\" is not a number"),
        "{e}"
    );
    // Meshes are placed after the walk, in parallel: the error still names
    // the shape that goes out of range, not its neighbours.
    let e = error(
        "range",
        "<scene version=\"3.0.0\">\n<shape type=\"rectangle\"/>\n<shape type=\"cube\">\n  <transform name=\"to_world\"><scale value=\"1e30\"/></transform>\n</shape>\n<shape type=\"cube\"/>\n</scene>",
    );
    assert!(
        e.contains("scene.xml:3:1:") && e.contains("reaches beyond"),
        "{e}"
    );
}

#[test]
fn what_is_not_rendered_is_a_warning_and_strict_makes_it_an_error() {
    let xml = format!(
        r##"<scene version="3.0.0">
  <default name="res" value="8"/><default name="spp" value="1"/><default name="power" value="1"/>
  {SENSOR}
  <shape type="cube">
    <bsdf type="blendbsdf"><float name="weight" value="0.3"/>
      <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf>
    <float name="mystery" value="1"/>
  </shape>
  <shape type="hair"/>
  <emitter type="sunsky"/>
  <shape type="obj"><string name="filename" value="empty.obj"/></shape>
</scene>"##
    );
    let scene = load("warnings", &xml, &[], false).unwrap_or_else(|e| panic!("{e}"));
    let w = scene.warnings.join("\n");
    for expected in [
        "scene.xml:13:5: shape `cube`: property `mystery` ignored",
        "scene.xml:15:3: shape \"hair\" is not supported: skipped",
        "scene.xml:16:3: emitter \"sunsky\" is not supported: skipped",
        "scene.xml:17:3: ",
        "empty.obj holds no triangles: the shape adds nothing",
    ] {
        assert!(w.contains(expected), "missing {expected:?} in\n{w}");
    }
    let e = load("strict", &xml, &[], true).expect_err("strict refuses");
    assert!(
        e.to_string().contains("property `mystery` ignored") && e.to_string().contains("--strict")
    );
}

/// A floor quad, an emissive quad, a camera and a point light under a
/// parent node, as glTF JSON; `uri` names the buffer file (None: a GLB's).
pub(crate) fn gltf_json(uri: Option<&str>) -> String {
    let buffer = match uri {
        Some(u) => format!(r#"{{"byteLength": 140, "uri": "{u}"}}"#),
        None => r#"{"byteLength": 140}"#.to_string(),
    };
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "point", "color": [1, 0.5, 0.25], "intensity": 10}}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2, 3]}}],
  "nodes": [
    {{"mesh": 0, "rotation": [-0.70710678, 0, 0, 0.70710678], "scale": [5, 5, 5]}},
    {{"mesh": 1, "rotation": [0.70710678, 0, 0, 0.70710678], "translation": [0, 3, 0]}},
    {{"camera": 0, "translation": [0, 1, 5]}},
    {{"translation": [1, 0, 0], "children": [4]}},
    {{"translation": [0, 2, 0], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1}}}}],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 3, "material": 1}}]}}
  ],
  "materials": [
    {{"name": "floor", "doubleSided": true, "pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.2, 0.2, 1], "metallicFactor": 0, "roughnessFactor": 0.5}}}},
    {{"name": "lamp", "emissiveFactor": [1, 1, 1], "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 5}}}},
      "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}}}
  ],
  "buffers": [{buffer}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 128, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#
    )
}

/// The buffer of [`gltf_json`]: a unit quad facing +z, normals, uvs, indices.
pub(crate) fn gltf_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for p in [[-1f32, -1., 0.], [1., -1., 0.], [1., 1., 0.], [-1., 1., 0.]] {
        p.iter().for_each(|x| b.extend(x.to_le_bytes()));
    }
    for _ in 0..4 {
        [0f32, 0., 1.]
            .iter()
            .for_each(|x| b.extend(x.to_le_bytes()));
    }
    for uv in [[0f32, 1.], [1., 1.], [1., 0.], [0., 0.]] {
        uv.iter().for_each(|x| b.extend(x.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

#[test]
fn gltf_nodes_meshes_camera_materials_and_lights_land_where_the_file_puts_them() {
    let dir = temp_dir("gltf");
    std::fs::write(dir.join("quad.bin"), gltf_buffer()).unwrap();
    std::fs::write(dir.join("scene.gltf"), gltf_json(Some("quad.bin"))).unwrap();
    // The same scene as one binary file: JSON chunk, then BIN chunk.
    let mut json = gltf_json(None).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin = gltf_buffer();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    std::fs::write(dir.join("scene.glb"), glb).unwrap();

    for file in ["scene.gltf", "scene.glb"] {
        let scene = Scene::load(&dir.join(file)).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.warnings.is_empty(), "{file}: {:?}", scene.warnings);
        assert_eq!(scene.geometry.triangle_count(), 4, "{file}");
        let c = &scene.camera;
        assert_eq!((c.width, c.height), (640, 427));
        assert!((c.eye - Vec3A::new(0.0, 1.0, 5.0)).length() < 1e-6);
        assert!((c.forward - Vec3A::new(0.0, 0.0, -1.0)).length() < 1e-6);
        assert!((c.tan_half_fov_y - 0.4f32.tan()).abs() < 1e-6);
        use tracelab::scene::light::Light;
        let lights = scene.lights.as_slice();
        let lamp = lights
            .iter()
            .find_map(|l| match l {
                Light::Parallelogram(p) => Some(p),
                _ => None,
            })
            .expect("the emissive quad is a light");
        // Rotated +90 degrees about x, up 3: facing down, radiance 5.
        assert!(
            (lamp.p0.y - 3.0).abs() < 1e-5 && lamp.normal.y < -0.999,
            "{lamp:?}"
        );
        assert!((lamp.radiance - Vec3A::splat(5.0)).length() < 1e-5);
        // The point light inherits its parent's translation.
        let point = lights
            .iter()
            .find_map(|l| match l {
                Light::Point {
                    position,
                    intensity,
                } => Some((*position, *intensity)),
                _ => None,
            })
            .expect("the punctual light");
        assert!((point.0 - Vec3A::new(1.0, 2.0, 0.0)).length() < 1e-5);
        assert!((point.1 - Vec3A::new(10.0, 5.0, 2.5)).length() < 1e-5);
        let floor = scene.materials.iter().find(|m| m.name == "floor").unwrap();
        assert!(
            matches!(
                floor.bsdf,
                tracelab::bsdf::Bsdf::RoughPlastic {
                    two_sided: true,
                    ..
                }
            ),
            "{:?}",
            floor.bsdf
        );
    }
    // Nodes reached twice (a cycle; a node under two parents) are an error
    // before anything is placed, not a hang.
    for children in ["[4, 3]", "[4, 4]"] {
        let json = gltf_json(Some("quad.bin"))
            .replace(r#""children": [4]"#, &format!(r#""children": {children}"#));
        std::fs::write(dir.join("bad.gltf"), json).unwrap();
        let e = Scene::load(&dir.join("bad.gltf"))
            .expect_err("refused")
            .to_string();
        assert!(e.contains("bad.gltf") && e.contains("not a tree"), "{e}");
    }
    // A missing buffer file is an error naming the file.
    std::fs::remove_file(dir.join("quad.bin")).unwrap();
    let e = Scene::load(&dir.join("scene.gltf"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("scene.gltf") && e.contains("quad.bin"), "{e}");
}

/// `smooth_angle` on a mesh without `vn`: a faceted sphere gets smooth
/// normals close to the true ones; `face_normals` with it is refused.
#[test]
fn smooth_angle_gives_a_faceted_sphere_smooth_normals() {
    let dir = temp_dir("smooth-angle");
    let obj = crate::common::uv_sphere_obj(24, 12, false);
    std::fs::write(dir.join("ball.obj"), obj).unwrap();
    let scene_text = |extra: &str| {
        format!(
            "[camera]\neye = [0, -4, 0]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nfov_y = 40\nwidth = 8\nheight = 8\n\n\
             [[mesh]]\nfile = \"ball.obj\"\nsmooth_angle = 40\n{extra}\n\n[[point_light]]\nposition = [0, -4, 4]\nintensity = [1, 1, 1]\n"
        )
    };
    std::fs::write(dir.join("scene.toml"), scene_text("")).unwrap();
    let scene = Scene::load(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.features.shading_normals);
    // At a hit, the interpolated normal is within 2 degrees of the sphere's.
    let ray = tracelab::math::Ray::new(Vec3A::new(0.3, -4.0, 0.2), Vec3A::Y);
    let hit = scene
        .geometry
        .intersect(&ray)
        .expect("the ray hits the ball");
    let n = scene.geometry.shading_normal(&hit);
    let true_normal = hit.point.normalize();
    assert!(
        n.dot(true_normal) > 2f32.to_radians().cos(),
        "{n} vs {true_normal}"
    );
    assert!(
        n.dot(hit.normal) < 0.99999,
        "the normal is interpolated, not the face's"
    );
    std::fs::write(dir.join("bad.toml"), scene_text("face_normals = true")).unwrap();
    let e = Scene::load(&dir.join("bad.toml"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("bad.toml:") && e.contains("smooth_angle"), "{e}");
}

/// Shapegroups are stored once and placed by each instance; what cannot be
/// shared (a group that emits, a mirrored placement) is copied; and the
/// image is the one of the copies: path tracing, BDPT and light tracing
/// each render the scene and its flattened copy with one seed, and their
/// means agree within 4 standard errors of the difference (the two
/// renders' errors combined as if independent, which over-covers: they
/// share their random numbers).
#[test]
fn instances_render_as_their_copies() {
    let dir = temp_dir("instances");
    std::fs::write(
        dir.join("ball.obj"),
        crate::common::uv_sphere_obj(24, 12, true),
    )
    .unwrap();
    let xml = r##"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0, 3, 9" target="0, 0.5, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="30"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="8"/></transform>
    <bsdf type="diffuse"/></shape>
  <shape type="shapegroup" id="thing">
    <shape type="obj"><string name="filename" value="ball.obj"/>
      <transform name="to_world"><translate y="1"/></transform>
      <bsdf type="roughplastic"><float name="alpha" value="0.2"/></bsdf></shape>
    <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="30"/><translate z="-1.2" y="1"/></transform>
      <bsdf type="twosided"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
        <transform name="to_uv"><scale value="4"/></transform></texture></bsdf></bsdf></shape>
  </shape>
  <shape type="shapegroup" id="lamp">
    <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><scale value="0.6"/><translate y="5"/></transform>
      <emitter type="area"><rgb name="radiance" value="12"/></emitter></shape>
  </shape>
  <shape type="instance"><ref id="thing"/><transform name="to_world"><translate x="-2.5"/></transform></shape>
  <shape type="instance"><ref id="thing"/><transform name="to_world"><rotate y="1" angle="70"/><scale x="0.8" y="1.3" z="1"/></transform></shape>
  <shape type="instance"><ref id="thing"/><transform name="to_world"><scale x="-1"/><translate x="2.5"/></transform></shape>
  <shape type="instance"><ref id="lamp"/><transform name="to_world"><translate x="-1"/></transform></shape>
  <shape type="instance"><ref id="lamp"/><transform name="to_world"><translate x="1.5" z="1"/></transform></shape>
</scene>"##;
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    let scene = Scene::load_with(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    // The sphere's poles are degenerate, counted once for the prototype.
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(scene.warnings[0].starts_with("dropped 48 degenerate"));
    // Two placements shared; the mirrored one and both lamps copied.
    assert_eq!(scene.geometry.instance_count(), 2);
    let lights = scene.lights.as_slice().len();
    assert_eq!(lights, 2);
    let flat = scene.flattened().expect("the scene has instances");
    assert_eq!(flat.geometry.instance_count(), 0);
    assert_eq!(
        flat.geometry.triangle_count(),
        scene.geometry.triangles_drawn()
    );
    use tracelab::integrator::{Bdpt, LightTracer};
    for (name, integrator) in [
        ("path", Integrator::from(PathTracer::default())),
        ("bdpt", Integrator::from(Bdpt::default())),
        ("light", Integrator::from(LightTracer::default())),
    ] {
        let render = |scene: &Scene| {
            let (snapshot, stats) = crate::common::render_with(
                scene.clone(),
                integrator,
                SamplerKind::Independent,
                64,
                7,
                0,
                16,
            );
            assert_eq!(stats.non_finite, 0);
            crate::common::mean_and_standard_error(&snapshot)
        };
        let ((a, sa), (b, sb)) = (render(&scene), render(&flat));
        for c in 0..3 {
            let tolerance = 4.0 * (sa[c] * sa[c] + sb[c] * sb[c]).sqrt();
            assert!(a[c] > 0.01, "{name}: {a:?}");
            assert!(
                (a[c] - b[c]).abs() <= tolerance,
                "{name}: {a:?} against {b:?} (± {tolerance})"
            );
        }
    }
}

/// A shapegroup holding an instance of another: the inner one is copied
/// into the outer prototype, which is then shared, each placement
/// composing both transforms.
#[test]
fn nested_instances_compose_their_transforms() {
    let xml = r##"<scene version="3.0.0">
  <shape type="shapegroup" id="tile">
    <shape type="rectangle"><transform name="to_world"><scale value="0.5"/></transform></shape>
  </shape>
  <shape type="shapegroup" id="pair">
    <shape type="rectangle"><transform name="to_world"><scale value="0.5"/></transform></shape>
    <shape type="instance"><ref id="tile"/><transform name="to_world"><translate x="2"/></transform></shape>
  </shape>
  <shape type="instance"><ref id="pair"/><transform name="to_world"><translate z="-3"/></transform></shape>
  <shape type="instance"><ref id="pair"/><transform name="to_world"><translate y="5" z="-4"/></transform></shape>
  <emitter type="constant"/>
</scene>"##;
    let scene = load("nested", xml, &[], false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.geometry.instance_count(), 2);
    assert_eq!(scene.geometry.triangles_drawn(), 8);
    // The inner tile of each placement: x = 2, at the placement's y and z.
    for (y, z) in [(0.0, -3.0), (5.0, -4.0)] {
        let ray = tracelab::math::Ray::new(Vec3A::new(2.0, y, 0.0), -Vec3A::Z);
        let hit = scene
            .geometry
            .intersect(&ray)
            .expect("the nested tile is hit");
        assert!((hit.t + z).abs() < 1e-5, "{} at y {y}", hit.t);
    }
}
