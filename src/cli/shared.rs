//! What the render, radiosity and solver commands share: the resolution
//! override and the progress bar.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use tracelab::scene::{Limits, Scene};
use tracelab::{Error, Result};

/// Applies `--width`/`--height` (either alone keeps the other side).
pub(crate) fn override_resolution(
    scene: &mut Scene,
    width: Option<u32>,
    height: Option<u32>,
    limits: &Limits,
) -> Result<()> {
    if width.is_none() && height.is_none() {
        return Ok(());
    }
    let (w, h) = (
        width.unwrap_or(scene.camera.width),
        height.unwrap_or(scene.camera.height),
    );
    limits
        .check_resolution(w, h)
        .map_err(|e| Error::new(format!("--width/--height: {e}")))?;
    scene.set_resolution(w, h);
    Ok(())
}

pub(crate) fn progress_bar(len: u64, unit: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let template =
        format!("{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit} ({{eta}} left)");
    bar.set_style(
        ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
