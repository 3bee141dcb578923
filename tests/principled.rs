//! Mitsuba 3's `principled` as the XML importer reads it, against Mitsuba
//! 3's own `eval` at fixed direction pairs, front and back
//! (`tests/data/principled_mitsuba.txt`, made by
//! `bench/peer/principled_eval.py` with Mitsuba 3.9 `scalar_rgb`). Both
//! evaluate the same closed form in f32, so they must agree to rounding.

use crate::import::load;
use glam::Vec3A;
use tracelab::bsdf::Bsdf;

/// The parameter sets of `principled_eval.py`, as XML properties.
const SETS: [&str; 4] = [
    "",
    r#"<rgb name="base_color" value="0.8, 0.3, 0.2"/> <float name="roughness" value="0.3"/>
       <float name="metallic" value="0.6"/> <float name="spec_tint" value="0.5"/>
       <float name="sheen" value="0.7"/> <float name="sheen_tint" value="0.4"/>
       <float name="clearcoat" value="0.8"/> <float name="clearcoat_gloss" value="0.6"/>
       <float name="specular" value="0.7"/>"#,
    r#"<rgb name="base_color" value="0.2, 0.6, 0.9"/> <float name="roughness" value="0.4"/>
       <float name="anisotropic" value="0.6"/> <float name="flatness" value="0.5"/>"#,
    r#"<rgb name="base_color" value="0.9, 0.9, 0.6"/> <float name="roughness" value="0.3"/>
       <float name="spec_trans" value="0.7"/> <float name="eta" value="1.45"/>
       <float name="metallic" value="0.2"/>"#,
];

fn principled(index: usize) -> Bsdf {
    let xml = format!(
        r#"<scene version="3.0.0">
             <shape type="rectangle"><bsdf type="principled">{}</bsdf></shape>
             <emitter type="constant"/>
           </scene>"#,
        SETS[index]
    );
    let scene = load(&format!("principled-{index}"), &xml, &[], false).unwrap();
    // The only warning is the missing sensor: every property was read.
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    scene.materials[0].bsdf
}

#[test]
fn principled_evaluates_as_mitsuba_3s() {
    let bsdfs: Vec<Bsdf> = (0..SETS.len()).map(principled).collect();
    let text = include_str!("data/principled_mitsuba.txt");
    let (mut worst, mut nonzero) = (0.0f32, 0);
    for line in text.lines() {
        let v: Vec<f32> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let wo = Vec3A::new(v[1], v[2], v[3]);
        let wi = Vec3A::new(v[4], v[5], v[6]);
        let expected = Vec3A::new(v[7], v[8], v[9]);
        let f = bsdfs[v[0] as usize].eval(wo, wi);
        // Relative to the value, with a floor for values near zero.
        let error = ((f - expected).abs() / expected.abs().max(Vec3A::splat(1e-3))).max_element();
        assert!(
            error < 1e-3,
            "set {}: wo {wo}, wi {wi}: tracelab {f}, Mitsuba {expected}",
            v[0]
        );
        worst = worst.max(error);
        nonzero += usize::from(expected.max_element() > 0.0);
    }
    // Most pairs see some lobe: the comparison is not of zeros.
    assert!(nonzero > 120, "only {nonzero} pairs non-zero");
    println!("worst relative difference {worst:.2e}");
}

/// `eta` with `specular`, and a weight outside [0, 1], are errors that
/// name the file, line and column; a texture where only a number is read
/// is its mean, with a warning; `base_color`, `roughness` and `metallic`
/// textures are read at each hit.
#[test]
fn principled_parameters_are_checked_and_textures_read_where_they_can_be() {
    let scene = |name: &str, properties: &str| {
        let xml = format!(
            "<scene version=\"3.0.0\">\n<shape type=\"rectangle\">\n\
             <bsdf type=\"principled\">{properties}</bsdf>\n</shape>\n</scene>"
        );
        load(name, &xml, &[], false)
    };
    let both = r#"<float name="eta" value="1.5"/><float name="specular" value="0.5"/>"#;
    let e = scene("principled-both", both).err().unwrap().to_string();
    assert!(e.contains("scene.xml:3:") && e.contains("not both"), "{e}");
    let out = r#"<float name="sheen" value="1.5"/>"#;
    let e = scene("principled-range", out).err().unwrap().to_string();
    assert!(e.contains("scene.xml:3:") && e.contains("sheen 1.5"), "{e}");

    let checker = |name: &str| {
        format!(
            r#"<texture type="checkerboard" name="{name}">
                 <rgb name="color0" value="0.2"/><rgb name="color1" value="0.8"/>
               </texture>"#
        )
    };
    let textured = format!(
        "{}{}{}{}",
        checker("base_color"),
        checker("roughness"),
        checker("metallic"),
        checker("clearcoat")
    );
    let s = scene("principled-textures", &textured).unwrap();
    let mean_warnings: Vec<_> = s
        .warnings
        .iter()
        .filter(|w| w.contains("its mean"))
        .collect();
    assert!(
        mean_warnings.len() == 1 && mean_warnings[0].contains("clearcoat"),
        "{:?}",
        s.warnings
    );
    // The checkerboard's two squares give two BSDFs, each with its own
    // base colour, roughness and metallic.
    let material = &s.materials[0];
    let at = |u: f32| match material.bsdf_at(&s.textures, glam::Vec2::new(u, 0.1)) {
        Bsdf::Principled { lobe, .. } => lobe,
        other => panic!("{other:?}"),
    };
    let (a, b) = (at(0.1), at(0.6));
    let near = |x: f32, y: f32| (x - y).abs() < 1e-5;
    for lobe in [a, b] {
        // The three textures are one checkerboard, whose squares Mitsuba
        // 3's `eval_1` swaps (as tracelab's does, to match it): roughness
        // and metallic read the other square's value.
        assert!(
            near(lobe.roughness, 1.0 - lobe.base[0]) && near(lobe.metallic, lobe.roughness),
            "{lobe:?}"
        );
        let expected = tracelab::bsdf::Principled::alphas(lobe.roughness, 0.0);
        assert_eq!(lobe.alpha, expected);
    }
    let mut values = [a.base[0], b.base[0]];
    values.sort_by(f32::total_cmp);
    assert!(near(values[0], 0.2) && near(values[1], 0.8), "{values:?}");
}
