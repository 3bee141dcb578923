//! Mitsuba's `serialized` meshes: a file of zlib-compressed shapes, with a
//! table of their offsets at the end (format versions 3 and 4).

use super::mesh::MeshData;
use crate::error::{Error, Result};
use flate2::read::ZlibDecoder;
use glam::{Vec2, Vec3};
use std::io::Read;
use std::path::Path;

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLOURS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Reads shape `index` of a serialized file.
pub fn load_serialized(path: &Path, index: usize) -> Result<MeshData> {
    let err = |m: String| Error::at(path, None, m);
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read: {e}")))?;
    let short = || err("the file ends early".into());
    // The table at the end: one offset per shape, then the count (u32).
    let count_at = bytes.len().checked_sub(4).ok_or_else(short)?;
    let count = u32::from_le_bytes(bytes[count_at..].try_into().unwrap()) as usize;
    if index >= count {
        return Err(err(format!(
            "shape_index {index}, but the file holds {count} shape(s)"
        )));
    }
    let version = u16::from_le_bytes(bytes.get(2..4).ok_or_else(short)?.try_into().unwrap());
    let offset = if version >= 4 {
        let at = count_at
            .checked_sub(8 * (count - index))
            .ok_or_else(short)?;
        u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize
    } else {
        let at = count_at
            .checked_sub(4 * (count - index))
            .ok_or_else(short)?;
        u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize
    };
    let head = bytes.get(offset..offset + 4).ok_or_else(short)?;
    if u16::from_le_bytes([head[0], head[1]]) != MAGIC {
        return Err(err(format!("shape {index}: not a Mitsuba serialized mesh")));
    }
    let mut data = Vec::new();
    ZlibDecoder::new(&bytes[offset + 4..])
        .read_to_end(&mut data)
        .map_err(|e| err(format!("shape {index}: bad compressed data: {e}")))?;
    parse_shape(&data, version).map_err(|m| err(format!("shape {index}: {m}")))
}

struct Cursor<'a> {
    data: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> std::result::Result<&[u8], String> {
        let s = self
            .data
            .get(self.at..self.at + n)
            .ok_or("the shape's data ends early")?;
        self.at += n;
        Ok(s)
    }
    fn u32(&mut self) -> std::result::Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn u64(&mut self) -> std::result::Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    fn reals(&mut self, n: usize, double: bool) -> std::result::Result<Vec<f32>, String> {
        let size = if double { 8 } else { 4 };
        let raw = self.take(n.checked_mul(size).ok_or("size overflows")?)?;
        Ok(raw
            .chunks_exact(size)
            .map(|c| match double {
                true => f64::from_le_bytes(c.try_into().unwrap()) as f32,
                false => f32::from_le_bytes(c.try_into().unwrap()),
            })
            .collect())
    }
}

fn parse_shape(data: &[u8], version: u16) -> std::result::Result<MeshData, String> {
    let mut c = Cursor { data, at: 0 };
    let flags = c.u32()?;
    if version >= 4 {
        // The shape's name, null-terminated.
        while c.take(1)?[0] != 0 {}
    }
    let vertices = c.u64()? as usize;
    let triangles = c.u64()? as usize;
    // Each vertex needs at least 12 bytes: a count beyond the data is a lie.
    if vertices.saturating_mul(12) > data.len() || triangles.saturating_mul(12) > data.len() {
        return Err(format!(
            "{vertices} vertices and {triangles} triangles do not fit the data"
        ));
    }
    let double = flags & DOUBLE_PRECISION != 0;
    let vec3s = |v: Vec<f32>| v.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
    let mut mesh = MeshData {
        positions: vec3s(c.reals(3 * vertices, double)?),
        ..Default::default()
    };
    if flags & HAS_NORMALS != 0 {
        mesh.normals = Some(vec3s(c.reals(3 * vertices, double)?));
    }
    if flags & HAS_UVS != 0 {
        let uv = c.reals(2 * vertices, double)?;
        mesh.uvs = Some(uv.chunks_exact(2).map(Vec2::from_slice).collect());
    }
    if flags & HAS_COLOURS != 0 {
        c.reals(3 * vertices, double)?;
    }
    let wide = vertices > u32::MAX as usize;
    for _ in 0..triangles {
        let mut t = [0u32; 3];
        for i in &mut t {
            *i = if wide { c.u64()? as u32 } else { c.u32()? };
        }
        mesh.indices.push(t);
    }
    mesh.validate()?;
    Ok(mesh)
}
