//! Colour values of Mitsuba files as RGB, as its RGB variants read them:
//! `<rgb>`, `<srgb>` (gamma-encoded or `#rrggbb`), `<float>`, `<spectrum>`
//! (one value, or `wavelength:value` pairs) and `<blackbody>`.
//!
//! Sampled spectra are integrated against the CIE 1931 observer as fitted by
//! Wyman, Sloan and Shirley (2013), within about 1% of the tables, then
//! white-balanced so that a flat spectrum is grey of the same value.

use super::props::{parse_f64, parse_list};
use super::xml::Element;
use crate::error::Result;
use crate::math::Rgb;
use crate::texture::srgb_to_linear;

/// The colour an element gives.
pub fn parse_colour(e: &Element, illuminant: bool) -> Result<Rgb> {
    let _ = illuminant; // Both kinds convert alike (see the module comment).
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
                sampled_to_rgb(&samples)
            } else {
                Rgb::splat(parse_f64(v, &e.loc)? as f32)
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

/// One lobe of the fit: a Gaussian with different widths left and right.
fn lobe(x: f64, mu: f64, left: f64, right: f64) -> f64 {
    let s = if x < mu { left } else { right };
    (-0.5 * ((x - mu) / s).powi(2)).exp()
}

/// CIE 1931 colour matching functions (Wyman et al. 2013, multi-lobe fit).
fn cie_xyz(l: f64) -> [f64; 3] {
    [
        1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7)
            - 0.065 * lobe(l, 501.1, 20.4, 26.2),
        0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
        1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8),
    ]
}

fn xyz_to_linear_srgb([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.240479 * x - 1.537150 * y - 0.498535 * z,
        -0.969256 * x + 1.875991 * y + 0.041556 * z,
        0.055648 * x - 0.204043 * y + 1.057311 * z,
    ]
}

/// ∫ s(λ) × CMF(λ) dλ over 360–830 nm, `s` given at any wavelength.
fn integrate(s: impl Fn(f64) -> f64) -> [f64; 3] {
    const STEPS: usize = 940;
    let (lo, hi) = (360.0, 830.0);
    let dl = (hi - lo) / STEPS as f64;
    let mut xyz = [0.0; 3];
    for i in 0..STEPS {
        let l = lo + (i as f64 + 0.5) * dl;
        let (v, c) = (s(l), cie_xyz(l));
        for k in 0..3 {
            xyz[k] += v * c[k] * dl;
        }
    }
    xyz
}

/// RGB of a spectrum relative to a flat one, so that flat 1 is (1, 1, 1).
fn relative_rgb(s: impl Fn(f64) -> f64) -> Rgb {
    let flat = xyz_to_linear_srgb(integrate(|_| 1.0));
    let rgb = xyz_to_linear_srgb(integrate(s));
    Rgb::new(
        (rgb[0] / flat[0]) as f32,
        (rgb[1] / flat[1]) as f32,
        (rgb[2] / flat[2]) as f32,
    )
}

/// Piecewise linear between the samples, zero outside them (as Mitsuba).
fn sampled_to_rgb(samples: &[(f64, f64)]) -> Rgb {
    relative_rgb(|l| {
        let i = samples.partition_point(|&(w, _)| w <= l);
        if i == 0 || i == samples.len() {
            return if l == samples[samples.len() - 1].0 {
                samples[samples.len() - 1].1
            } else {
                0.0
            };
        }
        let ((l0, v0), (l1, v1)) = (samples[i - 1], samples[i]);
        v0 + (v1 - v0) * (l - l0) / (l1 - l0)
    })
}

/// Planck's law in W / (m² sr nm), as Mitsuba's `blackbody`.
fn blackbody_rgb(kelvin: f64) -> Rgb {
    const C: f64 = 2.99792458e8;
    const H: f64 = 6.62607004e-34;
    const K: f64 = 1.38064852e-23;
    relative_rgb(|nm| {
        let l = nm * 1e-9;
        let p = 2.0 * H * C * C / (l.powi(5) * ((H * C / (l * K * kelvin)).exp() - 1.0));
        p * 1e-9
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_spectrum_is_grey_and_a_red_one_is_red() {
        let flat = sampled_to_rgb(&[(360.0, 0.5), (830.0, 0.5)]);
        for c in flat.to_array() {
            assert!((c - 0.5).abs() < 1e-3, "{flat:?}");
        }
        let red = sampled_to_rgb(&[(360.0, 0.0), (599.0, 0.0), (600.0, 1.0), (830.0, 1.0)]);
        assert!(red.x > 0.5 && red.y < 0.2 && red.z < 0.05, "{red:?}");
    }

    #[test]
    fn hex_colours_decode() {
        let c = hex_colour("ff8000").unwrap();
        assert_eq!((c.x, c.y, c.z), (1.0, 128.0 / 255.0, 0.0));
        assert!(hex_colour("ff80").is_none());
    }
}
