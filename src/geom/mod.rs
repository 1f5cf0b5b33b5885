//! Geometry on plain `f64` coordinates, below every pipeline stage that needs it: vector
//! arithmetic on `[f64; 3]`, the hasher of the integer-keyed tables (rustc-hash's Fx), exact
//! orientation predicates, exact triangle–triangle intersection and a broad phase for faces.

pub(crate) mod grid;
pub(crate) mod intersect;
pub(crate) mod predicates;
pub(crate) mod rng;
pub(crate) mod rows;
pub(crate) mod union_find;
pub(crate) mod vec3;

use crate::scalar::Vec3;

/// One face's normal error: the angle in degrees between the face with `corners` and
/// `normal_at` its centroid; 180 when that angle is NaN (a non-finite corner or field value),
/// so that such a face counts as the worst.
///
/// This is the error [`crate::quality::face_normal_error`] sums up and refinement to
/// [`MeshParams::max_normal_error`](crate::MeshParams::max_normal_error) bounds.
pub fn face_error_deg(
    corners: [[f64; 3]; 3],
    normal_at: impl FnOnce(&Vec3<f64>) -> Vec3<f64>,
) -> f64 {
    let [a, b, c] = corners.map(Vec3::from_f64);
    let face = (&b - &a).cross(&(&c - &a));
    let centroid = (&(&a + &b) + &c).scale(&(1.0 / 3.0));
    let e = face.angle_to(&normal_at(&centroid)).to_degrees();
    if e.is_nan() {
        180.0
    } else {
        e
    }
}
