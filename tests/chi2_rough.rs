//! Chi-square tests of the rough models' sampling routines, the thin
//! dielectric's discrete choice and the environment map (the tests of
//! `chi2.rs`, whose Šidák correction counts these too).

use crate::chi2::{SAMPLES, assert_fits, check_bsdf_events, check_directions, uniform};
use glam::{Vec2, Vec3A};
use tracelab::bsdf::{
    Distribution, Microfacet, Plastic, Principled, RoughConductor, RoughDielectric, RoughDiffuse,
    RoughPlastic, ThinDielectric,
};
use tracelab::lab::stats::ChiSquare;
use tracelab::lab::warps::Histogram;
use tracelab::math::Rgb;
use tracelab::scene::material::{Bsdf, fresnel_dielectric};

/// Directions at `theta` degrees from the normal, off the xz-plane so that
/// no symmetry of the grid hides an error in φ.
fn incident(theta: f32) -> Vec3A {
    let t = theta.to_radians();
    Vec3A::new(t.sin() * 0.8, t.sin() * 0.6, t.cos())
}

/// Visible normals of every distribution at α 0.05, 0.3 and 1 and an
/// anisotropic pair, at normal and grazing incidence, against D_wo(m).
/// Normals are histogrammed after the exact bijection m' = normalize(m_x /
/// α_u, m_y / α_v, m_z), whose density is D_wo(m) α_u α_v / |M m'|³ with M =
/// diag(α_u, α_v, 1): a lobe of any roughness then spans many cells, where
/// at α 0.05 it would sit inside one (and the cells' integrals of the pdf
/// would be wrong).
#[test]
fn microfacet_visible_normals() {
    let mut seed = 200;
    for distribution in [Distribution::Ggx, Distribution::Beckmann] {
        for (au, av) in [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.1, 0.5)] {
            let mf = Microfacet::new(distribution, au, av);
            let unstretch = Vec3A::new(au, av, 1.0);
            for theta in [5.0, 80.0] {
                let wo = incident(theta);
                seed += 1;
                check_directions(
                    &format!("{distribution:?} visible normals, alpha {au}/{av}, {theta} deg"),
                    |i| {
                        let u = Vec2::new(uniform(seed, i, 0), uniform(seed, i, 1));
                        Some((mf.sample_visible(wo, u) / unstretch).normalize())
                    },
                    |m_stretched| {
                        let m = m_stretched * unstretch;
                        let length = m.length() as f64;
                        mf.pdf_visible(wo, m / m.length()) as f64 * (au * av) as f64
                            / (length * length * length)
                    },
                );
            }
        }
    }
}

/// The test has power: GGX normals of α 0.3 against the density of α 0.33
/// (a 10% error in roughness) are rejected.
#[test]
fn microfacet_test_rejects_a_wrong_pdf() {
    let sampled = Microfacet::isotropic(Distribution::Ggx, 0.3);
    let claimed = Microfacet::isotropic(Distribution::Ggx, 0.33);
    let wo = incident(40.0);
    let histogram = Histogram::new(
        tracelab::lab::warps::Domain::Sphere,
        SAMPLES,
        |i| Some(sampled.sample_visible(wo, Vec2::new(uniform(299, i, 0), uniform(299, i, 1)))),
        |m| claimed.pdf_visible(wo, m) as f64,
    );
    let test = ChiSquare::test(&histogram.observed, &histogram.expected);
    assert!(test.p_value < 1e-6, "wrong pdf passed: p {}", test.p_value);
}

fn rough_bsdfs() -> Vec<(&'static str, Bsdf)> {
    let ggx = Microfacet::isotropic(Distribution::Ggx, 0.3);
    let beckmann = Microfacet::isotropic(Distribution::Beckmann, 0.2);
    let gold = tracelab::bsdf::presets::conductor("Au").unwrap();
    vec![
        (
            "rough conductor, anisotropic GGX",
            Bsdf::RoughConductor {
                lobe: RoughConductor {
                    microfacet: Microfacet::new(Distribution::Ggx, 0.1, 0.4),
                    eta: Vec3A::from(gold.0),
                    k: Vec3A::from(gold.1),
                    tint: Rgb::ONE,
                },
                two_sided: false,
            },
        ),
        (
            "rough dielectric, GGX",
            Bsdf::RoughDielectric(RoughDielectric {
                microfacet: ggx,
                eta: 1.5,
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
            }),
        ),
        (
            "rough dielectric, Beckmann",
            Bsdf::RoughDielectric(RoughDielectric {
                microfacet: beckmann,
                eta: 1.33,
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
            }),
        ),
        (
            "rough plastic, GGX",
            Bsdf::RoughPlastic {
                lobe: RoughPlastic::new(ggx, 1.49, Rgb::new(0.6, 0.3, 0.2), Rgb::ONE, false),
                two_sided: false,
            },
        ),
        (
            "rough plastic, Beckmann, nonlinear",
            Bsdf::RoughPlastic {
                lobe: RoughPlastic::new(beckmann, 1.6, Rgb::splat(0.4), Rgb::ONE, true),
                two_sided: false,
            },
        ),
        (
            "rough diffuse",
            Bsdf::RoughDiffuse {
                lobe: RoughDiffuse {
                    albedo: Rgb::splat(0.7),
                    alpha: 0.5,
                },
                two_sided: false,
            },
        ),
        (
            "principled, every reflecting lobe, anisotropic",
            Bsdf::Principled {
                lobe: principled(0.35, 0.6, 0.0),
                two_sided: false,
            },
        ),
        (
            "principled, transmitting",
            Bsdf::Principled {
                lobe: principled(0.3, 0.0, 0.7),
                two_sided: false,
            },
        ),
        (
            "plastic (diffuse events)",
            Bsdf::Plastic {
                lobe: Plastic::new(1.5, Rgb::splat(0.5), Rgb::ONE, false),
                two_sided: false,
            },
        ),
    ]
}

