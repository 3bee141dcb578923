//! What a radiosity solution shows where a ray lands: the element and its
//! radiance, the wireframe overlay, and the final gather.

use super::{Model, RadiosityState};
use crate::accel::SurfaceHit;
use crate::integrator::RayCounts;
use crate::math::{Frame, Rgb};
use crate::radiosity::Element;
use crate::sampling::warp::square_to_cosine_hemisphere;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;

/// What the solution says at a surface point.
pub(super) struct Surface {
    /// The element's number (a hierarchy's node, a mesh's element).
    pub(super) index: usize,
    /// The element's radiance (emission included).
    pub(super) radiance: Rgb,
    pub(super) element: Element,
    /// The point's barycentrics in the element.
    pub(super) barycentrics: glam::Vec2,
    /// Smooth display: the radiance interpolated over the element.
    pub(super) smooth: Option<Rgb>,
    pub(super) ambient: Rgb,
    /// Subdivision level of the element (0: the scene triangle).
    pub(super) level: u8,
}

/// Whether a point at `distance` from the camera lies within about a pixel
/// of its element's edges (the wireframe overlay).
pub(super) fn on_edge(scene: &Scene, surface: &Surface, distance: f32) -> bool {
    let camera = &scene.camera;
    let pixel = distance * 2.0 * camera.tan_half_fov_y / camera.height.max(1) as f32;
    let [a, b, c] = surface.element.vertices;
    let bary = surface.barycentrics;
    let weights = [1.0 - bary.x - bary.y, bary.x, bary.y];
    // Distance to the edge opposite vertex k: b_k times the height on it.
    let opposite = [(c - b).length(), (a - c).length(), (b - a).length()];
    (0..3).any(|k| weights[k] * 2.0 * surface.element.area / opposite[k] < 0.6 * pixel)
}

/// The colour of discontinuity lines over the wireframe.
pub(super) const LINE_COLOUR: Rgb = Rgb::new(0.0, 0.85, 1.0);

/// Whether a hit at `distance` from the camera lies within about a pixel
/// of a discontinuity line (an edge of its triangle that lies on one).
pub(super) fn on_line(
    scene: &Scene,
    state: &RadiosityState,
    hit: &SurfaceHit,
    distance: f32,
) -> bool {
    let Some(meshed) = state.meshed() else {
        return false;
    };
    let t = hit.primitive as usize;
    let (Some(flags), Some(&v)) = (meshed.on_line.get(t), scene.geometry.triangles().get(t)) else {
        return false;
    };
    if !flags.contains(&true) {
        return false;
    }
    let camera = &scene.camera;
    let pixel = distance * 2.0 * camera.tan_half_fov_y / camera.height.max(1) as f32;
    let (b1, b2) = barycentrics(hit.point, v);
    let weights = [1.0 - b1 - b2, b1, b2];
    let area2 = (v[1] - v[0]).cross(v[2] - v[0]).length();
    let opposite = [
        (v[2] - v[1]).length(),
        (v[0] - v[2]).length(),
        (v[1] - v[0]).length(),
    ];
    (0..3).any(|k| flags[k] && weights[k] * area2 / opposite[k] < 0.9 * pixel)
}

/// The wireframe's colour for elements of subdivision `level`.
pub(super) fn level_colour(level: u8) -> Rgb {
    const COLOURS: [[f32; 3]; 8] = [
        [1.0, 1.0, 1.0],
        [1.0, 0.9, 0.1],
        [1.0, 0.5, 0.0],
        [1.0, 0.1, 0.1],
        [0.9, 0.1, 0.9],
        [0.2, 0.3, 1.0],
        [0.1, 0.9, 1.0],
        [0.1, 1.0, 0.2],
    ];
    let [r, g, b] = COLOURS[level as usize % COLOURS.len()];
    Rgb::new(r, g, b)
}

