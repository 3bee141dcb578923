//! Linear RGB images: reading and writing EXR (float32) and PNG (tone-mapped
//! sRGB), always written atomically (temporary file, then rename), and the
//! error metrics used to compare renders.

use crate::error::{Error, Result};
use image::{ImageFormat, Rgb32FImage, RgbImage};
use std::path::{Path, PathBuf};

/// A linear RGB float image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// Error metrics between an image and a reference, averaged over all pixels
/// and channels, as tev defines them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorMetrics {
    /// sqrt(mean((a - b)^2)).
    pub rmse: f64,
    /// mean((a - b)^2 / (b^2 + 0.01)).
    pub relative_mse: f64,
    /// mean(|a - b| / (|b| + 0.01)).
    pub mean_relative_error: f64,
    /// The RMSE without the worst 0.1% of pixels (by their squared error
    /// over the channels): what a handful of fireflies cannot decide.
    pub trimmed_rmse: f64,
}

/// The share of pixels [`ErrorMetrics::trimmed_rmse`] leaves out.
pub const TRIMMED_SHARE: f64 = 0.001;

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            pixels: vec![[0.0; 3]; (width * height) as usize],
        }
    }

    /// Mean of each channel.
    pub fn mean(&self) -> [f64; 3] {
        let mut m = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                m[c] += p[c] as f64;
            }
        }
        m.map(|x| x / self.pixels.len().max(1) as f64)
    }

    /// Reads an EXR (or any format the image crate knows) as linear float RGB.
    pub fn read(path: &Path) -> Result<Image> {
        let img = image::open(path)
            .map_err(|e| Error::at(path, None, format!("cannot read image: {e}")))?;
        let rgb = img.into_rgb32f();
        let (width, height) = rgb.dimensions();
        let pixels = rgb.pixels().map(|p| p.0).collect();
        Ok(Image {
            width,
            height,
            pixels,
        })
    }

    /// Writes linear float32 RGB EXR.
    pub fn write_exr(&self, path: &Path) -> Result<()> {
        write_atomically(path, |tmp| self.encode_exr(tmp))
    }

    /// [`Image::write_exr`] without a copy of the pixels: for the end of
    /// a large render.
    pub fn into_exr(self, path: &Path) -> Result<()> {
        write_atomically(path, |tmp| self.into_exr_unchecked(tmp))
    }

    /// Writes an EXR straight to `path` (callers make it atomic).
    pub fn encode_exr(&self, path: &Path) -> std::result::Result<(), String> {
        self.clone().into_exr_unchecked(path)
    }

    fn into_exr_unchecked(self, path: &Path) -> std::result::Result<(), String> {
        let buffer = Rgb32FImage::from_raw(self.width, self.height, self.pixels.into_flattened())
            .ok_or("internal: image buffer size mismatch")?;
        buffer
            .save_with_format(path, ImageFormat::OpenExr)
            .map_err(|e| e.to_string())
    }

    /// Writes an 8-bit sRGB PNG: radiance times 2^exposure, clamped, sRGB-encoded.
    pub fn write_png(&self, path: &Path, exposure: f32) -> Result<()> {
        let buffer = self.to_srgb8(exposure);
        write_atomically(path, |tmp| {
            buffer
                .save_with_format(tmp, ImageFormat::Png)
                .map_err(|e| e.to_string())
        })
    }

    /// Tone-mapped 8-bit sRGB copy.
    pub fn to_srgb8(&self, exposure: f32) -> RgbImage {
        let scale = exposure.exp2();
        let data: Vec<u8> = self
            .pixels
            .iter()
            .flatten()
            .map(|&v| (linear_to_srgb(v * scale) * 255.0 + 0.5) as u8)
            .collect();
        RgbImage::from_raw(self.width, self.height, data).expect("buffer matches its dimensions")
    }

    /// How many times larger than `reference` this image is, the same
    /// whole number along both axes (1 for equal sizes); None otherwise.
    pub fn scale_over(&self, reference: &Image) -> Option<u32> {
        let (w, h) = (reference.width.max(1), reference.height.max(1));
        let k = self.width / w;
        (k >= 1 && self.width == k * w && self.height == k * h).then_some(k)
    }

    /// Each k × k block of pixels averaged into one (a box filter).
    pub fn downsampled(&self, k: u32) -> Image {
        let k = k.max(1);
        let (w, h) = (self.width / k, self.height / k);
        let mut pixels = vec![[0.0f32; 3]; (w * h) as usize];
        let weight = 1.0 / (k * k) as f32;
        for y in 0..h * k {
            let row = &self.pixels[(y * self.width) as usize..][..(w * k) as usize];
            let out = &mut pixels[((y / k) * w) as usize..][..w as usize];
            for (x, p) in row.iter().enumerate() {
                let o = &mut out[x / k as usize];
                for c in 0..3 {
                    o[c] += p[c] * weight;
                }
            }
        }
        Image {
            width: w,
            height: h,
            pixels,
        }
    }

    /// Error of `self` against `reference`. A reference smaller by a whole
    /// factor k (Tungsten's and the shipped references are box-downsampled)
    /// is compared with this image box-downsampled by k: callers that show
    /// the figure say so ([`Image::scale_over`]).
    pub fn compare(&self, reference: &Image) -> Result<ErrorMetrics> {
        match self.scale_over(reference) {
            Some(1) => {}
            Some(k) => return self.downsampled(k).compare(reference),
            None => {
                return Err(Error::new(format!(
                    "images differ in size: {}x{} vs {}x{} (nor is the first a whole multiple of the second)",
                    self.width, self.height, reference.width, reference.height
                )));
            }
        }
        let (mut se, mut rel_se, mut rel_ae) = (0.0f64, 0.0f64, 0.0f64);
        let mut per_pixel = Vec::with_capacity(self.pixels.len());
        for (a, b) in self.pixels.iter().zip(&reference.pixels) {
            let mut pixel_se = 0.0;
            for c in 0..3 {
                let (a, b) = (a[c] as f64, b[c] as f64);
                let d = a - b;
                pixel_se += d * d;
                rel_se += d * d / (b * b + 0.01);
                rel_ae += d.abs() / (b.abs() + 0.01);
            }
            se += pixel_se;
            // NaN counts among the worst.
            per_pixel.push(if pixel_se.is_nan() {
                f64::INFINITY
            } else {
                pixel_se
            });
        }
        let n = (self.pixels.len() * 3).max(1) as f64;
        let kept = per_pixel.len() - (per_pixel.len() as f64 * TRIMMED_SHARE) as usize;
        let trimmed_se: f64 = if kept < per_pixel.len() {
            per_pixel.select_nth_unstable_by(kept, f64::total_cmp);
            per_pixel[..kept].iter().sum()
        } else {
            se
        };
        Ok(ErrorMetrics {
            rmse: (se / n).sqrt(),
            relative_mse: rel_se / n,
            mean_relative_error: rel_ae / n,
            trimmed_rmse: (trimmed_se / (kept * 3).max(1) as f64).sqrt(),
        })
    }
}

