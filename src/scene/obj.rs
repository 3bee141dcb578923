//! OBJ/MTL loading with tobj, plus the checks tobj does not make.
//!
//! tobj parses; it does not say on which line a file is wrong and it accepts
//! `nan` and `inf` coordinates. A quick line scan before parsing catches
//! non-finite vertices, face indices out of range and missing material
//! libraries, and reports them as `file:line: what`.

use crate::error::{Error, Result};
use crate::math::Rgb;
use crate::scene::material::{Bsdf, Material};
use crate::scene::mesh::MeshData;
use glam::{Vec2, Vec3, Vec3A};
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

/// The models and converted materials of an OBJ file, parsed by tobj after
/// the checks it does not make.
/// With `single_index`, a vertex is a (position, texture coordinates,
/// normal) triple indexed once; without, each has its own indices.
fn parse(path: &Path, single_index: bool) -> Result<(Vec<tobj::Model>, Vec<Material>)> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::at(path, None, format!("cannot read OBJ file: {e}")))?;
    if !quick_scan(&text) {
        scan_obj_text(path, &text, false)?;
    }
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let options = tobj::LoadOptions {
        single_index,
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
    if materials.is_empty() {
        // Finding the library's name reads every line.
        return Ok((models, Vec::new()));
    }
    let mtl_path = mtl_library(&text)
        .map(|m| dir.join(m))
        .unwrap_or_else(|| path.to_path_buf());
    let materials = materials
        .iter()
        .map(|m| convert_material(&mtl_path, m))
        .collect::<Result<Vec<_>>>()?;

    Ok((models, materials))
}

