//! OBJ/MTL loading with tobj, plus the checks tobj does not make.
//!
//! tobj parses; it does not say on which line a file is wrong and it accepts
//! `nan` and `inf` coordinates. A quick line scan before parsing catches
//! non-finite vertices, face indices out of range and missing material
//! libraries, and reports them as `file:line: what`.

use crate::error::{Error, Result};
use crate::math::Rgb;
use crate::scene::material::{Bsdf, Material};
use glam::{Vec2, Vec3A};
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// One triangle of an OBJ file.
pub struct ObjTriangle {
    /// Vertex positions in file units.
    pub vertices: [Vec3A; 3],
    /// The `vn` normals of its vertices, if the face gives them.
    pub normals: Option<[Vec3A; 3]>,
    /// The `vt` coordinates, v flipped (1 − v) as Mitsuba flips them, so
    /// that v = 0 reads an image's top row.
    pub uvs: Option<[Vec2; 3]>,
    /// Index of its MTL material, if any.
    pub material: Option<usize>,
}

/// Triangles of one OBJ file.
pub struct ObjMesh {
    pub triangles: Vec<ObjTriangle>,
    /// Materials from the file's MTL libraries, converted.
    pub materials: Vec<Material>,
}

/// Reads and validates an OBJ file and its MTL libraries.
pub fn load_obj(path: &Path) -> Result<ObjMesh> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::at(path, None, format!("cannot read OBJ file: {e}")))?;
    scan_obj_text(path, &text, false)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // tobj has panicked on input our line scans did not foresee (found by
    // fuzzing: `Kd` with fewer than three numbers); a panic in it is a bad
    // file, not a crash.
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut BufReader::new(text.as_bytes()), &options, |mtl| {
            tobj::load_mtl(dir.join(mtl))
        })
    }))
    .map_err(|_| {
        check_obj_text(path, &text).err().unwrap_or_else(|| {
            Error::at(path, None, "malformed OBJ or MTL: the OBJ parser gave up")
        })
    })?;
    let (models, materials) = parsed.map_err(|e| {
        check_obj_text(path, &text)
            .err()
            .unwrap_or_else(|| Error::at(path, None, format!("malformed OBJ: {e}")))
    })?;
    let in_range = |x: &f32| x.is_finite() && x.abs() <= super::MAX_COORDINATE;
    if !models.iter().all(|m| m.mesh.positions.iter().all(in_range)) {
        return Err(check_obj_text(path, &text).err().unwrap_or_else(|| {
            Error::at(
                path,
                None,
                "a vertex coordinate is not finite or out of range",
            )
        }));
    }
    let materials = materials
        .map_err(|e| Error::at(path, None, format!("cannot load its material library: {e}")))?;
    let mtl_path = mtl_library(&text)
        .map(|m| dir.join(m))
        .unwrap_or_else(|| path.to_path_buf());
    let materials = materials
        .iter()
        .map(|m| convert_material(&mtl_path, m))
        .collect::<Result<Vec<_>>>()?;

    let mut triangles = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let vertex = |i: u32| -> Vec3A {
            let i = i as usize * 3;
            Vec3A::new(
                mesh.positions[i],
                mesh.positions[i + 1],
                mesh.positions[i + 2],
            )
        };
        let normal = |i: u32| -> Option<Vec3A> {
            let i = i as usize * 3;
            let n = Vec3A::new(
                *mesh.normals.get(i)?,
                *mesh.normals.get(i + 1)?,
                *mesh.normals.get(i + 2)?,
            )
            .normalize_or_zero();
            (n != Vec3A::ZERO && n.is_finite()).then_some(n)
        };
        let uv = |i: u32| -> Option<Vec2> {
            let i = i as usize * 2;
            let t = Vec2::new(*mesh.texcoords.get(i)?, 1.0 - *mesh.texcoords.get(i + 1)?);
            t.is_finite().then_some(t)
        };
        for (f, face) in mesh.indices.chunks_exact(3).enumerate() {
            let corners = |indices: &[u32]| -> Option<[u32; 3]> {
                let c = indices.get(3 * f..3 * f + 3)?;
                Some([c[0], c[1], c[2]])
            };
            let normals = corners(&mesh.normal_indices)
                .and_then(|[a, b, c]| Some([normal(a)?, normal(b)?, normal(c)?]));
            let uvs = corners(&mesh.texcoord_indices)
                .and_then(|[a, b, c]| Some([uv(a)?, uv(b)?, uv(c)?]));
            triangles.push(ObjTriangle {
                vertices: [vertex(face[0]), vertex(face[1]), vertex(face[2])],
                normals,
                uvs,
                material: mesh.material_id,
            });
        }
    }
    Ok(ObjMesh {
        triangles,
        materials,
    })
}

