//! PLY meshes (ASCII and binary, any property order) through `ply-rs-bw`:
//! positions, normals (`nx ny nz`), texture coordinates (`u v`, `s t` or
//! `texture_u texture_v`), and polygons fanned into triangles.

use super::mesh::MeshData;
use crate::error::{Error, Result};
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Encoding, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType};
use std::path::Path;

/// Reads a PLY file. Elements are read into typed vertices and faces
/// (ply-rs's `PropertyAccess`), not its default map per element, which
/// was most of the time of a large mesh.
pub fn load_ply(path: &Path) -> Result<MeshData> {
    let err = |m: String| Error::at(path, None, m);
    let file = std::fs::File::open(path).map_err(|e| err(format!("cannot read PLY file: {e}")))?;
    let bytes = file.metadata().map_or(u64::MAX, |m| m.len());
    let mut reader = Reader::new(std::io::BufReader::new(file));
    let invalid = |e: ply_rs_bw::parser::ParseError| err(format!("not a valid PLY file: {e}"));
    let header = Parser::<Skipped>::new()
        .read_header(&mut reader)
        .map_err(invalid)?;
    let scalar = |element: &str, names: &[&str]| {
        header.elements.get(element).is_some_and(|e| {
            names.iter().any(|n| {
                e.properties
                    .get(*n)
                    .is_some_and(|p| matches!(p.data_type, PropertyType::Scalar(_)))
            })
        })
    };
    if !header.elements.contains_key("vertex") {
        return Err(err("no `vertex` element".into()));
    }
    if !header.elements.contains_key("face") {
        return Err(err("no `face` element".into()));
    }
    if !(scalar("vertex", &["x"]) && scalar("vertex", &["y"]) && scalar("vertex", &["z"])) {
        return Err(err("vertices lack x, y or z".into()));
    }
    let (has_normals, has_uvs) = (scalar("vertex", &["nx"]), scalar("vertex", &U));
    // Each element takes at least a byte (a property, or an ASCII line),
    // so no count may pass the file's size: ply-rs pushes elements until
    // the count, and an element whose properties went elsewhere (a name
    // declared twice) reads nothing, forever (found by fuzzing).
    for (name, element) in &header.elements {
        let least: u64 = match header.encoding {
            Encoding::Ascii => 1,
            _ => element
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) | PropertyType::List(t, _) => scalar_bytes(t),
                })
                .sum::<u64>()
                .max(1),
        };
        if (element.count as u64).saturating_mul(least) > bytes {
            return Err(err(format!(
                "element `{name}` declares {} entries, more than the file's {bytes} bytes can hold",
                element.count
            )));
        }
    }
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    // Every element in the header's order, those not read skipped over.
    for (name, element) in &header.elements {
        match name.as_str() {
            "vertex" => {
                vertices = Parser::<Vertex>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(invalid)?;
            }
            "face" => {
                faces = Parser::<Face>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(invalid)?;
            }
            _ => {
                Parser::<Skipped>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(invalid)?;
            }
        }
    }
    let mut mesh = MeshData {
        positions: vertices.iter().map(|v| v.position).collect(),
        normals: has_normals.then(|| vertices.iter().map(|v| v.normal).collect()),
        uvs: has_uvs.then(|| vertices.iter().map(|v| v.uv).collect()),
        indices: Vec::with_capacity(faces.len()),
    };
    drop(vertices);
    for (i, f) in faces.iter().enumerate() {
        let list = match &f.indices {
            Some(Ok(list)) => list,
            Some(Err(())) => return Err(err(format!("face {i} has a negative vertex index"))),
            None => return Err(err(format!("face {i} has no vertex_indices list"))),
        };
        if list.len() < 3 {
            return Err(err(format!("face {i} has {} vertices", list.len())));
        }
        for k in 1..list.len() - 1 {
            mesh.indices.push([list[0], list[k], list[k + 1]]);
        }
    }
    mesh.validate().map_err(err)?;
    Ok(mesh)
}

/// Bytes of a binary scalar (a list's length, at least).
fn scalar_bytes(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The names of the first texture coordinate, and of the second.
const U: [&str; 4] = ["u", "s", "texture_u", "texture_s"];
const V: [&str; 4] = ["v", "t", "texture_v", "texture_t"];

/// A vertex's properties that tracelab reads.
#[derive(Default)]
struct Vertex {
    position: Vec3,
    normal: Vec3,
    uv: Vec2,
}

impl Vertex {
    fn set(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        match name {
            "x" => self.position.x = value,
            "y" => self.position.y = value,
            "z" => self.position.z = value,
            "nx" => self.normal.x = value,
            "ny" => self.normal.y = value,
            "nz" => self.normal.z = value,
            _ if U.contains(&name) => self.uv.x = value,
            _ if V.contains(&name) => self.uv.y = value,
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

/// ply-rs has one setter per PLY type; each `$method` here converts its
/// `$ty` and hands it to the element's own `set`.
macro_rules! forward {
    ($($method:ident($ty:ty) => $convert:expr;)*) => {
        $(fn $method(&mut self, name: &str, value: $ty) -> PropertyAccessResult {
            self.set(name, $convert(value))
        })*
    };
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }
    forward! {
        set_char(i8) => f32::from;
        set_uchar(u8) => f32::from;
        set_short(i16) => f32::from;
        set_ushort(u16) => f32::from;
        set_int(i32) => |v| v as f32;
        set_uint(u32) => |v| v as f32;
        set_float(f32) => |v| v;
        set_double(f64) => |v| v as f32;
    }
}

/// A face's vertex list: None until read, Err for a negative index.
#[derive(Default)]
struct Face {
    indices: Option<std::result::Result<Vec<u32>, ()>>,
}

impl Face {
    fn set<T: Copy + TryInto<u32>>(&mut self, name: &str, list: Vec<T>) -> PropertyAccessResult {
        if !matches!(name, "vertex_indices" | "vertex_index") {
            return PropertyAccessResult::Ignored;
        }
        self.indices = Some(list.iter().map(|&i| i.try_into().map_err(|_| ())).collect());
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face::default()
    }
    forward! {
        set_list_char(Vec<i8>) => |v| v;
        set_list_uchar(Vec<u8>) => |v| v;
        set_list_short(Vec<i16>) => |v| v;
        set_list_ushort(Vec<u16>) => |v| v;
        set_list_int(Vec<i32>) => |v| v;
        set_list_uint(Vec<u32>) => |v| v;
    }
}

/// An element tracelab does not read, consumed and dropped.
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
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
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
