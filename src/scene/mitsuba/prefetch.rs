//! The bitmaps a scene names, decoded on every core before the importer
//! walks the scene in file order: a dozen JPEGs were a quarter of the load
//! time of Bitterli's interiors on one thread. A file that fails here is
//! left out and read again in order, where its error gets the element's
//! file:line:column. Meshes are read in order: decoding them ahead too
//! holds every mesh at once beside the triangles made from them
//! (docs/performance.md, "Loading").

use super::props::Props;
use super::xml::{Document, Element};
use crate::texture::Bitmap;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A bitmap file and whether it is read `raw`.
type Key = (PathBuf, bool);

/// Bitmaps decoded ahead, shared by every texture that names them.
#[derive(Default)]
pub(super) struct Prefetched {
    bitmaps: HashMap<Key, Arc<Bitmap>>,
}

impl Prefetched {
    /// Decodes, in parallel, every bitmap file that an element of `doc`
    /// names (textures and environment maps).
    pub(super) fn new(doc: &Document, ids: &HashMap<String, &Element>) -> Prefetched {
        let mut keys = Vec::new();
        collect(&doc.root, doc, ids, &mut keys);
        keys.sort();
        keys.dedup();
        let bitmaps = keys
            .into_par_iter()
            .filter_map(|key| {
                let bitmap = Bitmap::read(&key.0, key.1).ok()?;
                Some((key, Arc::new(bitmap)))
            })
            .collect();
        Prefetched { bitmaps }
    }

    /// The bitmap of `path` read with `raw`, if it was decoded.
    pub(super) fn bitmap(&self, path: &Path, raw: bool) -> Option<Arc<Bitmap>> {
        self.bitmaps.get(&(path.to_path_buf(), raw)).cloned()
    }
}

/// The bitmaps that `e` and the elements inside it name.
fn collect(e: &Element, doc: &Document, ids: &HashMap<String, &Element>, keys: &mut Vec<Key>) {
    for c in &e.children {
        let bitmap = matches!(
            (c.tag.as_str(), c.plugin()),
            ("texture", "bitmap") | ("emitter", "envmap")
        );
        if bitmap {
            let p = Props::new(c, ids);
            let path = p
                .string("filename")
                .ok()
                .flatten()
                .and_then(|name| doc.resolve(name, &c.loc).ok());
            if let Some(path) = path {
                let raw = c.tag == "texture" && p.bool("raw").ok().flatten().unwrap_or(false);
                keys.push((path, raw));
            }
        }
        collect(c, doc, ids, keys);
    }
}
