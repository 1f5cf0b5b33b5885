//! Fields written once for every scalar type, and fields that can be built in every scalar
//! type (what the audits need).
//!
//! A [`NormalField<T>`] is a field in one scalar type. To audit a field (compare its `f64`
//! mesh with the same mesh in `Mpfr<256>`, its dual-number JVP with a central difference at
//! 512 bits), the audit must be able to build it in each type: that is [`EveryScalar`].
//! [`Invariant`] is one (its [`LieField`] in each type). For a field of one's own, write the
//! formula once, generic over [`Scalar`], as a [`FieldFormula`], and wrap it in [`Formula`]:
//! the JVP then comes from evaluating the same formula on dual numbers.
//!
//! ```
//! use liemesh::model::{FieldFormula, Formula, NormalField};
//! use liemesh::scalar::{Scalar, Vec3};
//!
//! /// The torus `(√(x² + y²) − R)² + z² = a²`: the gradient of its quartic
//! /// `(|p|² + R² − a²)² − 4R²(x² + y²)`, divided by 4.
//! #[derive(Clone)]
//! struct Torus {
//!     big: f64,
//!     small: f64,
//! }
//!
//! impl FieldFormula for Torus {
//!     fn normal<T: Scalar>(&self, p: &Vec3<T>) -> Vec3<T> {
//!         let c = |x: f64| T::from_f64(x);
//!         let s = p.norm_squared() + c(self.big * self.big - self.small * self.small);
//!         let r2 = c(2.0 * self.big * self.big);
//!         Vec3::new(
//!             p.x.clone() * (s.clone() - r2.clone()),
//!             p.y.clone() * (s.clone() - r2),
//!             p.z.clone() * s,
//!         )
//!     }
//! }
//!
//! let torus = Formula(Torus { big: 2.0, small: 0.5 });
//! // The same formula in f64 and f32; the JVP from dual numbers.
//! let p = Vec3::new(2.5, 0.0, 0.0);
//! let (v, jw) = NormalField::<f64>::normal_and_jvp(&torus, &p, &Vec3::new(0.0, 0.0, 1.0));
//! assert!(v.x > 0.0 && v.y == 0.0 && v.z == 0.0);
//! assert!(jw.z > 0.0);
//! let v32 = NormalField::<f32>::normal(&torus, &Vec3::new(2.5f32, 0.0, 0.0));
//! assert_eq!(v32.x as f64, v.x);
//! ```

use super::field::{LieField, NormalField};
use super::invariant::Invariant;
use crate::scalar::{Dual, Scalar, Vec3};

/// A normal field written once, generic over the scalar type.
///
/// Only the value is written; [`Formula`] gets the Jacobian-vector product by evaluating the
/// same formula on [`Dual`] numbers (forward-mode AD), in every precision. Constants enter as
/// `T::from_f64(c)`, exact for every type at least as precise as `f64`.
pub trait FieldFormula: Sync {
    /// `v(p)`, in any scalar type.
    fn normal<T: Scalar>(&self, p: &Vec3<T>) -> Vec3<T>;
}

/// A [`FieldFormula`] as a [`NormalField`] in every scalar type (and an [`EveryScalar`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Formula<F>(pub F);

impl<T: Scalar, F: FieldFormula> NormalField<T> for Formula<F> {
    #[inline]
    fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
        self.0.normal(p)
    }

    #[inline]
    fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
        let seeded = Vec3::new(
            Dual::new(p.x.clone(), w.x.clone()),
            Dual::new(p.y.clone(), w.y.clone()),
            Dual::new(p.z.clone(), w.z.clone()),
        );
        let v = self.0.normal(&seeded);
        (v.map(|d| d.re.clone()), v.map(|d| d.eps.clone()))
    }

    fn in_f64(&self) -> Option<&dyn NormalField<f64>> {
        // The same formula in f64: the solvers' cheap first guess for precise types.
        (T::unit_roundoff() < f64::unit_roundoff()).then_some(self as &dyn NormalField<f64>)
    }
}

/// A field that can be built in every scalar type: what the audits take, so that one field
/// is meshed in `f32`, `f64`, `Dual<f64>` and `Mpfr<N>` and the results compared.
///
/// Implemented by [`Invariant`] (its [`LieField`]) and by [`Formula`] (itself).
pub trait EveryScalar: Sync {
    /// The field in the scalar type `T`.
    type Field<T: Scalar>: NormalField<T>;
    /// Builds the field in `T`.
    fn in_scalar<T: Scalar>(&self) -> Self::Field<T>;
}

impl EveryScalar for Invariant {
    type Field<T: Scalar> = LieField<T>;
    fn in_scalar<T: Scalar>(&self) -> LieField<T> {
        LieField::new(self)
    }
}

impl<F: FieldFormula + Clone> EveryScalar for Formula<F> {
    type Field<T: Scalar> = Formula<F>;
    fn in_scalar<T: Scalar>(&self) -> Formula<F> {
        self.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::FnField;

    #[derive(Clone)]
    struct Cubic;
    impl FieldFormula for Cubic {
        fn normal<T: Scalar>(&self, p: &Vec3<T>) -> Vec3<T> {
            let three = T::from_f64(3.0);
            Vec3::new(
                p.x.clone() * p.x.clone() * three,
                p.y.clone() + p.z.clone(),
                p.y.clone() * p.z.clone(),
            )
        }
    }

    #[test]
    fn the_jvp_of_a_formula_is_the_dual_number_pass_of_the_same_formula() {
        let closure = FnField::new(|p: &Vec3<Dual<f64>>| Cubic.normal(p));
        for (p, w) in [
            ([0.3, -0.7, 0.5], [0.2, 0.1, -0.4]),
            ([1.7e3, 2.5e-4, -0.9], [-0.6, 0.8, 1e-9]),
        ] {
            let (p, w) = (Vec3::<f64>::from_f64(p), Vec3::from_f64(w));
            assert_eq!(
                Formula(Cubic).normal_and_jvp(&p, &w),
                closure.normal_and_jvp(&p, &w)
            );
            // J w = (6 x wx, wy + wz, z wy + y wz).
            let (_, jw) = Formula(Cubic).normal_and_jvp(&p, &w);
            assert_eq!(jw.x, 6.0 * p.x * w.x);
        }
    }

    #[test]
    fn an_invariant_builds_its_lie_field_in_every_scalar() {
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        let p = Vec3::new(0.3, -0.7, 0.5);
        let a = NormalField::<f64>::normal(&inv.in_scalar::<f64>(), &p);
        let b = LieField::<f64>::new(&inv).normal(&p);
        assert_eq!(a, b);
        let f32_field = inv.in_scalar::<f32>();
        let v = f32_field.normal(&Vec3::new(0.3f32, -0.7, 0.5));
        assert!((v.x as f64 - a.x).abs() < 1e-6);
    }
}
