//! Scenes: camera, geometry, materials and lights, loaded from TOML + OBJ/MTL
//! and checked before anything renders.

mod appearance;
pub mod description;
mod dropped;
pub mod emitters;
pub mod environment;
mod features;
pub mod framing;
pub mod gltf;
mod instances;
pub mod light;
mod light_pilot;
pub mod lights;
pub mod load;
pub mod material;
pub mod mesh;
pub mod mitsuba;
pub mod obj;
pub mod ply;
pub mod serialized;
mod shading;
pub use features::Features;
pub use instances::InstancesInput;
mod uri;

use crate::accel::blend::Blends;
use crate::accel::mask::Masks;
use crate::accel::{AccelChoice, Geometry, NO_LIGHT, Sphere, TriangleInput};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::math::OffsetMode;
use crate::shortcuts::{CameraSampling, NotApplied, PrimaryCandidates, Shortcuts, ShortcutsUsed};
use crate::texture::Texture;
use dropped::{Dropped, Survey};
use emitters::EmitterShape;
use glam::Vec3A;
use light::{EmissionTexture, Light, LightSampling, Lights, PlanarEmitter};
use material::{BlendWeight, Material, Opacity};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// Largest coordinate magnitude accepted anywhere in a scene. Beyond it,
/// squared distances and areas overflow f32 and the BVH builder's costs
/// become infinite (found by fuzzing: obvhs then builds a broken tree).
pub const MAX_COORDINATE: f32 = 1e15;

/// True when every component of `v` is finite and within [`MAX_COORDINATE`].
pub fn in_range(v: Vec3A) -> bool {
    v.is_finite() && v.abs().max_element() <= MAX_COORDINATE
}

/// Sizes beyond which input is taken for a typo rather than a wish.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub max_resolution: u32,
    pub max_triangles: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_resolution: 16384,
            max_triangles: 50_000_000,
        }
    }
}

impl Limits {
    /// Checks an image size against the limits.
    pub fn check_resolution(&self, width: u32, height: u32) -> std::result::Result<(), String> {
        let max = self.max_resolution;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(format!(
                "resolution {width}x{height} is outside 1..={max} per side"
            ));
        }
        Ok(())
    }
}

/// How a scene file is read: limits, parameters for Mitsuba's `$name`s
/// (`-D name=value`), and whether warnings are errors.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    pub limits: Limits,
    pub defines: Vec<(String, String)>,
    pub strict: bool,
}

impl LoadOptions {
    /// With `strict`, the first warning of an import as an error.
    pub fn check_strict(&self, warnings: &[String]) -> Result<()> {
        match warnings.first() {
            Some(w) if self.strict => {
                Err(Error::new(format!("{w} (--strict: warnings are errors)")))
            }
            _ => Ok(()),
        }
    }
}

/// Mitsuba's unbounded `max_depth = -1`: no limit where Russian roulette
/// ends every path (Mitsuba's survival probability is at most 0.95), and
/// [`crate::integrator::DEEPEST_WITHOUT_ROULETTE`] elsewhere.
pub const UNBOUNDED_DEPTH: u32 = u32::MAX;

/// What an imported file asks of the renderer (Mitsuba's integrator and
/// sampler), used where the command line does not say otherwise.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RenderHints {
    /// A technique's name (`IntegratorKind::name`).
    pub integrator: Option<String>,
    /// Bounces, tracelab's count (Mitsuba's `max_depth` − 1).
    pub max_depth: Option<u32>,
    pub rr_depth: Option<u32>,
    /// Path tracing's sampling of direct light as the CLI names it (`bsdf`,
    /// `light`, `mis`): Mitsuba's `direct` with one of its two sample
    /// counts 0.
    pub strategy: Option<String>,
    pub spp: Option<u32>,
    /// A sampler's name as the CLI takes it.
    pub sampler: Option<String>,
}

