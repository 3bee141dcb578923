//! glTF 2.0 scenes (`.gltf` with its buffers, or `.glb`) into a [`SceneInput`]:
//! the default scene's node tree with its transforms, triangle meshes with
//! normals and texture coordinates, the first camera, metallic-roughness
//! materials mapped onto tracelab's models, and KHR_lights_punctual.
//!
//! The mapping (say it where a user asks): transmission > 0 is a dielectric
//! (rough where roughness > 0) of the KHR_materials_ior index, else
//! metallic 1 a conductor whose reflectance is the base colour at every
//! angle, metallic 0 a plastic (a dielectric coat of IOR 1.5 over the base
//! colour), and between (or a metallic map that varies) a blend of the two
//! weighted by metallic; GGX with α = roughness² (a roughness map read at
//! each hit). glTF's single-sided materials are one-sided.
//! Punctual lights' intensities are taken as radiometric (W/sr, W/m²).

use super::appearance::build_material;
use super::description::{IorDesc, MaterialDesc, MaterialKind};
use super::environment::{Environment, Radiance};
use super::material::{Blend, BlendWeight, Material, MaterialTextures, NormalMap, Opacity};
use super::mesh::{MeshData, Orientation};
use super::uri::read_uri;
use super::{LoadOptions, SceneInput, in_range};
use crate::accel::TriangleInput;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::filter::PixelFilter;
use crate::math::Rgb;
use crate::scene::light::{Light, LightSampling, SpotCone};
use crate::texture::{Bitmap, Filter, Texture, UvTransform, Wrap};
use glam::{Mat3A, Mat4, Vec2, Vec3, Vec3A};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Reads a glTF 2.0 file.
pub fn load_gltf(path: &Path, options: &LoadOptions) -> Result<SceneInput> {
    let err = |m: String| Error::at(path, None, m);
    let gltf = gltf::Gltf::open(path).map_err(|e| err(format!("not a valid glTF file: {e}")))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut buffers = Vec::new();
    for buffer in gltf.document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| err("a buffer refers to a missing binary chunk".into()))?,
            gltf::buffer::Source::Uri(uri) => read_uri(uri, &dir).map_err(err)?,
        };
        if data.len() < buffer.length() {
            return Err(err(format!(
                "buffer {} holds {} bytes, fewer than its declared {}",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    let mut importer = Importer {
        path,
        dir: &dir,
        buffers: &buffers,
        warnings: Vec::new(),
        materials: Vec::new(),
        material_ids: HashMap::new(),
        textures: Vec::new(),
        texture_ids: HashMap::new(),
        triangles: Vec::new(),
        uses: HashMap::new(),
        prototypes: HashMap::new(),
        instances: Default::default(),
        drawn: 0,
        lights: Vec::new(),
        camera: None,
        max_triangles: options.limits.max_triangles,
    };
    let scene = gltf
        .document
        .default_scene()
        .or_else(|| gltf.document.scenes().next())
        .ok_or_else(|| err("the file has no scene".into()))?;
    let mut left = gltf.document.nodes().len();
    count_uses(scene.nodes(), &mut importer.uses, &mut left, 0).map_err(err)?;
    for node in scene.nodes() {
        importer.node(&node, Mat4::IDENTITY)?;
    }
    let camera = match importer.camera.take() {
        Some(c) => c,
        None => {
            importer.warn("no camera: a default one frames the scene".into());
            super::framing::default_camera(&importer.triangles, &[], &importer.instances)
        }
    };
    options
        .limits
        .check_resolution(camera.width, camera.height)
        .map_err(err)?;
    let emissive = importer.materials.iter().any(Material::is_emissive);
    let environment = if importer.lights.is_empty() && !emissive {
        importer.warn("no light: a constant white environment lights the scene".into());
        Some(Environment::new(
            Radiance::Constant(Rgb::ONE),
            1.0,
            Mat3A::IDENTITY,
        ))
    } else {
        None
    };
    options.check_strict(&importer.warnings)?;
    Ok(SceneInput {
        camera,
        materials: importer.materials,
        textures: importer.textures,
        environment,
        triangles: importer.triangles,
        spheres: Vec::new(),
        point_lights: importer.lights,
        moving: Vec::new(),
        instances: importer.instances,
        sphere_sampling: LightSampling::SolidAngle,
        triangle_sampling: LightSampling::Area,
        warnings: importer.warnings,
        hints: Default::default(),
    })
}

/// Counts, per mesh, the nodes under `nodes` that use it. glTF's nodes
/// form a forest (each node has at most one parent); a malformed file
/// whose nodes are reached more than once (a cycle, or a node listed under
/// two parents, which may multiply the walk exponentially) is an error
/// before the walk that places meshes, rather than a hang or a stack
/// overflow. `left` counts the visits a forest allows: one per node; a
/// tree deeper than 256 levels is refused too (no real file comes near).
fn count_uses<'a>(
    nodes: impl Iterator<Item = gltf::Node<'a>>,
    uses: &mut HashMap<usize, usize>,
    left: &mut usize,
    depth: usize,
) -> std::result::Result<(), String> {
    if depth > 256 {
        return Err("the node hierarchy is deeper than 256 levels".into());
    }
    for node in nodes {
        *left = left.checked_sub(1).ok_or_else(|| {
            format!(
                "node {} is reached twice: the node hierarchy is not a tree",
                node.index()
            )
        })?;
        if let Some(mesh) = node.mesh() {
            *uses.entry(mesh.index()).or_default() += 1;
        }
        count_uses(node.children(), uses, left, depth + 1)?;
    }
    Ok(())
}

struct Importer<'a> {
    path: &'a Path,
    dir: &'a Path,
    buffers: &'a [Vec<u8>],
    warnings: Vec<String>,
    materials: Vec<Material>,
    material_ids: HashMap<Option<usize>, u32>,
    textures: Vec<Texture>,
    texture_ids: HashMap<(usize, bool), u32>,
    triangles: Vec<TriangleInput>,
    /// How many nodes of the scene use each mesh: those used more than
    /// once are instanced.
    uses: HashMap<usize, usize>,
    /// Per instanced mesh, its prototype.
    prototypes: HashMap<usize, u32>,
    instances: super::InstancesInput,
    /// Triangles in the prototypes.
    drawn: usize,
    lights: Vec<Light>,
    camera: Option<Camera>,
    max_triangles: usize,
}

impl Importer<'_> {
    fn warn(&mut self, what: String) {
        self.warnings
            .push(format!("{}: {what}", self.path.display()));
    }

    fn error(&self, what: String) -> Error {
        Error::at(self.path, None, what)
    }

    fn node(&mut self, node: &gltf::Node, parent: Mat4) -> Result<()> {
        let to_world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !to_world.is_finite() {
            return Err(self.error(format!(
                "node {}: its transform is not finite",
                node.index()
            )));
        }
        if let Some(mesh) = node.mesh() {
            self.place(&mesh, to_world)?;
        }
        if let Some(camera) = node.camera() {
            self.camera(&camera, to_world);
        }
        if let Some(light) = node.light() {
            self.light(&light, to_world)?;
        }
        for child in node.children() {
            self.node(&child, to_world)?;
        }
        Ok(())
    }

    /// A mesh where a node puts it: shared by an instance where several
    /// nodes use it, copied where one does or the placement mirrors (see
    /// [`super::InstancesInput`]).
    fn place(&mut self, mesh: &gltf::Mesh, to_world: Mat4) -> Result<()> {
        let shared = self.uses.get(&mesh.index()).is_some_and(|&n| n > 1);
        if !shared || to_world.determinant() <= 0.0 {
            let out = self.mesh(mesh, to_world)?;
            return self.push(out);
        }
        let prototype = match self.prototypes.get(&mesh.index()) {
            Some(&p) => p,
            None => {
                let local = self.mesh(mesh, Mat4::IDENTITY)?;
                self.drawn += local.len();
                self.check_count(0)?;
                self.instances.prototypes.push(local);
                let p = self.instances.prototypes.len() as u32 - 1;
                self.prototypes.insert(mesh.index(), p);
                p
            }
        };
        let affine = glam::Affine3A::from_mat4(to_world);
        self.instances.placements.push((prototype, affine));
        Ok(())
    }

    fn check_count(&self, more: usize) -> Result<()> {
        if self.triangles.len() + self.drawn + more > self.max_triangles {
            return Err(self.error(format!(
                "more than {} triangles (raise the limit with --max-triangles)",
                self.max_triangles
            )));
        }
        Ok(())
    }

    fn push(&mut self, out: Vec<TriangleInput>) -> Result<()> {
        self.check_count(out.len())?;
        self.triangles.extend(out);
        Ok(())
    }

    /// A mesh's triangle primitives placed by `to_world`.
    fn mesh(&mut self, mesh: &gltf::Mesh, to_world: Mat4) -> Result<Vec<TriangleInput>> {
        let mut all = Vec::new();
        let name = mesh.name().unwrap_or("").to_string();
        for primitive in mesh.primitives() {
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                self.warn(format!(
                    "mesh {} `{name}`: a primitive of mode {:?} skipped (triangles only)",
                    mesh.index(),
                    primitive.mode()
                ));
                continue;
            }
            let buffers = self.buffers;
            let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
            let Some(positions) = reader.read_positions() else {
                self.warn(format!(
                    "mesh {} `{name}`: a primitive without positions skipped",
                    mesh.index()
                ));
                continue;
            };
            let mut data = MeshData {
                positions: positions.map(Vec3::from).collect(),
                normals: reader.read_normals().map(|n| n.map(Vec3::from).collect()),
                uvs: reader
                    .read_tex_coords(0)
                    .map(|t| t.into_f32().map(Vec2::from).collect()),
                indices: Vec::new(),
            };
            let flat: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..data.positions.len() as u32).collect(),
            };
            data.indices = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            data.validate()
                .map_err(|m| self.error(format!("mesh {} `{name}`: {m}", mesh.index())))?;
            let material = self.material(&primitive.material())?;
            let mut out = Vec::new();
            data.triangles(
                to_world,
                Orientation::Winding,
                false,
                false,
                material,
                &mut out,
            );
            self.check_count(all.len() + out.len())?;
            if !out.iter().all(|t| t.vertices.iter().all(|&v| in_range(v))) {
                return Err(self.error(format!(
                    "mesh {} `{name}`: coordinates out of range",
                    mesh.index()
                )));
            }
            all.extend(out);
        }
        Ok(all)
    }

    fn camera(&mut self, camera: &gltf::Camera, to_world: Mat4) {
        if self.camera.is_some() {
            return;
        }
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            self.warn(format!(
                "camera {}: orthographic cameras are not supported: skipped",
                camera.index()
            ));
            return;
        };
        let aspect = p.aspect_ratio().filter(|a| *a > 0.0).unwrap_or(4.0 / 3.0);
        let (width, height) = if aspect >= 1.0 {
            (640, (640.0 / aspect).round().max(1.0) as u32)
        } else {
            ((640.0 * aspect).round().max(1.0) as u32, 640)
        };
        // A glTF camera looks down its -z with +y up.
        let eye = Vec3A::from(to_world.w_axis.truncate());
        let forward = -Vec3A::from(to_world.z_axis.truncate()).normalize_or_zero();
        let up = Vec3A::from(to_world.y_axis.truncate()).normalize_or_zero();
        let fov_y = p.yfov().to_degrees();
        if forward == Vec3A::ZERO || up == Vec3A::ZERO || !(fov_y > 0.0 && fov_y < 180.0) {
            self.warn(format!(
                "camera {}: a degenerate frame or field of view: skipped",
                camera.index()
            ));
            return;
        }
        self.camera = Some(
            Camera::look_at(eye, eye + forward, up, fov_y, width, height, 0.0, 1.0)
                .with_filter(PixelFilter::Box),
        );
    }

    fn light(&mut self, light: &gltf::khr_lights_punctual::Light, to_world: Mat4) -> Result<()> {
        let power = Rgb::from(light.color()) * light.intensity();
        if !(power.is_finite() && power.min_element() >= 0.0) {
            return Err(self.error(format!(
                "light {}: colour and intensity must be >= 0",
                light.index()
            )));
        }
        let position = Vec3A::from(to_world.w_axis.truncate());
        let axis = -Vec3A::from(to_world.z_axis.truncate()).normalize_or_zero();
        if light.range().is_some() {
            self.warn(format!(
                "light {}: range ignored (light falls off with distance squared)",
                light.index()
            ));
        }
        use gltf::khr_lights_punctual::Kind;
        self.lights.push(match light.kind() {
            Kind::Point => Light::Point {
                position,
                intensity: power,
            },
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => Light::Spot {
                position,
                intensity: power,
                cone: SpotCone {
                    axis,
                    cutoff: outer_cone_angle.clamp(1e-4, std::f32::consts::FRAC_PI_2),
                    beam_width: inner_cone_angle.clamp(0.0, outer_cone_angle),
                },
            },
            Kind::Directional => Light::Directional {
                direction: axis,
                irradiance: power,
                center: Vec3A::ZERO,
                radius: 1.0,
            },
        });
        Ok(())
    }

    /// A glTF material as one of tracelab's (module comment: the mapping).
    fn material(&mut self, m: &gltf::Material) -> Result<u32> {
        if let Some(&id) = self.material_ids.get(&m.index()) {
            return Ok(id);
        }
        let name = m.name().unwrap_or("gltf material").to_string();
        let label = format!("material {} `{name}`", m.index().map_or(-1, |i| i as i64));
        let pbr = m.pbr_metallic_roughness();
        let base = pbr.base_color_factor();
        let base_rgb = [base[0], base[1], base[2]];
        let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
        let mut metallic = pbr.metallic_factor().clamp(0.0, 1.0);
        let alpha = roughness * roughness;
        let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let textures = MaterialTextures::default();
        let base_texture = match pbr.base_color_texture() {
            Some(info) => Some(self.texture(&info.texture(), info.tex_coord(), false, &label)?),
            None => None,
        };
        // Roughness in green, metallic in blue, each times its factor. The
        // roughness map becomes an α map (α = roughness²); a metallic map
        // that varies weighs the blend of the plastic and the metal below
        // (one that does not is its value).
        let mut alpha_texture = None;
        let mut metal_texture = None;
        if let Some(info) = pbr.metallic_roughness_texture() {
            let t = info.texture();
            if info.tex_coord() != 0 {
                self.warn(format!(
                    "{label}: texture coordinate set {} read as set 0",
                    info.tex_coord()
                ));
            }
            let bytes = self.image_bytes(&t.source())?;
            let image = t.source().index();
            let decode = |channel, map: &dyn Fn(f32) -> f32| {
                Bitmap::decode_channel(&bytes, channel, map)
                    .map_err(|m| format!("image {image}: {m}"))
            };
            if roughness > 0.0 {
                let alphas = decode(1, &|g| (roughness * g).powi(2)).map_err(|m| self.error(m))?;
                alpha_texture = Some(self.push_texture(&t, alphas, &label));
            }
            let metal = decode(2, &|b| metallic * b).map_err(|m| self.error(m))?;
            let (lo, hi, mean) = metal.first_channel_range();
            if hi > lo {
                metal_texture = Some(self.push_texture(&t, metal, &label));
            }
            metallic = mean;
        }
        if m.occlusion_texture().is_some() {
            self.warn(format!(
                "{label}: occlusion texture ignored (light transport finds occlusion itself)"
            ));
        }
        let normal_map = match m.normal_texture() {
            Some(info) => Some(NormalMap::Tangent {
                texture: self.texture(&info.texture(), info.tex_coord(), true, &label)?,
                scale: info.scale(),
            }),
            None => None,
        };
        // Alpha as an opacity mask: MASK keeps what reaches the cutoff,
        // BLEND keeps the fraction alpha of the hits (coverage, not a
        // transparency with colour).
        use gltf::material::AlphaMode;
        let cutoff = match m.alpha_mode() {
            AlphaMode::Opaque => None,
            AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5)),
            AlphaMode::Blend => Some(f32::NAN),
        };
        let opacity = match (cutoff, pbr.base_color_texture()) {
            (None, _) => Opacity::Opaque,
            (Some(c), Some(info)) => Opacity::Texture(self.alpha_texture(
                &info.texture(),
                base[3],
                (!c.is_nan()).then_some(c),
                &label,
            )?),
            (Some(c), None) if c.is_nan() && base[3] < 1.0 => Opacity::Constant(base[3].max(0.0)),
            (Some(c), None) if base[3] < c => Opacity::Constant(0.0),
            (Some(_), None) => Opacity::Opaque,
        };
        // glTF's BRDF is the dielectric's and the metal's mixed by metallic:
        // where it lies strictly between 0 and 1 (or its map varies), the
        // material is a blend of the two (crate::accel::blend).
        let blended =
            transmission == 0.0 && (metal_texture.is_some() || (metallic > 0.0 && metallic < 1.0));
        let model = |metal: bool| {
            let mut d = MaterialDesc {
                twosided: Some(m.double_sided()),
                ..Default::default()
            };
            let mut textures = textures;
            if transmission > 0.0 {
                d.twosided = None;
                let ior = m.ior().unwrap_or(1.5);
                // glTF's transmissive volumes are refracting solids.
                d.kind = match alpha > 1e-4 {
                    true => MaterialKind::RoughDielectric,
                    false => MaterialKind::Dielectric,
                };
                if d.kind == MaterialKind::Dielectric {
                    d.ior = Some(ior);
                    d.tint = Some(base_rgb);
                } else {
                    d.int_ior = Some(IorDesc::Value(ior));
                    d.ext_ior = Some(IorDesc::Value(1.0));
                    d.specular_transmittance = Some(base_rgb);
                    d.distribution = Some(crate::bsdf::Distribution::Ggx);
                    d.alpha = Some(alpha);
                    (textures.alpha, textures.alpha_v) = (alpha_texture, alpha_texture);
                }
            } else if metal {
                d.kind = match alpha > 1e-4 {
                    true => MaterialKind::RoughConductor,
                    false => MaterialKind::Conductor,
                };
                // η = 0, k = 1: Fresnel 1 at every angle, tinted by the base colour.
                d.eta = Some([0.0; 3]);
                d.k = Some([1.0; 3]);
                d.specular_reflectance = Some(base_rgb);
                textures.specular = base_texture;
                if d.kind == MaterialKind::RoughConductor {
                    d.distribution = Some(crate::bsdf::Distribution::Ggx);
                    d.alpha = Some(alpha);
                    (textures.alpha, textures.alpha_v) = (alpha_texture, alpha_texture);
                }
            } else {
                d.kind = match alpha > 1e-4 {
                    true => MaterialKind::RoughPlastic,
                    false => MaterialKind::Plastic,
                };
                d.int_ior = Some(IorDesc::Value(1.5));
                d.ext_ior = Some(IorDesc::Value(1.0));
                d.diffuse_reflectance = Some(base_rgb);
                textures.diffuse = base_texture;
                if d.kind == MaterialKind::RoughPlastic {
                    d.distribution = Some(crate::bsdf::Distribution::Ggx);
                    d.alpha = Some(alpha);
                    (textures.alpha, textures.alpha_v) = (alpha_texture, alpha_texture);
                }
            }
            (d, textures)
        };
        if transmission > 0.0 && transmission < 1.0 {
            self.warn(format!("{label}: transmission {transmission} read as 1"));
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let emission = Rgb::from(m.emissive_factor()) * strength;
        let emission_texture = match m.emissive_texture() {
            Some(info) => Some(self.texture(&info.texture(), info.tex_coord(), false, &label)?),
            None => None,
        };
        let build = |metal: bool| {
            let (mut d, textures) = model(metal);
            if emission.max_element() > 0.0 {
                d.emission = Some(emission.to_array());
                d.two_sided = Some(m.double_sided());
            }
            let mut material = build_material(&name, &d)?;
            material.emission_texture = emission_texture;
            material.set_textures(textures);
            material.opacity = opacity;
            material.normal_map = normal_map;
            Ok::<_, String>(material)
        };
        let built = |metal| build(metal).map_err(|e| self.error(format!("{label}: {e}")));
        let mut material = built(!blended && metallic >= 0.5)?;
        if blended {
            let metal = built(true)?;
            material.blend = Some(Blend {
                second: self.materials.len() as u32,
                weight: match metal_texture {
                    Some(t) => BlendWeight::Texture(t),
                    None => BlendWeight::Constant(metallic),
                },
            });
            self.materials.push(metal);
        }
        let id = self.materials.len() as u32;
        self.materials.push(material);
        self.material_ids.insert(m.index(), id);
        Ok(id)
    }

    fn texture(
        &mut self,
        t: &gltf::Texture,
        tex_coord: u32,
        raw: bool,
        label: &str,
    ) -> Result<u32> {
        if tex_coord != 0 {
            self.warn(format!(
                "{label}: texture coordinate set {tex_coord} read as set 0"
            ));
        }
        if let Some(&id) = self.texture_ids.get(&(t.index(), raw)) {
            return Ok(id);
        }
        let image = t.source();
        let bytes = self.image_bytes(&image)?;
        let bitmap = Bitmap::decode(&bytes, raw)
            .map_err(|m| self.error(format!("image {}: {m}", image.index())))?;
        let id = self.push_texture(t, bitmap, label);
        self.texture_ids.insert((t.index(), raw), id);
        Ok(id)
    }

    /// The opacity of a material whose base colour has texture `t`: the
    /// image's alpha channel times `factor`, cut at `cutoff` where the
    /// alpha mode is MASK (one texture per material: the cut differs).
    fn alpha_texture(
        &mut self,
        t: &gltf::Texture,
        factor: f32,
        cutoff: Option<f32>,
        label: &str,
    ) -> Result<u32> {
        let image = t.source();
        let bytes = self.image_bytes(&image)?;
        let bitmap = Bitmap::decode_alpha(&bytes, factor, cutoff)
            .map_err(|m| self.error(format!("image {}: {m}", image.index())))?;
        Ok(self.push_texture(t, bitmap, label))
    }

    /// The encoded bytes of `image`, from a buffer view or a URI.
    fn image_bytes(&self, image: &gltf::Image) -> Result<Vec<u8>> {
        Ok(match image.source() {
            gltf::image::Source::View { view, .. } => {
                let data = &self.buffers[view.buffer().index()];
                let range = view.offset()..view.offset() + view.length();
                data.get(range)
                    .ok_or_else(|| {
                        self.error(format!(
                            "image {}: its buffer view is out of range",
                            image.index()
                        ))
                    })?
                    .to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => {
                read_uri(uri, self.dir).map_err(|m| self.error(m))?
            }
        })
    }

    /// Adds `bitmap` sampled as texture `t` asks; returns its id.
    fn push_texture(&mut self, t: &gltf::Texture, bitmap: Bitmap, label: &str) -> u32 {
        let sampler = t.sampler();
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
        };
        let (wrap_s, wrap_t) = (wrap(sampler.wrap_s()), wrap(sampler.wrap_t()));
        if wrap_s != wrap_t {
            self.warn(format!(
                "{label}: different wrap modes for u and v: u's is used"
            ));
        }
        let filter = match sampler.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Bilinear,
        };
        let id = self.textures.len() as u32;
        self.textures.push(Texture::Bitmap {
            image: Arc::new(bitmap),
            wrap: wrap_s,
            filter,
            to_uv: UvTransform::default(),
        });
        id
    }
}