/// The first `mtllib` file name, if any.
fn mtl_library(text: &str) -> Option<&str> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix("mtllib ").map(str::trim))
}

/// Line scan for what tobj accepts silently or reports without a line.
pub fn check_obj_text(path: &Path, text: &str) -> Result<()> {
    scan_obj_text(path, text, true)
}

/// [`check_obj_text`]; without `coordinates`, vertex lines are only
/// counted, not parsed (a second parse of every number was a fifth of an
/// OBJ's load: [`load_obj`] checks the parsed positions instead, and scans
/// again with `coordinates` to say which line is wrong).
fn scan_obj_text(path: &Path, text: &str, coordinates: bool) -> Result<()> {
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let (mut vertex_count, mut texcoord_count, mut normal_count) = (0i64, 0i64, 0i64);
    for (number, line) in text.lines().enumerate() {
        let number = number + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut coords = [""; 3];
                let given = coords.iter_mut().zip(words).map(|(c, w)| *c = w).count();
                if given < 3 {
                    return Err(Error::at(
                        path,
                        Some(number),
                        "vertex needs three coordinates `v x y z`",
                    ));
                }
                for c in coords.into_iter().filter(|_| coordinates) {
                    match c.parse::<f32>() {
                        Ok(x) if x.is_finite() && x.abs() > super::MAX_COORDINATE => {
                            return Err(Error::at(
                                path,
                                Some(number),
                                format!(
                                    "vertex coordinate `{c}` is beyond ±{:e} (areas and distances would overflow)",
                                    super::MAX_COORDINATE
                                ),
                            ));
                        }
                        Ok(x) if x.is_finite() => {}
                        Ok(_) => {
                            return Err(Error::at(
                                path,
                                Some(number),
                                format!("vertex coordinate `{c}` is not finite"),
                            ));
                        }
                        Err(_) => {
                            return Err(Error::at(
                                path,
                                Some(number),
                                format!("vertex coordinate `{c}` is not a number"),
                            ));
                        }
                    }
                }
                vertex_count += 1;
            }
            Some("vt") => texcoord_count += 1,
            Some("vn") => normal_count += 1,
            Some("f") => {
                let mut corners = 0;
                for corner in words {
                    corners += 1;
                    // `v`, `v/vt`, `v//vn` or `v/vt/vn`; each index checked
                    // against what is defined so far (tobj overflows on some).
                    let mut parts = corner.split('/');
                    let kinds = [
                        ("vertex", vertex_count, false),
                        ("texture coordinate", texcoord_count, true),
                        ("normal", normal_count, true),
                    ];
                    for (what, count, optional) in kinds {
                        let index = parts.next().unwrap_or("");
                        if optional && index.is_empty() {
                            continue;
                        }
                        let resolved = match index.parse::<i64>() {
                            // OBJ indices are 1-based; negative ones count back from the last one.
                            Ok(i) if i > 0 => i,
                            Ok(i) if i < 0 => count + 1 + i,
                            _ => {
                                return Err(Error::at(
                                    path,
                                    Some(number),
                                    format!("face index `{corner}` is not a valid index"),
                                ));
                            }
                        };
                        if resolved < 1 || resolved > count {
                            return Err(Error::at(
                                path,
                                Some(number),
                                format!(
                                    "face {what} index {index} is out of range: {count} defined so far"
                                ),
                            ));
                        }
                    }
                }
                if corners < 3 {
                    return Err(Error::at(
                        path,
                        Some(number),
                        "face needs at least three vertices",
                    ));
                }
            }
            Some("mtllib") => {
                let name = line.trim_start()["mtllib".len()..].trim();
                let mtl: PathBuf = dir.join(name);
                if !mtl.is_file() {
                    return Err(Error::at(
                        path,
                        Some(number),
                        format!(
                            "material library `{name}` not found (looked for {})",
                            mtl.display()
                        ),
                    ));
                }
                let mtl_text = std::fs::read_to_string(&mtl).map_err(|e| {
                    Error::at(&mtl, None, format!("cannot read material library: {e}"))
                })?;
                check_mtl_text(&mtl, &mtl_text)?;
            }
            _ => {}
        }
    }
    Ok(())
}

/// Line scan of an MTL file: the colour and number statements tracelab reads
/// must hold finite numbers (tobj reports them without a line, or panics).
pub fn check_mtl_text(path: &Path, text: &str) -> Result<()> {
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else {
            continue;
        };
        let wanted = match key {
            "Ka" | "Kd" | "Ks" | "Ke" => 3,
            "Ns" | "Ni" | "d" => 1,
            _ => continue,
        };
        let values: Vec<&str> = words.take(wanted).collect();
        let finite = values
            .iter()
            .all(|v| v.parse::<f32>().is_ok_and(f32::is_finite));
        if values.len() < wanted || !finite {
            let what = if wanted == 3 {
                "three finite numbers"
            } else {
                "a finite number"
            };
            return Err(Error::at(
                path,
                Some(number + 1),
                format!("`{key}` needs {what}, got `{}`", line.trim()),
            ));
        }
    }
    Ok(())
}