/// Everything a scene is made of, before acceleration structures are built.
#[derive(Clone, Debug)]
pub struct SceneInput {
    pub camera: Camera,
    pub materials: Vec<Material>,
    /// Textures the materials read (see [`material::MaterialTextures`]).
    pub textures: Vec<Texture>,
    /// Light from infinity, placed around the scene when it is built.
    pub environment: Option<environment::Environment>,
    pub triangles: Vec<TriangleInput>,
    pub spheres: Vec<Sphere>,
    pub point_lights: Vec<Light>,
    /// Objects in linear motion.
    pub moving: Vec<MovingInput>,
    /// Shared geometry placed several times.
    pub instances: InstancesInput,
    pub sphere_sampling: LightSampling,
    pub triangle_sampling: LightSampling,
    /// What the file asked for and did not get exactly (file:line: what).
    pub warnings: Vec<String>,
    pub hints: RenderHints,
}

/// One object moving by `velocity` per unit of time, given at time 0.
#[derive(Clone, Debug)]
pub struct MovingInput {
    pub triangles: Vec<TriangleInput>,
    pub spheres: Vec<Sphere>,
    pub velocity: Vec3A,
}

/// The sphere around the geometry's bounding box (unit at the origin
/// for an empty scene): where light from infinity enters.
fn bounding_sphere(geometry: &Geometry) -> (Vec3A, f32) {
    let b = geometry.bounds();
    let (min, max) = (b.min, b.max);
    if (max - min).is_finite() && max.cmpge(min).all() {
        (0.5 * (min + max), (0.5 * (max - min).length()).max(1e-3))
    } else {
        (Vec3A::ZERO, 1.0)
    }
}

/// A scene ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    /// Shared, so that a scene with another camera costs no copy of the BVH.
    pub geometry: Arc<Geometry>,
    pub materials: Vec<Material>,
    /// Textures, each once, shared by the materials that read them.
    pub textures: Vec<Texture>,
    pub lights: Lights,
    pub features: Features,
    /// Things the user should know that did not stop loading (dropped triangles, ...).
    pub warnings: Vec<String>,
    /// What the scene file asked of the renderer.
    pub hints: RenderHints,
    /// What the renderer knows in advance about the rays of a small scene
    /// (`crate::shortcuts`): per-pixel candidates for camera rays, built for
    /// `camera` when first asked for, and per-voxel occluders of shadow rays.
    pub shortcuts: Shortcuts,
}

/// Per light, its corners in order where it is flat.
fn flat_light_corners(lights: &Lights) -> Vec<Option<Vec<Vec3A>>> {
    lights
        .as_slice()
        .iter()
        .map(|light| match light {
            Light::Triangle(p) => Some(vec![p.p0, p.p0 + p.e1, p.p0 + p.e2]),
            Light::Parallelogram(p) => {
                Some(vec![p.p0, p.p0 + p.e1, p.p0 + p.e1 + p.e2, p.p0 + p.e2])
            }
            _ => None,
        })
        .collect()
}

impl Scene {
    /// Bytes of the bitmaps (each once, however many textures share it)
    /// and of the environment's map and sampling table.
    pub fn texture_bytes(&self) -> usize {
        let mut seen = std::collections::HashSet::new();
        let bitmaps: usize = self
            .textures
            .iter()
            .filter_map(|t| match t {
                Texture::Bitmap { image, .. } => seen
                    .insert(Arc::as_ptr(image))
                    .then(|| image.memory_bytes()),
                _ => None,
            })
            .sum();
        bitmaps + self.lights.environment().map_or(0, |e| e.memory_bytes())
    }

    /// Loads a scene file with the default limits.
    pub fn load(path: &Path) -> Result<Scene> {
        Self::load_with_limits(path, &Limits::default())
    }

    /// Loads a scene file.
    pub fn load_with_limits(path: &Path, limits: &Limits) -> Result<Scene> {
        Self::load_with(
            path,
            &LoadOptions {
                limits: *limits,
                ..Default::default()
            },
        )
    }

    /// Loads a scene file of any format ([`load::load_any`]).
    pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene> {
        let _reuse = crate::heap::HeapReuse::begin();
        Scene::build(load::load_any(path, options)?)
    }

