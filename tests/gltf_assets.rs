//! A glTF asset as tools export them: a floor with a base-colour texture
//! and a normal map (PNG images in the binary buffer), a punctual light and
//! a camera, and the same quad again as a tilted panel (one mesh, two
//! nodes: an instance). It loads without a warning, reads both textures, and path
//! tracing, BDPT and light tracing agree on it (block z-test of
//! `strategies.rs`).

use crate::bidirectional::render;
use crate::common::temp_dir;
use crate::import::gltf_buffer;
use crate::strategies::assert_agree;
use std::io::Cursor;
use tracelab::integrator::{Bdpt, Integrator, LightTracer, PathTracer};
use tracelab::scene::Scene;

/// A PNG of `size`² texels from `texel(x, y)`.
fn png(size: u32, texel: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let image = image::RgbImage::from_fn(size, size, |x, y| image::Rgb(texel(x, y)));
    let mut bytes = Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

#[test]
fn a_textured_normal_mapped_gltf_renders_and_bdpt_agrees() {
    // The quad of `gltf_buffer` (140 bytes), then the two images, each
    // padded to 4 bytes.
    let mut buffer = gltf_buffer();
    let checks = png(16, |x, y| {
        if (x / 4 + y / 4) % 2 == 0 {
            [200, 180, 40]
        } else {
            [30, 60, 160]
        }
    });
    // Ridges along u: the normal leans ±0.5 in x, stored as (n + 1) / 2.
    let normals = png(16, |x, _| {
        let lean: f32 = if (x / 2) % 2 == 0 { 0.5 } else { -0.5 };
        let n = glam::Vec3::new(lean, 0.0, 1.0).normalize();
        [n.x, n.y, n.z].map(|c| ((c + 1.0) * 0.5 * 255.0).round() as u8)
    });
    // Roughness (green) in bands along v, 0.39 and 1 (times the factor
    // 0.6); metallic (blue) 0: a plastic with a roughness map. Not much
    // smoother: at α 0.008 light tracing meets the point light's highlight
    // so rarely that its block's estimated error is far too small (two
    // seeds of 4096 spp on a plain floor differ there by twice what they
    // differ from path tracing, and every other block agrees to 1e-3:
    // docs/validation.md), and the z-test fails without a bias.
    let roughness = png(16, |_, y| [0, if (y / 4) % 2 == 0 { 100 } else { 255 }, 0]);
    let mut views = Vec::new();
    for image in [&checks, &normals, &roughness] {
        views.push((buffer.len(), image.len()));
        buffer.extend_from_slice(image);
        while !buffer.len().is_multiple_of(4) {
            buffer.push(0);
        }
    }
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "point", "color": [1, 0.9, 0.8], "intensity": 20}}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2, 3]}}],
  "nodes": [
    {{"mesh": 0, "rotation": [-0.70710678, 0, 0, 0.70710678], "scale": [3, 3, 3]}},
    {{"camera": 0, "translation": [0, 2, 4], "rotation": [-0.2588190, 0, 0, 0.9659258]}},
    {{"translation": [0.5, 1.5, 0.5], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}},
    {{"mesh": 0, "translation": [-0.8, 0.7, -0.6], "rotation": [-0.3826834, 0.3, 0, 0.9238795], "scale": [0.5, 0.7, 0.5]}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.9, "aspectRatio": 1.0, "znear": 0.1}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0}}]}}],
  "materials": [{{"name": "floor", "doubleSided": true,
    "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}, "metallicRoughnessTexture": {{"index": 2}}, "metallicFactor": 1, "roughnessFactor": 0.6}},
    "normalTexture": {{"index": 1, "scale": 1.0}}}}],
  "textures": [{{"source": 0}}, {{"source": 1}}, {{"source": 2}}],
  "images": [{{"bufferView": 4, "mimeType": "image/png"}}, {{"bufferView": 5, "mimeType": "image/png"}}, {{"bufferView": 6, "mimeType": "image/png"}}],
  "buffers": [{{"byteLength": {}, "uri": "floor.bin"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 128, "byteLength": 12}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        buffer.len(),
        views[0].0,
        views[0].1,
        views[1].0,
        views[1].1,
        views[2].0,
        views[2].1
    );
    let dir = temp_dir("gltf-asset");
    std::fs::write(dir.join("floor.bin"), &buffer).unwrap();
    std::fs::write(dir.join("scene.gltf"), json).unwrap();
    let mut scene = Scene::load(&dir.join("scene.gltf")).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // Two nodes use the quad: it is stored once, placed twice (the second
    // a tilted panel over the floor, unevenly scaled).
    assert_eq!(scene.geometry.instance_count(), 2);
    assert_eq!(scene.geometry.triangles_drawn(), 4);
    let floor = &scene.materials[0];
    assert!(floor.textures.diffuse.is_some(), "{floor:?}");
    assert!(floor.normal_map.is_some(), "{floor:?}");
    // Metallic 1 × blue 0 everywhere: a plastic, its α from the green
    // channel, with coating tables by roughness.
    assert!(
        matches!(floor.bsdf, tracelab::bsdf::Bsdf::RoughPlastic { .. }),
        "{:?}",
        floor.bsdf
    );
    let alpha = floor.textures.alpha.expect("a roughness map");
    assert!(floor.textures.coating.is_some());
    let texels = |uv: glam::Vec2| scene.textures[alpha as usize].eval(uv).x;
    let (smooth, rough) = (
        texels(glam::Vec2::new(0.5, 0.1)),
        texels(glam::Vec2::new(0.5, 0.4)),
    );
    assert!(
        (smooth - (0.6f32 * 100.0 / 255.0).powi(2)).abs() < 1e-4,
        "{smooth}"
    );
    assert!((rough - 0.36).abs() < 1e-4, "{rough}");
    assert!(scene.features.normal_maps);
    scene.set_resolution(64, 64);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        256,
        61,
    );
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 62);
    // The point light is in view: neither technique shows it (no camera
    // ray can hit a point), as path tracing and Mitsuba do not.
    assert_agree("glTF asset, bdpt / path", &bdpt, &path);
    let light = render(
        scene.clone(),
        Integrator::from(LightTracer::default()),
        256,
        64,
    );
    assert_agree("glTF asset, light / path", &light, &path);
    // The normal map shows: without it the floor's shading differs.
    let scene_for_roughness = scene.clone();
    let mut smooth = scene;
    smooth.materials[0].normal_map = None;
    smooth.features.normal_maps = false;
    let flat = render(smooth, Integrator::from(PathTracer::default()), 256, 63);
    let worst = crate::strategies::largest_block_z(&flat, &path);
    assert!(worst > 4.5, "the normal map changes nothing (z {worst:.2})");
    // So does the roughness map: without it the floor is rough throughout.
    let mut even = scene_for_roughness;
    even.materials[0].textures.alpha = None;
    even.materials[0].textures.coating = None;
    let even = render(even, Integrator::from(PathTracer::default()), 256, 65);
    let worst = crate::strategies::largest_block_z(&even, &path);
    assert!(
        worst > 4.5,
        "the roughness map changes nothing (z {worst:.2})"
    );
}