/// The element a hit lies in, on the triangle's front or its `back`, and
/// its solution (None for spheres and sides that are not patches).
pub(super) fn surface_at(
    scene: &Scene,
    state: &RadiosityState,
    hit: &SurfaceHit,
    back: bool,
) -> Option<Surface> {
    let triangle = hit.primitive as usize;
    let [a, b, c] = *scene.geometry.triangles().get(triangle)?;
    let (b1, b2) = barycentrics(hit.point, [a, b, c]);
    let (b1, b2) = (b1.clamp(0.0, 1.0), b2.clamp(0.0, 1.0 - b1.clamp(0.0, 1.0)));
    let (k, radiance, element, field, ambient, level) = match &state.model {
        Model::Matrix(m) => {
            let k = m.mesh.element_at(triangle, back, b1, b2)?;
            (
                k,
                m.solution.radiance[k],
                m.mesh.elements[k],
                &m.vertex_radiance,
                m.solution.ambient,
                m.mesh.levels[k],
            )
        }
        Model::Hierarchical(h) => {
            let (k, radiance, element, level) = h.leaf_at(triangle, back, b1, b2)?;
            (k, radiance, *element, h.vertex_field(), Rgb::ZERO, level)
        }
    };
    let (e1, e2) = barycentrics(hit.point, element.vertices);
    Some(Surface {
        index: k,
        radiance,
        element,
        barycentrics: glam::Vec2::new(e1, e2),
        smooth: field.at(k, [1.0 - e1 - e2, e1, e2]),
        ambient,
        level,
    })
}

/// The patch a ray travelling along `direction` meets at `hit`, and whether
/// it meets its front. Met from behind, a triangle shows its back's patch
/// ([`crate::radiosity::mesh::exposed_backs`]: a thin surface lit on both
/// sides), or of two
/// coincident triangles facing apart ([`crate::radiosity::mesh::back_twins`]: indirect.toml's
/// table) the other's front.
pub(super) fn facing_surface(
    scene: &Scene,
    state: &RadiosityState,
    hit: &SurfaceHit,
    direction: glam::Vec3A,
) -> Option<(Surface, bool)> {
    let surface = surface_at(scene, state, hit, false)?;
    if surface.element.normal.dot(direction) < 0.0 {
        return Some((surface, true));
    }
    if let Some(back) = surface_at(scene, state, hit, true) {
        return Some((back, true));
    }
    let twin = state.back_twins.get(hit.primitive as usize).copied();
    let across = twin.filter(|&t| t != u32::MAX).and_then(|t| {
        let hit = SurfaceHit {
            primitive: t,
            normal: -hit.normal,
            ..*hit
        };
        surface_at(scene, state, &hit, false)
    });
    Some(across.map_or((surface, false), |s| (s, true)))
}

/// Barycentrics (b1, b2) of `p` in the triangle `v`, by sub-triangle areas.
fn barycentrics(p: glam::Vec3A, [a, b, c]: [glam::Vec3A; 3]) -> (f32, f32) {
    let n = (b - a).cross(c - a);
    let inv = 1.0 / n.length_squared();
    (
        (p - a).cross(c - a).dot(n) * inv,
        (b - a).cross(p - a).dot(n) * inv,
    )
}

/// The solution's elements as light sources for the gather: chosen in
/// proportion to the light they reflect (luminance of L − E times area),
/// so that a room lit by one bright spot on its ceiling gathers from the
/// spot instead of waiting for a cosine ray to meet it.
#[derive(Clone, Debug, Default)]
pub struct Senders {
    /// Per sender: its number, element and reflected radiance.
    senders: Vec<(u32, Element, Rgb)>,
    /// Cumulative probabilities over `senders`, the last 1.
    cdf: Vec<f32>,
    /// Per element number, its probability (0 for those never chosen).
    pmf: Vec<f32>,
}

impl Senders {
    /// From `numbers` element numbers and the elements (number, element,
    /// radiance) that may send.
    pub fn new<'a>(
        numbers: usize,
        elements: impl Iterator<Item = (usize, &'a Element, Rgb)>,
    ) -> Senders {
        let mut senders = Vec::new();
        let mut cdf = Vec::new();
        let mut total = 0.0f64;
        for (k, e, l) in elements {
            let reflected = (l - e.emission).max(Rgb::ZERO);
            let weight = crate::math::luminance(reflected) as f64 * e.area as f64;
            if weight > 0.0 && weight.is_finite() {
                total += weight;
                senders.push((k as u32, *e, reflected));
                cdf.push(total);
            }
        }
        let mut pmf = vec![0.0f32; if senders.is_empty() { 0 } else { numbers }];
        let mut before = 0.0;
        let cdf = cdf
            .into_iter()
            .zip(&senders)
            .map(|(c, s)| {
                pmf[s.0 as usize] = ((c - before) / total) as f32;
                before = c;
                (c / total) as f32
            })
            .collect();
        Senders { senders, cdf, pmf }
    }