/// Maps an MTL material onto tracelab's materials:
/// `illum` 3 or 5: mirror with reflectance `Ks` (default 1);
/// `illum` 4, 6 or 7: dielectric with IOR `Ni` (default 1.5), tinted by `Tf`;
/// `Ks` > 0 with `Ns` > 0: glossy (`Kd` diffuse + Phong lobe `Ks`, exponent `Ns`);
/// otherwise Lambertian with albedo `Kd`. `Ke` is emission (one-sided).
fn convert_material(mtl_path: &Path, m: &tobj::Material) -> Result<Material> {
    let check = |field: &str, v: Option<[f32; 3]>| -> Result<Option<Rgb>> {
        match v {
            Some(c) if c.iter().all(|x| x.is_finite() && *x >= 0.0) => Ok(Some(Rgb::from(c))),
            Some(c) => Err(Error::at(
                mtl_path,
                None,
                format!(
                    "material `{}`: `{field}` must be finite and non-negative, got {c:?}",
                    m.name
                ),
            )),
            None => Ok(None),
        }
    };
    let kd = check("Kd", m.diffuse)?.unwrap_or(Rgb::splat(0.8));
    let ks = check("Ks", m.specular)?;
    let emission = check("Ke", m.emissive)?.unwrap_or(Rgb::ZERO);
    let ns = m.shininess.unwrap_or(0.0);
    let tf = m
        .unknown_param
        .get("Tf")
        .and_then(|s| parse_rgb(s))
        .unwrap_or(Rgb::ONE);
    let bsdf = match m.illumination_model {
        Some(3 | 5) => Bsdf::Mirror {
            reflectance: ks.unwrap_or(Rgb::ONE).min(Rgb::ONE),
        },
        Some(4 | 6 | 7) => {
            let eta = m.optical_density.unwrap_or(1.5);
            if !(eta.is_finite() && eta > 0.0) {
                return Err(Error::at(
                    mtl_path,
                    None,
                    format!("material `{}`: `Ni` must be positive, got {eta}", m.name),
                ));
            }
            Bsdf::Dielectric {
                eta,
                tint: tf.min(Rgb::ONE),
            }
        }
        _ => match ks {
            Some(ks) if ks.max_element() > 0.0 && ns > 0.0 => Bsdf::glossy(kd, ks, ns),
            _ => Bsdf::Diffuse {
                albedo: kd.min(Rgb::ONE),
            },
        },
    };
    Ok(Material {
        name: m.name.clone(),
        bsdf,
        emission,
        two_sided_emission: false,
        textures: Default::default(),
        opacity: Default::default(),
        normal_map: None,
    })
}

fn parse_rgb(s: &str) -> Option<Rgb> {
    let v: Vec<f32> = s
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    match v.as_slice() {
        [r, g, b] => Some(Rgb::new(*r, *g, *b)),
        [x] => Some(Rgb::splat(*x)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<()> {
        check_obj_text(Path::new("m.obj"), text)
    }

    #[test]
    fn accepts_valid_faces_including_negative_indices() {
        check("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvn 0 1 0\nf 1 2 3\nf -3 -2 -1\nf 1/1/1 2//2 3/-1/-2\n")
            .unwrap();
        // Texture and normal indices are checked against their own counts.
        let e = check("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n").unwrap_err();
        assert_eq!(
            e.message(),
            "m.obj:4: face texture coordinate index 1 is out of range: 0 defined so far"
        );
    }

    #[test]
    fn names_the_line_of_bad_vertices_and_faces() {
        let e = check("v 0 0 0\nv nan 0 0\n").unwrap_err();
        assert_eq!(
            e.message(),
            "m.obj:2: vertex coordinate `nan` is not finite"
        );
        let e = check("v 0 0 0\nv 1 0 inf\n").unwrap_err();
        assert!(e.message().starts_with("m.obj:2:"));
        let e = check("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap_err();
        assert_eq!(
            e.message(),
            "m.obj:4: face vertex index 4 is out of range: 3 defined so far"
        );
        let e = check("v 0 0 0\nf 1 -5 1\n").unwrap_err();
        assert!(
            e.message()
                .starts_with("m.obj:2: face vertex index -5 is out of range")
        );
        let e = check("v 0 0 0\nmtllib nowhere.mtl\n").unwrap_err();
        assert!(
            e.message()
                .starts_with("m.obj:2: material library `nowhere.mtl` not found")
        );
    }
}