    /// Drops degenerate primitives (with a warning that counts them), builds
    /// the BVHs and turns every emissive primitive into a light.
    pub fn build(mut input: SceneInput) -> Result<Scene> {
        let mut warnings = input.warnings;
        let hints = input.hints;
        let mut dropped = Dropped::default();
        // Its degenerate triangles are counted here and left out by the
        // geometry as it packs them.
        let mut triangles = input.triangles;
        let spheres = dropped.spheres(input.spheres);
        let (prototypes, placements) = instances::checked(
            input.instances,
            &input.materials,
            &mut triangles,
            &mut dropped,
        )?;
        let moving: Vec<(Vec<TriangleInput>, Vec<Sphere>, Vec3A)> = input
            .moving
            .into_iter()
            .map(|m| {
                (
                    dropped.triangles(m.triangles),
                    dropped.spheres(m.spheres),
                    m.velocity,
                )
            })
            .collect();
        let survey = Survey::of(&triangles, input.materials.len());
        dropped.triangle_total += triangles.len();
        dropped.triangles += survey.degenerate;
        if dropped.triangles > 0 {
            let emitters_hint = "(zero-area emitters among them emit nothing)";
            warnings.push(format!(
                "dropped {} degenerate triangle(s) of {} {emitters_hint}",
                dropped.triangles, dropped.triangle_total
            ));
        }
        if dropped.spheres > 0 {
            warnings.push(format!("dropped {} sphere(s) of radius 0", dropped.spheres));
        }
        let triangle_out_of_range = |t: &TriangleInput| !t.vertices.iter().all(|&v| in_range(v));
        let sphere_out_of_range = |s: &Sphere| !in_range(s.center) || !(s.radius <= MAX_COORDINATE);
        let out_of_range = survey.out_of_range
            || spheres.iter().any(sphere_out_of_range)
            || moving.iter().any(|(t, s, v)| {
                t.iter().any(triangle_out_of_range)
                    || s.iter().any(sphere_out_of_range)
                    || !in_range(*v)
            })
            || !in_range(input.camera.eye);
        if out_of_range {
            return Err(Error::new(format!(
                "the scene has coordinates beyond ±{MAX_COORDINATE:e} (or not finite): areas and distances would overflow"
            )));
        }
        if let Some(bad) = survey.bad_material {
            return Err(Error::new(format!(
                "internal: triangle refers to material {bad}"
            )));
        }

        // Texture coordinates cost memory and a lookup per hit: kept only
        // when some material reads a texture.
        let textured = input.materials.iter().any(|m| {
            !m.textures.is_empty()
                || m.emission_texture.is_some()
                || matches!(m.opacity, Opacity::Texture(_))
                || m.normal_map.is_some()
                || m.blend
                    .is_some_and(|b| matches!(b.weight, BlendWeight::Texture(_)))
        });
        let mut geometry = Geometry::build_without_degenerate(triangles, spheres, textured);
        // An emitter is sampled where it is, mask or not: it stays whole.
        for m in input.materials.iter_mut() {
            if m.opacity != Opacity::Opaque && m.is_emissive() {
                warnings.push(format!(
                    "material `{}`: an emitter's opacity mask is ignored (it stays opaque)",
                    m.name
                ));
                m.opacity = Opacity::Opaque;
            }
        }
        geometry.set_masks(Masks {
            by_material: input.materials.iter().map(|m| m.opacity).collect(),
            textures: input.textures.clone(),
        });
        geometry.set_blends(Blends {
            by_material: input.materials.iter().map(|m| m.blend).collect(),
            textures: input.textures.clone(),
        });
        for (triangles, spheres, velocity) in moving {
            if !(triangles.is_empty() && spheres.is_empty()) {
                geometry.add_moving(Geometry::build(&triangles, spheres), velocity);
            }
        }
        if !placements.is_empty() {
            let prototypes = prototypes
                .into_iter()
                .map(|p| Geometry::build_full(p, Vec::new(), AccelChoice::Auto, textured))
                .collect();
            geometry.add_instances(prototypes, &placements);
        }
        if geometry.bvh_too_deep() {
            warnings.push(
                "the BVH would be too deep to traverse (many overlapping triangles): testing every triangle instead, which is slow"
                    .into(),
            );
        }
        let mut lights = Vec::new();
        let emissive: Vec<usize> = (0..geometry.triangle_count())
            .into_par_iter()
            .filter(|&i| input.materials[geometry.triangle_material(i) as usize].is_emissive())
            .collect();
        // Textured lights stay triangles: a parallelogram's point has no
        // barycentrics in one triangle to read the texture by.
        let textured_at = |i: usize| {
            input.materials[geometry.triangle_material(i) as usize]
                .emission_texture
                .is_some()
        };
        let (textured, plain): (Vec<usize>, Vec<usize>) =
            emissive.iter().partition(|&&i| textured_at(i));
        let mut shapes = emitters::group_emitters(geometry.triangles(), &plain, |i| {
            geometry.triangle_material(i)
        });
        shapes.extend(textured.into_iter().map(EmitterShape::Triangle));
        let mut emission_textures = Vec::new();
        for shape in &shapes {
            // The triangles the light is made of, its corner and edges, and
            // its area as a fraction of |e1 x e2|.
            let (members, [p0, e1, e2], fraction) = match shape {
                EmitterShape::Triangle(i) => {
                    let [p0, p1, p2] = geometry.triangles()[*i];
                    (std::slice::from_ref(i), [p0, p1 - p0, p2 - p0], 0.5)
                }
                EmitterShape::Parallelogram {
                    triangles,
                    p0,
                    e1,
                    e2,
                } => (&triangles[..], [*p0, *e1, *e2], 1.0),
            };
            let material = &input.materials[geometry.triangle_material(members[0]) as usize];
            for &i in members {
                geometry.set_triangle_light(i, lights.len() as u32);
            }
            let cross = e1.cross(e2);
            let emitter = PlanarEmitter {
                p0,
                e1,
                e2,
                normal: cross.normalize(),
                area: fraction * cross.length(),
                radiance: material.emission,
                two_sided: material.two_sided_emission,
                sampling: input.triangle_sampling,
            };
            lights.push(match shape {
                EmitterShape::Triangle(_) => Light::Triangle(emitter),
                EmitterShape::Parallelogram { .. } => Light::Parallelogram(emitter),
            });
            emission_textures.push(material.emission_texture.map(|texture| EmissionTexture {
                texture,
                corners: Some(geometry.triangle_uvs(members[0])),
            }));
        }
        for i in 0..geometry.spheres().len() {
            let s = geometry.spheres()[i];
            let material = &input.materials[s.material as usize];
            if material.is_emissive() {
                geometry.set_sphere_light(i, lights.len() as u32);
                lights.push(Light::Sphere {
                    center: s.center,
                    radius: s.radius,
                    radiance: material.emission,
                    two_sided: material.two_sided_emission,
                    sampling: input.sphere_sampling,
                });
                emission_textures.push(material.emission_texture.map(|texture| EmissionTexture {
                    texture,
                    corners: None,
                }));
            }
        }
        let (center, radius) = bounding_sphere(&geometry);
        lights.extend(input.point_lights.into_iter().map(|mut l| {
            if let Light::Directional {
                center: c,
                radius: r,
                ..
            } = &mut l
            {
                (*c, *r) = (center, radius);
            }
            l
        }));
        let environment = input.environment.map(|mut env| {
            env.bound(center, radius);
            env
        });
        let lights = Lights::with_environment(lights, environment)
            .with_textured_emission(emission_textures, input.textures.clone());
        if lights.is_empty() {
            warnings.push("the scene has no light source: the image will be black".into());
        }
        let features = Features::detect(&input.materials, &geometry, &lights, &input.camera);
        let shortcuts = Shortcuts::new(&geometry, &flat_light_corners(&lights));
        let mut scene = Scene {
            camera: input.camera,
            features,
            geometry: Arc::new(geometry),
            materials: input.materials,
            textures: input.textures,
            lights,
            warnings,
            hints,
            shortcuts,
        };
        if let Some(shares) = light_pilot::direct_shares(&scene) {
            scene.lights.set_direct_shares(&shares);
        }
        Ok(scene)
    }