/// A `principled` with every lobe: sheen, clearcoat and fake subsurface
/// on, metal and transmission as given.
fn principled(roughness: f32, anisotropic: f32, spec_trans: f32) -> Principled {
    Principled {
        base: [0.8, 0.4, 0.2],
        alpha: Principled::alphas(roughness, anisotropic),
        roughness,
        anisotropic,
        metallic: 0.3,
        spec_trans,
        eta: 1.45,
        spec_tint: 0.4,
        sheen: 0.6,
        sheen_tint: 0.5,
        flatness: 0.3,
        clearcoat: 0.8,
        clearcoat_alpha: 0.05,
    }
}

/// Every rough model's sampling (reflection and transmission together for
/// dielectrics, both lobes for plastics) against its pdf, from outside and,
/// for dielectrics, from inside; the sample's weight checked against
/// eval · cos / pdf as it goes.
#[test]
fn rough_bsdf_sampling() {
    let mut seed = 300;
    for (name, bsdf) in rough_bsdfs() {
        let mut sides = vec![("above", incident(35.0)), ("grazing", incident(82.0))];
        if bsdf.is_transmissive() {
            sides.push(("below", incident(35.0) * Vec3A::new(1.0, 1.0, -1.0)));
        }
        for (side, wo) in sides {
            seed += 1;
            check_bsdf_events(&format!("{name}, {side}"), bsdf, wo, seed);
        }
    }
}

/// The thin dielectric reflects with probability 2R/(1 + R) and otherwise
/// passes straight through.
#[test]
fn thin_dielectric_chooses_reflection_with_the_slab_reflectance() {
    let bsdf = ThinDielectric {
        eta: 1.5,
        reflectance: Rgb::ONE,
        transmittance: Rgb::ONE,
    };
    for (k, theta) in [10.0f32, 60.0, 85.0].into_iter().enumerate() {
        let wo = incident(theta);
        let r = fresnel_dielectric(wo.z, 1.5).reflectance as f64;
        let expected_r = 2.0 * r / (1.0 + r);
        let mut observed = [0.0f64; 2];
        for i in 0..SAMPLES {
            let s = Bsdf::ThinDielectric(bsdf)
                .sample(wo, uniform(400 + k as u64, i, 0), Vec2::ZERO)
                .unwrap();
            assert!(s.specular);
            if s.wi.z > 0.0 {
                assert!((s.wi - Vec3A::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                observed[0] += 1.0;
            } else {
                assert!((s.wi + wo).length() < 1e-6);
                observed[1] += 1.0;
            }
        }
        let n = SAMPLES as f64;
        assert_fits(
            &format!("thin dielectric at {theta} deg"),
            &observed,
            &[n * expected_r, n * (1.0 - expected_r)],
        );
    }
}

/// The environment map's importance sampling against its density, on the
/// test sky (a gradient, a ground and a small sun 800 times brighter), at
/// two rotations.
#[test]
fn environment_map_sampling() {
    use tracelab::scene::environment::{Environment, Radiance};
    use tracelab::texture::Bitmap;
    let sky = Bitmap::read(
        &crate::common::repo_path("tests/data/materials/sky.exr"),
        false,
    )
    .unwrap();
    let sky = std::sync::Arc::new(sky);
    for (k, to_world) in [
        glam::Mat3A::IDENTITY,
        glam::Mat3A::from_rotation_x(1.1) * glam::Mat3A::from_rotation_z(0.4),
    ]
    .into_iter()
    .enumerate()
    {
        let env = Environment::new(Radiance::Map(sky.clone()), 1.0, to_world);
        let seed = 700 + k as u64;
        // A sample's density is its cell's; pdf() reads the cell back from
        // the direction, which rounding (about 1e-7) may move across a
        // cell's edge: 2 in 500 000 samples here, at most 1 in 10 000 allowed.
        let (mut samples, mut differ) = (0u32, 0u32);
        check_directions(
            &format!("environment map, rotation {k}"),
            |i| {
                let (d, _, pdf) =
                    env.sample(Vec2::new(uniform(seed, i, 0), uniform(seed, i, 1)))?;
                samples += 1;
                differ += u32::from((pdf - env.pdf(d)).abs() > 1e-3 * pdf.max(1.0));
                Some(d)
            },
            |d| env.pdf(d) as f64,
        );
        assert!(
            differ * 10_000 <= samples,
            "{differ} of {samples} sample densities differ from pdf()"
        );
    }
}
