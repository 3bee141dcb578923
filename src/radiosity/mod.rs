//! Radiosity's building blocks: meshing diffuse surfaces into elements,
//! form factors between elements, and the solvers of the linear system.
//! The technique that renders with them is `crate::integrator::radiosity`.

pub mod cluster;
pub mod discontinuity;
pub mod element;
pub mod form_factor;
pub mod hierarchy;
pub mod mesh;
pub mod reconstruct;
pub mod solve;
pub mod vertex_field;

pub use element::Element;
pub use form_factor::FormFactorMethod;
pub use hierarchy::{Hierarchy, HierarchySettings};
pub use mesh::Mesh;
pub use solve::{FormFactors, RadiositySolver, Solution};
pub use vertex_field::VertexField;
