//! The shape of a field's surface at one point: its unit normal, a tangent frame and the
//! principal curvatures, from two Jacobian-vector products.
//!
//! The mesher's defaults are set from this at `p0` (see [`MeshParams`](crate::MeshParams)),
//! so that a surface meshes the same way at any scale.

use super::NormalField;
use crate::scalar::{Scalar, Vec3};

/// A field whose [integrability defect](LocalShape::integrability_defect) stays below this is
/// treated as integrable (rounding leaves about 1e-16 on the model's integrable fields; a
/// rotation of 0.001 rad leaves 1e-3).
pub const INTEGRABLE_DEFECT: f64 = 1e-9;

/// The local shape of the surface through a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalShape {
    /// The unit field normal.
    pub normal: [f64; 3],
    /// A unit tangent: the coordinate axis least aligned with the normal (the first of equals),
    /// projected onto the tangent plane.
    pub tangent: [f64; 3],
    /// The principal curvatures (eigenvalues of the symmetric part of the shape operator
    /// `(I − n nᵀ) J_v / |v|` on the tangent plane), the larger in magnitude first.
    pub curvatures: [f64; 2],
    /// `|v · (∇ × v)| / (|v|² ‖J_v‖)`: zero (to rounding) where the field is normal to a
    /// family of surfaces (Frobenius), of order one where it is far from any.
    pub integrability_defect: f64,
}

impl LocalShape {
    /// The shape at `p`, or `None` where the field vanishes or is not finite (a singular
    /// point). The field is evaluated in `T`; the result is rounded to `f64`.
    pub fn at<T: Scalar, F: NormalField<T> + ?Sized>(field: &F, p: [f64; 3]) -> Option<LocalShape> {
        let q = Vec3::<T>::from_f64(p);
        let v = field.normal(&q).to_f64();
        let len = norm(v);
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let n = v.map(|x| x / len);
        let tangent = least_aligned_tangent(n);
        let other = cross(n, tangent);
        // S e = (I − n nᵀ) J e / |v| in the frame (tangent, other).
        let jvp = |e: [f64; 3]| field.normal_and_jvp(&q, &Vec3::from_f64(e)).1.to_f64();
        let (j1, j2) = (jvp(tangent), jvp(other));
        let s11 = dot(tangent, j1) / len;
        let s22 = dot(other, j2) / len;
        let s12 = 0.5 * (dot(tangent, j2) + dot(other, j1)) / len;
        let mean = 0.5 * (s11 + s22);
        let root = (0.25 * (s11 - s22).powi(2) + s12 * s12).sqrt();
        let (k1, k2) = (mean + root, mean - root);
        if !(k1.is_finite() && k2.is_finite()) {
            return None;
        }
        let curvatures = if k1.abs() >= k2.abs() {
            [k1, k2]
        } else {
            [k2, k1]
        };
        let j = super::jacobian(field, &q).map(|row| row.to_f64());
        let curl = [j[2][1] - j[1][2], j[0][2] - j[2][0], j[1][0] - j[0][1]];
        let size = j.iter().map(|r| dot(*r, *r)).sum::<f64>().sqrt();
        let integrability_defect = if size > 0.0 {
            dot(v, curl).abs() / (len * len * size)
        } else {
            0.0
        };
        Some(LocalShape {
            normal: n,
            tangent,
            curvatures,
            integrability_defect,
        })
    }

    /// Whether the field is integrable here: its defect is below [`INTEGRABLE_DEFECT`].
    pub fn is_integrable(&self) -> bool {
        self.integrability_defect < INTEGRABLE_DEFECT
    }

    /// The radius of curvature in the most curved direction, `1/|κ|max` (infinite on a flat
    /// patch).
    pub fn radius_of_curvature(&self) -> f64 {
        1.0 / self.curvatures[0].abs()
    }
}

/// The coordinate axis least aligned with the unit normal `n` (the first of equals), projected
/// onto the plane across `n` and normalised: the default initial direction `w00`.
pub fn least_aligned_tangent(n: [f64; 3]) -> [f64; 3] {
    let k = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let mut axis = [0.0; 3];
    axis[k] = 1.0;
    let along = dot(axis, n);
    let t = [0, 1, 2].map(|i| axis[i] - along * n[i]);
    let l = norm(t);
    t.map(|x| x / l)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Invariant, LieField};

    fn field(numbers: &[f64]) -> LieField<f64> {
        LieField::new(&Invariant::from_numbers(numbers).expect("valid invariant"))
    }

    #[test]
    fn a_sphere_of_radius_r_curves_by_one_over_r_everywhere() {
        for r in [1e-3, 1.0, 1e3] {
            let f = field(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]);
            let s = LocalShape::at::<f64, _>(&f, [0.0, r, 0.0]).expect("regular point");
            for k in s.curvatures {
                assert!((k * r - 1.0).abs() < 1e-12, "{k} at radius {r}");
            }
            assert_eq!(s.normal, [0.0, 1.0, 0.0]);
            assert!(dot(s.tangent, s.normal).abs() < 1e-15);
        }
    }

    #[test]
    fn a_cylinder_curves_across_and_not_along() {
        let f = field(&[1.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let s = LocalShape::at::<f64, _>(&f, [2.0, 0.0, 7.0]).expect("regular point");
        assert!((s.curvatures[0] - 0.5).abs() < 1e-12 && s.curvatures[1].abs() < 1e-12);
        assert!((s.radius_of_curvature() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_saddle_has_curvatures_of_both_signs_and_the_origin_none() {
        let f = field(&[1.0, 1.0, -1.0, 0.0, 0.0, 0.0]);
        let s = LocalShape::at::<f64, _>(&f, [1.0, 0.0, 0.0]).expect("regular point");
        assert!(
            s.curvatures[0] * s.curvatures[1] < 0.0,
            "{:?}",
            s.curvatures
        );
        assert!(LocalShape::at::<f64, _>(&f, [0.0, 0.0, 0.0]).is_none());
    }

    #[test]
    fn symmetric_invariants_are_integrable_and_rotated_ones_are_not() {
        let p = [0.3, -0.4, 0.5];
        let symmetric = LocalShape::at::<f64, _>(&field(&[1.0, 4.0, 9.0, 0.0, 0.0, 0.0]), p);
        assert!(symmetric.expect("regular").integrability_defect < 1e-15);
        let literal = LocalShape::at::<f64, _>(&field(&[1.0, 4.0, 9.0, 0.3, 0.5, 0.7]), p);
        assert!(literal.expect("regular").integrability_defect > 1e-3);
    }

    #[test]
    fn the_default_direction_is_the_axis_least_aligned_with_the_normal() {
        assert_eq!(least_aligned_tangent([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
        assert_eq!(least_aligned_tangent([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        let t = least_aligned_tangent([0.6, 0.0, 0.8]);
        assert_eq!(t, [0.0, 1.0, 0.0]);
    }
}
