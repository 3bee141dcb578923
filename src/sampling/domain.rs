//! The sampling domains a path draws numbers for, and the sets of them a
//! sampler applies to (`--domains`).

/// The sampling domains a path draws numbers for. A sampler stratifies (or
/// uses its low-discrepancy points in) the domains selected in
/// [`Domains`]; the others get independent numbers, so each domain's effect
/// on the noise can be seen alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// Position inside the pixel (antialiasing).
    Pixel,
    /// Point on the thin lens (depth of field).
    Lens,
    /// Instant within the shutter interval (motion blur).
    Time,
    /// Light choice and point on the light (and particle emission).
    Light,
    /// BSDF lobe and direction.
    Bsdf,
    /// Everything else (Russian roulette).
    Other,
}

/// A set of [`Domain`]s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Domains {
    pub pixel: bool,
    pub lens: bool,
    /// Missing in settings saved before the time domain existed.
    #[serde(default = "yes")]
    pub time: bool,
    pub light: bool,
    pub bsdf: bool,
}

impl Domains {
    pub const ALL: Domains = Domains {
        pixel: true,
        lens: true,
        time: true,
        light: true,
        bsdf: true,
    };

    #[inline]
    pub fn contains(&self, domain: Domain) -> bool {
        match domain {
            Domain::Pixel => self.pixel,
            Domain::Lens => self.lens,
            Domain::Time => self.time,
            Domain::Light => self.light,
            Domain::Bsdf => self.bsdf,
            Domain::Other => true,
        }
    }
}

impl Domains {
    /// Parses names separated by `sep` (`pixel`, `lens`, `time`, `light`, `bsdf`).
    pub fn parse(text: &str, sep: char) -> Result<Domains, String> {
        let mut d = Domains {
            pixel: false,
            lens: false,
            time: false,
            light: false,
            bsdf: false,
        };
        for name in text.split(sep).map(str::trim).filter(|n| !n.is_empty()) {
            match name {
                "pixel" => d.pixel = true,
                "lens" => d.lens = true,
                "time" => d.time = true,
                "light" => d.light = true,
                "bsdf" => d.bsdf = true,
                other => {
                    return Err(format!(
                        "unknown sampling domain `{other}` (pixel, lens, time, light, bsdf)"
                    ));
                }
            }
        }
        Ok(d)
    }
}

fn yes() -> bool {
    true
}

impl Default for Domains {
    fn default() -> Self {
        Domains::ALL
    }
}
