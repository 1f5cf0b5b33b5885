//! Geometry on plain `f64` coordinates, below every pipeline stage that needs it: vector
//! arithmetic on `[f64; 3]` and a fast hasher for integer keys.

pub(crate) mod vec3;
