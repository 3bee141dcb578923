//! What the importer gives a shape when the file leaves something out.

use crate::bidirectional::render;
use crate::import::load;
use tracelab::integrator::{Integrator, PathTracer};

/// A lamp given no BSDF reflects nothing, as in Mitsuba 3 and 0.6 (their
/// default diffuse has reflectance 0 on emitters, 0.5 elsewhere; Mitsuba
/// 3.9.1 renders a mask before such a lamp grey, where a lamp of the
/// default 0.5 reflects the mask's colour back through it). Here a lamp of
/// radiance 1 fills the view and a second one, behind the camera, lights
/// it: every pixel is 1 exactly with a black BSDF, and about 1.5 if it
/// reflected half of what reaches it. A plain shape keeps reflectance 0.5.
#[test]
fn an_emitter_given_no_bsdf_reflects_nothing() {
    let xml = |front_bsdf: &str| {
        format!(
            r#"<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="20"/>
    <transform name="to_world"><lookat origin="0, 0, 0.5" target="0, 0, -1" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
      <rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle">
    <transform name="to_world"><scale value="10"/><translate z="-1"/></transform>
    {front_bsdf}<emitter type="area"><rgb name="radiance" value="1"/></emitter>
  </shape>
  <shape type="rectangle">
    <transform name="to_world"><scale value="10"/><rotate y="1" angle="180"/><translate z="1"/></transform>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter>
  </shape>
</scene>"#
        )
    };
    let mean = |front_bsdf: &str| {
        let scene =
            load("emitter-default", &xml(front_bsdf), &[], false).unwrap_or_else(|e| panic!("{e}"));
        let film = render(scene, Integrator::from(PathTracer::default()), 16, 5);
        film.image.mean()
    };
    // Every sample is the lamp's radiance alone: no variance at all.
    for (c, m) in mean("").into_iter().enumerate() {
        assert!((m - 1.0).abs() < 1e-5, "channel {c}: {m}");
    }
    // The same lamp given Mitsuba's plain default does reflect.
    let reflecting = mean(r#"<bsdf type="diffuse"/>"#);
    assert!(reflecting[0] > 1.3, "{reflecting:?}");
}

/// Mitsuba 0.6's conductor defaults to copper, but its preset "none" is the
/// perfect mirror there too (Bitterli's living-room mirrors; read as copper,
/// they were a dark, red reflection).
#[test]
fn a_06_conductor_named_none_is_a_mirror_and_one_named_nothing_copper() {
    use tracelab::math::Rgb;
    let xml = |material: &str| {
        format!(
            r#"<scene version="0.6.0">
  <shape type="rectangle"><bsdf type="conductor">{material}</bsdf></shape>
  <emitter type="constant"/>
</scene>"#
        )
    };
    let conductor = |name: &str, xml: &str| match load(name, xml, &[], false)
        .unwrap_or_else(|e| panic!("{e}"))
        .materials[0]
        .bsdf
    {
        tracelab::bsdf::Bsdf::Conductor { lobe, .. } => lobe,
        ref other => panic!("{other:?}"),
    };
    let mirror = conductor(
        "v06-none",
        &xml(r#"<string name="material" value="none"/>"#),
    );
    assert_eq!((mirror.eta, mirror.k), (Rgb::ZERO, Rgb::ONE));
    let copper = conductor("v06-default", &xml(""));
    assert!(copper.k.x > 3.0 && copper.eta.x < 0.5, "{copper:?}");
}
