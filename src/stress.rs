//! The numerical stress suite (`tracelab stress`): scenes at scales and
//! distances where a fixed epsilon breaks, each rendered with the same seed as
//! an easy reference version of itself and compared.
//!
//! A case passes when its image is no further from the reference than an
//! independent render of the reference is (relative RMSE, tev's definition,
//! at most the noise level measured with another seed), no spawned ray hits
//! the surface it left, and no sample is non-finite.

use crate::accel::{SurfaceHit, TriangleInput};
use crate::error::{Error, Result};
use crate::image::Image;
use crate::integrator::{CameraIntegrator, Integrator, PathTracer};
use crate::math::{Frame, OffsetMode};
use crate::render::{RenderSettings, Session};
use crate::sampling::warp::square_to_cosine_hemisphere;
use crate::sampling::{Sampler, SamplerKind};
use crate::scene::light::Light;
use crate::scene::load::load_scene_file;
use crate::scene::{Limits, Scene, SceneInput};
use glam::Vec3A;
use std::path::Path;
use std::sync::Arc;

/// One stress case: a scene and the index of its reference among
/// [`StressSuite::references`].
pub struct StressCase {
    pub name: String,
    pub scene: Scene,
    pub reference: usize,
}

/// Reference scenes and the cases derived from them.
pub struct StressSuite {
    pub references: Vec<(String, Scene)>,
    pub cases: Vec<StressCase>,
}

/// What one case measured.
#[derive(Clone, Debug)]
pub struct CaseResult {
    pub name: String,
    /// sqrt of tev's relative MSE against the reference render.
    pub relative_rmse: f64,
    /// The same between two independent renders of the reference.
    pub tolerance: f64,
    /// Spawned rays (bounce and shadow) whose first hit was the surface they left.
    pub self_intersections: u64,
    pub spawned: u64,
    pub non_finite: u64,
    pub image: Image,
}

impl CaseResult {
    pub fn passed(&self) -> bool {
        self.relative_rmse <= self.tolerance && self.self_intersections == 0 && self.non_finite == 0
    }
}

/// Render settings of the suite.
#[derive(Clone, Copy, Debug)]
pub struct StressSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub offset: OffsetMode,
}

impl StressSettings {
    /// `--quick`: small enough for `cargo test`.
    pub fn quick() -> Self {
        StressSettings {
            width: 48,
            height: 48,
            spp: 16,
            offset: OffsetMode::Robust,
        }
    }

    pub fn full() -> Self {
        StressSettings {
            width: 128,
            height: 128,
            spp: 64,
            offset: OffsetMode::Robust,
        }
    }
}

/// Moves and scales a whole scene: geometry, camera, point lights (whose
/// intensity grows with the square of the scale, so that irradiance and
/// hence the image stay the same; radiance needs no change).
pub fn transform(mut input: SceneInput, scale: f32, translate: Vec3A) -> SceneInput {
    let map = |p: Vec3A| p * scale + translate;
    for t in &mut input.triangles {
        t.vertices = t.vertices.map(map);
    }
    for s in &mut input.spheres {
        s.center = map(s.center);
        s.radius *= scale;
    }
    for m in &mut input.moving {
        for t in &mut m.triangles {
            t.vertices = t.vertices.map(map);
        }
        for s in &mut m.spheres {
            s.center = map(s.center);
            s.radius *= scale;
        }
        m.velocity *= scale;
    }
    let placed = glam::Affine3A::from_scale_rotation_translation(
        glam::Vec3::splat(scale),
        glam::Quat::IDENTITY,
        translate.into(),
    );
    for (_, to_world) in &mut input.instances.placements {
        *to_world = placed * *to_world;
    }
    for l in &mut input.point_lights {
        if let Light::Point {
            position,
            intensity,
        } = l
        {
            *position = map(*position);
            *intensity *= scale * scale;
        }
    }
    let c = &mut input.camera;
    c.eye = map(c.eye);
    c.focus_distance *= scale;
    c.aperture_radius *= scale;
    input
}

fn load(dir: &Path, name: &str) -> Result<SceneInput> {
    load_scene_file(&dir.join(name), &Limits::default())
}

