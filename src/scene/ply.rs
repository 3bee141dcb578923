//! PLY meshes (ASCII and binary, any property order) through `ply-rs-bw`:
//! positions, normals (`nx ny nz`), texture coordinates (`u v`, `s t` or
//! `texture_u texture_v`), and polygons fanned into triangles.

use super::mesh::MeshData;
use crate::error::{Error, Result};
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::path::Path;

/// Reads a PLY file.
pub fn load_ply(path: &Path) -> Result<MeshData> {
    let err = |m: String| Error::at(path, None, m);
    let file = std::fs::File::open(path).map_err(|e| err(format!("cannot read PLY file: {e}")))?;
    let mut reader = std::io::BufReader::new(file);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut reader)
        .map_err(|e| err(format!("not a valid PLY file: {e}")))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| err("no `vertex` element".into()))?;
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| err("no `face` element".into()))?;
    let number = |e: &DefaultElement, names: &[&str]| -> Option<f32> {
        names.iter().find_map(|n| scalar(e.get(*n)?))
    };
    let mut mesh = MeshData::default();
    let first = vertices.first();
    let has = |names: &[&str]| first.is_some_and(|e| names.iter().any(|n| e.contains_key(*n)));
    let (has_normals, has_uvs) = (has(&["nx"]), has(&["u", "s", "texture_u", "texture_s"]));
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        let p = [&["x"][..], &["y"], &["z"]].map(|n| number(v, n));
        let [Some(x), Some(y), Some(z)] = p else {
            return Err(err(format!("vertex {i} lacks x, y or z")));
        };
        mesh.positions.push(Vec3::new(x, y, z));
        if has_normals {
            let n = [&["nx"][..], &["ny"], &["nz"]].map(|n| number(v, n).unwrap_or(0.0));
            normals.push(Vec3::from(n));
        }
        if has_uvs {
            let u = number(v, &["u", "s", "texture_u", "texture_s"]).unwrap_or(0.0);
            let w = number(v, &["v", "t", "texture_v", "texture_t"]).unwrap_or(0.0);
            uvs.push(Vec2::new(u, w));
        }
    }
    for (i, f) in faces.iter().enumerate() {
        let list = ["vertex_indices", "vertex_index"]
            .iter()
            .find_map(|n| f.get(*n))
            .and_then(index_list)
            .ok_or_else(|| err(format!("face {i} has no vertex_indices list")))?;
        if list.len() < 3 {
            return Err(err(format!("face {i} has {} vertices", list.len())));
        }
        for k in 1..list.len() - 1 {
            mesh.indices.push([list[0], list[k], list[k + 1]]);
        }
    }
    mesh.normals = has_normals.then_some(normals);
    mesh.uvs = has_uvs.then_some(uvs);
    mesh.validate().map_err(err)?;
    Ok(mesh)
}

fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Float(x) => x,
        Property::Double(x) => x as f32,
        Property::Char(x) => x as f32,
        Property::UChar(x) => x as f32,
        Property::Short(x) => x as f32,
        Property::UShort(x) => x as f32,
        Property::Int(x) => x as f32,
        Property::UInt(x) => x as f32,
        _ => return None,
    })
}

fn index_list(p: &Property) -> Option<Vec<u32>> {
    let to = |v: i64| u32::try_from(v).ok();
    match p {
        Property::ListChar(v) => v.iter().map(|&x| to(x as i64)).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| Some(x as u32)).collect(),
        Property::ListShort(v) => v.iter().map(|&x| to(x as i64)).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| Some(x as u32)).collect(),
        Property::ListInt(v) => v.iter().map(|&x| to(x as i64)).collect(),
        Property::ListUInt(v) => Some(v.clone()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_quads_read_alike() {
        let dir = std::env::temp_dir().join(format!("tracelab_ply_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let header = |format: &str| {
            format!(
                "ply\nformat {format} 1.0\nelement vertex 4\nproperty float y\nproperty float x\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            )
        };
        let ascii = format!(
            "{}0 0 0 0 0\n0 1 0 1 0\n1 1 0 1 1\n1 0 0 0 1\n4 0 1 2 3\n",
            header("ascii")
        );
        std::fs::write(dir.join("a.ply"), ascii).unwrap();
        let mut binary = header("binary_little_endian").into_bytes();
        for v in [
            [0f32, 0., 0., 0., 0.],
            [0., 1., 0., 1., 0.],
            [1., 1., 0., 1., 1.],
            [1., 0., 0., 0., 1.],
        ] {
            for x in v {
                binary.extend(x.to_le_bytes());
            }
        }
        binary.push(4);
        for i in 0i32..4 {
            binary.extend(i.to_le_bytes());
        }
        std::fs::write(dir.join("b.ply"), binary).unwrap();
        let a = load_ply(&dir.join("a.ply")).unwrap();
        let b = load_ply(&dir.join("b.ply")).unwrap();
        assert_eq!(a.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(a.positions, b.positions);
        assert_eq!(
            a.positions[1],
            Vec3::new(1.0, 0.0, 0.0),
            "x and y read by name"
        );
        assert_eq!(a.uvs, b.uvs);
        let bad = load_ply(&dir.join("missing.ply")).unwrap_err();
        assert!(bad.message().contains("missing.ply"), "{bad}");
    }
}