    /// Solid-angle density at a point of choosing element `k` and a
    /// uniform point on it seen at `distance` and cosine `cos_there`.
    fn pdf(&self, k: usize, element: &Element, distance: f32, cos_there: f32) -> f32 {
        let p = self.pmf.get(k).copied().unwrap_or(0.0);
        if p == 0.0 || !(cos_there > 0.0) {
            return 0.0;
        }
        p * distance * distance / (element.area * cos_there)
    }
}

/// Reflected radiance at a diffuse hit: direct light by one light sample,
/// indirect by the solution (L - E) read where a cosine-sampled ray lands
/// and at a point of an element chosen by [`Senders`], the two combined by
/// the power heuristic.
pub(super) fn gather(
    scene: &Scene,
    state: &RadiosityState,
    hit: &SurfaceHit,
    reflectance: Rgb,
    wo: glam::Vec3A,
    sampler: &mut Sampler,
    counts: &mut RayCounts,
) -> Rgb {
    // The side the camera ray came from.
    let normal = if hit.normal.dot(wo) < 0.0 {
        -hit.normal
    } else {
        hit.normal
    };
    let mut direct = Rgb::ZERO;
    let u_select = sampler.next_1d_for(Domain::Light);
    let u_light = sampler.next_2d_for(Domain::Light);
    if let Some(ls) = scene.lights.sample(hit.point, u_select, u_light) {
        let cos = normal.dot(ls.wi);
        if cos > 0.0 {
            counts.shadow += 1;
            if !scene.geometry.occluded(&ls.shadow_ray_from(hit)) {
                // f = ρ/π (Lambert).
                direct = reflectance * ls.radiance * (cos / (std::f32::consts::PI * ls.pdf));
            }
        }
    }
    let senders = &state.senders;
    let mis = |a: f32, b: f32| {
        if a > 0.0 {
            a * a / (a * a + b * b)
        } else {
            0.0
        }
    };
    let local = square_to_cosine_hemisphere(sampler.next_2d_for(Domain::Bsdf));
    let ray = hit.spawn_ray(Frame::from_normal(normal).to_world(local));
    counts.bounce += 1;
    // A patch's back sends nothing: the solution has its front only.
    let mut indirect = match scene.geometry.intersect(&ray) {
        Some(next) => match facing_surface(scene, state, &next, ray.direction) {
            Some((s, true)) => {
                let cos_there = s.element.normal.dot(-ray.direction);
                let p_sender = senders.pdf(s.index, &s.element, next.t, cos_there);
                // Cosine sampling: f cos / p = ρ.
                (s.radiance - s.element.emission) * mis(local.z / std::f32::consts::PI, p_sender)
            }
            _ => Rgb::ZERO,
        },
        None => Rgb::ZERO,
    };
    let u = sampler.next_1d_for(Domain::Light);
    let u_point = sampler.next_2d_for(Domain::Light);
    let pick = senders.cdf.partition_point(|&c| c <= u);
    if pick < senders.senders.len() {
        let (k, e, l) = &senders.senders[pick];
        let b = crate::sampling::warp::square_to_uniform_triangle(u_point);
        let y = b.x * e.vertices[0] + b.y * e.vertices[1] + (1.0 - b.x - b.y) * e.vertices[2];
        let d = y - hit.point;
        let distance = d.length();
        let w = d / distance;
        let (cos_here, cos_there) = (normal.dot(w), -e.normal.dot(w));
        let p_sender = senders.pdf(*k as usize, e, distance, cos_there);
        if cos_here > 0.0 && p_sender > 0.0 {
            counts.shadow += 1;
            let y_error = crate::math::gamma(7) * y.abs();
            let shadow =
                crate::math::ray_between(hit.point, hit.error, normal, y, y_error, e.normal);
            if !scene.geometry.occluded(&shadow) {
                let p_cosine = cos_here / std::f32::consts::PI;
                indirect +=
                    *l * (cos_here / (std::f32::consts::PI * p_sender) * mis(p_sender, p_cosine));
            }
        }
    }
    direct + reflectance * indirect
}
