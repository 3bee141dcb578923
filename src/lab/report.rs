//! What an experiment produces: tables, figures and checked statements,
//! as plain data that the CLI prints and writes and the viewer draws.

use crate::error::Result;
use crate::image::write_atomically;
pub use crate::plot::{Axes, Figure, Heatmap, Series, SeriesStyle};
use std::fmt::Write as _;
use std::path::Path;

/// One result of an experiment (or a partial one while it runs).
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub tables: Vec<Table>,
    pub figures: Vec<Figure>,
    pub checks: Vec<Check>,
    /// Stages done and planned: `done == planned` once the run is complete.
    pub stages_done: u32,
    pub stages_planned: u32,
}

/// A table; every row has as many cells as there are columns.
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub title: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
}

/// A table cell: the text shown, and the number written to CSV at full
/// precision where it is one.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    pub text: String,
    pub value: Option<f64>,
}

impl Cell {
    /// `value` with `decimals` digits after the point.
    pub fn fixed(value: f64, decimals: usize) -> Cell {
        Cell {
            text: format!("{value:.decimals$}"),
            value: Some(value),
        }
    }

    /// `value` in scientific notation with 3 significant digits.
    pub fn sci(value: f64) -> Cell {
        Cell {
            text: format!("{value:.3e}"),
            value: Some(value),
        }
    }

    /// An integer.
    pub fn int(value: u64) -> Cell {
        Cell {
            text: value.to_string(),
            value: Some(value as f64),
        }
    }

    /// Text only.
    pub fn text(text: impl Into<String>) -> Cell {
        Cell {
            text: text.into(),
            value: None,
        }
    }
}

/// A statement the experiment checks against what theory says, and whether
/// it holds on this run.
#[derive(Clone, Debug)]
pub struct Check {
    pub statement: String,
    pub measured: String,
    pub holds: bool,
}

impl Report {
    /// The report as the CLI prints it: tables with aligned columns, then the checks.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for table in &self.tables {
            let _ = writeln!(out, "{}", table.title);
            let mut widths: Vec<usize> = table.columns.iter().map(|c| c.chars().count()).collect();
            for row in &table.rows {
                for (w, cell) in widths.iter_mut().zip(row) {
                    *w = (*w).max(cell.text.chars().count());
                }
            }
            let line = |cells: Vec<&str>| {
                let mut s = String::from(" ");
                for (cell, w) in cells.iter().zip(&widths) {
                    let pad = w - cell.chars().count();
                    let _ = write!(s, " {}{}", " ".repeat(pad), cell);
                }
                s
            };
            let _ = writeln!(
                out,
                "{}",
                line(table.columns.iter().map(String::as_str).collect())
            );
            for row in &table.rows {
                let _ = writeln!(
                    out,
                    "{}",
                    line(row.iter().map(|c| c.text.as_str()).collect())
                );
            }
            out.push('\n');
        }
        for check in &self.checks {
            let mark = if check.holds {
                "holds"
            } else {
                "DOES NOT HOLD"
            };
            let _ = writeln!(out, "[{mark}] {}: {}", check.statement, check.measured);
        }
        out
    }

    /// Every table in one CSV file, long format: the table's title in the
    /// first column, then its columns (a header row starts each table).
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        let quote = |s: &str| {
            if s.contains([',', '"', '\n']) {
                format!("\"{}\"", s.replace('"', "\"\""))
            } else {
                s.to_string()
            }
        };
        let mut text = String::new();
        for table in &self.tables {
            let _ = write!(text, "table");
            for c in &table.columns {
                let _ = write!(text, ",{}", quote(c));
            }
            text.push('\n');
            for row in &table.rows {
                text.push_str(&quote(&table.title));
                for cell in row {
                    match cell.value {
                        Some(v) => {
                            let _ = write!(text, ",{v}");
                        }
                        None => {
                            let _ = write!(text, ",{}", quote(&cell.text));
                        }
                    }
                }
                text.push('\n');
            }
        }
        write_atomically(path, |tmp| {
            std::fs::write(tmp, &text).map_err(|e| e.to_string())
        })
    }

    /// Whether every check holds.
    pub fn all_hold(&self) -> bool {
        self.checks.iter().all(|c| c.holds)
    }
}