/// Axis-aligned box as 12 triangles, normals outward.
fn cuboid(min: Vec3A, max: Vec3A, material: u32) -> Vec<TriangleInput> {
    let corner = |i: usize| {
        Vec3A::new(
            if i & 1 != 0 { max.x } else { min.x },
            if i & 2 != 0 { max.y } else { min.y },
            if i & 4 != 0 { max.z } else { min.z },
        )
    };
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    faces
        .iter()
        .flat_map(|f| {
            let [a, b, c, d] = f.map(corner);
            [
                TriangleInput {
                    vertices: [a, b, c],
                    material,
                    uvs: None,
                    normals: None,
                },
                TriangleInput {
                    vertices: [a, c, d],
                    material,
                    uvs: None,
                    normals: None,
                },
            ]
        })
        .collect()
}

impl StressSuite {
    /// The cases, built from the scenes in `scenes_dir` (the Cornell box and
    /// the glass-ball caustic scene).
    pub fn new(scenes_dir: &Path, settings: &StressSettings) -> Result<StressSuite> {
        let sized = |mut input: SceneInput| {
            input.camera.width = settings.width;
            input.camera.height = settings.height;
            input
        };
        let cornell = sized(load(scenes_dir, "cornell_box.toml")?);
        let caustic = sized(load(scenes_dir, "caustic.toml")?);
        let white = cornell
            .materials
            .iter()
            .position(|m| m.name.to_lowercase().contains("white"))
            .ok_or_else(|| Error::new("stress: the Cornell box has no white material"))?
            as u32;
        let mut references = vec![
            ("cornell box".to_string(), Scene::build(cornell.clone())?),
            ("caustic".to_string(), Scene::build(caustic.clone())?),
        ];
        let mut cases = Vec::new();
        let mut add = |name: String, input: SceneInput, reference: usize| -> Result<()> {
            let mut scene = Scene::build(input)?;
            scene.set_offset(settings.offset);
            cases.push(StressCase {
                name,
                scene,
                reference,
            });
            Ok(())
        };

        for scale in [1e-4f32, 1e-2, 1e2, 1e4] {
            add(
                format!("cornell box scaled by {scale:e}"),
                transform(cornell.clone(), scale, Vec3A::ZERO),
                0,
            )?;
        }
        for (axis, d) in [("x", Vec3A::X), ("y", Vec3A::Y), ("z", Vec3A::Z)] {
            add(
                format!("cornell box moved 1e5 along {axis}"),
                transform(cornell.clone(), 1.0, d * 1e5),
                0,
            )?;
        }
        // The glass ball (radius 0.35) at radius 1e-3 and 1e3.
        for radius in [1e-3f32, 1e3] {
            add(
                format!("glass sphere of radius {radius:e}"),
                transform(caustic.clone(), radius / 0.35, Vec3A::ZERO),
                1,
            )?;
        }

        // A thin shelf, 1e-3 thick, against its reference: a single quad
        // (both sides shade alike) in its mid-plane.
        let (lo, hi) = (
            Vec3A::new(180.0, 300.0, 180.0),
            Vec3A::new(380.0, 300.0, 380.0),
        );
        let mut slab = cornell.clone();
        slab.triangles
            .extend(cuboid(lo - Vec3A::Y * 5e-4, hi + Vec3A::Y * 5e-4, white));
        let mut sheet = cornell.clone();
        sheet.triangles.extend(TriangleInput::quad(
            lo,
            Vec3A::Z * 200.0,
            Vec3A::X * 200.0,
            white,
        ));
        references.push(("cornell box with a sheet".into(), Scene::build(sheet)?));
        add("thin slab (1e-3 thick)".into(), slab, references.len() - 1)?;

        // Nearly coplanar, overlapping faces: the floor again, 1e-3 higher.
        let mut doubled = cornell.clone();
        let floor: Vec<TriangleInput> = doubled
            .triangles
            .iter()
            .filter(|t| t.vertices.iter().all(|v| v.y == 0.0))
            .map(|t| TriangleInput {
                vertices: t.vertices.map(|v| v + Vec3A::Y * 1e-3),
                ..*t
            })
            .collect();
        if floor.is_empty() {
            return Err(Error::new("stress: the Cornell box floor was not found"));
        }
        doubled.triangles.extend(floor);
        add("overlapping floor 1e-3 above".into(), doubled, 0)?;

        // Tiny and huge triangles in one mesh: a 1e7-wide triangle behind the
        // back wall, where neither the camera nor any light reaches, and 64
        // triangles of side 1e-3 in the air.
        let mut mixed = cornell.clone();
        mixed.triangles.push(TriangleInput {
            vertices: [
                Vec3A::new(-1e7, -1e7, 570.0),
                Vec3A::new(1e7, -1e7, 570.0),
                Vec3A::new(0.0, 1e7, 570.0),
            ],
            material: white,
            uvs: None,
            normals: None,
        });
        for i in 0..64 {
            let p = Vec3A::new(
                100.0 + 5.0 * i as f32,
                200.0 + 3.0 * (i % 7) as f32,
                150.0 + 4.0 * (i % 11) as f32,
            );
            mixed.triangles.push(TriangleInput {
                vertices: [p, p + Vec3A::X * 1e-3, p + Vec3A::Z * 1e-3],
                material: white,
                uvs: None,
                normals: None,
            });
        }
        add("tiny and huge triangles".into(), mixed, 0)?;

        Ok(StressSuite { references, cases })
    }
}

