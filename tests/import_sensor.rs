//! Mitsuba sensors: what the importer reads of a camera beyond its frame.

use crate::import::load;

/// Mitsuba clips by depth along the view; tracelab does not, and says so
/// only where the scene's box crosses the file's near_clip or far_clip
/// (Mitsuba's cube, -1 to 1, seen from 5 away spans depths 4 to 6).
#[test]
fn near_and_far_clips_that_would_cut_the_scene_are_warnings() {
    let warnings = |clips: &str| {
        let xml = format!(
            r#"<scene version="3.0.0">
  <sensor type="perspective">{clips}
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0"/></transform>
  </sensor>
  <shape type="cube"/>
  <emitter type="constant"/>
</scene>"#
        );
        let scene = load("clips", &xml, &[], false).unwrap_or_else(|e| panic!("{e}"));
        scene.warnings
    };
    let clip = |near: f32, far: f32| {
        format!(r#"<float name="near_clip" value="{near}"/><float name="far_clip" value="{far}"/>"#)
    };
    assert!(warnings("").is_empty());
    // A pinhole's focus distance changes nothing, in Mitsuba as here.
    let focus = r#"<float name="focus_distance" value="6"/>"#;
    assert!(warnings(focus).is_empty(), "{:?}", warnings(focus));
    assert!(
        warnings(&clip(3.9, 6.1)).is_empty(),
        "{:?}",
        warnings(&clip(3.9, 6.1))
    );
    let w = warnings(&clip(4.5, 6.1));
    assert!(
        w.len() == 1 && w[0].contains("near_clip 4.5 ignored"),
        "{w:?}"
    );
    let w = warnings(&clip(3.9, 5.5));
    assert!(
        w.len() == 1 && w[0].contains("far_clip 5.5 ignored"),
        "{w:?}"
    );
}
