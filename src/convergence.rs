//! Convergence measurements: error against a reference as samples (or time,
//! or rays) grow, for any estimator configuration, and the slope of the
//! log-log curve. `tracelab bench` prints, writes CSV and plots these.

use crate::error::{Error, Result};
use crate::image::{ErrorMetrics, Image};
use crate::integrator::{IntegratorKind, IntegratorOptions, Strategy};
use crate::render::{Adaptive, RenderSettings, Session};
use crate::sampling::{Domains, SamplerKind};
use crate::scene::Scene;
use crate::scene::light::LightSampling;
use std::sync::Arc;
use std::time::Instant;

/// One configuration to measure, as `integrator:sampler[:key=value...]`.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchConfig {
    pub label: String,
    pub integrator: IntegratorOptions,
    pub sampler: SamplerKind,
    pub light_sampling: Option<LightSampling>,
    pub domains: Domains,
    /// Adaptive sampling by noise after this many uniform spp (`distribute=N`).
    pub distribute: Option<u32>,
}

impl BenchConfig {
    /// Parses `path:sobol`, `mcrt:independent:shadow-rays=1:glossy-rays=1`,
    /// `path:stratified:max-depth=1:strategy=light`, `light:independent`.
    pub fn parse(text: &str) -> Result<BenchConfig> {
        let err = |m: String| Error::new(format!("--config `{text}`: {m}"));
        let mut parts = text.split(':');
        let mut integrator = IntegratorOptions {
            kind: {
                let name = parts.next().unwrap_or("");
                IntegratorKind::from_name(name).ok_or_else(|| {
                    err(format!(
                        "unknown integrator `{name}` ({})",
                        IntegratorKind::names()
                    ))
                })?
            },
            ..Default::default()
        };
        let sampler = match parts.next().unwrap_or("independent") {
            "independent" => SamplerKind::Independent,
            "stratified" => SamplerKind::Stratified,
            "multijitter" => SamplerKind::MultiJittered,
            "sobol" => SamplerKind::Sobol,
            other => {
                return Err(err(format!(
                    "unknown sampler `{other}` (independent, stratified, multijitter, sobol)"
                )));
            }
        };
        let mut light_sampling = None;
        let mut domains = Domains::ALL;
        let mut distribute = None;
        for option in parts {
            let (key, value) = option
                .split_once('=')
                .ok_or_else(|| err(format!("`{option}` is not key=value")))?;
            let number = || {
                value
                    .parse::<u32>()
                    .map_err(|_| err(format!("`{key}` needs a whole number, got `{value}`")))
            };
            let kind = integrator.kind;
            let missing = || err(format!("`{key}` is not a setting of {}", kind.name()));
            match key {
                "max-depth" => *integrator.max_depth_mut().ok_or_else(missing)? = number()?,
                "rr-depth" => integrator.length_mut().ok_or_else(missing)?.rr_depth = number()?,
                "rr" => {
                    integrator
                        .length_mut()
                        .ok_or_else(missing)?
                        .russian_roulette = value != "off"
                }
                "seen-emitters" => {
                    let exact = match value {
                        "exact" => true,
                        "sampled" => false,
                        _ => return Err(err(format!("seen-emitters `{value}` (exact, sampled)"))),
                    };
                    match kind {
                        IntegratorKind::Path => integrator.path.exact_seen_emitters = exact,
                        IntegratorKind::Mcrt => integrator.mcrt.exact_seen_emitters = exact,
                        _ => return Err(missing()),
                    }
                }
                "shadow-rays" if kind == IntegratorKind::Mcrt => {
                    integrator.mcrt.shadow_rays = number()?
                }
                "glossy-rays" if kind == IntegratorKind::Mcrt => {
                    integrator.mcrt.glossy_rays = number()?
                }
                "strategy" if kind == IntegratorKind::Path => {
                    integrator.path.strategy = match value {
                        "bsdf" => Strategy::Bsdf,
                        "light" => Strategy::Light,
                        "mis" => Strategy::Mis,
                        _ => return Err(err(format!("strategy `{value}` (bsdf, light, mis)"))),
                    }
                }
                "light-paths" if kind == IntegratorKind::Bdpt => {
                    integrator.bdpt.light_paths = number()?
                }
                "light-path-bounces" if kind == IntegratorKind::Bdpt => {
                    integrator.bdpt.light_path_bounces = number()?
                }
                "shadow-rays" | "glossy-rays" | "strategy" | "light-paths"
                | "light-path-bounces" => return Err(missing()),
                "light-sampling" => {
                    light_sampling = Some(match value {
                        "area" => LightSampling::Area,
                        "solid-angle" => LightSampling::SolidAngle,
                        _ => {
                            return Err(err(format!(
                                "light-sampling `{value}` (area, solid-angle)"
                            )));
                        }
                    })
                }
                "domains" => domains = Domains::parse(value, '+').map_err(err)?,
                "distribute" => distribute = Some(number()?.max(1)),
                _ => return Err(err(format!("unknown option `{key}`"))),
            }
        }
        integrator.validate().map_err(err)?;
        Ok(BenchConfig {
            label: text.to_string(),
            integrator,
            sampler,
            light_sampling,
            domains,
            distribute,
        })
    }
}

