//! Mitsuba scene files (XML, Mitsuba 3 and 0.5/0.6) into a [`SceneInput`].
//!
//! What a file asks for and tracelab cannot render is never dropped in
//! silence: each such place gives a warning with file:line:column and what
//! was done instead, and `strict` makes the first one an error.

mod bsdfs;
mod cie;
mod meshes;
mod prefetch;
mod principled;
mod props;
mod shapes;
mod spectrum;
pub mod xml;

use super::environment::{Environment, Radiance};
use super::material::Material;
use super::{Limits, LoadOptions, RenderHints, SceneInput, in_range};
use crate::accel::{Sphere, TriangleInput};
use crate::camera::Camera;
use crate::error::Result;
use crate::filter::PixelFilter;
use crate::math::Rgb;
use crate::scene::light::{Light, LightSampling, SpotCone};
use crate::texture::{Bitmap, Texture};
use glam::{Mat3A, Mat4, Vec3A};
use props::Props;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use xml::{Document, Element, Loc};

/// Reads a Mitsuba scene file.
pub fn load_mitsuba(path: &Path, options: &LoadOptions) -> Result<SceneInput> {
    let doc = xml::read(path, &options.defines)?;
    let mut ids = HashMap::new();
    collect_ids(&doc.root, &mut ids)?;
    let mut importer = Importer {
        doc: &doc,
        ids: &ids,
        limits: options.limits,
        warnings: Vec::new(),
        materials: Vec::new(),
        material_ids: HashMap::new(),
        textures: Vec::new(),
        texture_ids: HashMap::new(),
        triangles: Vec::new(),
        pending: Vec::new(),
        pending_triangles: 0,
        spheres: Vec::new(),
        instances: Default::default(),
        groups: HashMap::new(),
        reading_group: false,
        lights: Vec::new(),
        environment: None,
        hints: RenderHints::default(),
        prefetched: prefetch::Prefetched::new(&doc, &ids, options.limits.max_triangles),
    };
    // Decoding's scratch buffers were freed into the workers' arenas;
    // during a load they would stay there (living-room: 21 MB), below the
    // triangle list.
    crate::heap::release_free_pages();
    // One allocation for the scene's triangles, not a doubling per mesh.
    let expected = importer.prefetched.triangle_count();
    importer
        .triangles
        .reserve(expected.min(options.limits.max_triangles));
    for name in &doc.unused_defines {
        importer.warnings.push(format!(
            "{}: -D {name}: the file never reads `${name}`: ignored",
            path.display()
        ));
    }
    let camera = importer.scene()?;
    // The meshes the walk consumed were decoded on worker threads, so
    // glibc freed them into those threads' arenas, where the build on this
    // thread cannot reuse them: on a million triangles, 165 MB held
    // through the build's peak.
    crate::heap::release_free_pages();
    options.check_strict(&importer.warnings)?;
    Ok(SceneInput {
        camera,
        materials: importer.materials,
        textures: importer.textures,
        environment: importer.environment,
        triangles: importer.triangles,
        spheres: importer.spheres,
        point_lights: importer.lights,
        moving: Vec::new(),
        instances: importer.instances,
        // Mitsuba samples spheres by solid angle and triangles by area.
        sphere_sampling: LightSampling::SolidAngle,
        triangle_sampling: LightSampling::Area,
        warnings: importer.warnings,
        hints: importer.hints,
    })
}

/// The ids that some `<ref>` names.
fn collect_references<'a>(e: &'a Element, ids: &mut HashSet<&'a str>) {
    for c in &e.children {
        if c.tag == "ref"
            && let Some(id) = c.attr("id")
        {
            ids.insert(id);
        }
        collect_references(c, ids);
    }
}

