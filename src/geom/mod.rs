//! Geometry on plain `f64` coordinates, below every pipeline stage that needs it: vector
//! arithmetic on `[f64; 3]` and the hasher of the integer-keyed tables (rustc-hash's Fx).

pub(crate) mod vec3;
