//! Mitsuba's XML as an owned tree: `<include>` spliced in, `<default>` and
//! `$name` substituted, Mitsuba 0.5/0.6 camelCase names rewritten to
//! Mitsuba 3's snake_case, and every element located by file, line and column.

use crate::error::{Error, Result};
use std::collections::{HashMap, HashSet};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where an element starts.
#[derive(Clone, Debug)]
pub struct Loc {
    pub file: Arc<Path>,
    pub line: u32,
    pub col: u32,
}

impl Loc {
    /// An error at this place.
    pub fn error(&self, message: impl fmt::Display) -> Error {
        Error::new(format!("{self}: {message}"))
    }
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file.display(), self.line, self.col)
    }
}

/// One XML element, attributes already substituted.
#[derive(Clone, Debug)]
pub struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub loc: Loc,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// An attribute that must be there.
    pub fn require(&self, name: &str) -> Result<&str> {
        self.attr(name).ok_or_else(|| {
            self.loc
                .error(format!("<{}> needs the attribute `{name}`", self.tag))
        })
    }

    /// The plugin type (`type="..."`), or "" where there is none.
    pub fn plugin(&self) -> &str {
        self.attr("type").unwrap_or("")
    }
}

/// A scene file read with everything it includes.
pub struct Document {
    pub root: Element,
    /// Folders searched for referenced files, the scene's own first.
    pub search_paths: Vec<PathBuf>,
    /// Major version of the file's format (0 for Mitsuba 0.x, 3 for Mitsuba 3).
    pub major_version: u32,
    /// Names given by `-D` that no `$name` of the file (or its includes)
    /// reads, in the order given.
    pub unused_defines: Vec<String>,
}

impl Document {
    /// Resolves a file name the way Mitsuba does: as given, then relative
    /// to the scene's folder and each `<path>`.
    pub fn resolve(&self, name: &str, at: &Loc) -> Result<PathBuf> {
        let given = Path::new(name);
        if given.is_absolute() {
            return given
                .is_file()
                .then(|| given.to_path_buf())
                .ok_or_else(|| at.error(format!("file `{name}` not found")));
        }
        for dir in &self.search_paths {
            let candidate = dir.join(given);
            if candidate.is_file() {
                return Ok(candidate);
            }
        }
        Err(at.error(format!(
            "file `{name}` not found (looked in {})",
            self.search_paths
                .iter()
                // The scene's folder is empty when it was named without one.
                .map(|p| {
                    if p.as_os_str().is_empty() {
                        ".".to_string()
                    } else {
                        p.display().to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join(", ")
        )))
    }
}

/// Includes deeper than this are taken for a cycle.
const MAX_INCLUDE_DEPTH: usize = 32;

/// Reads `path` with `defines` (`-D name=value`, which win over the file's
/// `<default>`s).
pub fn read(path: &Path, defines: &[(String, String)]) -> Result<Document> {
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut reader = Reader {
        params: defines.iter().cloned().collect(),
        read: HashSet::new(),
        search_paths: vec![dir],
        major_version: 3,
        depth: 0,
    };
    let root = reader.read_file(path, None)?;
    let mut unused_defines: Vec<String> = Vec::new();
    for (name, _) in defines {
        if !reader.read.contains(name) && !unused_defines.contains(name) {
            unused_defines.push(name.clone());
        }
    }
    Ok(Document {
        root,
        search_paths: reader.search_paths,
        major_version: reader.major_version,
        unused_defines,
    })
}

struct Reader {
    params: HashMap<String, String>,
    /// Every `$name` substituted so far.
    read: HashSet<String>,
    search_paths: Vec<PathBuf>,
    major_version: u32,
    depth: usize,
}

impl Reader {
    fn read_file(&mut self, path: &Path, included_at: Option<&Loc>) -> Result<Element> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            let msg = format!("cannot read `{}`: {e}", path.display());
            match included_at {
                Some(loc) => loc.error(msg),
                None => Error::new(msg),
            }
        })?;
        let file: Arc<Path> = Arc::from(path);
        let doc = roxmltree::Document::parse(&text).map_err(|e| {
            let p = e.pos();
            Error::new(format!("{}:{}:{}: {e}", path.display(), p.row, p.col))
        })?;
        let root = doc.root_element();
        let loc_of = |node: roxmltree::Node| {
            let p = doc.text_pos_at(node.range().start);
            Loc {
                file: file.clone(),
                line: p.row,
                col: p.col,
            }
        };
        if root.tag_name().name() != "scene" {
            return Err(loc_of(root).error(format!(
                "the root element is <{}>, not <scene>: is this a Mitsuba scene?",
                root.tag_name().name()
            )));
        }
        if included_at.is_none() {
            self.major_version = match root.attribute("version") {
                Some(v) => v
                    .split('.')
                    .next()
                    .and_then(|m| m.trim().parse().ok())
                    .ok_or_else(|| loc_of(root).error(format!("bad version \"{v}\"")))?,
                None => {
                    return Err(loc_of(root).error(
                        "<scene> needs a `version` (\"3.0.0\" for Mitsuba 3, \"0.6.0\" for 0.6)",
                    ));
                }
            };
        }
        // `<default>`s first: they apply to the whole file, wherever they are.
        for node in root.children().filter(|n| n.has_tag_name("default")) {
            let (Some(name), Some(value)) = (node.attribute("name"), node.attribute("value"))
            else {
                return Err(loc_of(node).error("<default> needs `name` and `value`"));
            };
            self.params
                .entry(name.to_string())
                .or_insert_with(|| value.to_string());
        }
        let mut out = Element {
            tag: "scene".into(),
            attrs: Vec::new(),
            children: Vec::new(),
            loc: loc_of(root),
        };
        for node in root.children().filter(|n| n.is_element()) {
            self.convert_into(node, &loc_of, &mut out.children)?;
        }
        Ok(out)
    }