/// One measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkpoint {
    pub spp: u32,
    /// Wall-clock render time.
    pub seconds: f64,
    /// CPU time of the whole process over the render (all threads), when
    /// the platform reports it: about `seconds` x threads when the threads
    /// are not waiting.
    pub cpu_seconds: Option<f64>,
    pub rays_per_pixel: f64,
    pub error: ErrorMetrics,
    /// RMSE (over the pixels [`ErrorOver`] chose) with the reference's own
    /// noise taken out: sqrt(MSE - mean reference variance), when the
    /// variance is known; else the RMSE.
    pub rmse: f64,
}

/// When a measurement stops doubling the sample count (besides `max_spp`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopAt {
    /// Once a checkpoint's RMSE is at most this.
    pub rmse: Option<f64>,
    /// Once a checkpoint took at least this many seconds.
    pub seconds: Option<f64>,
}

/// Which error a measurement's [`Checkpoint::rmse`] reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ErrorOver {
    /// Every pixel.
    #[default]
    AllPixels,
    /// Every pixel but the worst 0.1% ([`ErrorMetrics::trimmed_rmse`]).
    Trimmed,
}

impl Checkpoint {
    /// Efficiency 1 / (MSE x time): constant for an unbiased estimator whose
    /// MSE falls as 1/time; higher is better.
    pub fn efficiency(&self) -> f64 {
        1.0 / (self.rmse * self.rmse * self.seconds)
    }
}

/// Render time needed to reach `target` RMSE: interpolated log-log between
/// the two checkpoints that bracket it (RMSE ~ time^slope locally), or the
/// first checkpoint's time if it is already below. None if never reached.
pub fn time_to_rmse(points: &[Checkpoint], target: f64) -> Option<f64> {
    let first = points.first()?;
    if first.rmse <= target {
        return Some(first.seconds);
    }
    points.windows(2).find_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        if b.rmse > target || a.rmse <= 0.0 || b.rmse <= 0.0 {
            return None;
        }
        let (ta, tb) = (a.seconds.max(1e-9).ln(), b.seconds.max(1e-9).ln());
        let (ea, eb) = (a.rmse.ln(), b.rmse.ln());
        if ea == eb {
            return Some(b.seconds);
        }
        let f = (target.ln() - ea) / (eb - ea);
        Some((ta + f * (tb - ta)).exp())
    })
}

/// Renders `config` separately at 1, 2, 4, ... `max_spp` samples per pixel
/// (each render plans its own count, so stratified samplers are measured at
/// their best) and compares each image with `reference`, stopping early as
/// `stop` says.
#[allow(clippy::too_many_arguments)]
pub fn measure(
    scene: &Arc<Scene>,
    config: &BenchConfig,
    reference: &Image,
    reference_mse: f64,
    max_spp: u32,
    stop: StopAt,
    over: ErrorOver,
    seed: u64,
    threads: usize,
) -> Result<Vec<Checkpoint>> {
    let scene = match config.light_sampling {
        Some(mode) => {
            let mut s = (**scene).clone();
            s.set_light_sampling(mode);
            Arc::new(s)
        }
        None => scene.clone(),
    };
    let pixels = f64::from(scene.camera.width) * f64::from(scene.camera.height);
    let pool = crate::render::thread_pool(threads)?;
    let mut out = Vec::new();
    let mut spp = 1;
    while spp <= max_spp {
        let settings = RenderSettings {
            integrator: config.integrator.build(),
            sampler: config.sampler,
            seed,
            planned_spp: spp,
            threads,
            adaptive: config
                .distribute
                .map(|warmup_spp| Adaptive::Distribute { warmup_spp }),
            domains: config.domains,
            clamp: None,
            filter_sampling: Default::default(),
        };
        let session = Session::with_pool(scene.clone(), settings, pool.clone());
        let start = Instant::now();
        let cpu_start = cpu_time::ProcessTime::try_now().ok();
        let mut done = 0;
        while done < spp {
            // Distributing re-plans after every pass: let passes double.
            let pass = if config.distribute.is_some() {
                done.max(1)
            } else {
                spp
            };
            let k = (spp - done).min(pass).min(64);
            session.render_pass(k);
            done += k;
        }
        let seconds = start.elapsed().as_secs_f64();
        let cpu_seconds = cpu_start
            .and_then(|t| t.try_elapsed().ok())
            .map(|d| d.as_secs_f64());
        let stats = session.stats();
        let error = session.snapshot().image.compare(reference)?;
        out.push(Checkpoint {
            spp,
            seconds,
            cpu_seconds,
            rays_per_pixel: stats.rays.total() as f64 / pixels,
            error,
            rmse: {
                let rmse = match over {
                    ErrorOver::AllPixels => error.rmse,
                    ErrorOver::Trimmed => error.trimmed_rmse,
                };
                (rmse * rmse - reference_mse).max(0.0).sqrt()
            },
        });
        let last = out[out.len() - 1];
        let reached = stop.rmse.is_some_and(|e| last.rmse <= e)
            || stop.seconds.is_some_and(|s| last.seconds >= s);
        if config.integrator.build().is_deterministic() || reached {
            break;
        }
        spp *= 2;
    }
    Ok(out)
}