/// sRGB transfer function with clamping to [0, 1]; NaN maps to 0.
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Temporary path next to `path`, so that the final rename stays on one file system.
fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Checks early that `path` can be written, so a long render does not end in
/// a failed save. Leaves nothing behind.
pub fn check_writable(path: &Path) -> Result<()> {
    let tmp = temporary_path(path);
    std::fs::write(&tmp, b"")
        .map_err(|e| Error::at(path, None, format!("cannot write output: {e}")))?;
    let _ = std::fs::remove_file(&tmp);
    Ok(())
}

/// Writes through a temporary file and renames it over `path`, so that an
/// interrupted write never leaves a half file in place of a good one.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> std::result::Result<(), String>,
) -> Result<()> {
    let tmp = temporary_path(path);
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::at(path, None, format!("cannot write output: {e}")));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::at(path, None, format!("cannot write output: {e}"))
    })
}

/// Writes a new file at `path`, or at `stem-2.ext`, `stem-3.ext`, ... when
/// that exists: never overwrites. The data goes to a temporary file first and
/// is hard-linked into place, which fails rather than replace a file that
/// appeared meanwhile. Returns the path written.
pub fn write_new_file(
    path: &Path,
    write: impl FnOnce(&Path) -> std::result::Result<(), String>,
) -> Result<PathBuf> {
    let tmp = temporary_path(path);
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::at(path, None, format!("cannot write output: {e}")));
    }
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("export");
    let ext = path.extension().and_then(|s| s.to_str()).unwrap_or("");
    let mut result = Err(Error::at(path, None, "no free file name"));
    for n in 1..10_000 {
        let candidate = if n == 1 {
            path.to_path_buf()
        } else {
            path.with_file_name(format!("{stem}-{n}.{ext}"))
        };
        match std::fs::hard_link(&tmp, &candidate) {
            Ok(()) => {
                result = Ok(candidate);
                break;
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => {
                result = Err(Error::at(
                    &candidate,
                    None,
                    format!("cannot write output: {e}"),
                ));
                break;
            }
        }
    }
    let _ = std::fs::remove_file(&tmp);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_trimmed_rmse_leaves_out_the_worst_thousandth() {
        // 2 000 pixels off by 0.1, two of them by 100 (fireflies): the plain
        // RMSE is theirs, the trimmed one leaves exactly those two out.
        let reference = Image::new(2000, 1);
        let mut image = Image::new(2000, 1);
        image.pixels.fill([0.1; 3]);
        image.pixels[7] = [100.0; 3];
        image.pixels[1500] = [f32::NAN; 3];
        let m = image.compare(&reference).unwrap();
        assert!(m.rmse.is_nan());
        assert!((m.trimmed_rmse - 0.1).abs() < 1e-6, "{}", m.trimmed_rmse);
        image.pixels[1500] = [0.1; 3];
        let m = image.compare(&reference).unwrap();
        assert!(m.rmse > 2.0);
        // One of 2 000 pixels left out: the firefly and nothing else.
        assert!((m.trimmed_rmse - 0.1).abs() < 1e-6, "{}", m.trimmed_rmse);
    }

    #[test]
    fn metrics_of_a_known_difference() {
        let mut a = Image::new(2, 1);
        let b = Image {
            width: 2,
            height: 1,
            pixels: vec![[1.0; 3], [0.0; 3]],
        };
        a.pixels = vec![[1.1; 3], [0.1; 3]];
        let m = a.compare(&b).unwrap();
        assert!((m.rmse - 0.1).abs() < 1e-6);
        let expected_rel_mse = (0.01 / 1.01 + 0.01 / 0.01) / 2.0;
        assert!((m.relative_mse - expected_rel_mse).abs() < 1e-5);
        assert!(a.compare(&Image::new(3, 1)).is_err());
    }

    #[test]
    fn a_smaller_reference_is_compared_with_the_box_downsampled_image() {
        // 4 x 2 against 2 x 1: each reference pixel is the mean of a 2 x 2 block.
        let image = Image {
            width: 4,
            height: 2,
            pixels: [1.0, 3.0, 10.0, 10.0, 3.0, 1.0, 10.0, 14.0]
                .map(|v| [v; 3])
                .to_vec(),
        };
        assert_eq!(image.downsampled(2).pixels, vec![[2.0; 3], [11.0; 3]]);
        let reference = Image {
            width: 2,
            height: 1,
            pixels: vec![[2.0; 3], [10.0; 3]],
        };
        assert_eq!(image.scale_over(&reference), Some(2));
        let m = image.compare(&reference).unwrap();
        assert!((m.rmse - 0.5f64.sqrt()).abs() < 1e-6, "{}", m.rmse);
        assert_eq!(Image::new(4, 3).scale_over(&reference), None);
    }

    #[test]
    fn exr_round_trips_exactly_and_atomically() {
        let dir = std::env::temp_dir().join(format!("tracelab-img-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.exr");
        let img = Image {
            width: 3,
            height: 2,
            pixels: (0..6).map(|i| [i as f32 * 0.37, 1e-4, 123.5]).collect(),
        };
        img.write_exr(&path).unwrap();
        assert_eq!(Image::read(&path).unwrap(), img);
        // No temporary file is left next to it.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn new_files_never_overwrite() {
        let dir = std::env::temp_dir().join(format!("tracelab-new-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("shot.png");
        let write =
            |text: &'static str| move |p: &Path| std::fs::write(p, text).map_err(|e| e.to_string());
        assert_eq!(write_new_file(&path, write("a")).unwrap(), path);
        let second = write_new_file(&path, write("b")).unwrap();
        assert_eq!(second, dir.join("shot-2.png"));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a");
        assert_eq!(std::fs::read_to_string(&second).unwrap(), "b");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
