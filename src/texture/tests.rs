//! Tests of `texture.rs`.

use super::*;

/// A float image whose values half floats hold exactly (an EXR of
/// halves) is kept in halves and reads back the same; one other value
/// keeps it in floats.
#[test]
fn float_images_of_halves_are_kept_in_halves() {
    let image = |values: [f32; 3]| {
        image::DynamicImage::ImageRgb32F(image::ImageBuffer::from_fn(2, 1, |x, _| {
            image::Rgb(values.map(|v| v * (x + 1) as f32))
        }))
    };
    let exact = Bitmap::from_image(image([0.5, 1.25, 3.0e4]), false).unwrap();
    assert!(matches!(exact.texels, Texels::Halves(_)));
    assert_eq!(exact.at(1, 0), Rgb::new(1.0, 2.5, 6.0e4));
    assert_eq!(exact.memory_bytes(), 12);
    let inexact = Bitmap::from_image(image([0.1, 1.25, 3.0e4]), false).unwrap();
    assert!(matches!(inexact.texels, Texels::Floats(_)));
    assert_eq!(inexact.at(0, 0), Rgb::new(0.1, 1.25, 3.0e4));
}

/// Every texel reads back where it was given: bytes stored in tiles, at
/// a size that leaves partial tiles, and floats stored row-major.
#[test]
fn tiled_texels_read_back_in_place() {
    let (width, height) = (13, 10);
    let value = |x: usize, y: usize| Rgb::new(x as f32, y as f32, (x * y) as f32);
    let given: Vec<Rgb> = (0..height)
        .flat_map(|y| (0..width).map(move |x| value(x, y)))
        .collect();
    let floats = Bitmap::from_texels(width, height, &given);
    let bytes: Vec<u8> = (given.iter())
        .flat_map(|t| t.to_array().map(|c| c as u8))
        .collect();
    let raw = Bitmap::new(
        width,
        height,
        Texels::Bytes {
            bytes,
            decode: Box::new(std::array::from_fn(|i| i as f32)),
        },
    );
    for (y, x) in (0..height).flat_map(|y| (0..width).map(move |x| (y, x))) {
        assert_eq!(floats.at(x, y), value(x, y), "float texel ({x}, {y})");
        assert_eq!(raw.at(x, y), value(x, y), "byte texel ({x}, {y})");
    }
    let mean = given.iter().copied().sum::<Rgb>() / given.len() as f32;
    assert_eq!(floats.mean(), mean);
}

fn two_by_two() -> Bitmap {
    Bitmap::from_texels(
        2,
        2,
        &[
            Rgb::splat(0.0),
            Rgb::splat(1.0),
            Rgb::splat(2.0),
            Rgb::splat(3.0),
        ],
    )
}

#[test]
fn bitmap_lookup_filters_and_wraps() {
    let b = two_by_two();
    let repeat = |u, v, filter| b.lookup(Vec2::new(u, v), Wrap::Repeat, filter).x;
    // Texel centres read exactly; the middle is the mean of four.
    assert_eq!(repeat(0.25, 0.25, Filter::Bilinear), 0.0);
    assert_eq!(repeat(0.75, 0.75, Filter::Bilinear), 3.0);
    assert_eq!(repeat(0.5, 0.5, Filter::Bilinear), 1.5);
    // Row 0 is the top: v = 0.25 reads texels 0 and 1.
    assert_eq!(repeat(0.75, 0.25, Filter::Nearest), 1.0);
    // Repeat, clamp and mirror one texel beyond the right edge.
    let beyond = Vec2::new(1.25, 0.25);
    assert_eq!(b.lookup(beyond, Wrap::Repeat, Filter::Nearest).x, 0.0);
    assert_eq!(b.lookup(beyond, Wrap::Clamp, Filter::Nearest).x, 1.0);
    assert_eq!(b.lookup(beyond, Wrap::Mirror, Filter::Nearest).x, 1.0);
    assert_eq!(
        b.lookup(Vec2::new(1.75, 0.25), Wrap::Mirror, Filter::Nearest)
            .x,
        0.0
    );
    assert_eq!(
        b.lookup(Vec2::NAN, Wrap::Repeat, Filter::Bilinear),
        Rgb::ZERO
    );
}

#[test]
fn checkerboard_alternates_as_mitsubas() {
    let t = Texture::Checkerboard {
        color0: Rgb::ONE,
        color1: Rgb::ZERO,
        to_uv: UvTransform {
            scale: Vec2::splat(2.0),
            offset: Vec2::ZERO,
        },
    };
    assert_eq!(t.eval(Vec2::new(0.1, 0.1)), Rgb::ONE);
    assert_eq!(t.eval(Vec2::new(0.3, 0.1)), Rgb::ZERO);
    assert_eq!(t.eval(Vec2::new(0.3, 0.3)), Rgb::ONE);
    assert_eq!(t.mean(), Rgb::splat(0.5));
}

#[test]
fn pfm_reads_bottom_up_little_endian() {
    let mut bytes = b"PF\n2 1\n-1.0\n".to_vec();
    for v in [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let b = read_pfm(&bytes).unwrap();
    assert_eq!((b.width, b.height), (2, 1));
    assert_eq!(b.at(1, 0), Rgb::new(4.0, 5.0, 6.0));
    assert!(read_pfm(b"PF\n2 1\n-1.0\n").is_err());
    assert!(read_pfm(b"P6\n2 1\n255\n").is_err());
}

#[test]
fn eight_bit_images_stay_eight_bit_and_decode_by_their_table() {
    let bytes = vec![0u8, 128, 255, 10, 20, 30];
    let image =
        || image::DynamicImage::ImageRgb8(image::RgbImage::from_raw(2, 1, bytes.clone()).unwrap());
    let colour = Bitmap::from_image(image(), false).unwrap();
    let data = Bitmap::from_image(image(), true).unwrap();
    for (i, &b) in bytes.iter().enumerate() {
        let (texel, channel) = (i / 3, i % 3);
        let c = f32::from(b) / 255.0;
        assert_eq!(colour.at(texel, 0)[channel], srgb_to_linear(c));
        assert_eq!(data.at(texel, 0)[channel], c);
    }
    // Three bytes a texel (and the table), not sixteen; the two texels
    // lie in one tile, padded to 8 × 8.
    assert_eq!(colour.memory_bytes(), 3 * TILE * TILE + 1024);
}

#[test]
fn srgb_decoding_matches_the_standard() {
    assert_eq!(srgb_to_linear(0.0), 0.0);
    assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
    assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
}