/// Reads and validates an OBJ file and its MTL libraries.
pub fn load_obj(path: &Path) -> Result<ObjMesh> {
    let (models, materials) = parse(path, false)?;
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

/// An OBJ file as one indexed mesh in file units, its groups merged and its
/// materials ignored (Mitsuba reads an OBJ as one shape); `flip_v` maps v
/// to 1 − v, as Mitsuba does by default. A vertex is one (position,
/// texture coordinates, normal) triple of the faces, shared by the faces
/// that name it: a third of an unindexed mesh's size where exporters write
/// smooth meshes. As [`load_obj`], normals and texture coordinates are
/// kept only when every face has valid ones.
pub fn load_obj_mesh(path: &Path, flip_v: bool) -> Result<MeshData> {
    let (models, _) = parse(path, true)?;
    let mut mesh = MeshData::default();
    let (mut normals, mut uvs) = (Some(Vec::new()), Some(Vec::new()));
    for model in &models {
        let m = &model.mesh;
        let count = m.positions.len() / 3;
        // A face without them gives its new vertices none, which leaves
        // the arrays short.
        let has_normals = m.normals.len() == 3 * count
            && m.normals.chunks_exact(3).all(|n| {
                let n = Vec3A::new(n[0], n[1], n[2]).normalize_or_zero();
                n != Vec3A::ZERO && n.is_finite()
            });
        let has_uvs = m.texcoords.len() == 2 * count && m.texcoords.iter().all(|x| x.is_finite());
        if !has_normals {
            normals = None;
        }
        if !has_uvs {
            uvs = None;
        }
        let base = mesh.positions.len() as u32;
        let vec3 = |p: &[f32]| Vec3::new(p[0], p[1], p[2]);
        mesh.positions.extend(m.positions.chunks_exact(3).map(vec3));
        if let Some(normals) = normals.as_mut() {
            normals.extend(m.normals.chunks_exact(3).map(vec3));
        }
        if let Some(uvs) = uvs.as_mut() {
            let uv = |t: &[f32]| Vec2::new(t[0], if flip_v { 1.0 - t[1] } else { t[1] });
            uvs.extend(m.texcoords.chunks_exact(2).map(uv));
        }
        let corners = m.indices.chunks_exact(3);
        mesh.indices
            .extend(corners.map(|c| [c[0], c[1], c[2]].map(|i| base + i)));
    }
    mesh.normals = normals.filter(|n| !n.is_empty());
    mesh.uvs = uvs.filter(|t| !t.is_empty());
    Ok(mesh)
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

/// The common case of [`scan_obj_text`] in one pass over the bytes (its
/// word splitting cost a third of an OBJ's decoding): true when every face
/// passes as the full scan would pass it. A line it cannot vouch for (a face
/// index out of range, `mtllib`, a `+` sign, a byte outside ASCII) gives
/// false, and the full scan decides and names the line. Vertex lines are
/// only counted: tobj refuses one with fewer than three numbers, and the
/// full scan then names it.
fn quick_scan(text: &str) -> bool {
    let b = text.as_bytes();
    // `split_whitespace` also splits at Unicode spaces and vertical tabs.
    if !text.is_ascii() || b.contains(&0x0b) {
        return false;
    }
    let space = |c: u8| matches!(c, b' ' | b'\t' | b'\r' | 0x0c);
    let skip_spaces = |mut i: usize| {
        while i < b.len() && space(b[i]) {
            i += 1;
        }
        i
    };
    // Vertices, texture coordinates and normals defined so far.
    let mut defined = [0u64; 3];
    let mut i = 0;
    while i < b.len() {
        let key = skip_spaces(i);
        i = key;
        while i < b.len() && !space(b[i]) && b[i] != b'\n' {
            i += 1;
        }
        match &b[key..i] {
            b"v" => defined[0] += 1,
            b"vt" => defined[1] += 1,
            b"vn" => defined[2] += 1,
            b"f" => {
                let mut corners = 0;
                loop {
                    i = skip_spaces(i);
                    if i == b.len() || b[i] == b'\n' {
                        break;
                    }
                    corners += 1;
                    // `v`, `v/vt`, `v//vn` or `v/vt/vn`, each index 1-based or
                    // counting back from the last when negative.
                    let mut part = 0;
                    loop {
                        // After a final `/`, i is past the end.
                        let negative = b.get(i) == Some(&b'-');
                        i += usize::from(negative);
                        let (start, mut value) = (i, 0u64);
                        while i < b.len() && b[i].is_ascii_digit() && i - start < 18 {
                            value = value * 10 + u64::from(b[i] - b'0');
                            i += 1;
                        }
                        let empty = i == start && !negative;
                        let known = part >= 3
                            || (part > 0 && empty)
                            || (1..=defined[part]).contains(&value);
                        if !known {
                            return false;
                        }
                        if i < b.len() && b[i] == b'/' {
                            (i, part) = (i + 1, part + 1);
                        } else {
                            break;
                        }
                    }
                    if i < b.len() && !space(b[i]) && b[i] != b'\n' {
                        return false;
                    }
                }
                if corners < 3 {
                    return false;
                }
            }
            b"mtllib" => return false,
            _ => {}
        }
        // `str::find` of one byte is a memchr: most lines are vertices,
        // passed over whole.
        match text[i..].find('\n') {
            Some(k) => i += k + 1,
            None => break,
        }
    }
    true
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
        emission_texture: None,
        textures: Default::default(),
        opacity: Default::default(),
        normal_map: None,
        blend: None,
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
    fn the_quick_scan_vouches_only_for_what_the_full_scan_passes() {
        let valid = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvn 0 1 0\nf 1 2 3\r\nf -3 -2 -1\n\tf 1/1/1 2//2 3/-1/-2 \n# f 9 9 9\ng x\n";
        assert!(quick_scan(valid));
        check(valid).unwrap();
        let triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        for face in [
            "f 1 2 4",
            "f 1 -5 1",
            "f 1/1 2/1 3/1",
            "f 1 2",
            "f 0 1 2",
            "f 1 2 3x",
            "f 1 2 99999999999999999999",
            "f 1 2 /3",
        ] {
            let bad = format!("{triangle}{face}\n");
            assert!(!quick_scan(&bad), "{face}");
            assert!(check(&bad).is_err(), "{face}");
        }
        // A corner ending in `/` at the end of the file (no newline): read
        // without going past the end.
        let ends_in_slash = format!("{triangle}f 1 2 3/");
        assert!(quick_scan(&ends_in_slash));
        assert!(check(&ends_in_slash).is_ok());
        // Valid, but left to the full scan.
        for unsure in [
            format!("{triangle}f +1 2 3\n"),
            format!("{triangle}v 0 0 0\u{a0}\n"),
        ] {
            assert!(!quick_scan(&unsure), "{unsure:?}");
            check(&unsure).unwrap();
        }
    }

    #[test]
    fn an_obj_mesh_shares_the_vertices_its_faces_share() {
        let dir = std::env::temp_dir().join(format!("tracelab-obj-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("quad.obj");
        let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 2\n";
        std::fs::write(&path, format!("{quad}f 1/1/1 2/2/1 3/3/1 4/4/1\n")).unwrap();
        let mesh = load_obj_mesh(&path, true).unwrap();
        // The quad's two triangles share two of its four corners.
        assert_eq!((mesh.positions.len(), mesh.indices.len()), (4, 2));
        let (normals, uvs) = (mesh.normals.unwrap(), mesh.uvs.unwrap());
        let obj = load_obj(&path).unwrap();
        for (t, &corners) in obj.triangles.iter().zip(&mesh.indices) {
            let corners = corners.map(|i| i as usize);
            assert_eq!(t.vertices, corners.map(|i| Vec3A::from(mesh.positions[i])));
            assert_eq!(t.uvs.unwrap(), corners.map(|i| uvs[i]));
            // Normalised when placed.
            let normal = |i: usize| Vec3A::from(normals[i]).normalize();
            assert_eq!(t.normals.unwrap(), corners.map(normal));
        }
        // One face without normals: the mesh has none.
        std::fs::write(&path, format!("{quad}f 1//1 2//1 3//1\nf 1 3 4\n")).unwrap();
        assert!(load_obj_mesh(&path, true).unwrap().normals.is_none());
        std::fs::remove_dir_all(&dir).unwrap();
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