/// Mean over pixels and channels of a per-pixel variance image: the MSE a
/// reference with that variance adds to every comparison.
pub fn mean_variance(variance: &Image) -> f64 {
    let n = (variance.pixels.len() * 3).max(1) as f64;
    variance
        .pixels
        .iter()
        .flat_map(|p| p.iter())
        .map(|v| f64::from(*v))
        .sum::<f64>()
        / n
}

/// Least-squares slope of log(rmse) against log(spp) over the checkpoints
/// with at least `from_spp` samples (the asymptotic rate).
pub fn log_log_slope(points: &[Checkpoint], from_spp: u32) -> Option<f64> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.spp >= from_spp && p.rmse > 0.0)
        .map(|p| (f64::from(p.spp).ln(), p.rmse.ln()))
        .collect();
    if xy.len() < 2 {
        return None;
    }
    let n = xy.len() as f64;
    let (mx, my) = (
        xy.iter().map(|p| p.0).sum::<f64>() / n,
        xy.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod time_to_rmse_tests {
    use super::*;

    fn point(seconds: f64, rmse: f64) -> Checkpoint {
        Checkpoint {
            spp: 1,
            seconds,
            cpu_seconds: None,
            rays_per_pixel: 0.0,
            error: ErrorMetrics::default(),
            rmse,
        }
    }

    #[test]
    fn interpolates_on_the_log_log_line() {
        // RMSE = 0.1 / sqrt(t): 0.1 at t = 1, 0.05 at t = 4, 0.025 at t = 16.
        let points = [point(1.0, 0.1), point(4.0, 0.05), point(16.0, 0.025)];
        let t = time_to_rmse(&points, 0.04).unwrap();
        assert!((t - (0.1f64 / 0.04).powi(2)).abs() < 1e-9, "{t}");
        assert_eq!(time_to_rmse(&points, 0.2), Some(1.0));
        assert_eq!(time_to_rmse(&points, 0.01), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn configs_parse_with_options_and_reject_typos() {
        let c =
            BenchConfig::parse("mcrt:independent:shadow-rays=5:glossy-rays=2:max-depth=3").unwrap();
        assert_eq!(c.integrator.kind, IntegratorKind::Mcrt);
        assert_eq!(
            (c.integrator.mcrt.shadow_rays, c.integrator.mcrt.glossy_rays),
            (5, 2)
        );
        assert_eq!(c.integrator.max_depth(), Some(3));
        // A setting the technique does not have is refused, not ignored.
        assert!(BenchConfig::parse("light:independent:shadow-rays=5").is_err());
        let c = BenchConfig::parse("path:sobol:strategy=light:light-sampling=solid-angle").unwrap();
        assert_eq!(c.sampler, SamplerKind::Sobol);
        assert_eq!(c.integrator.path.strategy, Strategy::Light);
        assert_eq!(c.light_sampling, Some(LightSampling::SolidAngle));
        assert_eq!(c.distribute, None);
        let c = BenchConfig::parse("path:sobol:distribute=4").unwrap();
        assert_eq!(c.distribute, Some(4));
        assert!(BenchConfig::parse("path:sobol:distribute=x").is_err());
        let c = BenchConfig::parse("bdpt:sobol:light-paths=4:light-path-bounces=3").unwrap();
        assert_eq!(
            (
                c.integrator.bdpt.light_paths,
                c.integrator.bdpt.light_path_bounces
            ),
            (4, 3)
        );
        assert!(BenchConfig::parse("path:sobol:light-paths=4").is_err());
        assert!(BenchConfig::parse("bdpt:sobol:light-paths=0").is_err());
        assert!(BenchConfig::parse("bdpt:sobol:light-path-bounces=33").is_err());
        assert!(BenchConfig::parse("paht:sobol").is_err());
        assert!(BenchConfig::parse("path:sobel").is_err());
        assert!(BenchConfig::parse("path:sobol:depth=3").is_err());
        assert!(BenchConfig::parse("path:sobol:max-depth=x").is_err());
    }

    #[test]
    fn slope_of_a_power_law_is_its_exponent() {
        let points: Vec<Checkpoint> = (0..8)
            .map(|k| {
                let spp = 1u32 << k;
                let rmse = 0.3 * f64::from(spp).powf(-0.75);
                Checkpoint {
                    rmse,
                    spp,
                    seconds: 0.0,
                    cpu_seconds: None,
                    rays_per_pixel: 0.0,
                    error: ErrorMetrics {
                        rmse,
                        relative_mse: 0.0,
                        mean_relative_error: 0.0,
                        trimmed_rmse: 0.0,
                    },
                }
            })
            .collect();
        assert!((log_log_slope(&points, 1).unwrap() + 0.75).abs() < 1e-9);
    }
}
