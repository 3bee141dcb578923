//! The bitmaps and mesh files a scene names, decoded on every core before
//! the importer walks the scene in file order: the dozen JPEGs and the
//! hundreds of OBJ files of Bitterli's interiors were most of their load
//! time on one thread. A file that fails here is left out and read again
//! in order, where its error gets the element's file:line:column. A mesh
//! is handed over once and dropped from here, so that the meshes waiting
//! and the triangles made from them add up to about one copy of the scene
//! (docs/performance.md, "Loading").

use super::meshes::MeshFile;
use super::props::Props;
use super::xml::{Document, Element};
use crate::scene::appearance::build_material;
use crate::scene::description::MaterialDesc;
use crate::scene::mesh::MeshData;
use crate::texture::Bitmap;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A bitmap file and whether it is read `raw`.
type Key = (PathBuf, bool);

/// A file to decode.
#[derive(PartialEq, Eq, PartialOrd, Ord)]
enum Job {
    /// A bitmap, and whether a texture reads it (materials ask for its mean).
    Bitmap(Key, bool),
    Mesh(MeshFile),
}

impl Job {
    /// About how long decoding takes, in the bytes of an OBJ file that
    /// parse as fast (measured on the kitchen: a pixel of a JPEG took about
    /// as long as 3 bytes of OBJ text; 4 allows for float images).
    fn cost(&self) -> u64 {
        let bytes = |path: &Path| std::fs::metadata(path).map_or(0, |m| m.len());
        match self {
            Job::Bitmap((path, _), _) => image::image_dimensions(path)
                .map_or_else(|_| bytes(path), |(w, h)| 4 * u64::from(w) * u64::from(h)),
            Job::Mesh(file) => bytes(&file.path),
        }
    }
}

/// A file to decode, or a coating whose tables to make.
enum Task {
    File(Job),
    Coating(MaterialDesc),
}

/// Bitmaps and meshes decoded ahead.
#[derive(Default)]
pub(super) struct Prefetched {
    /// Shared by every texture that names them.
    bitmaps: HashMap<Key, Arc<Bitmap>>,
    /// Taken by the first shape that names them.
    meshes: HashMap<MeshFile, MeshData>,
}

impl Prefetched {
    /// Decodes, in parallel, every bitmap file that an element of `doc`
    /// names (textures and environment maps) and every mesh file, meshes
    /// until they hold `max_triangles` (the walk reads the rest, and stops
    /// at the limit with the shape's place).
    pub(super) fn new(
        doc: &Document,
        ids: &HashMap<String, &Element>,
        max_triangles: usize,
    ) -> Prefetched {
        let (mut jobs, mut coatings) = (Vec::new(), Vec::new());
        collect(&doc.root, doc, ids, &mut jobs, &mut coatings);
        jobs.sort();
        // One job per file; a bitmap read both as a texture and as an
        // environment is a texture (sorted after, `true` > `false`).
        jobs.dedup_by(|later, kept| match (later, kept) {
            (Job::Bitmap(a, texture), Job::Bitmap(b, kept_texture)) if a == b => {
                *kept_texture |= *texture;
                true
            }
            (later, kept) => later == kept,
        });
        // Longest first, taken in that order by whichever core is free, so
        // that no core is left with a long job at the end. An image's
        // decoding costs by its pixels, not its compressed bytes: a 760 KB
        // progressive JPEG of the kitchen took as long as a 5 MB OBJ file,
        // and, sorted by bytes among them, was its load's last job.
        let mut jobs: Vec<(u64, Job)> = jobs.into_iter().map(|job| (job.cost(), job)).collect();
        jobs.sort_by_key(|&(cost, _)| std::cmp::Reverse(cost));
        let same = |a: &MaterialDesc, b: &MaterialDesc| {
            (a.distribution, a.alpha) == (b.distribution, b.alpha)
                && (&a.int_ior, &a.ext_ior) == (&b.int_ior, &b.ext_ior)
        };
        let mut distinct: Vec<MaterialDesc> = Vec::new();
        for c in coatings {
            if !distinct.iter().any(|d| same(d, &c)) {
                distinct.push(c);
            }
        }
        // A coating's tables took about as long as a megabyte of OBJ text.
        let later = jobs.split_off(jobs.partition_point(|&(cost, _)| cost > 1 << 20));
        let file = |(_, job): (u64, Job)| Task::File(job);
        let tasks = (jobs.into_iter().map(file))
            .chain(distinct.into_iter().map(Task::Coating))
            .chain(later.into_iter().map(file));
        let triangles = AtomicUsize::new(0);
        let decoded: Vec<Decoded> = tasks
            .par_bridge()
            .filter_map(|task| match task {
                Task::Coating(desc) => {
                    // Made once per process; the walk's material finds them.
                    let _ = build_material("coating", &desc);
                    None
                }
                Task::File(job) => match job {
                    Job::Bitmap(key, texture) => {
                        let bitmap = Bitmap::read(&key.0, key.1).ok()?;
                        if texture {
                            // Materials read it in the walk, on one thread.
                            bitmap.mean();
                        }
                        Some(Decoded::Bitmap(key, Arc::new(bitmap)))
                    }
                    Job::Mesh(file) => {
                        if triangles.load(Ordering::Relaxed) > max_triangles {
                            return None;
                        }
                        let mesh = file.read().ok()?;
                        triangles.fetch_add(mesh.indices.len(), Ordering::Relaxed);
                        Some(Decoded::Mesh(file, mesh))
                    }
                },
            })
            .collect();
        let mut prefetched = Prefetched::default();
        for d in decoded {
            match d {
                Decoded::Bitmap(key, bitmap) => {
                    prefetched.bitmaps.insert(key, bitmap);
                }
                Decoded::Mesh(file, mesh) => {
                    prefetched.meshes.insert(file, mesh);
                }
            }
        }
        prefetched
    }

