//! The properties of one plugin element (`<bsdf>`, `<shape>`, ...), read by
//! name and type. Each read marks its child used, so that whatever a scene
//! sets and the importer does not read becomes a warning, never a silence.

use super::spectrum;
use super::xml::{Element, Loc};
use crate::error::Result;
use crate::math::Rgb;
use glam::{DMat4, DVec3, Mat4, Vec3};
use std::cell::Cell;
use std::collections::HashMap;

/// A colour parameter: a value or a texture element.
pub enum Colour<'a> {
    Value(Rgb),
    Texture(&'a Element),
}

/// Read access to one plugin element's properties.
pub struct Props<'a> {
    pub element: &'a Element,
    ids: &'a HashMap<String, &'a Element>,
    used: Vec<Cell<bool>>,
}

impl<'a> Props<'a> {
    pub fn new(element: &'a Element, ids: &'a HashMap<String, &'a Element>) -> Self {
        Props {
            element,
            ids,
            used: element.children.iter().map(|_| Cell::new(false)).collect(),
        }
    }

    pub fn loc(&self) -> &Loc {
        &self.element.loc
    }

    /// The tag of the child named `name` (not marking it used).
    pub fn tag_of(&self, name: &str) -> Option<&'a str> {
        let e: &'a Element = self.element;
        e.children
            .iter()
            .find(|c| c.attr("name") == Some(name))
            .map(|c| c.tag.as_str())
    }

    /// Marks every child used (a plugin replaced as a whole, with a warning).
    pub fn mark_all_used(&self) {
        self.used.iter().for_each(|u| u.set(true));
    }

    /// The child named `name`, marked used.
    fn named(&self, name: &str) -> Option<&'a Element> {
        let i = self
            .element
            .children
            .iter()
            .position(|c| c.attr("name") == Some(name))?;
        self.used[i].set(true);
        Some(&self.element.children[i])
    }

    fn value_of(e: &'a Element) -> Result<&'a str> {
        e.require("value")
    }

    pub fn float(&self, name: &str) -> Result<Option<f32>> {
        let Some(e) = self.named(name) else {
            return Ok(None);
        };
        match e.tag.as_str() {
            "float" | "integer" => parse_f64(Self::value_of(e)?, &e.loc).map(|x| Some(x as f32)),
            // A grey spectrum or colour given where a number is expected (0.6 files do).
            "spectrum" | "rgb" => Ok(Some(crate::math::luminance(spectrum::parse_colour(
                e, false,
            )?))),
            other => Err(e
                .loc
                .error(format!("`{name}` should be a <float>, not <{other}>"))),
        }
    }

    pub fn float_or(&self, name: &str, default: f32) -> Result<f32> {
        Ok(self.float(name)?.unwrap_or(default))
    }

    pub fn int(&self, name: &str) -> Result<Option<i64>> {
        let Some(e) = self.named(name) else {
            return Ok(None);
        };
        let v = Self::value_of(e)?;
        v.trim().parse::<i64>().map(Some).map_err(|_| {
            e.loc
                .error(format!("`{name}` should be an integer, got \"{v}\""))
        })
    }

    pub fn bool(&self, name: &str) -> Result<Option<bool>> {
        let Some(e) = self.named(name) else {
            return Ok(None);
        };
        match Self::value_of(e)?.trim() {
            "true" | "1" => Ok(Some(true)),
            "false" | "0" => Ok(Some(false)),
            v => Err(e
                .loc
                .error(format!("`{name}` should be true or false, got \"{v}\""))),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&'a str>> {
        match self.named(name) {
            None => Ok(None),
            Some(e) => Self::value_of(e).map(Some),
        }
    }

    /// A colour or a texture. `illuminant` spectra are converted as
    /// emission, the others as reflectance.
    pub fn colour(&self, name: &str, illuminant: bool) -> Result<Option<Colour<'a>>> {
        let Some(e) = self.named(name) else {
            return Ok(None);
        };
        Ok(Some(match e.tag.as_str() {
            "texture" => Colour::Texture(e),
            "ref" => Colour::Texture(self.lookup(e)?),
            _ => Colour::Value(spectrum::parse_colour(e, illuminant)?),
        }))
    }

    /// A colour that may not be a texture.
    pub fn rgb(&self, name: &str, illuminant: bool) -> Result<Option<Rgb>> {
        match self.colour(name, illuminant)? {
            None => Ok(None),
            Some(Colour::Value(c)) => Ok(Some(c)),
            Some(Colour::Texture(t)) => {
                Err(t.loc.error(format!("`{name}` cannot be a texture here")))
            }
        }
    }

    pub fn point(&self, name: &str) -> Result<Option<Vec3>> {
        match self.named(name) {
            None => Ok(None),
            Some(e) => vector_of(e).map(|v| Some(v.as_vec3())),
        }
    }

    /// A `<transform>`, composed in Mitsuba's order (each step applied after
    /// the ones above it).
    pub fn transform(&self, name: &str) -> Result<Option<Mat4>> {
        match self.named(name) {
            None => Ok(None),
            Some(e) if e.tag == "transform" => transform(e).map(|m| Some(m.as_mat4())),
            Some(e) => Err(e
                .loc
                .error(format!("`{name}` should be a <transform>, not <{}>", e.tag))),
        }
    }

    /// Every nested `tag` element, named or not (a `bumpmap`'s texture
    /// goes by any name).
    pub fn any_objects(&self, tag: &str) -> Result<Vec<&'a Element>> {
        let mut out = Vec::new();
        for (i, c) in self.element.children.iter().enumerate() {
            let target = match c.tag.as_str() {
                "ref" => self.lookup(c)?,
                _ => c,
            };
            if target.tag == tag {
                self.used[i].set(true);
                out.push(target);
            }
        }
        Ok(out)
    }

    /// The unnamed child plugins with tag `tag` (nested or referenced),
    /// marked used.
    pub fn objects(&self, tag: &str) -> Result<Vec<&'a Element>> {
        let mut out = Vec::new();
        for (i, c) in self.element.children.iter().enumerate() {
            let target = match c.tag.as_str() {
                "ref" => self.lookup(c)?,
                _ => c,
            };
            if target.tag == tag && (c.tag == "ref" || c.attr("name").is_none()) {
                self.used[i].set(true);
                out.push(target);
            }
        }
        Ok(out)
    }

    /// The element a `<ref id="..."/>` names.
    pub fn lookup(&self, r: &Element) -> Result<&'a Element> {
        let id = r.require("id")?;
        self.ids.get(id).copied().ok_or_else(|| {
            r.loc
                .error(format!("<ref id=\"{id}\"/>: nothing has this id"))
        })
    }

    /// Warnings for every child nobody read.
    pub fn unused(&self, warnings: &mut Vec<String>) {
        let what = format!("{} `{}`", self.element.tag, self.element.plugin());
        for (c, used) in self.element.children.iter().zip(&self.used) {
            if used.get() {
                continue;
            }
            let description = match (c.attr("name"), c.tag.as_str()) {
                (Some(n), _) => format!("property `{n}`"),
                (None, "ref") => format!("reference to `{}`", c.attr("id").unwrap_or("?")),
                (None, t) => format!("<{t} type=\"{}\">", c.plugin()),
            };
            warnings.push(format!("{}: {what}: {description} ignored", c.loc));
        }
    }
}

