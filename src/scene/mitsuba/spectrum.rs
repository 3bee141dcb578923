//! Colour values of Mitsuba files as RGB, as its RGB variants read them:
//! `<rgb>`, `<srgb>` (gamma-encoded or `#rrggbb`), `<float>`, `<spectrum>`
//! (one value, or `wavelength:value` pairs) and `<blackbody>`.
//!
//! Sampled spectra are integrated against the CIE 1931 observer as Mitsuba
//! 3's RGB variants integrate them (`spectrum_list_to_srgb`): a reflectance
//! weighted by D65 and normalised so that a flat one is grey, and clamped to
//! [0, 1]; an emitter's spectrum unweighted and normalised so that ȳ
//! integrates to 1, so that a flat one is the equal-energy white, slightly
//! pink in sRGB (1.205, 0.948, 0.909) × its value. A single-valued
//! `<spectrum>` is that flat spectrum; `<rgb>` and `<float>` are taken as
//! they are.

use super::props::{parse_f64, parse_list};
use super::xml::Element;
use crate::error::Result;
use crate::math::Rgb;
use crate::texture::srgb_to_linear;

/// The colour an element gives.
pub fn parse_colour(e: &Element, illuminant: bool) -> Result<Rgb> {
    let rgb = match e.tag.as_str() {
        "rgb" | "color" => triple(e.require("value")?, e)?,
        "srgb" => {
            let v = e.require("value")?;
            let c = match v.trim().strip_prefix('#') {
                Some(hex) => hex_colour(hex)
                    .ok_or_else(|| e.loc.error(format!("\"{v}\" is not a #rrggbb colour")))?,
                None => triple(v, e)?,
            };
            Rgb::new(
                srgb_to_linear(c.x),
                srgb_to_linear(c.y),
                srgb_to_linear(c.z),
            )
        }
        "float" => Rgb::splat(parse_f64(e.require("value")?, &e.loc)? as f32),
        "spectrum" => {
            if e.attr("filename").is_some() {
                return Err(e.loc.error(
                    "spectra from files are not read; give <rgb> or wavelength:value pairs",
                ));
            }
            let v = e.require("value")?;
            if v.contains(':') {
                let mut samples = Vec::new();
                for pair in v.split(',').map(str::trim).filter(|p| !p.is_empty()) {
                    let (l, s) = pair.split_once(':').ok_or_else(|| {
                        e.loc.error(format!("\"{pair}\" is not wavelength:value"))
                    })?;
                    samples.push((parse_f64(l, &e.loc)?, parse_f64(s, &e.loc)?));
                }
                if samples.len() < 2 || samples.windows(2).any(|w| w[1].0 <= w[0].0) {
                    return Err(e
                        .loc
                        .error("a spectrum needs two or more increasing wavelengths"));
                }
                sampled_to_rgb(&samples, illuminant)
            } else {
                let value = parse_f64(v, &e.loc)?;
                match illuminant {
                    true => spectrum_to_rgb(|_| Some(value), true),
                    false => Rgb::splat(value as f32),
                }
            }
        }
        "blackbody" => {
            let t = parse_f64(e.require("temperature")?.trim_end_matches('K'), &e.loc)?;
            if t <= 0.0 {
                return Err(e.loc.error("a blackbody's temperature must be > 0 K"));
            }
            let scale = match e.attr("scale") {
                Some(s) => parse_f64(s, &e.loc)?,
                None => 1.0,
            };
            blackbody_rgb(t) * scale as f32
        }
        other => {
            return Err(e.loc.error(format!(
                "<{other}> is not a colour (rgb, srgb, spectrum, blackbody, float)"
            )));
        }
    };
    if !rgb.is_finite() {
        return Err(e.loc.error("the colour is not finite"));
    }
    Ok(rgb)
}

fn triple(v: &str, e: &Element) -> Result<Rgb> {
    let list = parse_list(v, &e.loc)?;
    match list[..] {
        [x] => Ok(Rgb::splat(x as f32)),
        [r, g, b] => Ok(Rgb::new(r as f32, g as f32, b as f32)),
        _ => Err(e
            .loc
            .error(format!("a colour has 1 or 3 numbers, got \"{v}\""))),
    }
}

fn hex_colour(hex: &str) -> Option<Rgb> {
    if hex.len() != 6 {
        return None;
    }
    let channel = |i: usize| {
        u8::from_str_radix(&hex[i..i + 2], 16)
            .ok()
            .map(|b| b as f32 / 255.0)
    };
    Some(Rgb::new(channel(0)?, channel(2)?, channel(4)?))
}

fn xyz_to_linear_srgb([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.240479 * x - 1.537150 * y - 0.498535 * z,
        -0.969256 * x + 1.875991 * y + 0.041556 * z,
        0.055648 * x - 0.204043 * y + 1.057311 * z,
    ]
}