    /// The bitmap of `path` read with `raw`, if it was decoded.
    pub(super) fn bitmap(&self, path: &Path, raw: bool) -> Option<Arc<Bitmap>> {
        self.bitmaps.get(&(path.to_path_buf(), raw)).cloned()
    }

    /// Triangles in the meshes decoded (each counted once).
    pub(super) fn triangle_count(&self) -> usize {
        self.meshes.values().map(|m| m.indices.len()).sum()
    }

    /// The mesh of `file`, if it was decoded and not yet taken.
    pub(super) fn mesh(&mut self, file: &MeshFile) -> Option<MeshData> {
        self.meshes.remove(file)
    }
}

enum Decoded {
    Bitmap(Key, Arc<Bitmap>),
    Mesh(MeshFile, MeshData),
}

/// The files that `e` and the elements inside it name.
fn collect(
    e: &Element,
    doc: &Document,
    ids: &HashMap<String, &Element>,
    jobs: &mut Vec<Job>,
    coatings: &mut Vec<MaterialDesc>,
) {
    for c in &e.children {
        match (c.tag.as_str(), c.plugin()) {
            ("texture", "bitmap") | ("emitter", "envmap") => {
                let p = Props::new(c, ids);
                let path = p
                    .string("filename")
                    .ok()
                    .flatten()
                    .and_then(|name| doc.resolve(name, &c.loc).ok());
                if let Some(path) = path {
                    let raw = c.tag == "texture" && p.bool("raw").ok().flatten().unwrap_or(false);
                    jobs.push(Job::Bitmap((path, raw), c.tag == "texture"));
                }
            }
            ("bsdf", "roughplastic") => {
                if let Some(desc) = super::bsdfs::coating(c, ids) {
                    coatings.push(desc);
                }
            }
            ("shape", _) => {
                if let Ok(Some(file)) = MeshFile::of(c, &Props::new(c, ids), doc) {
                    jobs.push(Job::Mesh(file));
                }
            }
            _ => {}
        }
        collect(c, doc, ids, jobs, coatings);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::rough_plastic::coating_tables_made;
    use crate::bsdf::{Distribution, Microfacet};

    /// A rough plastic's tables are made while files decode, for the values
    /// the walk will read (Mitsuba 0.6 names here); the α and η are this
    /// test's own, so no other test can have made them first.
    #[test]
    fn a_rough_plastics_coating_is_made_ahead() {
        let dir = std::env::temp_dir().join(format!("tracelab_coating_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.xml");
        std::fs::write(
            &path,
            r#"<scene version="0.6.0">
                <bsdf type="twosided" id="a"><bsdf type="roughplastic">
                    <string name="distribution" value="ggx"/>
                    <float name="alpha" value="0.0371"/>
                    <float name="intIOR" value="1.317"/>
                </bsdf></bsdf>
                <bsdf type="roughplastic" id="b"><float name="alpha" value="0.0373"/>
                    <texture name="alpha_u" type="checkerboard"/></bsdf>
            </scene>"#,
        )
        .unwrap();
        let doc = super::super::xml::read(&path, &[]).unwrap();
        let mut ids = HashMap::new();
        super::super::collect_ids(&doc.root, &mut ids).unwrap();
        let ggx = Microfacet::new(Distribution::Ggx, 0.0371, 0.0371);
        let eta = 1.317f32 / 1.000277;
        let beckmann = Microfacet::new(Distribution::Beckmann, 0.0373, 0.0373);
        assert!(!coating_tables_made(ggx, eta));
        let _ = Prefetched::new(&doc, &ids, usize::MAX);
        assert!(coating_tables_made(ggx, eta));
        // An α given by a texture is the walk's to read.
        assert!(!coating_tables_made(beckmann, 1.49 / 1.000277));
        std::fs::remove_dir_all(&dir).ok();
    }
}
