//! Measuring a mesh.

mod topology;

pub use topology::Topology;