/// Renders `scene` with the suite's path tracer and seed.
pub fn render(scene: &Scene, spp: u32, seed: u64) -> Result<(Image, u64)> {
    let settings = RenderSettings {
        integrator: Integrator::Camera(CameraIntegrator::Path(PathTracer::default())),
        sampler: SamplerKind::Independent,
        seed,
        planned_spp: spp,
        threads: 0,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    let session = Session::new(Arc::new(scene.clone()), settings)?;
    session.render_pass(spp);
    Ok((session.snapshot().image, session.stats().non_finite))
}

/// True when `next`, the first hit of a ray spawned from `from` towards
/// `direction`, is the surface the ray left: a triangle is flat, and a ray
/// leaving a sphere outwards cannot meet it again.
fn is_self_hit(from: &SurfaceHit, direction: Vec3A, next: &SurfaceHit) -> bool {
    next.primitive == from.primitive
        && next.instance == from.instance
        && (next.normal == from.normal || direction.dot(from.normal) > 0.0)
}

/// Casts bounce and shadow rays from the first four hits of one path per
/// pixel and counts those that hit the surface they left.
pub fn count_self_intersections(scene: &Scene, seed: u64) -> (u64, u64) {
    let (width, height) = (scene.camera.width, scene.camera.height);
    let mut sampler = Sampler::new(SamplerKind::Independent, seed, 0);
    let (mut self_hits, mut spawned) = (0, 0);
    for pixel in 0..width * height {
        sampler.start(pixel, 0);
        let film =
            glam::Vec2::new((pixel % width) as f32, (pixel / width) as f32) + sampler.next_2d();
        let mut ray = scene.camera.generate_ray(film, sampler.next_2d());
        for _ in 0..4 {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                break;
            };
            if let Some(ls) = scene
                .lights
                .sample(hit.point, sampler.next_1d(), sampler.next_2d())
                && ls.wi.dot(hit.normal) * ray.direction.dot(hit.normal) < 0.0
            {
                let shadow = ls.shadow_ray_from(&hit);
                spawned += 1;
                if let Some(next) = scene.geometry.intersect(&shadow) {
                    self_hits += u64::from(is_self_hit(&hit, shadow.direction, &next));
                }
            }
            // A diffuse bounce back to the side the ray came from.
            let frame = Frame::from_normal(hit.normal);
            let mut local = square_to_cosine_hemisphere(sampler.next_2d());
            if ray.direction.dot(hit.normal) > 0.0 {
                local.z = -local.z;
            }
            let direction = frame.to_world(local);
            ray = hit.spawn_ray(direction);
            spawned += 1;
            let Some(next) = scene.geometry.intersect(&ray) else {
                break;
            };
            if is_self_hit(&hit, direction, &next) {
                self_hits += 1;
                break;
            }
        }
    }
    (self_hits, spawned)
}

/// Runs every case; `progress` hears about each result as it comes.
pub fn run(
    suite: &StressSuite,
    settings: &StressSettings,
    mut progress: impl FnMut(&CaseResult),
) -> Result<Vec<CaseResult>> {
    let mut references = Vec::new();
    for (_, scene) in &suite.references {
        let (image, _) = render(scene, settings.spp, 0)?;
        let (other, _) = render(scene, settings.spp, 1)?;
        let noise = other.compare(&image)?.relative_mse.sqrt();
        references.push((image, noise));
    }
    let mut results = Vec::new();
    for case in &suite.cases {
        let (image, non_finite) = render(&case.scene, settings.spp, 0)?;
        let (reference, tolerance) = &references[case.reference];
        let relative_rmse = image.compare(reference)?.relative_mse.sqrt();
        let (self_intersections, spawned) = count_self_intersections(&case.scene, 0);
        let result = CaseResult {
            name: case.name.clone(),
            relative_rmse,
            tolerance: *tolerance,
            self_intersections,
            spawned,
            non_finite,
            image,
        };
        progress(&result);
        results.push(result);
    }
    Ok(results)
}