    /// The scene with triangle `i` split into `pieces[i]` where that is not
    /// empty ([`Geometry::with_pieces`]: radiosity's discontinuity
    /// meshing), and per triangle of the new scene the one it comes from.
    pub fn with_pieces(&self, pieces: &[Vec<[Vec3A; 3]>]) -> (Scene, Vec<u32>) {
        let (geometry, from) = self.geometry.with_pieces(pieces);
        (self.with_geometry(geometry), from)
    }

    /// This scene over other geometry (of the same materials and lights).
    fn with_geometry(&self, geometry: Geometry) -> Scene {
        Scene {
            camera: self.camera.clone(),
            features: Features::detect(&self.materials, &geometry, &self.lights, &self.camera),
            shortcuts: Shortcuts::new(&geometry, &flat_light_corners(&self.lights)),
            geometry: Arc::new(geometry),
            materials: self.materials.clone(),
            textures: self.textures.clone(),
            lights: self.lights.clone(),
            warnings: self.warnings.clone(),
            hints: self.hints.clone(),
        }
    }

    /// The scene with every instance's triangles copied into the
    /// geometry's own (see [`Geometry::flattened`]), where it has instances.
    pub fn flattened(&self) -> Option<Scene> {
        if self.geometry.instance_count() == 0 {
            return None;
        }
        Some(self.with_geometry(self.geometry.flattened()))
    }