    fn convert_into(
        &mut self,
        node: roxmltree::Node,
        loc_of: &dyn Fn(roxmltree::Node) -> Loc,
        out: &mut Vec<Element>,
    ) -> Result<()> {
        let loc = loc_of(node);
        let tag = node.tag_name().name();
        let mut attrs = Vec::new();
        for a in node.attributes() {
            let value = substitute(a.value(), &self.params, &mut self.read, &loc)?;
            let value = match (a.name(), self.major_version) {
                ("name", 0..=2) => camel_to_snake(&value),
                _ => value,
            };
            attrs.push((a.name().to_string(), value));
        }
        // Mitsuba 0.x's schema takes the look-at step in both spellings
        // (its own veach_mi scene says `<lookAt>`).
        let tag = match (tag, self.major_version) {
            ("lookAt", 0..=2) => "lookat",
            _ => tag,
        };
        let element = Element {
            tag: tag.to_string(),
            attrs,
            children: Vec::new(),
            loc,
        };
        match tag {
            "default" => return Ok(()),
            "include" => {
                if self.depth >= MAX_INCLUDE_DEPTH {
                    return Err(element.loc.error("includes nest too deeply (a cycle?)"));
                }
                let name = element.require("filename")?;
                let path = self
                    .search_paths
                    .iter()
                    .map(|d| d.join(name))
                    .find(|p| p.is_file())
                    .ok_or_else(|| {
                        element
                            .loc
                            .error(format!("included file `{name}` not found"))
                    })?;
                self.depth += 1;
                let included = self.read_file(&path, Some(&element.loc))?;
                self.depth -= 1;
                out.extend(included.children);
                return Ok(());
            }
            "path" => {
                let value = element.require("value")?;
                let base = element
                    .loc
                    .file
                    .parent()
                    .map(Path::to_path_buf)
                    .unwrap_or_default();
                self.search_paths.push(base.join(value));
                return Ok(());
            }
            _ => {}
        }
        let mut element = element;
        for child in node.children().filter(|n| n.is_element()) {
            self.convert_into(child, loc_of, &mut element.children)?;
        }
        out.push(element);
        Ok(())
    }
}

/// Replaces `$name` by its value; an unknown name is an error, as in Mitsuba.
fn substitute(
    value: &str,
    params: &HashMap<String, String>,
    read: &mut HashSet<String>,
    loc: &Loc,
) -> Result<String> {
    if !value.contains('$') {
        return Ok(value.to_string());
    }
    let mut out = String::with_capacity(value.len());
    let mut rest = value;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        let len = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        let name = &after[..len];
        match params.get(name) {
            Some(v) if !name.is_empty() => {
                if !read.contains(name) {
                    read.insert(name.to_string());
                }
                out.push_str(v);
            }
            _ => {
                return Err(loc.error(format!(
                    "`${name}` is not defined (add <default name=\"{name}\" value=\"...\"/> or -D {name}=...)"
                )));
            }
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Mitsuba 0.x names to Mitsuba 3's: `toWorld` → `to_world`, `intIOR` → `int_ior`.
pub fn camel_to_snake(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut previous_lower = false;
    for c in name.chars() {
        if c.is_ascii_uppercase() && previous_lower {
            out.push('_');
        }
        previous_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        out.push(c.to_ascii_lowercase());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_names_become_snake_case() {
        assert_eq!(camel_to_snake("toWorld"), "to_world");
        assert_eq!(camel_to_snake("intIOR"), "int_ior");
        assert_eq!(
            camel_to_snake("specularReflectance"),
            "specular_reflectance"
        );
        assert_eq!(camel_to_snake("alphaU"), "alpha_u");
        assert_eq!(camel_to_snake("max_depth"), "max_depth");
    }

    fn loc(file: &str, line: u32, col: u32) -> Loc {
        Loc {
            file: Arc::from(Path::new(file)),
            line,
            col,
        }
    }

    #[test]
    fn a_missing_file_names_the_folders_searched() {
        let loc = loc("scene.xml", 2, 1);
        // `tracelab render scene.xml` from the scene's folder: its folder is "".
        let document = Document {
            root: Element {
                tag: "scene".into(),
                attrs: Vec::new(),
                children: Vec::new(),
                loc: loc.clone(),
            },
            search_paths: vec![PathBuf::new(), PathBuf::from("textures")],
            major_version: 0,
            unused_defines: Vec::new(),
        };
        let e = document.resolve("none.jpg", &loc).unwrap_err().to_string();
        assert!(e.ends_with("(looked in ., textures)"), "{e}");
    }

    #[test]
    fn parameters_substitute_and_unknown_ones_are_errors() {
        let loc = loc("s.xml", 3, 5);
        let params: HashMap<String, String> = [("spp".to_string(), "64".to_string())].into();
        assert_eq!(
            substitute("$spp", &params, &mut HashSet::new(), &loc).unwrap(),
            "64"
        );
        assert_eq!(
            substitute("a$spp.b", &params, &mut HashSet::new(), &loc).unwrap(),
            "a64.b"
        );
        let e = substitute("$res", &params, &mut HashSet::new(), &loc).unwrap_err();
        assert!(
            e.message().starts_with("s.xml:3:5: `$res` is not defined"),
            "{e}"
        );
    }
}
