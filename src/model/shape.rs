//! The shape of a field's surface at one point: its unit normal, a tangent frame and the
//! principal curvatures, from two Jacobian-vector products.
//!
//! The mesher's defaults are set from this at `p0` (see [`MeshParams`](crate::MeshParams)),
//! so that a surface meshes the same way at any scale.

use super::NormalField;
use crate::scalar::{Scalar, Vec3};

/// A field whose [integrability defect](LocalShape::integrability_defect) stays below this is
/// treated as integrable (rounding leaves about 1e-16 on the model's integrable fields; a
/// rotation of 0.001 rad leaves 1e-3), or below a thousand units of roundoff of the scalar
/// type the field is evaluated in, where that is larger
/// ([`LocalShape::integrable_below`]).
pub const INTEGRABLE_DEFECT: f64 = 1e-9;

/// The defect below which a field evaluated in `T` counts as integrable: [`INTEGRABLE_DEFECT`],
/// or a thousand units of `T`'s roundoff if that is larger. In `f32` rounding alone leaves
/// defects near 10⁻⁷: a torus of one's own at ten times unit size was taken for a twisted field
/// at points away from `p0`, stitched without new points, and kept three triangular holes
/// (closed at unit size, where its coordinates happen to round exactly).
fn integrable_below<T: Scalar>() -> f64 {
    INTEGRABLE_DEFECT.max(jacobian_rounding::<T>())
}

/// What rounding in `T` may leave in a number read off a field's Jacobian relative to its
/// size (a curl, a twist): a thousand units of `T`'s roundoff. The floor below which a field
/// evaluated in `T` cannot be told from a curl-free or integrable one.
pub(crate) fn jacobian_rounding<T: Scalar>() -> f64 {
    1e3 * T::unit_roundoff()
}