    /// What radiosity makes of material `m` (see
    /// [`crate::bsdf::Bsdf::diffuse_albedo`]); a textured diffuse colour
    /// is read as the texture's mean, which counts as dropping detail.
    pub fn diffuse_albedo(&self, m: u32) -> Option<(crate::math::Rgb, bool)> {
        let material = &self.materials[m as usize];
        if let Some(blend) = material.blend {
            // The two albedos mixed by the weight's mean; a specular part
            // adds nothing diffuse.
            let w = match blend.weight {
                BlendWeight::Constant(w) => w.clamp(0.0, 1.0),
                BlendWeight::Texture(t) => {
                    crate::math::luminance(self.textures[t as usize].mean()).clamp(0.0, 1.0)
                }
            };
            let part = |m: &Material| match m.bsdf.diffuse_albedo() {
                None => None,
                Some((a, _)) => Some(match m.textures.diffuse {
                    Some(t) => self.textures[t as usize].mean(),
                    None => a,
                }),
            };
            let (a, b) = (part(material), part(&self.materials[blend.second as usize]));
            if a.is_none() && b.is_none() {
                return None;
            }
            let zero = crate::math::Rgb::ZERO;
            return Some((a.unwrap_or(zero) * (1.0 - w) + b.unwrap_or(zero) * w, true));
        }
        let (albedo, approximated) = material.bsdf.diffuse_albedo()?;
        match material.textures.diffuse {
            Some(t) => Some((self.textures[t as usize].mean(), true)),
            None => Some((albedo, approximated)),
        }
    }

    /// Samples every area light by `mode` (the CLI's `--light-sampling`).
    pub fn set_light_sampling(&mut self, mode: LightSampling) {
        self.lights = self.lights.with_sampling(mode);
    }

    /// Sets how rays leave surfaces (`--offset`). Clones the geometry only
    /// when it is shared and the mode changes.
    pub fn set_offset(&mut self, offset: OffsetMode) {
        if self.geometry.offset() != offset {
            Arc::make_mut(&mut self.geometry).set_offset(offset);
        }
        self.lights.set_offset(offset);
    }

    /// Overrides the image size (keeping the field of view).
    pub fn set_resolution(&mut self, width: u32, height: u32) {
        let mut camera = self.camera;
        camera.width = width;
        camera.height = height;
        self.set_camera(camera);
    }

