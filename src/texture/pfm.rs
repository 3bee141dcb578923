//! Portable Float Maps: [`super::Bitmap::read`] sends `.pfm` files here.

use super::{Bitmap, Texels};

/// A Portable Float Map (`PF` colour or `Pf` grey; rows stored bottom to
/// top; a negative scale means little-endian). Linear.
pub fn read_pfm(bytes: &[u8]) -> Result<Bitmap, String> {
    // The header: three whitespace-separated tokens after the magic.
    let mut tokens = Vec::new();
    let mut at = 0;
    while tokens.len() < 4 {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if start == at {
            return Err("truncated PFM header".into());
        }
        tokens.push(String::from_utf8_lossy(&bytes[start..at]).into_owned());
    }
    at += 1; // The single whitespace byte before the data.
    let channels = match tokens[0].as_str() {
        "PF" => 3,
        "Pf" => 1,
        m => return Err(format!("not a PFM file (magic {m:?})")),
    };
    let parse = |t: &str| {
        t.parse::<usize>()
            .map_err(|_| format!("bad PFM size {t:?}"))
    };
    let (width, height) = (parse(&tokens[1])?, parse(&tokens[2])?);
    let scale: f32 = tokens[3]
        .parse()
        .map_err(|_| format!("bad PFM scale {:?}", tokens[3]))?;
    let count = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels))
        .filter(|&n| n > 0 && n <= 1 << 28)
        .ok_or_else(|| format!("PFM size {width}x{height} is empty or too large"))?;
    let data = bytes.get(at..at + 4 * count).ok_or("truncated PFM data")?;
    let value = |i: usize| {
        let b = [
            data[4 * i],
            data[4 * i + 1],
            data[4 * i + 2],
            data[4 * i + 3],
        ];
        let v = if scale < 0.0 {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        if v.is_finite() { v.max(0.0) } else { 0.0 }
    };
    let mut texels = vec![[0.0f32; 3]; width * height];
    for y in 0..height {
        for x in 0..width {
            let i = ((height - 1 - y) * width + x) * channels;
            texels[y * width + x] = if channels == 3 {
                [value(i), value(i + 1), value(i + 2)]
            } else {
                [value(i); 3]
            };
        }
    }
    Ok(Bitmap::new(width, height, Texels::Floats(texels)))
}