/// x̄, ȳ, z̄ and D65 at wavelength `l` (nm), linear between the table's rows.
fn cie(l: f64) -> [f64; 4] {
    use super::cie::{FIRST, STEP, TABLE};
    let t = ((l - FIRST) / STEP).clamp(0.0, (TABLE.len() - 1) as f64);
    let k = (t as usize).min(TABLE.len() - 2);
    let f = t - k as f64;
    std::array::from_fn(|c| TABLE[k][c] * (1.0 - f) + TABLE[k + 1][c] * f)
}

/// RGB of the spectrum `s` (None outside the wavelengths it is given at),
/// as an emitter's (`illuminant`) or a reflectance (see the module comment),
/// by Mitsuba's rule: 1 000 points over 360–830 nm.
fn spectrum_to_rgb(s: impl Fn(f64) -> Option<f64>, illuminant: bool) -> Rgb {
    const POINTS: usize = 1000;
    let (mut xyz, mut norm) = ([0.0; 3], 0.0);
    for i in 0..POINTS {
        let l = 360.0 + 470.0 * i as f64 / (POINTS - 1) as f64;
        let [x, y, z, d65] = cie(l);
        let weight = if illuminant { 1.0 } else { d65 };
        norm += weight * y;
        if let Some(v) = s(l) {
            for (sum, c) in xyz.iter_mut().zip([x, y, z]) {
                *sum += v * weight * c;
            }
        }
    }
    let rgb = xyz_to_linear_srgb(xyz.map(|c| c / norm));
    let upper = if illuminant { f64::INFINITY } else { 1.0 };
    Rgb::new(
        rgb[0].clamp(0.0, upper) as f32,
        rgb[1].clamp(0.0, upper) as f32,
        rgb[2].clamp(0.0, upper) as f32,
    )
}

/// Piecewise linear between the samples, nothing outside them (as Mitsuba).
fn sampled_to_rgb(samples: &[(f64, f64)], illuminant: bool) -> Rgb {
    let (first, last) = (samples[0].0, samples[samples.len() - 1].0);
    let at = |l: f64| {
        if l < first || l > last {
            return None;
        }
        let i = samples
            .partition_point(|&(w, _)| w <= l)
            .min(samples.len() - 1);
        let ((l0, v0), (l1, v1)) = (samples[i - 1], samples[i]);
        Some(v0 + (v1 - v0) * (l - l0) / (l1 - l0))
    };
    spectrum_to_rgb(at, illuminant)
}

/// Planck's law in W / (m² sr nm), as Mitsuba's `blackbody`: an emitter's
/// spectrum.
fn blackbody_rgb(kelvin: f64) -> Rgb {
    const C: f64 = 2.99792458e8;
    const H: f64 = 6.62607004e-34;
    const K: f64 = 1.38064852e-23;
    let planck = |nm: f64| {
        let l = nm * 1e-9;
        let p = 2.0 * H * C * C / (l.powi(5) * ((H * C / (l * K * kelvin)).exp() - 1.0));
        Some(p * 1e-9)
    };
    spectrum_to_rgb(planck, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3's own conversions (`mi.spectrum_list_to_srgb`, scalar_rgb,
    /// 3.9.1): its cbox light, a reflectance, a green band, flat spectra. The
    /// 5 nm tables and linear steps between them stay within 0.5% of its
    /// 1 nm tables.
    #[test]
    fn spectra_convert_as_mitsubas_rgb_variants_convert_them() {
        let close = |rgb: Rgb, expected: [f32; 3]| {
            let ok = (0..3).all(|c| (rgb[c] - expected[c]).abs() <= 5e-3 * expected[c].max(0.2));
            assert!(ok, "{rgb:?} against Mitsuba's {expected:?}");
        };
        let light = [(400.0, 0.0), (500.0, 8.0), (600.0, 15.6), (700.0, 18.4)];
        close(sampled_to_rgb(&light, true), [20.7108, 10.8546, 2.77115]);
        let surface = [(400.0, 0.2), (500.0, 0.8), (600.0, 0.3), (700.0, 0.5)];
        close(
            sampled_to_rgb(&surface, false),
            [0.203246, 0.616323, 0.520872],
        );
        let band = [(500.0, 1.0), (600.0, 1.0)];
        close(sampled_to_rgb(&band, true), [0.273065, 0.987913, 0.0]);
        close(sampled_to_rgb(&band, false), [0.209804, 1.0, 0.0]);
        close(
            sampled_to_rgb(&[(400.0, 1.0), (700.0, 1.0)], false),
            [0.995341, 0.999756, 0.99491],
        );
        close(
            sampled_to_rgb(&[(300.0, 1.0), (900.0, 1.0)], true),
            [1.20488, 0.948229, 0.909267],
        );
        close(
            spectrum_to_rgb(|_| Some(2.0), true),
            [2.40959, 1.89658, 1.81783],
        );
    }

    #[test]
    fn hex_colours_decode() {
        let c = hex_colour("ff8000").unwrap();
        assert_eq!((c.x, c.y, c.z), (1.0, 128.0 / 255.0, 0.0));
        assert!(hex_colour("ff80").is_none());
    }
}
