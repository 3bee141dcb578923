//! Numbers for the viewer's plots and readouts: log axes labelled 1, 2, 5,
//! 10, ... and quantiles of per-pixel values.

/// Grid marks of a log10 axis at 1, 2 and 5 times powers of ten, or at
/// powers of ten alone when the axis spans more than four decades; decades
/// get the thicker lines. Labels then read 1, 2, 5, 10, 20 ... instead of
/// 10^x at the plot's own linear steps (1.9953, 2.5119, 3.1623 ...).
pub(super) fn log_grid(input: egui_plot::GridInput) -> Vec<egui_plot::GridMark> {
    let (lo, hi) = input.bounds;
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Vec::new();
    }
    let mantissas: &[f64] = if hi - lo > 4.0 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    let mut marks = Vec::new();
    for decade in (lo.floor() as i32)..=(hi.ceil() as i32) {
        for &m in mantissas {
            let value = f64::from(decade) + m.log10();
            if (lo..=hi).contains(&value) {
                let step_size = if m == 1.0 { 1.0 } else { 0.3 };
                marks.push(egui_plot::GridMark { value, step_size });
            }
        }
    }
    marks
}

/// Axis label of a log10 value: 10^x as a plain number (0.002, 5, 20) where
/// short, else in exponent form (2e-5).
pub(super) fn format_power(x: f64) -> String {
    let v = 10f64.powf(x);
    // Round to 3 significant digits so that log10 round trips print cleanly.
    let digits = 2 - v.log10().floor() as i32;
    let rounded = if digits > 0 {
        let scale = 10f64.powi(digits);
        (v * scale).round() / scale
    } else {
        v.round()
    };
    if (-3.0..=5.0).contains(&x) {
        let s = format!("{rounded:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        let exponent = v.log10().floor();
        let mantissa = (v / 10f64.powf(exponent)).round();
        format!("{mantissa}e{exponent}")
    }
}

/// The `q` quantile (0..=1) of `values`, None when there are none.
pub(super) fn percentile(values: impl Iterator<Item = f32>, q: f32) -> Option<f32> {
    let mut v: Vec<f32> = values.collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f32::total_cmp);
    let i = ((v.len() - 1) as f32 * q).round() as usize;
    Some(v[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_label_one_two_five() {
        let marks = log_grid(egui_plot::GridInput {
            bounds: (0.0, 2.0),
            base_step_size: 0.01,
        });
        let labels: Vec<String> = marks.iter().map(|m| format_power(m.value)).collect();
        assert_eq!(labels, ["1", "2", "5", "10", "20", "50", "100"]);
        let small = log_grid(egui_plot::GridInput {
            bounds: (-3.5, -2.0),
            base_step_size: 0.01,
        });
        let labels: Vec<String> = small.iter().map(|m| format_power(m.value)).collect();
        assert_eq!(labels, ["5e-4", "0.001", "0.002", "0.005", "0.01"]);
        let wide = log_grid(egui_plot::GridInput {
            bounds: (-7.0, 0.0),
            base_step_size: 0.01,
        });
        let labels: Vec<String> = wide.iter().map(|m| format_power(m.value)).collect();
        assert_eq!(labels[0], "1e-7");
        assert_eq!(labels.len(), 8);
    }
}
