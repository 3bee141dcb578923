//! Rough plastic (Mitsuba's `roughplastic`): a rough dielectric coating
//! (microfacet reflection, sampled by visible normals) over a Lambertian
//! base. Light enters the base in proportion to the coating's rough
//! transmittance T(cos θ) = 1 − (the specular lobe's directional albedo),
//! precomputed per (distribution, α, η) as Mitsuba does; the light the
//! coating reflects back inside is summed through its internal diffuse
//! reflectance, ρ / (1 − F_dr) or ρ / (1 − ρ F_dr) with `nonlinear`.

use super::BsdfSample;
use super::fresnel::fresnel_dielectric;
use super::microfacet::{Distribution, Microfacet};
use super::plastic::mean;
use crate::math::Rgb;
use crate::sampling::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use glam::{Vec2, Vec3A};
use std::f32::consts::FRAC_1_PI;
use std::sync::Mutex;

/// Entries of the transmittance table over cos θ ∈ [0, 1] (Mitsuba's count).
const TABLE_SIZE: usize = 64;

/// What a rough coating lets through, as a function of the cosine.
#[derive(Debug, PartialEq)]
pub struct CoatingTables {
    /// T(cos θ_k) at cos θ_k = k / 63.
    pub external_transmittance: [f32; TABLE_SIZE],
    /// Diffuse reflectance of the rough coating seen from inside.
    pub internal_reflectance: f32,
}

/// A rough plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    pub microfacet: Microfacet,
    pub eta: f32,
    pub diffuse: Rgb,
    pub specular: Rgb,
    pub nonlinear: bool,
    pub specular_sampling_weight: f32,
    /// Shared by every material with the same coating; computed once per
    /// process for each (distribution, α, η) and never freed, so the BSDF
    /// stays a small `Copy` value.
    pub tables: &'static CoatingTables,
}

impl RoughPlastic {
    pub fn new(
        microfacet: Microfacet,
        eta: f32,
        diffuse: Rgb,
        specular: Rgb,
        nonlinear: bool,
    ) -> RoughPlastic {
        let (d, s) = (mean(diffuse), mean(specular));
        RoughPlastic {
            microfacet,
            eta,
            diffuse,
            specular,
            nonlinear,
            specular_sampling_weight: if d + s > 0.0 { s / (d + s) } else { 0.5 },
            tables: coating_tables(microfacet, eta),
        }
    }

    /// T(cos θ), linearly interpolated in the table.
    #[inline]
    fn transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let t = x - i as f32;
        let table = &self.tables.external_transmittance;
        table[i] * (1.0 - t) + table[i + 1] * t
    }

    #[inline]
    fn specular_probability(&self, wo: Vec3A) -> f32 {
        let t = self.transmittance(wo.z);
        let ps = (1.0 - t) * self.specular_sampling_weight;
        let pd = t * (1.0 - self.specular_sampling_weight);
        if ps + pd > 0.0 { ps / (ps + pd) } else { 0.0 }
    }

    /// f(wo, wi): both lobes; directions on the upper side.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let m = (wo + wi).normalize();
        let specular = if m.is_finite() {
            let f = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
            let dg = self.microfacet.d(m) * self.microfacet.g(wo, wi, m);
            self.specular * (f * dg / (4.0 * wo.z * wi.z))
        } else {
            Rgb::ZERO
        };
        let fdr = self.tables.internal_reflectance;
        let base = if self.nonlinear {
            self.diffuse / (Rgb::ONE - self.diffuse * fdr)
        } else {
            self.diffuse / (1.0 - fdr)
        };
        let diffuse = base
            * (FRAC_1_PI / (self.eta * self.eta)
                * self.transmittance(wo.z)
                * self.transmittance(wi.z));
        specular + diffuse
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability(wo);
        let m = (wo + wi).normalize();
        let specular = if m.is_finite() && wo.dot(m) > 0.0 {
            self.microfacet.pdf_visible(wo, m) / (4.0 * wo.dot(m))
        } else {
            0.0
        };
        ps * specular + (1.0 - ps) * cosine_hemisphere_pdf(wi)
    }

    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if u_lobe < self.specular_probability(wo) {
            let m = self.microfacet.sample_visible(wo, u);
            2.0 * wo.dot(m) * m - wo
        } else {
            square_to_cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        let weight = self.eval(wo, wi) * (wi.z / pdf);
        weight.is_finite().then_some(BsdfSample {
            wi,
            weight,
            pdf,
            specular: false,
        })
    }

    pub fn albedo_hint(&self) -> f32 {
        self.diffuse.max_element().max(self.specular.max_element())
    }
}

