//! Everything random: the counter-based hash RNG, the samplers that turn
//! (pixel, sample index, dimension) into numbers in [0, 1), the warps that
//! turn those into directions and points with their densities, and the alias
//! table for discrete choices.

pub mod alias;
mod domain;
pub mod hash;
pub mod piecewise;
pub mod sampler;
mod sobol;
pub mod spherical_triangle;
pub mod warp;

pub use alias::AliasTable;
pub use sampler::{Domain, Domains, Sampler, SamplerKind};
