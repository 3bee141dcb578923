//! The multiple importance sampling weights of bidirectional path tracing,
//! by ratios of densities: each strategy's weight is 1 / sum_i (p_i / p_s)^beta
//! (Veach 1997, 10.2), the ratios walked vertex by vertex from the stored
//! forward and reverse densities (area measure), which stays finite for long
//! paths where products of densities would not. The part of the sum that no
//! connection changes is summed once per subpath. Here too: the density
//! (area) with which a light point's particle reaches a vertex.

use super::{Bdpt, Connection, Vertex};
use crate::integrator::MisHeuristic;
use crate::scene::Scene;

impl Bdpt {
    /// The heuristic applied to one ratio of densities: the power
    /// heuristic's square of a product is the product of the squares, so
    /// ratios can be raised one by one.
    #[inline]
    fn mis_power(&self, rev: f32, fwd: f32) -> f32 {
        // A delta density is stored as 0 and stands for itself in a ratio.
        let remap = |p: f32| if p != 0.0 { p } else { 1.0 };
        let r = remap(rev) / remap(fwd);
        match self.mis {
            MisHeuristic::Balance => r,
            _ => r * r,
        }
    }

    /// The heuristic's factor for light tracing's density in paths of
    /// `light_vertices` light vertices: n^beta where each of the n particles
    /// makes them, else 1.
    #[inline]
    fn lens_count(&self, light_vertices: usize) -> f32 {
        if self.light_paths > 1 && light_vertices <= self.light_path_vertices {
            self.mis_power(self.light_paths as f32, 1.0)
        } else {
            1.0
        }
    }

    /// Stores in every vertex the part of the MIS sum that no connection
    /// changes (Georgiev et al.'s recursive quantities in ratio form): for
    /// camera vertex z_j, sum over i <= j of prod_{k=i..j} r_k, where r_k =
    /// p_rev(z_k) / p_fwd(z_k) and strategy i counts where z_i and z_{i-1}
    /// are not specular; likewise on the light subpath. A connection at
    /// z_{t-1} changes the reverse densities of z_{t-1} and z_{t-2} only, so
    /// [`Bdpt::mis_weight`] needs two ratios and the prefix at z_{t-3}: O(1)
    /// instead of a walk over the path (12% of the time on SmallVCM's scene).
    pub(super) fn prepare_mis(&self, cam: &mut [Vertex], light: &mut [Vertex]) {
        let mut prefix = 0.0f32;
        let mut lens = 0.0f32;
        for i in 1..cam.len() {
            let counts = !cam[i].delta && !cam[i - 1].delta;
            let r = self.mis_power(cam[i].pdf_rev, cam[i].pdf_fwd);
            // Capped so that a zero ratio later gives 0, not 0 * inf.
            prefix = (r * (f32::from(u8::from(counts)) + prefix)).min(f32::MAX);
            cam[i].mis_prefix = prefix;
            lens = if i == 1 {
                prefix
            } else {
                (r * lens).min(f32::MAX)
            };
            cam[i].mis_lens = lens;
        }
        let mut prefix = 0.0f32;
        for i in 0..light.len() {
            let previous_delta = if i > 0 {
                light[i - 1].delta
            } else {
                light[0].delta_light
            };
            let counts = !light[i].delta && !previous_delta;
            let r = self.mis_power(light[i].pdf_rev, light[i].pdf_fwd);
            prefix = (r * (f32::from(u8::from(counts)) + prefix)).min(f32::MAX);
            light[i].mis_prefix = prefix;
        }
    }

    /// The MIS weight of strategy (s, t) for the path it made: the
    /// densities next to the connection are the joined path's (from
    /// [`Bdpt::connect`]), the rest are the subpaths' own, summed in
    /// advance by [`Bdpt::prepare_mis`].
    pub(super) fn mis_weight(
        &self,
        cam: &[Vertex],
        light: &[Vertex],
        s: usize,
        t: usize,
        joint: &Connection,
    ) -> f32 {
        let one_if = |b: bool| f32::from(u8::from(b));
        // Light tracing's samples: n particles make its paths of up to
        // `light_path_vertices` light vertices, and its density counts n
        // times (Veach's multi-sample combination, n_i p_i).
        let lens_count = self.lens_count(if t == 1 { s } else { s + t - 1 });
        // Strategies with fewer camera vertices: z_i made by the light side.
        let camera_sum = if t >= 2 {
            let r_t1 = self.mis_power(joint.pt_rev, cam[t - 1].pdf_fwd);
            let (deeper, lens) = if t >= 3 {
                let r_t2 = self.mis_power(joint.pt_minus_rev, cam[t - 2].pdf_fwd);
                let counts = one_if(!cam[t - 2].delta && !cam[t - 3].delta);
                let (prefix, lens) = if t >= 4 {
                    (cam[t - 3].mis_prefix, cam[t - 3].mis_lens)
                } else {
                    (0.0, counts)
                };
                (r_t2 * (counts + prefix), r_t2 * lens)
            } else {
                (0.0, one_if(!cam[t - 2].delta))
            };
            // (Only where it counts: 0 * inf would make the weight NaN.)
            let lens = if lens_count != 1.0 {
                (lens_count - 1.0) * lens
            } else {
                0.0
            };
            r_t1 * (one_if(!cam[t - 2].delta) + deeper + lens)
        } else {
            0.0
        };
        // Strategies with fewer light vertices: y_i made by the camera side.
        // The connection's end: a light point s = 1 sampled itself replaces
        // the subpath's own.
        let light_sum = if s >= 1 {
            let (pdf_fwd, delta_light) = match joint.sampled_light {
                Some(l) => (l.pdf_fwd, l.delta),
                None => (light[s - 1].pdf_fwd, light[s - 1].delta_light),
            };
            let r_s1 = self.mis_power(joint.qs_rev, pdf_fwd);
            let deeper = if s >= 2 {
                let r_s2 = self.mis_power(joint.qs_minus_rev, light[s - 2].pdf_fwd);
                let previous_delta = if s >= 3 {
                    light[s - 3].delta
                } else {
                    light[0].delta_light
                };
                let prefix = if s >= 3 { light[s - 3].mis_prefix } else { 0.0 };
                r_s2 * (one_if(!light[s - 2].delta && !previous_delta) + prefix)
            } else {
                0.0
            };
            let previous_delta = if s >= 2 {
                light[s - 2].delta
            } else {
                delta_light
            };
            r_s1 * (one_if(!previous_delta) + deeper)
        } else {
            0.0
        };
        let weight = if t == 1 {
            1.0 / (1.0 + light_sum / lens_count)
        } else {
            1.0 / (1.0 + camera_sum + light_sum)
        };
        if weight.is_finite() { weight } else { 0.0 }
    }
}

/// The density (area, at `next`) with which a particle leaving the light
/// point `v` heads for `next`.
#[inline]
pub(super) fn light_direction_pdf(scene: &Scene, v: &Vertex, next: &Vertex) -> f32 {
    if v.infinite {
        // A parallel beam along `v.normal`: the disc's density, projected.
        return scene.lights.disc_density(v.light) * next.cos(v.normal);
    }
    let w = (next.point - v.point).normalize_or_zero();
    let (_, pdf_direction) = scene.lights.emission_pdf(v.light, v.normal, w);
    v.area_density_at(pdf_direction, next)
}
