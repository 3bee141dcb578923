//! tracelab: a lab for the rendering equation and Monte Carlo light transport.
//!
//! The core (scene, geometry, BVH, sampling, materials, integrators, film)
//! is plain data and free functions; front ends (the CLI, the tests, and the
//! viewer) drive it through [`render::Session`] and [`live::LiveRender`].
//! Only `viewer` (behind the default `viewer` feature) imports egui.

pub mod accel;
pub mod allocation;
pub mod bsdf;
pub mod camera;
pub mod convergence;
pub mod error;
pub mod film;
pub mod filter;
pub mod heap;
pub mod image;
pub mod integrator;
pub mod lab;
pub mod live;
pub mod math;
pub mod plot;
pub mod radiosity;
pub mod render;
pub mod replay;
pub mod sampling;
pub mod scene;
pub mod shortcuts;
pub mod stress;
pub mod texture;
#[cfg(feature = "viewer")]
pub mod viewer;

pub use error::{Error, Result};
