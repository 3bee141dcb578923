//! Bidirectional path tracing's subpath vertices: what each stores, the
//! densities between two of them, and the lights at infinity's densities.

use super::super::light::shading_correction;
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::math::{Frame, Rgb};
use crate::scene::Scene;
use crate::scene::light::Light;
use crate::scene::material::Bsdf;
use glam::{Vec2, Vec3A};

/// [`Vertex::packed_shading`] where the shading normal is the geometric one.
pub(super) const NO_SHADING_NORMAL: u32 = u32::MAX;

/// What kind of point a subpath vertex is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// The lens point z_0.
    Camera,
    /// A point on a light, y_0 (or the light point sampled for s = 1).
    Light,
    /// A surface the subpath hit.
    Surface,
}

/// A subpath vertex: where it is, what the subpath carries to it, and the
/// densities (area measure) of sampling it from either side.
#[derive(Clone, Copy, Debug)]
pub(super) struct Vertex {
    pub(super) kind: Kind,
    pub(super) point: Vec3A,
    pub(super) error: Vec3A,
    /// Geometric normal; zero for a pinhole or a point light, which have
    /// no surface to project densities on.
    pub(super) normal: Vec3A,
    /// Shading normal of a surface (interpolated vertex normals), which
    /// frames its BSDF, packed in 32 bits (`math::octahedral_encode`), so
    /// that subpath copies stay small; [`NO_SHADING_NORMAL`] where it is
    /// the geometric one.
    pub(super) packed_shading: u32,
    /// The BSDF frame's turn about the normal (`Scene::shading_turn`), for
    /// an anisotropic surface.
    pub(super) turn: u16,
    /// Unit direction towards the previous vertex of its subpath.
    pub(super) wo: Vec3A,
    pub(super) bsdf: Bsdf,
    /// The subpath's weight up to here: the product of f cos / p, with the
    /// emission (light) or importance (camera) it started with.
    pub(super) beta: Rgb,
    /// Density of this vertex when sampled from the previous one of its
    /// own subpath, and when sampled from the next one (the other way).
    pub(super) pdf_fwd: f32,
    pub(super) pdf_rev: f32,
    /// The vertex scattered specularly: no connection can reach it.
    pub(super) delta: bool,
    /// A point light: no subpath can hit it.
    pub(super) delta_light: bool,
    /// A light at infinity (the environment, a directional light): `point`
    /// stands far beyond the scene, `normal` is the direction its light
    /// travels, and densities towards it stay per solid angle.
    pub(super) infinite: bool,
    /// The part of the MIS sum that depends on this subpath alone: the
    /// heuristic's ratios p_i / p_s of the strategies that would have made
    /// this vertex and the ones before it from the other side (see
    /// [`Bdpt::prepare_mis`]).
    pub(super) mis_prefix: f32,
    /// On the camera subpath, the one term of `mis_prefix` that stands for
    /// light tracing (t = 1): the product of the ratios down to z_1.
    pub(super) mis_lens: f32,
    /// The light the point lies on (light vertices and emitting surfaces),
    /// else [`NO_LIGHT`].
    pub(super) light: u32,
    /// Radiance emitted towards `wo` (surfaces); Le (or a point light's
    /// intensity) and its sidedness for light vertices.
    pub(super) emitted: Rgb,
    pub(super) two_sided: bool,
    /// Random numbers reserved for this vertex's connection: a light
    /// choice and point (camera subpath), a lens point (light subpath).
    pub(super) u_select: f32,
    pub(super) u_connect: Vec2,
}

impl Vertex {
    pub(super) const EMPTY: Vertex = Vertex {
        kind: Kind::Surface,
        point: Vec3A::ZERO,
        error: Vec3A::ZERO,
        normal: Vec3A::ZERO,
        packed_shading: NO_SHADING_NORMAL,
        turn: crate::math::NO_TURN,
        wo: Vec3A::ZERO,
        bsdf: Bsdf::Diffuse { albedo: Rgb::ZERO },
        beta: Rgb::ZERO,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
        delta_light: false,
        infinite: false,
        mis_prefix: 0.0,
        mis_lens: 0.0,
        light: NO_LIGHT,
        emitted: Rgb::ZERO,
        two_sided: false,
        u_select: 0.0,
        u_connect: Vec2::ZERO,
    };

    /// At a light subpath's surface vertex (whose frame is `local`), the
    /// adjoint BSDF from wo (the light's side) to w, with the density
    /// (solid angle) of sampling wo from w; at a light vertex (whose beta
    /// is 1 / p_position), the emitted radiance towards `w`, density 0 (not
    /// read); `w` is a unit vector.
    #[inline]
    pub(super) fn scatter(&self, scene: &Scene, w: Vec3A, local: &Local) -> (Rgb, f32) {
        let emitted = match self.kind {
            Kind::Surface => {
                let w = local.frame.to_local(w);
                let (f, pdf_back, _) = self.bsdf.eval_with_pdfs(w, local.wo);
                return (f * shading_correction(local.wo, w, local.normal), pdf_back);
            }
            Kind::Light if self.infinite => Rgb::ZERO,
            Kind::Light => {
                if self.normal == Vec3A::ZERO {
                    // A point or spot light: a spot's falloff shapes it.
                    match scene.lights.as_slice().get(self.light as usize) {
                        Some(Light::Spot { cone, .. }) => self.emitted * cone.falloff(w),
                        _ => self.emitted,
                    }
                } else if self.two_sided || self.normal.dot(w) > 0.0 {
                    self.emitted
                } else {
                    Rgb::ZERO
                }
            }
            Kind::Camera => Rgb::ZERO,
        };
        (emitted, 0.0)
    }