    /// Replaces the camera; the camera rays' candidate lists are made
    /// again for it when first asked for.
    pub fn set_camera(&mut self, camera: Camera) {
        if camera != self.camera {
            self.camera = camera;
            self.shortcuts.camera_changed();
        }
    }

    /// The camera rays' candidate lists for the current camera, built on the
    /// first call (by a render pass), or why there are none.
    pub fn try_primary_candidates(&self) -> std::result::Result<&PrimaryCandidates, NotApplied> {
        let geometry = &self.geometry;
        let (materials, camera) = (&self.materials, &self.camera);
        let textured_emission = materials
            .iter()
            .any(|m| m.is_emissive() && m.emission_texture.is_some());
        self.shortcuts.primary_candidates(geometry, camera, |i| {
            // A textured light is not constant over its triangle, and a
            // pixel counted as known skips every emitter it sees: with one,
            // no pixel is known.
            if textured_emission || geometry.triangle_light(i) == NO_LIGHT {
                return None;
            }
            // One side of a flat emitter faces the eye everywhere on it.
            let towards_eye = (camera.eye - geometry.triangles()[i][0]).normalize_or_zero();
            let material = &materials[geometry.triangle_material(i) as usize];
            Some(material.emitted(geometry.triangle_normal(i), towards_eye))
        })
    }

    /// One line per shortcut that `used` names: whether it applies here and
    /// what it saves, or why not ("lights seen directly: sampled (the scene
    /// has spheres)"). Builds the camera lists if they are not built yet.
    /// `sampling` says where the render's camera samples lie.
    pub fn shortcut_report(&self, used: ShortcutsUsed, sampling: CameraSampling) -> Vec<String> {
        let mut lines = Vec::new();
        lines.extend(self.lights.direct_summary());
        let primary = match sampling.lists_apply() {
            true => self.try_primary_candidates(),
            false => Err(NotApplied::WideFilter),
        };
        if used.primary_candidates {
            lines.push(match &primary {
                Ok(lists) => {
                    let (mean, full) = lists.summary();
                    format!(
                        "camera rays: their pixel's candidate triangles only ({mean:.2} per pixel, {full} pixels test all)"
                    )
                }
                Err(reason) => format!("camera rays: the whole scene ({reason})"),
            });
        }
        match used.seen_emitters {
            Some(true) if !sampling.seen_emission_applies() => lines.push(
                "lights seen directly: sampled (the pixel filter is wider than a pixel)".into(),
            ),
            Some(true) => lines.push(match &primary {
                Ok(lists) if lists.pixels_with_seen_emission() > 0 => format!(
                    "lights seen directly: integrated exactly over {} pixels",
                    lists.pixels_with_seen_emission()
                ),
                Ok(_) => "lights seen directly: sampled (no pixel sees a light it can integrate)"
                    .to_string(),
                Err(reason) => format!("lights seen directly: sampled ({reason})"),
            }),
            Some(false) => lines.push("lights seen directly: sampled (switched off)".into()),
            None => {}
        }
        if used.shadow_voxels {
            let voxels = self.shortcuts.all_shadow_voxels();
            for (light, v) in voxels.iter().enumerate() {
                match v {
                    Ok(v) => {
                        let (clear, listed) = v.summary();
                        lines.push(format!(
                            "shadow rays to light {light}: no test from {:.0}% of the voxels (the light is seen whole), a short list of occluders from {:.0}%",
                            100.0 * clear,
                            100.0 * listed
                        ));
                    }
                    // One line for lights that all have the same reason.
                    Err(reason) if voxels.iter().all(|v| v.as_ref().err() == Some(reason)) => {
                        lines.push(format!("shadow rays: the whole scene ({reason})"));
                        break;
                    }
                    Err(reason) => lines.push(format!(
                        "shadow rays to light {light}: the whole scene ({reason})"
                    )),
                }
            }
        }
        lines
    }

    /// [`Scene::try_primary_candidates`], where there are lists.
    #[inline]
    pub fn primary_candidates(&self) -> Option<&PrimaryCandidates> {
        self.try_primary_candidates().ok()
    }
}
