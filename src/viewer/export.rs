//! Exports: the tone-mapped image as PNG (settings in PNG text chunks), the
//! linear radiance as EXR, and any screen capture (the window, the comparison
//! sheet) as PNG. Names carry the scene, the settings and the sample count;
//! files are written through a temporary file and never overwrite one.

use crate::error::{Error, Result};
use crate::film::FilmSnapshot;
use crate::image::write_new_file;
use eframe::egui::ColorImage;
use std::path::{Path, PathBuf};

/// File name stem from free text: letters, digits and '-' only.
pub fn slug(text: &str) -> String {
    let mut out = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') && !out.is_empty() {
            out.push('-');
        }
    }
    out.trim_end_matches('-').to_string()
}

/// `dir/scene_settings_NNNspp.ext`.
pub fn export_path(dir: &Path, scene: &str, label: &str, spp: u32, ext: &str) -> PathBuf {
    dir.join(format!("{}_{}_{spp}spp.{ext}", slug(scene), slug(label)))
}

fn ensure_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::at(dir, None, format!("cannot create the export folder: {e}")))
}

/// Writes RGBA8 pixels as PNG with `text` as tEXt chunks.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[u8],
    text: &[(&str, String)],
) -> Result<PathBuf> {
    if let Some(dir) = path.parent() {
        ensure_dir(dir)?;
    }
    write_new_file(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        for (key, value) in text {
            encoder
                .add_text_chunk((*key).to_string(), value.clone())
                .map_err(|e| e.to_string())?;
        }
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(rgba).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    })
}

/// Writes a screen image (already display colours) as PNG.
pub fn write_color_image(
    path: &Path,
    image: &ColorImage,
    text: &[(&str, String)],
) -> Result<PathBuf> {
    let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    write_png(
        path,
        image.size[0] as u32,
        image.size[1] as u32,
        &rgba,
        text,
    )
}

/// Writes the film's linear radiance as EXR.
pub fn write_exr(path: &Path, snapshot: &FilmSnapshot) -> Result<PathBuf> {
    if let Some(dir) = path.parent() {
        ensure_dir(dir)?;
    }
    write_new_file(path, |tmp| snapshot.image.encode_exr(tmp))
}

/// Reads the text chunks of a PNG (for tests and for users checking what
/// settings made an image).
pub fn read_png_text(path: &Path) -> Result<Vec<(String, String)>> {
    let file = std::fs::File::open(path).map_err(|e| Error::at(path, None, e.to_string()))?;
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let reader = decoder
        .read_info()
        .map_err(|e| Error::at(path, None, e.to_string()))?;
    Ok(reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_slugs_with_settings_and_spp() {
        let p = export_path(
            Path::new("out"),
            "cornell_box",
            "path d8 mis Stratified",
            64,
            "png",
        );
        assert_eq!(
            p,
            Path::new("out/cornell-box_path-d8-mis-stratified_64spp.png")
        );
    }
}