/// The local shape of the surface through a point.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct LocalShape {
    /// The unit field normal.
    pub normal: [f64; 3],
    /// A unit tangent: the coordinate axis least aligned with the normal (the first of equals),
    /// projected onto the tangent plane.
    pub tangent: [f64; 3],
    /// The principal curvatures (eigenvalues of the symmetric part of the shape operator
    /// `(I − n nᵀ) J_v / |v|` on the tangent plane), the larger in magnitude first.
    pub curvatures: [f64; 2],
    /// `|v · (∇ × v)| / (|v| ‖J_v‖)`: zero (to rounding) where the field is normal to a
    /// family of surfaces (Frobenius), of order one where it is far from any. Free of units:
    /// the same for the field scaled by any factor and for the surface scaled about any point.
    pub integrability_defect: f64,
    /// The defect below which the field counts as integrable here ([`INTEGRABLE_DEFECT`],
    /// raised to a thousand units of roundoff of the scalar type it was evaluated in).
    pub integrable_below: f64,
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
        // `n · (∇ × n) = v · (∇ × v) / |v|²` is a curvature (one over a length); times the
        // field's own length `|v| / ‖J‖` it is a number, so that neither a field scaled by
        // 10¹⁰ nor a surface 10¹⁰ wide passes for integrable (a twist over `|v|²‖J‖` did).
        let integrability_defect = if size > 0.0 {
            dot(v, curl).abs() / (len * size)
        } else {
            0.0
        };
        Some(LocalShape {
            normal: n,
            tangent,
            curvatures,
            integrability_defect,
            integrable_below: integrable_below::<T>(),
        })
    }

    /// Whether the field is integrable here: its defect is below
    /// [`integrable_below`](Self::integrable_below).
    pub fn is_integrable(&self) -> bool {
        self.integrability_defect < self.integrable_below
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

/// How far a zero of the field may lie from a bend and still be blamed for it, in the bend's
/// radii of curvature. A circular cone of half-angle `α` bends at distance `d` from its apex
/// with radius `d tan α`, so this takes in cones down to a half-angle of about 2°; an
/// elliptic cone's flat side bends more sharply than its apex accounts for, and a step floor
/// met there ends its curve short of where it could have gone.
const ZERO_REACH: f64 = 32.0;

/// How far off the level set through the bend a zero of the field may lie and still be a
/// singular point of the surface: the potential's change to it over `|v| |δ|` (`δ` the step to
/// the zero). On a cone it is zero to rounding; a one-sheet hyperboloid's field `A p`
/// vanishes at the centre, where the ratio is `c / (2 |A p| |p|)` (0.2–0.5 near its waist).
const ON_LEVEL: f64 = 0.01;

/// Whether a bend of the surface at `p` of radius `radius` too sharp for the smallest step can
/// be blamed on a singular point: a zero of the field on the level set through `p`, within
/// [`ZERO_REACH`] radii. For a field integrable at `p` only.
///
/// The field's linearisation at `p` gives the nearest zero (a least-squares Newton step, which
/// also finds a zero set that is a curve), and Simpson's rule for `∫ v · dp` on the way there
/// (exact on a cubic potential) says whether it is on the level set. `false` means the field
/// is regular there and the bend only sharp — a flared one-sheet hyperboloid's waist, whose
/// field vanishes only at the centre, off the surface — so that a curve stopped there was cut
/// short. Where the linearisation has no zero (a field scaled to unit length) nothing is
/// known, and the answer is `true`, as it was before a field could be asked.
pub(crate) fn bend_has_singular_point<T: Scalar, F: NormalField<T> + ?Sized>(
    field: &F,
    p: [f64; 3],
    radius: f64,
) -> bool {
    let at = |x: [f64; 3]| field.normal(&Vec3::<T>::from_f64(x)).to_f64();
    let (v, j) = super::value_and_jacobian(field, &Vec3::<T>::from_f64(p));
    let (v, j) = (v.to_f64(), j.map(|row| row.to_f64()));
    let finite = |a: [f64; 3]| a.iter().all(|x| x.is_finite());
    if !(finite(v) && j.iter().all(|r| finite(*r)) && radius.is_finite()) {
        return true;
    }
    let jm = nalgebra::Matrix3::from_fn(|r, c| j[r][c]);
    let vm = nalgebra::Vector3::from(v);
    let svd = jm.svd(true, true);
    let tolerance = 1e-12 * svd.singular_values.max();
    let Ok(step) = svd.solve(&(-vm), tolerance) else {
        return true;
    };
    // A zero of the linearisation, or none (a unit field's Jacobian is blind along it).
    if (vm + jm * step).norm() > 0.5 * vm.norm() {
        return true;
    }
    let delta: [f64; 3] = step.into();
    let reach = norm(delta);
    if reach > ZERO_REACH * radius {
        return false;
    }
    let mid = [0, 1, 2].map(|k| p[k] + 0.5 * delta[k]);
    let zero = [0, 1, 2].map(|k| p[k] + delta[k]);
    let (vm_, vz) = (at(mid), at(zero));
    let change = [0, 1, 2]
        .map(|k| (v[k] + 4.0 * vm_[k] + vz[k]) * delta[k])
        .iter()
        .sum::<f64>()
        / 6.0;
    // (A change that is not a number says nothing either.)
    change.abs() <= ON_LEVEL * norm(v) * reach || change.is_nan()
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
    fn the_integrability_defect_does_not_depend_on_scale() {
        let numbers = [1.0, 4.0, 9.0, 0.3, 0.5, 0.7];
        let p = [0.3, -0.4, 0.5];
        let defect = |numbers: [f64; 6], p: [f64; 3]| {
            LocalShape::at::<f64, _>(&field(&numbers), p)
                .expect("regular")
                .integrability_defect
        };
        let at_one = defect(numbers, p);
        let stronger = [1e10, 4e10, 9e10, 0.3, 0.5, 0.7];
        for d in [defect(numbers, p.map(|x| x * 1e10)), defect(stronger, p)] {
            assert!((d - at_one).abs() <= 1e-12 * at_one, "{d} against {at_one}");
        }
    }

    #[test]
    fn a_sharp_bend_is_blamed_on_a_cone_apex_but_not_on_a_hyperboloid_centre() {
        // Near a cone's apex the bend's radius is about the distance to it.
        let cone = field(&[1.0, 1.0, -1.0, 0.0, 0.0, 0.0]);
        assert!(bend_has_singular_point::<f64, _>(
            &cone,
            [6e-4, 8e-4, 1e-3],
            1e-3
        ));
        // ... but a bend 100 times sharper than the apex explains is not its doing.
        assert!(!bend_has_singular_point::<f64, _>(
            &cone,
            [6e-4, 8e-4, 1e-3],
            1e-5
        ));
        // A flared waist bends with radius 1/100; its field vanishes only at the centre, too
        // far from the waist, and off the surface even for a bend of radius 1.
        let flared = field(&[1.0, 1.0, -100.0, 0.0, 0.0, 0.0]);
        let waist = [1.02, 0.0, 0.0404f64.sqrt() / 10.0];
        assert!(!bend_has_singular_point::<f64, _>(&flared, waist, 0.01));
        assert!(!bend_has_singular_point::<f64, _>(&flared, waist, 1.0));
        // A field scaled to unit length has no zero to find: nothing is known.
        struct Unit;
        impl<T: Scalar> NormalField<T> for Unit {
            fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
                let n = p.norm_squared().sqrt();
                Vec3::new(
                    p.x.clone() / n.clone(),
                    p.y.clone() / n.clone(),
                    p.z.clone() / n,
                )
            }
            fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
                let n = p.norm_squared().sqrt();
                let u = self.normal(p);
                let along = u.x.clone() * w.x.clone()
                    + u.y.clone() * w.y.clone()
                    + u.z.clone() * w.z.clone();
                let j = Vec3::new(
                    (w.x.clone() - u.x.clone() * along.clone()) / n.clone(),
                    (w.y.clone() - u.y.clone() * along.clone()) / n.clone(),
                    (w.z.clone() - u.z.clone() * along) / n,
                );
                (u, j)
            }
        }
        assert!(bend_has_singular_point::<f64, _>(
            &Unit,
            [0.0, 0.0, 1.0],
            1e-3
        ));
    }

    #[test]
    fn the_default_direction_is_the_axis_least_aligned_with_the_normal() {
        assert_eq!(least_aligned_tangent([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
        assert_eq!(least_aligned_tangent([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        let t = least_aligned_tangent([0.6, 0.0, 0.8]);
        assert_eq!(t, [0.0, 1.0, 0.0]);
    }
}
