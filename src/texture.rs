//! Textures (Mitsuba's `bitmap` and `checkerboard`): evaluated at a hit's
//! texture coordinates into the parameter of a material. A scene holds
//! each texture once; materials refer to it by index, so textures are
//! shared and a bitmap is decoded once.

use crate::math::Rgb;
use glam::Vec2;
use half::f16;
use std::path::Path;
use std::sync::Arc;

mod pfm;
pub use pfm::read_pfm;

/// How coordinates outside [0, 1) map into a bitmap (Mitsuba's `wrap_mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

/// How a bitmap is read between texel centres (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Nearest,
    Bilinear,
}

/// RGB texels, row 0 at the top of the image file: v = 0 reads the top
/// row, as Mitsuba's bitmap (OBJ files' v, which counts from the bottom,
/// is flipped at load, as Mitsuba does).
#[derive(Debug)]
pub struct Bitmap {
    pub width: usize,
    pub height: usize,
    texels: Texels,
    /// The mean texel, computed once (materials ask for it; the importer
    /// computes it on the thread that decoded the image).
    mean: std::sync::OnceLock<Rgb>,
}

/// How texels are kept. 8-bit images stay 8-bit, 3 bytes a texel, and are
/// decoded through a table of 256 values when read (pbrt-v4 keeps them
/// so too): a 4096² JPEG takes 48 MiB instead of 256 MiB as linear floats,
/// and loading it costs no per-texel transfer function.
#[derive(Debug)]
enum Texels {
    /// Three bytes per texel and what each byte value means (sRGB-decoded
    /// colour, or raw data divided by 255).
    Bytes {
        bytes: Vec<u8>,
        decode: Box<[f32; 256]>,
    },
    /// Linear values (float and 16-bit images).
    Floats(Vec<[f32; 3]>),
    /// Linear values that half floats hold exactly (OpenEXR's usual
    /// format), in half the memory: a 2048 × 1024 sky takes 12.6 MB, not
    /// 25.2.
    Halves(Vec<[f16; 3]>),
}

/// Side of the square tiles texels are stored in. A bilinear lookup reads
/// two rows; stored row-major, a wide image's rows lie kilobytes apart and
/// each lookup missed the cache twice (28% of BDPT's time on a glTF
/// asset's 2048² textures); an 8 × 8 tile of bytes is three cache lines
/// (docs/performance.md, "Bidirectional techniques"). Float images are
/// kept row-major ([`Bitmap::new`]).
const TILE: usize = 8;

/// `bytes` (three a texel, `width` × `height` texels, row-major from the
/// top row) in tiles of [`TILE`] × [`TILE`], the partial tiles at the
/// right and bottom edges padded.
fn tiled(bytes: &[u8], width: usize, height: usize) -> Vec<u8> {
    let (across, down) = (width.div_ceil(TILE), height.div_ceil(TILE));
    let mut out = vec![0; 3 * across * down * TILE * TILE];
    for y in 0..height {
        for tile_x in 0..across {
            let (x0, x1) = (tile_x * TILE, (tile_x * TILE + TILE).min(width));
            let to = ((y / TILE) * across + tile_x) * (TILE * TILE) + (y % TILE) * TILE;
            let from = y * width + x0;
            out[3 * to..3 * (to + x1 - x0)].copy_from_slice(&bytes[3 * from..3 * (from + x1 - x0)]);
        }
    }
    out
}

/// The affine map from a surface's texture coordinates to the texture's:
/// uv · scale + offset (Mitsuba's `to_uv` with a scale and a translation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub scale: Vec2,
    pub offset: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        UvTransform {
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        }
    }
}

/// A texture.
#[derive(Clone, Debug)]
pub enum Texture {
    Bitmap {
        image: Arc<Bitmap>,
        wrap: Wrap,
        filter: Filter,
        to_uv: UvTransform,
    },
    /// color0 where the fractional parts of u and v are on the same side
    /// of 1/2, else color1 (Mitsuba's checkerboard).
    Checkerboard {
        color0: Rgb,
        color1: Rgb,
        to_uv: UvTransform,
    },
}

/// True where a checkerboard shows its first colour (`eval`): the
/// fractional parts of u and v on the same side of 1/2.
#[inline]
fn first_square(uv: Vec2, to_uv: &UvTransform) -> bool {
    let uv = uv * to_uv.scale + to_uv.offset;
    (uv.x - uv.x.floor() > 0.5) == (uv.y - uv.y.floor() > 0.5)
}

