//! What a scene uses, detected when it is built, so that estimators can
//! skip what it does not.

use super::light::{Light, Lights};
use super::material::{Bsdf, Material};
use crate::accel::Geometry;
use crate::camera::Camera;

/// What a scene uses, detected at load, so that estimators can run a hot
/// loop specialised for it (no specular branches without mirrors or glass,
/// Lambertian-only BSDF code when every material is diffuse).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    pub mirror: bool,
    pub dielectric: bool,
    pub glossy: bool,
    /// Some surface uses a model added for real scenes (microfacet,
    /// plastic, conductor, thin glass, Oren–Nayar).
    pub rich_materials: bool,
    pub point_lights: bool,
    pub spheres: bool,
    pub area_lights: usize,
    /// Something moves while the shutter is open: camera rays need a time.
    pub motion: bool,
    /// Some triangle has vertex normals, or some material a normal map.
    pub shading_normals: bool,
    /// Some material has a normal map.
    pub normal_maps: bool,
    /// Some material's roughness differs along u and v: its frame follows
    /// the surface's dp/du.
    pub anisotropic: bool,
    /// Some material's BSDF reads a texture.
    pub textures: bool,
}

impl Features {
    pub(super) fn detect(
        materials: &[Material],
        geometry: &Geometry,
        lights: &Lights,
        camera: &Camera,
    ) -> Features {
        let used = |f: &dyn Fn(&Bsdf) -> bool| materials.iter().any(|m| f(&m.bsdf));
        Features {
            mirror: used(&|b| matches!(b, Bsdf::Mirror { .. })),
            dielectric: used(&|b| matches!(b, Bsdf::Dielectric { .. })),
            glossy: used(&|b| matches!(b, Bsdf::Glossy { .. })),
            rich_materials: used(&|b| {
                !matches!(
                    b,
                    Bsdf::Diffuse { .. }
                        | Bsdf::Glossy { .. }
                        | Bsdf::Mirror { .. }
                        | Bsdf::Dielectric { .. }
                )
            }),
            point_lights: lights.as_slice().iter().any(|l| {
                matches!(
                    l,
                    Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. }
                )
            }),
            spheres: geometry.has_spheres(),
            area_lights: lights
                .as_slice()
                .iter()
                .filter(|l| {
                    !matches!(
                        l,
                        Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. }
                    )
                })
                .count(),
            motion: geometry.has_motion() && camera.has_shutter_interval(),
            shading_normals: geometry.has_shading_normals()
                || materials.iter().any(|m| m.normal_map.is_some()),
            normal_maps: materials.iter().any(|m| m.normal_map.is_some()),
            anisotropic: materials.iter().any(Material::is_anisotropic),
            textures: materials.iter().any(|m| !m.textures.is_empty()),
        }
    }

    /// True when some surface is a mirror or glass.
    pub fn specular(&self) -> bool {
        self.mirror || self.dielectric
    }

    /// True when every material is Lambertian.
    pub fn diffuse_only(&self) -> bool {
        !self.specular() && !self.glossy && !self.rich_materials
    }

    /// What the code specialised for this scene leaves out, for render
    /// summaries: only what the technique's code really skips (`whitted`:
    /// Whitted's, else path tracing's), since a line that names a skip the
    /// code does not make misleads whoever reads the summary to measure it.
    /// `general` (`--general`) turns off the skips made by feature
    /// detection; those the geometry and lights make themselves stay.
    /// `plain`: the geometry is [`Geometry::is_plain`].
    pub fn skipped(&self, whitted: bool, general: bool, plain: bool) -> Vec<&'static str> {
        let mut v = Vec::new();
        if !general {
            if whitted && !self.dielectric {
                v.push("walks of tinted shadow rays through glass (no glass)");
            }
            if !whitted && self.diffuse_only() {
                v.push("specular-bounce branches and non-Lambertian BSDF code");
            }
            if !self.motion {
                v.push("time dimension (static scene)");
            }
        }
        if !whitted && plain {
            v.push("mask, instance and moving-object tests");
        }
        if !self.spheres {
            v.push("sphere intersection");
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_skipped_list_is_the_techniques_own() {
        // A Lambertian static scene without spheres or glass.
        let f = Features::default();
        let path = f.skipped(false, false, true);
        assert!(path.contains(&"specular-bounce branches and non-Lambertian BSDF code"));
        assert!(path.contains(&"mask, instance and moving-object tests"));
        assert!(!path.iter().any(|s| s.contains("glass")), "{path:?}");
        // Masks or instances: the plain loop does not run.
        assert!(
            !f.skipped(false, false, false)
                .iter()
                .any(|s| s.contains("mask"))
        );
        let whitted = f.skipped(true, false, true);
        assert!(whitted.iter().any(|s| s.contains("through glass")));
        assert!(
            !whitted
                .iter()
                .any(|s| s.contains("Lambertian") || s.contains("mask"))
        );
        // --general: feature detection's skips go, the geometry's stay.
        let general = f.skipped(false, true, true);
        assert_eq!(
            general,
            [
                "mask, instance and moving-object tests",
                "sphere intersection"
            ]
        );
        let glass = Features {
            dielectric: true,
            ..f
        };
        assert!(
            !glass
                .skipped(true, false, true)
                .iter()
                .any(|s| s.contains("glass"))
        );
        assert!(
            !glass
                .skipped(false, false, true)
                .iter()
                .any(|s| s.contains("Lambertian"))
        );
    }
}