    /// The frame of the BSDF: the shading normal's where there is one.
    #[inline]
    pub(super) fn frame(&self) -> Frame {
        let n = match self.packed_shading {
            NO_SHADING_NORMAL => self.normal,
            p => crate::math::octahedral_decode(p),
        };
        Frame::from_normal(n).turned(self.turn)
    }

    /// The geometric normal in `frame` (exactly +z without a shading normal,
    /// where the adjoint's correction is 1).
    #[inline]
    pub(super) fn normal_local(&self, frame: &Frame) -> Vec3A {
        if self.packed_shading == NO_SHADING_NORMAL {
            Vec3A::Z
        } else {
            frame.to_local(self.normal)
        }
    }

    /// |cos| between the shading normal and `w`: the cosine of the
    /// scattering integral (Veach's thesis, 5.3; pbrt's G).
    #[inline]
    pub(super) fn shading_cos(&self, w: Vec3A) -> f32 {
        match self.packed_shading {
            NO_SHADING_NORMAL => self.cos(w),
            p => crate::math::octahedral_decode(p).dot(w).abs(),
        }
    }

    /// |cos| between the normal and the unit vector `w` (1 without a normal).
    #[inline]
    pub(super) fn cos(&self, w: Vec3A) -> f32 {
        if self.normal == Vec3A::ZERO {
            1.0
        } else {
            self.normal.dot(w).abs()
        }
    }

    /// A density wrt. solid angle at this vertex turned into one wrt. area
    /// at `next`.
    #[inline]
    pub(super) fn area_density_at(&self, pdf_direction: f32, next: &Vertex) -> f32 {
        if next.infinite {
            return pdf_direction;
        }
        let d = next.point - self.point;
        let dist2 = d.length_squared();
        if !(dist2 > 0.0) {
            return 0.0;
        }
        pdf_direction * next.cos(d / dist2.sqrt()) / dist2
    }
}

/// A vertex's BSDF frame with its directions in that frame, made once per
/// subpath vertex rather than once per strategy through it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Local {
    pub(super) frame: Frame,
    /// [`Vertex::wo`] in the frame.
    pub(super) wo: Vec3A,
    /// The geometric normal in the frame ([`Vertex::normal_local`]).
    pub(super) normal: Vec3A,
    /// What turns a density (solid angle) of this vertex sampling its
    /// subpath's previous vertex into one per area there
    /// ([`Vertex::area_density_at`] is linear in the density); 0 at the
    /// subpath's first vertex.
    pub(super) to_previous: f32,
}

impl Local {
    #[inline]
    fn of(v: &Vertex, previous: Option<&Vertex>) -> Local {
        let frame = v.frame();
        Local {
            wo: frame.to_local(v.wo),
            normal: v.normal_local(&frame),
            frame,
            to_previous: previous.map_or(0.0, |p| v.area_density_at(1.0, p)),
        }
    }

    /// |cos| between the shading normal and the unit vector `w` (a surface
    /// vertex's [`Vertex::shading_cos`]).
    #[inline]
    pub(super) fn shading_cos(&self, w: Vec3A) -> f32 {
        self.frame.n.dot(w).abs()
    }
}

/// A subpath: its vertices and, beside each, its [`Local`] frame.
#[derive(Default)]
pub(super) struct Subpath {
    pub(super) vertices: Vec<Vertex>,
    pub(super) local: Vec<Local>,
}

impl Subpath {
    pub(super) fn with_capacity(capacity: usize) -> Self {
        Subpath {
            vertices: Vec::with_capacity(capacity),
            local: Vec::with_capacity(capacity),
        }
    }

    pub(super) fn clear(&mut self) {
        self.vertices.clear();
        self.local.clear();
    }

    pub(super) fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Appends `v` and returns its frame.
    #[inline]
    pub(super) fn push(&mut self, v: Vertex) -> Local {
        let local = Local::of(&v, self.vertices.last());
        self.vertices.push(v);
        self.local.push(local);
        local
    }
}

/// A light's emitted radiance (or intensity) at `point` (normal `normal`)
/// on it, and its sidedness.
pub(super) fn emission_of(scene: &Scene, light: u32, point: Vec3A, normal: Vec3A) -> (Rgb, bool) {
    let Some(&emitter) = scene.lights.as_slice().get(light as usize) else {
        return (Rgb::ZERO, false); // the environment, whose radiance is per direction
    };
    let texture = || {
        scene
            .lights
            .texture_at(light as usize, point, normal)
            .unwrap_or(Rgb::ONE)
    };
    match emitter {
        Light::Triangle(p) | Light::Parallelogram(p) => (p.radiance * texture(), p.two_sided),
        Light::Sphere {
            radiance,
            two_sided,
            ..
        } => (radiance * texture(), two_sided),
        Light::Point { intensity, .. } | Light::Spot { intensity, .. } => (intensity, true),
        Light::Directional { .. } => (Rgb::ZERO, false),
    }
}

#[inline]
pub(super) fn surface_vertex(hit: &SurfaceHit, bsdf: Bsdf, wo: Vec3A, beta: Rgb) -> Vertex {
    Vertex {
        kind: Kind::Surface,
        point: hit.point,
        error: hit.error,
        normal: hit.normal,
        wo,
        bsdf,
        beta,
        ..Vertex::EMPTY
    }
}

/// The density of a light at infinity as a path's first vertex: its choice
/// times the solid-angle density of the direction `to_light` (pointing from
/// the scene to the light); 0 for a directional light (a delta).
#[inline]
pub(super) fn origin_density(scene: &Scene, light: u32, to_light: Vec3A) -> f32 {
    if scene.lights.is_directional(light) {
        return 0.0;
    }
    scene.lights.environment_pdf_as_emitted(to_light)
}