impl Texture {
    /// The texture's value at surface coordinates `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        match self {
            Texture::Bitmap {
                image,
                wrap,
                filter,
                to_uv,
            } => image.lookup(uv * to_uv.scale + to_uv.offset, *wrap, *filter),
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                if first_square(uv, to_uv) {
                    *color0
                } else {
                    *color1
                }
            }
        }
    }

    /// Asks the cache for the texels [`Texture::eval`] reads at `uv`.
    #[inline(always)]
    pub fn prefetch(&self, uv: Vec2) {
        if let Texture::Bitmap {
            image,
            wrap,
            filter,
            to_uv,
        } = self
        {
            image.prefetch_lookup(uv * to_uv.scale + to_uv.offset, *wrap, *filter);
        }
    }

    /// One value at `uv`, as Mitsuba's `eval_1` reads it for a roughness or
    /// an opacity: the luminance; a checkerboard's squares swapped, as
    /// Mitsuba 3 (3.9.1) gives color1 from `eval_1` where `eval` gives
    /// color0 (its own textured-roughness preview is rendered so).
    #[inline]
    pub fn eval_1(&self, uv: Vec2) -> f32 {
        let value = match self {
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                if first_square(uv, to_uv) {
                    *color1
                } else {
                    *color0
                }
            }
            _ => self.eval(uv),
        };
        crate::math::luminance(value)
    }

    /// The texture's luminance at `uv` and its gradient in uv (Mitsuba's
    /// `eval_1_grad`: the bilinear interpolant's derivatives; zero for
    /// nearest filtering and the checkerboard, which are flat between
    /// their steps).
    #[inline]
    pub fn eval_gradient(&self, uv: Vec2) -> Vec2 {
        let Texture::Bitmap {
            image,
            wrap,
            filter: Filter::Bilinear,
            to_uv,
        } = self
        else {
            return Vec2::ZERO;
        };
        let uv = uv * to_uv.scale + to_uv.offset;
        if !uv.is_finite() {
            return Vec2::ZERO;
        }
        let (w, h) = (image.width as f32, image.height as f32);
        let (x, y) = (uv.x * w - 0.5, uv.y * h - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let f = |dx: i64, dy: i64| crate::math::luminance(image.texel(x0 + dx, y0 + dy, *wrap));
        let (f00, f10, f01, f11) = (f(0, 0), f(1, 0), f(0, 1), f(1, 1));
        let d_dx = (1.0 - fy) * (f10 - f00) + fy * (f11 - f01);
        let d_dy = (1.0 - fx) * (f01 - f00) + fx * (f11 - f10);
        let g = Vec2::new(d_dx * w * to_uv.scale.x, d_dy * h * to_uv.scale.y);
        if g.is_finite() { g } else { Vec2::ZERO }
    }

    /// The mean over the texture (for lobe choices that want one value).
    pub fn mean(&self) -> Rgb {
        match self {
            Texture::Bitmap { image, .. } => image.mean(),
            Texture::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
        }
    }
}

/// What an image of 0 bytes is called (a download that lacks its large
/// files); the decoders' own word for it is "failed to fill whole buffer".
const EMPTY: &str = "the file is empty (0 bytes)";

/// An image held in memory, decoded; an empty one named as such.
fn from_memory(bytes: &[u8]) -> Result<image::DynamicImage, String> {
    if bytes.is_empty() {
        return Err(EMPTY.into());
    }
    image::load_from_memory(bytes).map_err(|e| e.to_string())
}

impl Bitmap {
    /// A bitmap of `texels` given row-major from the top row; bytes are
    /// stored in tiles ([`TILE`]). Floats stay as given: an EXR sky of
    /// 62 MiB took 0.05 s longer to load tiled, for no faster render.
    fn new(width: usize, height: usize, texels: Texels) -> Bitmap {
        let texels = match texels {
            Texels::Bytes { bytes, decode } => Texels::Bytes {
                bytes: tiled(&bytes, width, height),
                decode,
            },
            floats => floats,
        };
        Bitmap {
            width,
            height,
            texels,
            mean: Default::default(),
        }
    }