pub fn parse_f64(s: &str, loc: &Loc) -> Result<f64> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| loc.error(format!("\"{s}\" is not a number")))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(loc.error(format!("\"{s}\" is not finite")))
    }
}

/// Numbers separated by commas and/or white space.
pub fn parse_list(s: &str, loc: &Loc) -> Result<Vec<f64>> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| parse_f64(t, loc))
        .collect()
}

/// `x`, `y`, `z` attributes (missing ones 0), or `value="x, y, z"`.
fn vector_of(e: &Element) -> Result<DVec3> {
    if let Some(v) = e.attr("value") {
        let list = parse_list(v, &e.loc)?;
        return match list[..] {
            [x] => Ok(DVec3::splat(x)),
            [x, y, z] => Ok(DVec3::new(x, y, z)),
            _ => Err(e.loc.error(format!("expected 1 or 3 numbers, got \"{v}\""))),
        };
    }
    let coordinate = |n: &str| match e.attr(n) {
        Some(s) => parse_f64(s, &e.loc),
        None => Ok(0.0),
    };
    Ok(DVec3::new(
        coordinate("x")?,
        coordinate("y")?,
        coordinate("z")?,
    ))
}

/// The matrix of a `<transform>` element.
pub fn transform(e: &Element) -> Result<DMat4> {
    let mut m = DMat4::IDENTITY;
    for step in &e.children {
        let s = match step.tag.as_str() {
            "translate" => DMat4::from_translation(vector_of(step)?),
            "scale" => {
                // Missing axes of a scale stay 1.
                let v = match step.attr("value") {
                    Some(_) => vector_of(step)?,
                    None => {
                        let axis = |n: &str| match step.attr(n) {
                            Some(s) => parse_f64(s, &step.loc),
                            None => Ok(1.0),
                        };
                        DVec3::new(axis("x")?, axis("y")?, axis("z")?)
                    }
                };
                DMat4::from_scale(v)
            }
            "rotate" => {
                let axis = vector_of(step)?;
                let angle = parse_f64(step.require("angle")?, &step.loc)?;
                if axis.length_squared() == 0.0 {
                    return Err(step.loc.error("rotation about a zero axis"));
                }
                DMat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = parse_list(step.require("value")?, &step.loc)?;
                match v.len() {
                    // Row-major in the file; glam is column-major.
                    16 => DMat4::from_cols_array(&v.try_into().unwrap()).transpose(),
                    9 => {
                        let r: [f64; 9] = v.try_into().unwrap();
                        DMat4::from_mat3(glam::DMat3::from_cols_array(&r).transpose())
                    }
                    n => {
                        return Err(step
                            .loc
                            .error(format!("a <matrix> has 9 or 16 numbers, not {n}")));
                    }
                }
            }
            "lookat" => {
                let get = |n: &str| -> Result<DVec3> {
                    let list = parse_list(step.require(n)?, &step.loc)?;
                    match list[..] {
                        [x, y, z] => Ok(DVec3::new(x, y, z)),
                        _ => Err(step.loc.error(format!("`{n}` needs three numbers"))),
                    }
                };
                let origin = get("origin")?;
                let target = get("target")?;
                let up = match step.attr("up") {
                    Some(_) => get("up")?,
                    None => DVec3::Y,
                };
                let dir = (target - origin).normalize_or_zero();
                let left = up.normalize_or_zero().cross(dir).normalize_or_zero();
                if dir == DVec3::ZERO || left == DVec3::ZERO {
                    return Err(step.loc.error(
                        "lookat: `origin` equals `target`, or `up` is parallel to the view",
                    ));
                }
                let new_up = dir.cross(left);
                DMat4::from_cols(
                    left.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    origin.extend(1.0),
                )
            }
            other => {
                return Err(step.loc.error(format!("<{other}> is not a transform step")));
            }
        };
        m = s * m;
    }
    if !m.is_finite() {
        return Err(e.loc.error("the transform is not finite"));
    }
    Ok(m)
}
