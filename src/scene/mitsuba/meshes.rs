//! The mesh files that shapes name (obj, ply, serialized) and their readers.

use super::props::Props;
use super::xml::{Document, Element};
use crate::error::Result;
use crate::scene::mesh::MeshData;
use std::path::PathBuf;

/// Which reader a mesh file takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum MeshKind {
    /// `flip_tex_coords` (Mitsuba flips v by default).
    Obj {
        flip_uv: bool,
    },
    Ply,
    /// `shape_index`.
    Serialized {
        index: usize,
    },
}

/// A mesh file, parsed into an indexed mesh in its own coordinates.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) struct MeshFile {
    pub path: PathBuf,
    pub kind: MeshKind,
}

impl MeshFile {
    /// The file that shape `e` (its properties `p`) reads; None for a shape
    /// that is not a mesh file.
    pub fn of(e: &Element, p: &Props, doc: &Document) -> Result<Option<MeshFile>> {
        let kind = match e.plugin() {
            "obj" => MeshKind::Obj {
                flip_uv: p.bool("flip_tex_coords")?.unwrap_or(true),
            },
            "ply" => MeshKind::Ply,
            "serialized" => {
                let index = p.int("shape_index")?.unwrap_or(0);
                let index =
                    usize::try_from(index).map_err(|_| e.loc.error("shape_index must be >= 0"))?;
                MeshKind::Serialized { index }
            }
            _ => return Ok(None),
        };
        let file = p.string("filename")?.ok_or_else(|| {
            e.loc
                .error(format!("a {} shape needs `filename`", e.plugin()))
        })?;
        let path = doc.resolve(file, &e.loc)?;
        Ok(Some(MeshFile { path, kind }))
    }

    pub fn read(&self) -> Result<MeshData> {
        match self.kind {
            MeshKind::Obj { flip_uv } => obj_mesh(&self.path, flip_uv),
            MeshKind::Ply => crate::scene::ply::load_ply(&self.path),
            MeshKind::Serialized { index } => {
                crate::scene::serialized::load_serialized(&self.path, index)
            }
        }
    }
}

/// An OBJ file as an indexed mesh (its MTL materials are Mitsuba's to ignore).
fn obj_mesh(path: &std::path::Path, flip_uv: bool) -> Result<MeshData> {
    crate::scene::obj::load_obj_mesh(path, flip_uv)
}
