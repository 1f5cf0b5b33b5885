//! Geometry on plain `f64` coordinates, below every pipeline stage that needs it: vector
//! arithmetic on `[f64; 3]`, the hasher of the integer-keyed tables (rustc-hash's Fx), exact
//! orientation predicates, exact triangle–triangle intersection and a broad phase for faces.

pub(crate) mod grid;
pub(crate) mod intersect;
pub(crate) mod predicates;
pub(crate) mod vec3;