/// Every element with an `id`, for `<ref>`.
fn collect_ids<'a>(e: &'a Element, ids: &mut HashMap<String, &'a Element>) -> Result<()> {
    for c in &e.children {
        if let Some(id) = c.attr("id")
            && c.tag != "ref"
            && ids.insert(id.to_string(), c).is_some()
        {
            return Err(c.loc.error(format!("id \"{id}\" is used twice")));
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

/// What a shape's `area` emitter emits: a radiance, times a texture
/// (an index into the importer's) where it is textured.
#[derive(Clone, Copy, Debug)]
pub(super) struct Emission {
    radiance: crate::math::Rgb,
    texture: Option<u32>,
}

pub(super) struct Importer<'a> {
    doc: &'a Document,
    ids: &'a HashMap<String, &'a Element>,
    limits: Limits,
    warnings: Vec<String>,
    materials: Vec<Material>,
    /// Materials by the BSDF element they came from (shared, not copied).
    material_ids: HashMap<*const Element, u32>,
    textures: Vec<Texture>,
    texture_ids: HashMap<*const Element, u32>,
    triangles: Vec<TriangleInput>,
    /// Meshes of the top level waiting to be placed, in file order, and
    /// their triangles (see `place_pending`).
    pending: Vec<shapes::Pending<'a>>,
    pending_triangles: usize,
    spheres: Vec<Sphere>,
    instances: crate::scene::InstancesInput,
    /// Per shapegroup, its prototype, or None where it must be copied
    /// (it holds a sphere).
    groups: HashMap<*const Element, Option<u32>>,
    /// A shapegroup is being read into a prototype.
    reading_group: bool,
    lights: Vec<Light>,
    environment: Option<Environment>,
    hints: RenderHints,
    /// Meshes and bitmaps decoded ahead, in parallel.
    prefetched: prefetch::Prefetched,
}

impl<'a> Importer<'a> {
    fn warn(&mut self, at: &Loc, what: &str) {
        self.warnings.push(format!("{at}: {what}"));
    }

    /// The top level, in file order; returns the camera.
    fn scene(&mut self) -> Result<Camera> {
        let root = &self.doc.root;
        let mut referenced = HashSet::new();
        collect_references(root, &mut referenced);
        let mut sensor = None;
        for e in &root.children {
            // Declared here and used where a `<ref>` names it (Mitsuba's
            // own scenes declare area emitters and samplers so).
            if e.tag != "shape" && e.attr("id").is_some_and(|id| referenced.contains(id)) {
                continue;
            }
            match e.tag.as_str() {
                "shape" => self.shape(e, Mat4::IDENTITY)?,
                "emitter" => self.emitter(e)?,
                "sensor" => match sensor {
                    None => sensor = Some(e),
                    Some(_) => self.warn(&e.loc, "a second sensor ignored (the first one renders)"),
                },
                "integrator" => self.integrator(e)?,
                // Declarations, used where referenced.
                "bsdf" | "texture" => {}
                "medium" | "phase" => self.warn(&e.loc, "participating medium ignored"),
                other => self.warn(&e.loc, &format!("<{other}> ignored")),
            }
        }
        self.place_pending()?;
        match sensor {
            Some(s) => self.sensor(s),
            None => {
                self.warn(&root.loc, "no sensor: a default camera frames the scene");
                Ok(super::framing::default_camera(
                    &self.triangles,
                    &self.spheres,
                    &self.instances,
                ))
            }
        }
    }

    fn integrator(&mut self, e: &'a Element) -> Result<()> {
        let p = Props::new(e, self.ids);
        let technique = match e.plugin() {
            "path" | "volpath" | "volpathmis" | "prb" | "direct" => "path",
            "bdpt" => "bdpt",
            "ptracer" => "light",
            "sppm" => "sppm",
            "photonmapper" => "photon",
            "aov" | "moment" | "stokes" => {
                // Wrappers: the integrator inside renders the image.
                let inner = p.objects("integrator")?;
                p.mark_all_used();
                self.warn(
                    &e.loc,
                    &format!("{} integrator: its inner integrator renders", e.plugin()),
                );
                return match inner.first() {
                    Some(i) => self.integrator(i),
                    None => Ok(()),
                };
            }
            other => {
                self.warn(
                    &e.loc,
                    &format!(
                        "integrator \"{other}\" is not one of tracelab's: path tracing renders"
                    ),
                );
                p.mark_all_used();
                "path"
            }
        };
        self.hints.integrator = Some(technique.to_string());
        // Mitsuba counts segments (1: emitters seen directly, -1: unbounded,
        // every integrator's default); tracelab counts bounces, one fewer.
        let max_depth = match e.plugin() {
            "direct" => self.direct_samples(e, &p)?,
            _ => p.int("max_depth")?.unwrap_or(-1),
        };
        self.hints.max_depth = match max_depth {
            -1 => Some(super::UNBOUNDED_DEPTH),
            d if d >= 1 => Some((d - 1) as u32),
            d => {
                return Err(e
                    .loc
                    .error(format!("max_depth must be -1 or >= 1, got {d}")));
            }
        };
        self.hints.rr_depth = match p.int("rr_depth")? {
            Some(d) if d >= 1 => Some(d as u32),
            Some(d) => return Err(e.loc.error(format!("rr_depth must be >= 1, got {d}"))),
            None => None,
        };
        // Settings that change speed or noise, not the image.
        for quiet in [
            "hide_emitters",
            "samples_per_pass",
            "timeout",
            "strict_normals",
        ] {
            let _ = p.tag_of(quiet).map(|_| p.string(quiet));
        }
        p.unused(&mut self.warnings);
        Ok(())
    }

    /// Mitsuba's `direct`: emitter and BSDF samples at the first hit,
    /// combined by MIS, become path tracing's one bounce with the strategy
    /// whose counts are not 0 (Veach's figure in `integrator_direct_lum`
    /// and `_bsdf`). Returns the depth in Mitsuba's count.
    fn direct_samples(&mut self, e: &'a Element, p: &Props<'a>) -> Result<i64> {
        let count = |name: &str, default: i64| -> Result<i64> {
            match p.int(name)?.unwrap_or(default) {
                n if n >= 0 => Ok(n),
                n => Err(e.loc.error(format!("{name} must be >= 0, got {n}"))),
            }
        };
        let shading = count("shading_samples", 1)?;
        let (emitter, bsdf) = (
            count("emitter_samples", shading)?,
            count("bsdf_samples", shading)?,
        );
        let strategy = match (emitter > 0, bsdf > 0) {
            (true, true) => "mis",
            (true, false) => "light",
            (false, true) => "bsdf",
            // Only the emitters the camera sees.
            (false, false) => return Ok(1),
        };
        self.hints.strategy = Some(strategy.into());
        if emitter > 1 || bsdf > 1 {
            self.warn(
                &e.loc,
                &format!(
                    "direct integrator: {emitter} emitter and {bsdf} BSDF samples read as one of \
                     each per camera ray (the same expectation; Mitsuba weighs its samples by \
                     their counts)"
                ),
            );
        }
        Ok(2)
    }

    fn emitter(&mut self, e: &'a Element) -> Result<()> {
        let p = Props::new(e, self.ids);
        let to_world = p.transform("to_world")?;
        let bad = |m: &str| e.loc.error(format!("{} emitter: {m}", e.plugin()));
        let colour = |name: &str| -> Result<Rgb> {
            let c = p.rgb(name, true)?.unwrap_or(Rgb::ONE);
            if !(c.min_element() >= 0.0) {
                return Err(bad(&format!("`{name}` must be >= 0")));
            }
            Ok(c)
        };
        match e.plugin() {
            "point" => {
                let position = match p.point("position")? {
                    Some(v) => Vec3A::from(v),
                    None => Vec3A::from(to_world.unwrap_or_default().w_axis.truncate()),
                };
                if !in_range(position) {
                    return Err(bad("position out of range"));
                }
                let intensity = colour("intensity")?;
                self.lights.push(Light::Point {
                    position,
                    intensity,
                });
            }
            "spot" => {
                let m = to_world.unwrap_or_default();
                let position = Vec3A::from(m.w_axis.truncate());
                let axis = Vec3A::from(m.z_axis.truncate()).normalize_or_zero();
                let cutoff = p.float_or("cutoff_angle", 20.0)?;
                let beam = p.float_or("beam_width", 0.75 * cutoff)?;
                if !(cutoff > 0.0 && cutoff <= 90.0 && beam >= 0.0 && beam <= cutoff) {
                    return Err(bad(
                        "need 0 < cutoff_angle <= 90 and 0 <= beam_width <= cutoff_angle",
                    ));
                }
                if axis == Vec3A::ZERO || !in_range(position) {
                    return Err(bad("to_world must be a finite frame"));
                }
                let intensity = colour("intensity")?;
                self.lights.push(Light::Spot {
                    position,
                    intensity,
                    cone: SpotCone {
                        axis,
                        cutoff: cutoff.to_radians(),
                        beam_width: beam.to_radians(),
                    },
                });
            }
            "directional" => {
                let direction = match p.point("direction")? {
                    Some(d) => Vec3A::from(d),
                    None => Vec3A::from(to_world.unwrap_or_default().z_axis.truncate()),
                }
                .normalize_or_zero();
                if direction == Vec3A::ZERO || !direction.is_finite() {
                    return Err(bad("`direction` must be a finite non-zero vector"));
                }
                let irradiance = colour("irradiance")?;
                self.lights.push(Light::Directional {
                    direction,
                    irradiance,
                    center: Vec3A::ZERO,
                    radius: 1.0,
                });
            }
            "constant" | "envmap" => {
                let rotation = Mat3A::from_mat4(to_world.unwrap_or_default());
                let radiance = if e.plugin() == "constant" {
                    Radiance::Constant(colour("radiance")?)
                } else {
                    let file = p
                        .string("filename")?
                        .ok_or_else(|| bad("needs `filename`"))?;
                    let path = self.doc.resolve(file, &e.loc)?;
                    let map = match self.prefetched.bitmap(&path, false) {
                        Some(map) => map,
                        None => std::sync::Arc::new(
                            Bitmap::read(&path, false).map_err(|m| e.loc.error(m))?,
                        ),
                    };
                    Radiance::Map(map)
                };
                let scale = p.float_or("scale", 1.0)?;
                if !(scale >= 0.0 && scale.is_finite()) {
                    return Err(bad("`scale` must be >= 0"));
                }
                if self.environment.is_some() {
                    self.warn(
                        &e.loc,
                        "a second environment ignored (one light at infinity)",
                    );
                } else {
                    self.environment = Some(Environment::new(radiance, scale, rotation));
                }
            }
            other => {
                self.warn(
                    &e.loc,
                    &format!("emitter \"{other}\" is not supported: skipped"),
                );
                p.mark_all_used();
            }
        }
        p.unused(&mut self.warnings);
        Ok(())
    }

    fn sensor(&mut self, e: &'a Element) -> Result<Camera> {
        let p = Props::new(e, self.ids);
        let kind = e.plugin();
        if kind != "perspective" && kind != "thinlens" {
            return Err(e.loc.error(format!(
                "sensor \"{kind}\" is not supported (perspective and thinlens are)"
            )));
        }
        let films = p.objects("film")?;
        let film = films.first().copied();
        let (width, height, filter) = match film {
            Some(f) => self.film(f)?,
            None => (
                768,
                576,
                PixelFilter::Gaussian {
                    stddev: 0.5,
                    radius: 2.0,
                },
            ),
        };
        self.limits
            .check_resolution(width, height)
            .map_err(|m| e.loc.error(m))?;
        if let Some(s) = p.objects("sampler")?.first() {
            self.sampler(s)?;
        }
        let m = p.transform("to_world")?.unwrap_or_default();
        let eye = Vec3A::from(m.w_axis.truncate());
        let forward = Vec3A::from(m.z_axis.truncate()).normalize_or_zero();
        let up = Vec3A::from(m.y_axis.truncate()).normalize_or_zero();
        if forward == Vec3A::ZERO || up == Vec3A::ZERO || forward.cross(up).length() < 1e-6 {
            return Err(e.loc.error("the sensor's to_world is degenerate"));
        }
        let aspect = width as f32 / height as f32;
        let mut axis = None;
        let fov = match (p.float("fov")?, p.string("focal_length")?) {
            (Some(f), _) => f,
            (None, Some(length)) => {
                let mm: f32 = length.trim_end_matches("mm").trim().parse().map_err(|_| {
                    e.loc
                        .error(format!("focal_length \"{length}\" is not like \"50mm\""))
                })?;
                // Mitsuba: a 35 mm film's diagonal.
                let diagonal = (36.0f32 * 36.0 + 24.0 * 24.0).sqrt();
                axis = Some("diagonal");
                2.0 * (diagonal / (2.0 * mm)).atan().to_degrees()
            }
            (None, None) => 45.0,
        };
        let axis = match axis {
            Some(a) => a,
            None => p.string("fov_axis")?.unwrap_or("x"),
        };
        let tan_half = (fov.to_radians() * 0.5).tan();
        let tan_half_y = match axis {
            "x" => tan_half / aspect,
            "y" => tan_half,
            "diagonal" => tan_half / (1.0 + aspect * aspect).sqrt(),
            "smaller" => tan_half / aspect.min(1.0),
            "larger" => tan_half / aspect.max(1.0),
            other => {
                return Err(e.loc.error(format!(
                    "fov_axis \"{other}\" is not x, y, diagonal, smaller or larger"
                )));
            }
        };
        let fov_y = 2.0 * tan_half_y.atan().to_degrees();
        if !(fov_y > 0.0 && fov_y < 180.0) {
            return Err(e
                .loc
                .error(format!("the field of view ({fov} degrees) is out of range")));
        }
        let (aperture, focus) = if kind == "thinlens" {
            let a = p.float_or("aperture_radius", 0.03)?;
            let f = p.float_or("focus_distance", 0.0)?;
            if !(a >= 0.0 && f > 0.0) {
                return Err(e
                    .loc
                    .error("thinlens needs aperture_radius >= 0 and focus_distance > 0"));
            }
            (a, f)
        } else {
            // Read by Mitsuba's pinhole too, where it changes nothing.
            let _ = p.float("focus_distance")?;
            (0.0, 1.0)
        };
        let clips = (p.float("near_clip")?, p.float("far_clip")?);
        for quiet in ["shutter_open", "shutter_close"] {
            let _ = p.float(quiet)?;
        }
        let mut camera = Camera::look_at(
            eye,
            eye + forward,
            up,
            fov_y,
            width,
            height,
            aperture,
            focus,
        )
        .with_filter(filter);
        // Mitsuba's camera x is image left; a mirroring to_world flips the image.
        if Vec3A::from(m.x_axis.truncate()).dot(camera.right) > 0.0 {
            camera.right = -camera.right;
        }
        for note in self.clipping(&camera, clips) {
            self.warn(&e.loc, &note);
        }
        p.unused(&mut self.warnings);
        Ok(camera)
    }

    /// What the file's `near_clip` and `far_clip` would cut away, which
    /// tracelab's camera does not: a note for each that the scene's box
    /// crosses, by depth along the view (Mitsuba clips by depth).
    fn clipping(&self, camera: &Camera, (near, far): (Option<f32>, Option<f32>)) -> Vec<String> {
        // The box is a pass over every triangle: only where a clip is given.
        if near.is_none() && far.is_none() {
            return Vec::new();
        }
        let Some((lo, hi)) =
            super::framing::bounds(&self.triangles, &self.spheres, &self.instances)
        else {
            return Vec::new();
        };
        let depths = (0..8).map(|k| {
            let corner = Vec3A::select(
                glam::BVec3A::new(k & 1 != 0, k & 2 != 0, k & 4 != 0),
                hi,
                lo,
            );
            (corner - camera.eye).dot(camera.forward)
        });
        let (nearest, farthest) = depths.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), d| {
            (a.min(d), b.max(d))
        });
        let mut notes = Vec::new();
        if let Some(near) = near.filter(|&near| nearest < near) {
            notes.push(format!(
                "near_clip {near} ignored: the scene's box comes to depth {nearest:.4} of the camera, \
                 and surfaces nearer than near_clip are rendered, not clipped"
            ));
        }
        if let Some(far) = far.filter(|&far| farthest > far) {
            notes.push(format!(
                "far_clip {far} ignored: the scene's box reaches depth {farthest:.4} of the camera, \
                 and surfaces beyond far_clip are rendered, not clipped"
            ));
        }
        notes
    }

    fn film(&mut self, e: &'a Element) -> Result<(u32, u32, PixelFilter)> {
        let p = Props::new(e, self.ids);
        let size = |name: &str, default: i64| -> Result<u32> {
            let v = p.int(name)?.unwrap_or(default);
            u32::try_from(v).map_err(|_| e.loc.error(format!("`{name}` must be >= 1, got {v}")))
        };
        let (width, height) = (size("width", 768)?, size("height", 576)?);
        for crop in [
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ] {
            if p.int(crop)?.is_some() {
                self.warn(&e.loc, &format!("{crop} ignored: the whole frame renders"));
            }
        }
        // Output format settings: the CLI's output file decides.
        for quiet in [
            "file_format",
            "pixel_format",
            "component_format",
            "banner",
            "high_quality_edges",
            "sample_border",
            "compensate",
            "rgb_tonemap",
        ] {
            if p.tag_of(quiet).is_some() {
                let _ = p.string(quiet)?;
            }
        }
        // Mitsuba 0.5 files name it (`<rfilter name="rfilter" ...>`).
        let filter = match p.any_objects("rfilter")?.first() {
            // Mitsuba's default: a Gaussian of standard deviation 0.5.
            None => PixelFilter::Gaussian {
                stddev: 0.5,
                radius: 2.0,
            },
            Some(f) => {
                let fp = Props::new(f, self.ids);
                let filter = match f.plugin() {
                    "box" => PixelFilter::Box,
                    "tent" => PixelFilter::Tent {
                        radius: fp.float_or("radius", 1.0)?,
                    },
                    "gaussian" => {
                        let stddev = fp.float_or("stddev", 0.5)?;
                        PixelFilter::Gaussian {
                            stddev,
                            radius: 4.0 * stddev,
                        }
                    }
                    other => {
                        self.warn(
                            &f.loc,
                            &format!(
                                "reconstruction filter \"{other}\" read as gaussian (stddev 0.5)"
                            ),
                        );
                        fp.mark_all_used();
                        PixelFilter::Gaussian {
                            stddev: 0.5,
                            radius: 2.0,
                        }
                    }
                };
                fp.unused(&mut self.warnings);
                filter
            }
        };
        p.unused(&mut self.warnings);
        Ok((width, height, filter))
    }

    fn sampler(&mut self, e: &'a Element) -> Result<()> {
        let p = Props::new(e, self.ids);
        self.hints.sampler = Some(
            match e.plugin() {
                "independent" => "independent",
                "stratified" => "stratified",
                "multijitter" => "multijitter",
                "ldsampler" | "sobol" | "halton" | "hammersley" | "orthogonal" => "sobol",
                other => {
                    self.warn(&e.loc, &format!("sampler \"{other}\" read as independent"));
                    "independent"
                }
            }
            .to_string(),
        );
        if let Some(n) = p.int("sample_count")? {
            self.hints.spp = Some(
                u32::try_from(n)
                    .ok()
                    .filter(|&n| n > 0)
                    .ok_or_else(|| e.loc.error(format!("sample_count must be >= 1, got {n}")))?,
            );
        }
        for quiet in ["seed", "jitter", "scramble", "dimension"] {
            if p.tag_of(quiet).is_some() {
                let _ = p.string(quiet)?;
            }
        }
        p.unused(&mut self.warnings);
        Ok(())
    }
}