    /// The mean texel.
    pub fn mean(&self) -> Rgb {
        *self.mean.get_or_init(|| {
            let n = self.width * self.height;
            self.row_major().sum::<Rgb>() / n.max(1) as f32
        })
    }

    /// Every texel, row-major from the top row, linear.
    fn row_major(&self) -> impl Iterator<Item = Rgb> + '_ {
        (0..self.height).flat_map(move |y| (0..self.width).map(move |x| self.at(x, y)))
    }

    /// Where byte texel (`x`, `y`) is stored: tiles row-major, texels
    /// row-major within a tile.
    #[inline]
    fn tiled_index(&self, x: usize, y: usize) -> usize {
        let tiles_across = self.width.div_ceil(TILE);
        ((y / TILE) * tiles_across + x / TILE) * (TILE * TILE) + (y % TILE) * TILE + x % TILE
    }

    /// Reads an image (PNG, JPEG, TGA, EXR, HDR, by extension). 8- and
    /// 16-bit colour is sRGB-decoded unless `raw` (data such as roughness);
    /// float images (EXR, HDR) are linear. Non-finite texels become 0.
    pub fn read(path: &Path, raw: bool) -> Result<Bitmap, String> {
        if std::fs::metadata(path).is_ok_and(|m| m.len() == 0) {
            return Err(format!("{}: {EMPTY}", path.display()));
        }
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("pfm"))
        {
            let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
            return read_pfm(&bytes).map_err(|e| format!("{}: {e}", path.display()));
        }
        let image = image::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::from_image(image, raw).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Decodes an image held in memory (a glTF file's embedded images).
    pub fn decode(bytes: &[u8], raw: bool) -> Result<Bitmap, String> {
        let image = from_memory(bytes)?;
        Self::from_image(image, raw)
    }

    /// The alpha channel of an image held in memory, times `factor`, as a
    /// grey bitmap; cut to 0 or 1 at `cutoff` where given (glTF's MASK).
    /// An image without alpha is opaque.
    pub fn decode_alpha(bytes: &[u8], factor: f32, cutoff: Option<f32>) -> Result<Bitmap, String> {
        let image = from_memory(bytes)?;
        let rgba = image.to_rgba32f();
        let (width, height) = (rgba.width() as usize, rgba.height() as usize);
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        let texels = rgba
            .pixels()
            .map(|p| {
                let a = p[3] * factor;
                let a = match cutoff {
                    Some(c) => f32::from(u8::from(a >= c)),
                    None if a.is_finite() => a.clamp(0.0, 1.0),
                    None => 0.0,
                };
                [a; 3]
            })
            .collect();
        Ok(Bitmap::new(width, height, Texels::Floats(texels)))
    }

    /// One channel of an image held in memory (0 red, 1 green, 2 blue),
    /// read raw and mapped by `map`, as a grey bitmap: glTF's packed
    /// metallic-roughness maps. 8-bit images stay 8-bit, `map` applied
    /// through the decode table.
    pub fn decode_channel(
        bytes: &[u8],
        channel: usize,
        map: impl Fn(f32) -> f32,
    ) -> Result<Bitmap, String> {
        use image::ColorType;
        let image = from_memory(bytes)?;
        let (width, height) = (image.width() as usize, image.height() as usize);
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        let clean = |c: f32| {
            let v = map(c);
            if v.is_finite() { v.max(0.0) } else { 0.0 }
        };
        let texels = match image.color() {
            ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8 => {
                let rgb = image.into_rgb8();
                Texels::Bytes {
                    bytes: rgb.pixels().flat_map(|p| [p[channel]; 3]).collect(),
                    decode: Box::new(std::array::from_fn(|i| clean(i as f32 / 255.0))),
                }
            }
            _ => Texels::Floats(
                image
                    .into_rgb32f()
                    .pixels()
                    .map(|p| [clean(p[channel]); 3])
                    .collect(),
            ),
        };
        Ok(Bitmap::new(width, height, texels))
    }

    /// The smallest, largest and mean texel value of the first channel.
    pub fn first_channel_range(&self) -> (f32, f32, f32) {
        let n = self.width * self.height;
        let (mut lo, mut hi, mut sum) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f64);
        for texel in self.row_major() {
            let v = texel.x;
            (lo, hi, sum) = (lo.min(v), hi.max(v), sum + f64::from(v));
        }
        (lo, hi, (sum / n.max(1) as f64) as f32)
    }

    fn from_image(image: image::DynamicImage, raw: bool) -> Result<Bitmap, String> {
        use image::ColorType;
        let (width, height) = (image.width() as usize, image.height() as usize);
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        let texels = match image.color() {
            ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8 => {
                let decode: Box<[f32; 256]> = Box::new(std::array::from_fn(|i| {
                    let c = i as f32 / 255.0;
                    if raw { c } else { srgb_to_linear(c) }
                }));
                Texels::Bytes {
                    bytes: image.into_rgb8().into_raw(),
                    decode,
                }
            }
            colour => {
                let linear = matches!(colour, ColorType::Rgb32F | ColorType::Rgba32F);
                let decode = |c: f32| {
                    let c = if c.is_finite() { c.max(0.0) } else { 0.0 };
                    if linear || raw { c } else { srgb_to_linear(c) }
                };
                let rgb = image.into_rgb32f();
                let texels: Vec<[f32; 3]> = rgb
                    .pixels()
                    .map(|p| [decode(p[0]), decode(p[1]), decode(p[2])])
                    .collect();
                halves_if_exact(&texels).unwrap_or(Texels::Floats(texels))
            }
        };
        Ok(Bitmap::new(width, height, texels))
    }

    /// Linear texels given as values (for tests and generated maps).
    pub fn from_texels(width: usize, height: usize, texels: &[Rgb]) -> Bitmap {
        assert_eq!(texels.len(), width * height, "{width}x{height} texels");
        Bitmap::new(
            width,
            height,
            Texels::Floats(texels.iter().map(|t| t.to_array()).collect()),
        )
    }

    /// The texel in column `x` of row `y` (from the top), linear.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> Rgb {
        match &self.texels {
            Texels::Bytes { bytes, decode } => {
                let i = 3 * self.tiled_index(x, y);
                Rgb::new(
                    decode[bytes[i] as usize],
                    decode[bytes[i + 1] as usize],
                    decode[bytes[i + 2] as usize],
                )
            }
            Texels::Floats(texels) => Rgb::from_array(texels[y * self.width + x]),
            Texels::Halves(texels) => from_halves(texels[y * self.width + x]),
        }
    }

    /// Texels (x0, y0), (x1, y0), (x0, y1) and (x1, y1): a bilinear
    /// lookup's, with one match on how they are kept.
    #[inline(always)]
    fn quad(&self, [x0, x1]: [usize; 2], [y0, y1]: [usize; 2]) -> [Rgb; 4] {
        let corners = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
        match &self.texels {
            Texels::Bytes { bytes, decode } => corners.map(|(x, y)| {
                let i = 3 * self.tiled_index(x, y);
                Rgb::new(
                    decode[bytes[i] as usize],
                    decode[bytes[i + 1] as usize],
                    decode[bytes[i + 2] as usize],
                )
            }),
            Texels::Floats(texels) => {
                corners.map(|(x, y)| Rgb::from_array(texels[y * self.width + x]))
            }
            Texels::Halves(texels) => corners.map(|(x, y)| from_halves(texels[y * self.width + x])),
        }
    }

    /// Asks the cache for texels (`x`, `y`) and (`x` + 1, `y`), the row of a
    /// bilinear lookup (nothing past the row's end).
    #[inline(always)]
    pub fn prefetch(&self, x: usize, y: usize) {
        let x1 = (x + 1).min(self.width - 1);
        match &self.texels {
            Texels::Bytes { bytes, .. } => {
                for x in [x, x1] {
                    if let Some(b) = bytes.get(3 * self.tiled_index(x, y)) {
                        crate::math::prefetch(b);
                    }
                }
            }
            Texels::Floats(texels) => prefetch_texels(texels, y * self.width, [x, x1]),
            Texels::Halves(texels) => prefetch_texels(texels, y * self.width, [x, x1]),
        }
    }

    /// Bytes the texels take.
    pub fn memory_bytes(&self) -> usize {
        match &self.texels {
            Texels::Bytes { bytes, .. } => bytes.len() + 1024,
            Texels::Floats(texels) => 12 * texels.len(),
            Texels::Halves(texels) => 6 * texels.len(),
        }
    }

    #[inline]
    fn texel(&self, x: i64, y: i64, wrap: Wrap) -> Rgb {
        self.at(wrapped(x, self.width, wrap), wrapped(y, self.height, wrap))
    }

    /// Asks the cache for the texels [`Bitmap::lookup`] reads at `uv`.
    #[inline(always)]
    pub fn prefetch_lookup(&self, uv: Vec2, wrap: Wrap, filter: Filter) {
        if !uv.is_finite() {
            return;
        }
        match filter {
            Filter::Nearest => {
                let (x, y) = self.nearest(uv, wrap);
                self.prefetch(x, y);
            }
            Filter::Bilinear => {
                let ([x0, _], [y0, y1], _) = self.bilinear(uv, wrap);
                self.prefetch(x0, y0);
                if y1 != y0 {
                    self.prefetch(x0, y1);
                }
            }
        }
    }

    /// The texel [`Filter::Nearest`] reads at `uv`.
    #[inline(always)]
    fn nearest(&self, uv: Vec2, wrap: Wrap) -> (usize, usize) {
        // As the bilinear filter's grid places texel centres (the half
        // texel's rounding included).
        let x = (uv.x * self.width as f32 - 0.5 + 0.5).floor() as i64;
        let y = (uv.y * self.height as f32 - 0.5 + 0.5).floor() as i64;
        (wrapped(x, self.width, wrap), wrapped(y, self.height, wrap))
    }

    /// The columns and rows [`Filter::Bilinear`] reads at `uv`, and the
    /// weights of the second of each.
    #[inline(always)]
    fn bilinear(&self, uv: Vec2, wrap: Wrap) -> ([usize; 2], [usize; 2], Vec2) {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let xs = wrapped_pair(x0 as i64, self.width, wrap);
        let ys = wrapped_pair(y0 as i64, self.height, wrap);
        (xs, ys, Vec2::new(x - x0, y - y0))
    }

    /// The bitmap at texture coordinates `uv` (texel centres at
    /// ((i + 1/2) / width, (j + 1/2) / height)).
    #[inline]
    pub fn lookup(&self, uv: Vec2, wrap: Wrap, filter: Filter) -> Rgb {
        if !uv.is_finite() {
            return Rgb::ZERO;
        }
        match filter {
            Filter::Nearest => {
                let (x, y) = self.nearest(uv, wrap);
                self.at(x, y)
            }
            Filter::Bilinear => {
                let (xs, ys, f) = self.bilinear(uv, wrap);
                let (fx, fy) = (f.x, f.y);
                let [a, b, c, d] = self.quad(xs, ys);
                let top = a * (1.0 - fx) + b * fx;
                let bottom = c * (1.0 - fx) + d * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }
}

/// Texel index `i` of a row or column of `n` wrapped into it.
#[inline(always)]
fn wrapped(i: i64, n: usize, wrap: Wrap) -> usize {
    let n = n as i64;
    let i = match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
    };
    i as usize
}