/// The means of the `K` values of `term(wo, m)` over the normals visible
/// from the direction at incident cosine `cos` (in the xz-plane), by a
/// 64 × 64 midpoint rule in the sampler's unit square, where the
/// integrand is smooth at any roughness. Integrals that share a direction
/// share its samples, which are most of the cost (Beckmann's especially).
fn visible_normal_means<const K: usize>(
    microfacet: &Microfacet,
    cos: f32,
    term: impl Fn(Vec3A, Vec3A) -> [f32; K],
) -> [f32; K] {
    const N: usize = 64;
    let wo = Vec3A::new((1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos);
    let mut sums = [0.0f64; K];
    for i in 0..N {
        for j in 0..N {
            let u = Vec2::new((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
            let values = term(wo, microfacet.sample_visible(wo, u));
            for (sum, v) in sums.iter_mut().zip(values) {
                *sum += f64::from(v);
            }
        }
    }
    sums.map(|sum| (sum / (N * N) as f64) as f32)
}

/// The integrand of the coating's specular albedo (Fresnel at relative
/// IOR `eta`): E[F(wo·m) G1(wi)] over visible normals is the directional
/// albedo of its reflection.
fn reflected(microfacet: &Microfacet, wo: Vec3A, m: Vec3A, eta: f32) -> f32 {
    let dot = wo.dot(m);
    let wi = 2.0 * dot * m - wo;
    if wi.z > 0.0 && dot > 0.0 {
        fresnel_dielectric(dot, eta).reflectance * microfacet.g1(wi, m)
    } else {
        0.0
    }
}

/// The integrand of the coating's directional transmittance into a medium
/// of relative IOR `eta`: E[(1 − F(wo·m)) G1(wt, m)] over visible normals,
/// wt the direction refracted through m (Mitsuba 3's `eval_transmittance`;
/// the refracted ray's shadowing makes it fall faster towards grazing than
/// 1 − the reflectance).
fn transmitted(microfacet: &Microfacet, wo: Vec3A, m: Vec3A, eta: f32) -> f32 {
    let dot = wo.dot(m);
    let sin2_t = (1.0 - dot * dot).max(0.0) / (eta * eta);
    if dot <= 0.0 || sin2_t >= 1.0 {
        return 0.0;
    }
    let wt = -wo / eta + m * (dot / eta - (1.0 - sin2_t).sqrt());
    if wt.z < 0.0 {
        (1.0 - fresnel_dielectric(dot, eta).reflectance) * microfacet.g1(wt, m)
    } else {
        0.0
    }
}

/// At incident cosine `cos`: the coating's transmittance from outside
/// (IOR ratio `eta`), and the albedo of its reflection seen from inside
/// (1 / `eta`). Each integral's cosine is kept off 0 (1e-6 and 1e-4, as
/// Mitsuba): where that makes them differ, two passes.
fn coating_row(microfacet: &Microfacet, cos: f32, eta: f32) -> (f32, f32) {
    let (outside, inside) = (cos.max(1e-6), cos.max(1e-4));
    if outside != inside {
        let [t] = visible_normal_means(microfacet, outside, |wo, m| {
            [transmitted(microfacet, wo, m, eta)]
        });
        let [r] = visible_normal_means(microfacet, inside, |wo, m| {
            [reflected(microfacet, wo, m, 1.0 / eta)]
        });
        return (t, r);
    }
    let [t, r] = visible_normal_means(microfacet, cos, |wo, m| {
        [
            transmitted(microfacet, wo, m, eta),
            reflected(microfacet, wo, m, 1.0 / eta),
        ]
    });
    (t, r)
}

/// Roughness levels of [`CoatingLevels`]: √α = k / (LEVELS − 1). Each
/// level's tables take 64 × 2 integrals of 4096 samples: made once per
/// (distribution, η), in parallel, only for a plastic with a roughness map.
pub const COATING_LEVELS: usize = 64;

/// A rough plastic's coating tables at [`COATING_LEVELS`] roughnesses, for
/// a roughness read from a texture at each hit: the tables are smooth in
/// α, and the nearest level's stand for the texel's (the lobe itself
/// uses the texel's exact α).
#[derive(Debug)]
pub struct CoatingLevels {
    tables: [&'static CoatingTables; COATING_LEVELS],
}

/// One set per (distribution, η), made once: the same set is the same address.
impl PartialEq for CoatingLevels {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

impl Eq for CoatingLevels {}

impl CoatingLevels {
    /// The levels for (distribution, η), computed on first use.
    pub fn of(distribution: Distribution, eta: f32) -> &'static CoatingLevels {
        type Key = (Distribution, u32);
        static CACHE: Mutex<Vec<(Key, &'static CoatingLevels)>> = Mutex::new(Vec::new());
        let key = (distribution, eta.to_bits());
        let find =
            |c: &[(Key, &'static CoatingLevels)]| c.iter().find(|(k, _)| *k == key).map(|e| e.1);
        if let Some(levels) = find(&CACHE.lock().unwrap_or_else(|e| e.into_inner())) {
            return levels;
        }
        let tables = std::array::from_fn(|k| {
            let root = k as f32 / (COATING_LEVELS - 1) as f32;
            coating_tables(Microfacet::new(distribution, root * root, root * root), eta)
        });
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(first) = find(&cache) {
            return first;
        }
        let levels: &'static CoatingLevels = Box::leak(Box::new(CoatingLevels { tables }));
        cache.push((key, levels));
        levels
    }

    /// The tables of the level nearest to roughness `alpha` (in √α).
    #[inline]
    pub fn nearest(&self, alpha: f32) -> &'static CoatingTables {
        let k = (alpha.max(0.0).sqrt() * (COATING_LEVELS - 1) as f32).round() as usize;
        self.tables[k.min(COATING_LEVELS - 1)]
    }
}

/// (distribution, α_u, α_v, η), exactly.
type CoatingKey = (Distribution, u32, u32, u32);

fn coating_key(microfacet: Microfacet, eta: f32) -> CoatingKey {
    let Microfacet {
        distribution,
        alpha_u,
        alpha_v,
    } = microfacet;
    (
        distribution,
        alpha_u.to_bits(),
        alpha_v.to_bits(),
        eta.to_bits(),
    )
}

/// Every coating's tables made so far in this process.
static CACHE: Mutex<Vec<(CoatingKey, &'static CoatingTables)>> = Mutex::new(Vec::new());

/// Whether the tables for (distribution, α, η) are made already.
#[cfg(test)]
pub(crate) fn coating_tables_made(microfacet: Microfacet, eta: f32) -> bool {
    let key = coating_key(microfacet, eta);
    let cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    cache.iter().any(|(k, _)| *k == key)
}

/// The coating tables for (distribution, α, η), computed on first use.
fn coating_tables(microfacet: Microfacet, eta: f32) -> &'static CoatingTables {
    let key = coating_key(microfacet, eta);
    let cached = |cache: &[(CoatingKey, &'static CoatingTables)]| {
        cache.iter().find(|(k, _)| *k == key).map(|&(_, t)| t)
    };
    // Not locked while computing: a rayon worker waiting on the loop below
    // may run another task that asks for tables.
    if let Some(tables) = cached(&CACHE.lock().unwrap_or_else(|e| e.into_inner())) {
        return tables;
    }
    // Each cosine's two integrals on its own core: a few materials' tables
    // were a seventh of loading a textured interior.
    use rayon::prelude::*;
    let rows: Vec<(f32, f32)> = (0..TABLE_SIZE)
        .into_par_iter()
        .map(|k| {
            let cos = k as f32 / (TABLE_SIZE - 1) as f32;
            // Mitsuba's estimate of 2 ∫ R_int(μ) μ dμ: twice the mean over
            // the same 64 points, kept for agreement with its images.
            let (transmittance, albedo) = coating_row(&microfacet, cos, eta);
            (transmittance, albedo * cos)
        })
        .collect();
    let external_transmittance = std::array::from_fn(|k| rows[k].0);
    let internal: f32 = rows.iter().map(|r| r.1).sum();
    let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    // Another thread may have made the same tables meanwhile: keep one.
    if let Some(first) = cached(&cache) {
        return first;
    }
    let tables: &'static CoatingTables = Box::leak(Box::new(CoatingTables {
        external_transmittance,
        internal_reflectance: 2.0 * internal / TABLE_SIZE as f32,
    }));
    cache.push((key, tables));
    tables
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A texel's roughness reads the tables of the nearest level, which
    /// are the very tables of a plastic of that level's α; between levels
    /// the tables change little: the diffuse lobe's scale 1 / (1 − the
    /// coating's internal reflectance) by at most 2.1% from one level to
    /// the next (measured; 2.5% asserted), so a texel halfway between
    /// levels is off by about 1% (32 levels stepped by 4.1%).
    #[test]
    fn roughness_levels_are_the_tables_of_their_alpha() {
        let levels = CoatingLevels::of(Distribution::Ggx, 1.5);
        assert!(std::ptr::eq(
            levels,
            CoatingLevels::of(Distribution::Ggx, 1.5)
        ));
        for k in 0..COATING_LEVELS {
            let root = k as f32 / (COATING_LEVELS - 1) as f32;
            let alpha = root * root;
            let plastic = RoughPlastic::new(
                Microfacet::new(Distribution::Ggx, alpha, alpha),
                1.5,
                Rgb::splat(0.5),
                Rgb::ONE,
                false,
            );
            assert!(
                std::ptr::eq(levels.nearest(alpha), plastic.tables),
                "level {k}"
            );
            // Half a step in √α either side still rounds to this level.
            let step = 0.49 / (COATING_LEVELS - 1) as f32;
            for r in [(root - step).max(0.0), (root + step).min(1.0)] {
                assert!(
                    std::ptr::eq(levels.nearest(r * r), plastic.tables),
                    "level {k}, √α {r}"
                );
            }
            if k > 0 {
                let scale = |t: &CoatingTables| 1.0 / (1.0 - t.internal_reflectance);
                let (previous, here) = (scale(levels.tables[k - 1]), scale(levels.tables[k]));
                assert!(
                    (here / previous - 1.0).abs() < 0.025,
                    "level {k}: {previous} -> {here}"
                );
            }
        }
    }
}