/// Texels `i` and `i` + 1 wrapped: inside the image (almost every
/// lookup), without the divisions of [`wrapped`].
#[inline(always)]
fn wrapped_pair(i: i64, n: usize, wrap: Wrap) -> [usize; 2] {
    if i >= 0 && i + 1 < n as i64 {
        [i as usize, i as usize + 1]
    } else {
        [wrapped(i, n, wrap), wrapped(i + 1, n, wrap)]
    }
}

/// `texels` as half floats, where each value is exactly one (an EXR of
/// halves, read as floats); else `None`.
fn halves_if_exact(texels: &[[f32; 3]]) -> Option<Texels> {
    let exact = |v: f32| f16::from_f32(v).to_f32() == v;
    texels
        .iter()
        .flatten()
        .all(|&v| exact(v))
        .then(|| Texels::Halves(texels.iter().map(|t| t.map(f16::from_f32)).collect()))
}

/// Asks the cache for texels `row + x` of row-major `texels`.
#[inline(always)]
fn prefetch_texels<T>(texels: &[T], row: usize, xs: [usize; 2]) {
    for x in xs {
        if let Some(t) = texels.get(row + x) {
            crate::math::prefetch(t);
        }
    }
}

#[inline(always)]
fn from_halves([r, g, b]: [f16; 3]) -> Rgb {
    Rgb::new(r.to_f32(), g.to_f32(), b.to_f32())
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests;
