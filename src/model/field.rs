//! Normal fields: what the mesher consumes.

use super::invariant::{AngleReading, Invariant, Lift, Mat3};
use crate::geom::vec3;
use crate::scalar::{Dual, Scalar, Vec3};

/// A normal field `v: R³ → R³` evaluated in the scalar type `T`.
///
/// The mesher needs the field value and one Jacobian-vector product `J_v(p) w` per step
/// (the paper's eq. 8–9). Implement both for your own field, or wrap a closure written for
/// dual numbers in [`FnField`], which gets both from one forward-mode pass.
///
/// A field is a pure function, so it must be `Sync`: the relaxation evaluates it on all
/// cores at once (the result does not depend on how many).
///
/// Implement it for every `T: Scalar` at once to be able to audit your field in `f32`, `f64`
/// and MPFR (or write only the value as a [`crate::model::FieldFormula`] and let dual numbers
/// give the JVP):
///
/// ```
/// use liemesh::model::NormalField;
/// use liemesh::scalar::{Dual, Scalar, Vec3};
///
/// /// The unit sphere's field `v(p) = p`.
/// struct Radial;
/// impl<T: Scalar> NormalField<T> for Radial {
///     fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
///         p.clone()
///     }
///     fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
///         (p.clone(), w.clone())
///     }
/// }
/// let (v, jw) = NormalField::<f64>::normal_and_jvp(&Radial, &Vec3::new(0.0, 0.0, 1.0), &Vec3::new(1.0, 0.0, 0.0));
/// assert_eq!((v.z, jw.x), (1.0, 1.0));
/// ```
pub trait NormalField<T: Scalar>: Sync {
    /// `v(p)`.
    fn normal(&self, p: &Vec3<T>) -> Vec3<T>;
    /// `(v(p), J_v(p) w)`.
    fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>);
    /// The same field evaluated in `f64`, offered when `T` is more precise than `f64`.
    ///
    /// Solvers use it for a cheap first guess that they then refine in `T` to `T`'s own
    /// tolerance, so the result does not depend on it beyond rounding: the drift-free chord
    /// finds its angle in `f64` and then needs one Newton iteration with Jacobian-vector
    /// products at 256 bits, and one or two with field values only, instead of four or five
    /// with products. The default, `None`, runs every iteration in `T`.
    fn in_f64(&self) -> Option<&dyn NormalField<f64>> {
        None
    }
    /// How far from the origin the surface through `p0` reaches, when the field knows it
    /// (an ellipsoid's longest semi-axis, a hyperboloid's or a cylinder's widest waist):
    /// the automatic terminal conditions then reach at least that far, where the shape at
    /// `p0` alone could not tell (the flat side of a long ellipsoid looks like a cylinder).
    ///
    /// The default estimates it from the centres of curvature at `p0` on an integrable field
    /// ([`crate::Scales::centres_reach`]: a torus meshed from its inner equator reaches out
    /// round its tube's centre), and otherwise returns `None`, which leaves the terminal
    /// conditions to the shape at `p0` ([`crate::Scales`]).
    fn size_through(&self, p0: [f64; 3]) -> Option<f64> {
        let shape = crate::model::LocalShape::at::<T, Self>(self, p0)?;
        if !shape.is_integrable() {
            return None;
        }
        crate::Scales::of(p0, &shape).centres_reach(p0, &shape)
    }

    /// The semi-axes of the surface through `p0`, shortest first, when the field knows it is
    /// an ellipsoid: the automatic step clamps then keep steps shorter than the ellipsoid is
    /// thick and let them shrink enough for its sharpest bend (`shortest² / longest`), which
    /// the shape at `p0` cannot tell (the pole of a flattened ellipsoid is nearly flat, its
    /// rim is sharp). The default, `None`, leaves the clamps to the shape at `p0`.
    fn semi_axes_through(&self, p0: [f64; 3]) -> Option<[f64; 3]> {
        let _ = p0;
        None
    }

    /// Whether the field is known not to vanish anywhere on the surface through `p0`: the
    /// surface then has no singular point, and a curve whose steps cannot follow its bend even
    /// at `dt_min` (the waist of a sharply flared hyperboloid, the rim of a flat ellipsoid)
    /// ends on the step floor, which the run reports as cut short by a budget, not as at a
    /// singular point. The default says so for an ellipsoid the field knows
    /// ([`Self::semi_axes_through`]) and otherwise `false`, which is always safe: a field
    /// integrable at `p0` is then asked at each such bend whether it vanishes on the surface
    /// near it (a zero of its linearisation on the level set, within a few dozen radii of the
    /// bend), and only then is the end counted as at a singular point.
    fn is_regular_through(&self, p0: [f64; 3]) -> bool {
        self.semi_axes_through(p0).is_some()
    }

    /// The hole the surface through `p0` goes round, when the field knows it is a band: a
    /// one-sheet hyperboloid's or an elliptic cylinder's waist ([`Hole`]). The mesh
    /// then keeps every triangle off the hole's axis (the stitching, the flips and the last
    /// check of a run, [`crate::run`]), a boundary loop that does not go round the axis is
    /// reported as a hole ([`crate::triangulate::Stitched::holes`]), and no automatic step is
    /// longer than the waist's narrowest radius (from a flat flange, steps sized at `p0` would
    /// go round it in a hexagon). The default, `None`, does none of this.
    fn hole_through(&self, p0: [f64; 3]) -> Option<Hole> {
        let _ = p0;
        None
    }

    /// Whether the field is exactly the gradient of a polynomial of degree at most three, as
    /// every integrable invariant's field is. The drift-free chord is exact on such a field
    /// (Simpson's rule integrates its quadratic `v·dp` exactly). On any other integrable field
    /// each chord is corrected back onto its level set (its potential error found with
    /// Gauss–Legendre's five-point rule, removed by Newton steps along the normal), at six
    /// more field values a step.
    /// The default, `false`, is always safe; `true` on a field that is not such a gradient
    /// leaves its chords' drift uncorrected.
    fn has_cubic_potential(&self) -> bool {
        false
    }
}

impl<T: Scalar, F: NormalField<T> + ?Sized> NormalField<T> for &F {
    #[inline(always)]
    fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
        (**self).normal(p)
    }
    #[inline(always)]
    fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
        (**self).normal_and_jvp(p, w)
    }
    #[inline(always)]
    fn in_f64(&self) -> Option<&dyn NormalField<f64>> {
        (**self).in_f64()
    }
    fn size_through(&self, p0: [f64; 3]) -> Option<f64> {
        (**self).size_through(p0)
    }
    fn semi_axes_through(&self, p0: [f64; 3]) -> Option<[f64; 3]> {
        (**self).semi_axes_through(p0)
    }
    fn is_regular_through(&self, p0: [f64; 3]) -> bool {
        (**self).is_regular_through(p0)
    }
    fn hole_through(&self, p0: [f64; 3]) -> Option<Hole> {
        (**self).hole_through(p0)
    }
    fn has_cubic_potential(&self) -> bool {
        (**self).has_cubic_potential()
    }
}

/// The hole a band goes round (a one-sheet hyperboloid's or a cylinder's waist), as a field
/// knows it ([`NormalField::hole_through`]).
///
/// The mesher takes every loop on the surface that does not go round the axis to bound a
/// disc of it, which holds for a band but not for a torus (a loop round its tube does not go
/// round its axis either): declare holes of bands only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hole {
    axis: [[f64; 3]; 2],
    waist: f64,
}

impl Hole {
    /// The hole whose axis is the line through the two distinct points `axis` (a line the
    /// surface never meets), round which the surface is at least `waist` wide (its narrowest
    /// radius about the axis); `None` unless the points are finite and distinct and `waist`
    /// finite and positive.
    ///
    /// ```
    /// use liemesh::model::Hole;
    /// // The hyperboloid x² + y² − 4z² = 2.25 about the z axis: its waist has radius 1.5.
    /// let hole = Hole::new([[0.0; 3], [0.0, 0.0, 1.0]], 1.5).unwrap();
    /// assert_eq!(hole.waist(), 1.5);
    /// assert!(Hole::new([[0.0; 3], [0.0; 3]], 1.5).is_none());
    /// ```
    pub fn new(axis: [[f64; 3]; 2], waist: f64) -> Option<Hole> {
        let finite = axis.iter().flatten().all(|x| x.is_finite());
        (finite && axis[0] != axis[1] && waist.is_finite() && waist > 0.0)
            .then_some(Hole { axis, waist })
    }
    /// Two distinct points on the axis.
    pub fn axis(&self) -> [[f64; 3]; 2] {
        self.axis
    }
    /// The surface's narrowest radius about the axis.
    pub fn waist(&self) -> f64 {
        self.waist
    }

    /// The distance of `p` from the axis.
    ///
    /// ```
    /// use liemesh::model::Hole;
    /// let hole = Hole::new([[0.0; 3], [0.0, 0.0, 2.0]], 1.0).unwrap();
    /// assert_eq!(hole.radius_about([3.0, 4.0, 100.0]), 5.0);
    /// ```
    pub fn radius_about(&self, p: [f64; 3]) -> f64 {
        let [a, b] = self.axis;
        let d = vec3::sub(b, a);
        let c = vec3::cross(vec3::sub(p, a), d);
        (vec3::dot(c, c) / vec3::dot(d, d)).sqrt()
    }
}

/// The field of an [`Invariant`]: `v(p) = A p + B ℓ₂(p)`, the upper block of `H ℓ(p)`.
///
/// The matrices are stored in the scalar type `T`, so an `f64` field never converts per
/// evaluation, an MPFR field has MPFR-accurate rotations, and a `Dual<f64>` field built
/// with [`LieField::seeded`] carries the derivative with respect to one invariant number.
///
/// The JVP is one forward-mode pass seeded with `w` (eq. 8–9), written out: the matrix
/// entries stay plain `T` and multiply the value and the derivative parts alike.
#[derive(Clone, Debug)]
pub struct LieField<T> {
    a: Mat3<T>,
    b: Mat3<T>,
    c: Mat3<T>,
    lift: Lift,
    /// `false` when `B = 0`: the quadratic term is skipped (the linear model).
    quadratic: bool,
    /// The field rounded to `f64` when `T` is more precise ([`NormalField::in_f64`]).
    in_f64: Option<Box<LieField<f64>>>,
}

impl<T: Scalar> LieField<T> {
    /// The field of `invariant`, with matrices computed in `T`.
    pub fn new(invariant: &Invariant) -> Self {
        Self::from_parameters(&invariant.parameters::<T>(), invariant.reading())
    }

    /// The field whose invariant number `index` (in the 18-number layout: row-major over
    /// Table 2's three rows, so 0..6 build `A`) is the dual variable: running the mesher on
    /// it gives every vertex's derivative with respect to that number.
    pub fn seeded(invariant: &Invariant, index: usize) -> LieField<Dual<T>> {
        let params: Vec<Dual<T>> = invariant
            .parameters::<T>()
            .into_iter()
            .enumerate()
            .map(|(i, x)| {
                if i == index {
                    Dual::variable(x)
                } else {
                    Dual::constant(x)
                }
            })
            .collect();
        LieField::from_parameters(&params, invariant.reading())
    }

    /// The field from the 18 numbers of the Table 2 layout, already in `T`, with the angles
    /// read as `reading` says.
    pub fn from_parameters(params: &[T], reading: AngleReading) -> Self {
        let a = reading.matrix(&params[0..6]);
        let b = reading.matrix(&params[6..12]);
        let c = reading.matrix(&params[12..18]);
        let quadratic = b
            .iter()
            .any(|r| !(r.x.is_zero() && r.y.is_zero() && r.z.is_zero()));
        let in_f64 = (T::unit_roundoff() < f64::unit_roundoff()).then(|| {
            let rounded: Vec<f64> = params.iter().map(Scalar::to_f64).collect();
            Box::new(LieField::from_parameters(&rounded, reading))
        });
        LieField {
            a,
            b,
            c,
            lift: Lift::Squares,
            quadratic,
            in_f64,
        }
    }

    /// The matrix `A`.
    pub fn a(&self) -> &Mat3<T> {
        &self.a
    }
    /// The matrix `B`.
    pub fn b(&self) -> &Mat3<T> {
        &self.b
    }
    /// The matrix `C` (part of `H`; it does not enter the 3-D field under [`Lift::Squares`]).
    pub fn c(&self) -> &Mat3<T> {
        &self.c
    }

    /// For a quadric (`B = 0`, `A` symmetric), the eigenvalues of `A` and the level
    /// `c = p0ᵀ A p0`, both for `A` scaled to entries of order one (so that the eigen solver
    /// neither overflows nor underflows; the semi-axes `√(c / λ)` do not change). Eigenvalues
    /// within the rounding of `A` ([`rounding_of`]) are exactly zero, so callers test `λ c`'s
    /// sign alone.
    fn quadric_through(&self, p0: [f64; 3]) -> Option<([f64; 3], f64)> {
        self.quadric_frame_through(p0).map(|(l, _, c)| (l, c))
    }

    /// [`Self::quadric_through`] with the unit eigenvectors of `A` beside its eigenvalues.
    #[allow(clippy::type_complexity)]
    fn quadric_frame_through(&self, p0: [f64; 3]) -> Option<([f64; 3], [[f64; 3]; 3], f64)> {
        if self.quadratic {
            return None;
        }
        let a: [[f64; 3]; 3] = std::array::from_fn(|i| self.a[i].to_f64());
        let scale = a.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
        let tolerance = rounding_of::<T>();
        let symmetric =
            (0..3).all(|i| (0..i).all(|j| (a[i][j] - a[j][i]).abs() <= tolerance * scale));
        if !(symmetric && scale.is_finite() && scale > 0.0) {
            return None;
        }
        let m = nalgebra::Matrix3::from_fn(|i, j| a[i][j] / scale);
        let p = nalgebra::Vector3::from(p0);
        let c = p.dot(&(m * p));
        let eigen = nalgebra::SymmetricEigen::new(m);
        let vectors = [0, 1, 2].map(|k| [0, 1, 2].map(|i| eigen.eigenvectors[(i, k)]));
        // An eigenvalue within the rounding of `A` is zero: a cylinder turned in `f32` has
        // one of 10⁻⁸, which made it a band 10⁴ wide, sized by that "semi-axis".
        let eigenvalues = [0, 1, 2].map(|k| {
            let l = eigen.eigenvalues[k];
            if l.abs() <= tolerance {
                0.0
            } else {
                l
            }
        });
        Some((eigenvalues, vectors, c))
    }
}

/// How far rounding in the scalar `T` may have moved `A`'s entries and eigenvalues, relative
/// to its largest entry: the field builds `A` in `T`, so an `f32` field's turned cylinder has
/// an eigenvalue of 10⁻⁸ where it should have 0. Never below `10⁻¹²` (`f64`'s).
fn rounding_of<T: Scalar>() -> f64 {
    (64.0 * T::unit_roundoff()).max(1e-12)
}

/// A quadric's level `c` (for `A` scaled to entries of at most one) counts as clear of zero
/// from this many times `|p0|²`: a `p0` on a cone put there in `f64` gives `c` of about
/// 10⁻¹⁶ `|p0|²`.
const REGULAR_LEVEL: f64 = 1e-9;

/// Whether a quadric's level `c` through `p0` (of `A` scaled to entries of at most one, so
/// that `|c| ≤ 3 |p0|²`) is clear of zero: not a cone, whose `p0` gives a `c` of rounding size.
/// In a scalar coarser than `f64`, `c` is also off by the rounding of `A`'s entries (a cone
/// turned in `f32`: about 10⁻⁷ `|p0|²`), so the bar is at least four times that bound.
fn clear_of_zero<T: Scalar>(c: f64, p0: [f64; 3]) -> bool {
    let level = REGULAR_LEVEL.max(4.0 * rounding_of::<T>());
    c.abs() > level * p0.iter().map(|x| x * x).sum::<f64>()
}

#[inline(always)]
fn mat_vec<T: Scalar>(m: &Mat3<T>, p: &Vec3<T>) -> Vec3<T> {
    Vec3::new(m[0].dot(p), m[1].dot(p), m[2].dot(p))
}

impl<T: Scalar> NormalField<T> for LieField<T> {
    #[inline]
    fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
        let v = mat_vec(&self.a, p);
        if self.quadratic {
            let mut v = v;
            v += &mat_vec(&self.b, &self.lift.lower(p));
            v
        } else {
            v
        }
    }

    #[inline]
    fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
        // The forward-mode pass written out: the value and the derivative parts of
        // `A p + B ℓ₂(p)` side by side, the same operations a dual number would do, without
        // building dual numbers (for MPFR that is a third of the allocations).
        let mut v = mat_vec(&self.a, p);
        let mut jw = mat_vec(&self.a, w);
        if self.quadratic {
            v += &mat_vec(&self.b, &self.lift.lower(p));
            jw += &mat_vec(&self.b, &self.lift.lower_derivative(p, w));
        }
        (v, jw)
    }

    fn in_f64(&self) -> Option<&dyn NormalField<f64>> {
        self.in_f64.as_deref().map(|f| f as &dyn NormalField<f64>)
    }

    /// `A` symmetric and `B` diagonal, exactly: `v = ∇(½ pᵀ A p + Σ Bᵢᵢ pᵢ³ / 3)`.
    fn has_cubic_potential(&self) -> bool {
        let (a, b) = (&self.a, &self.b);
        let entry = |m: &Mat3<T>, i: usize, j: usize| match j {
            0 => m[i].x.clone(),
            1 => m[i].y.clone(),
            _ => m[i].z.clone(),
        };
        (0..3).all(|i| {
            (0..3).all(|j| {
                i == j || (entry(a, i, j) == entry(a, j, i) && entry(b, i, j) == T::zero())
            })
        }) && match self.lift {
            // `B ℓ₂(p)` with diagonal `B` is `∇(Σ Bᵢᵢ pᵢ³ / 3)` for this lift; another lift
            // must say whether its term is a gradient.
            Lift::Squares => true,
        }
    }

    /// For a quadric (`B = 0`, `A` symmetric: the level set `pᵀ A p = c` through `p0`), its
    /// largest semi-axis `√(c / λ)` over the eigenvalues `λ` of `A` of the sign of `c`, the
    /// directions in which it is bounded. `None` for other fields and for a cone (`c = 0`),
    /// rather than the default's estimate from the centres of curvature: on an invariant's
    /// own field, the shape at `p0` sizes the terminal conditions.
    fn size_through(&self, p0: [f64; 3]) -> Option<f64> {
        let (eigenvalues, c) = self.quadric_through(p0)?;
        let size = eigenvalues
            .iter()
            .filter(|&&l| l * c > 0.0)
            .map(|&l| (c / l).sqrt())
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        size.filter(|s| s.is_finite() && *s > 0.0)
    }

    /// For a quadric other than a cone (`pᵀ A p = c` with `c` clear of zero: every ellipsoid,
    /// hyperboloid and elliptic cylinder), `true`: its gradient `2 A p` vanishes only where
    /// `pᵀ A p = 0`. A cone's apex is a singular point; other fields may have them.
    fn is_regular_through(&self, p0: [f64; 3]) -> bool {
        self.quadric_through(p0)
            .is_some_and(|(_, c)| clear_of_zero::<T>(c, p0))
    }

    /// For a quadric `pᵀ A p = c` (`c` clear of zero) with exactly one eigenvalue `λ` of `A`
    /// not of the sign of `c` (a one-sheet hyperboloid, `λ c < 0`, or an elliptic cylinder,
    /// `λ = 0`): the line through the origin along its eigenvector, on which `pᵀ A p = λ t²`
    /// never equals `c`, and the waist's shorter semi-axis, the smallest `√(c / μ)` over the
    /// other two eigenvalues `μ`.
    fn hole_through(&self, p0: [f64; 3]) -> Option<Hole> {
        let (eigenvalues, vectors, c) = self.quadric_frame_through(p0)?;
        if !clear_of_zero::<T>(c, p0) {
            return None;
        }
        let across = |k: usize| eigenvalues[k] * c <= 0.0;
        let mut axes = (0..3).filter(|&k| across(k));
        let (Some(k), None) = (axes.next(), axes.next()) else {
            return None;
        };
        let waist = (0..3)
            .filter(|&j| j != k)
            .map(|j| (c / eigenvalues[j]).sqrt())
            .fold(f64::INFINITY, f64::min);
        // The second point as far out as `p0`, so that both are of the surface's scale.
        let r = p0.iter().map(|x| x * x).sum::<f64>().sqrt();
        let far = vectors[k].map(|x| x * r);
        Hole::new([[0.0; 3], far], waist)
    }

    /// For a quadric that is an ellipsoid (every eigenvalue `λ` of `A` of the sign of `c`),
    /// its semi-axes `√(c / λ)`, shortest first.
    fn semi_axes_through(&self, p0: [f64; 3]) -> Option<[f64; 3]> {
        let (eigenvalues, c) = self.quadric_through(p0)?;
        if !eigenvalues.iter().all(|&l| l * c > 0.0) {
            return None;
        }
        let mut axes = eigenvalues.map(|l| (c / l).sqrt());
        axes.sort_by(f64::total_cmp);
        axes.iter()
            .all(|s| s.is_finite() && *s > 0.0)
            .then_some(axes)
    }
}

/// A field given by a closure over dual numbers, so that one closure yields both the value
/// and the Jacobian-vector product. The closure is tied to one scalar type; to run (and
/// audit) a field in every precision, write it as a [`crate::model::FieldFormula`] instead.
///
/// ```
/// use liemesh::model::{FnField, NormalField};
/// use liemesh::scalar::{Dual, Vec3};
/// // The gradient of |p|⁴/4 (its level sets are spheres), written for Dual<f64>.
/// let field = FnField::new(|p: &Vec3<Dual<f64>>| {
///     let r2 = p.norm_squared();
///     p.scale(&r2)
/// });
/// let (v, jw) = field.normal_and_jvp(&Vec3::new(1.0, 0.0, 0.0), &Vec3::new(1.0, 0.0, 0.0));
/// assert_eq!((v.x, jw.x), (1.0, 3.0));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct FnField<F>(pub F);

impl<F> FnField<F> {
    /// Wraps a closure `Fn(&Vec3<Dual<T>>) -> Vec3<Dual<T>> + Sync`.
    pub fn new(f: F) -> Self {
        FnField(f)
    }
}

impl<T: Scalar, F: Fn(&Vec3<Dual<T>>) -> Vec3<Dual<T>> + Sync> NormalField<T> for FnField<F> {
    fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
        let v = (self.0)(&p.map(|x| Dual::constant(x.clone())));
        v.map(|d| d.re.clone())
    }
    fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
        let pd = Vec3::new(
            Dual::new(p.x.clone(), w.x.clone()),
            Dual::new(p.y.clone(), w.y.clone()),
            Dual::new(p.z.clone(), w.z.clone()),
        );
        let v = (self.0)(&pd);
        (v.map(|d| d.re.clone()), v.map(|d| d.eps.clone()))
    }
}

/// The full Jacobian `J_v(p)` (rows = components of `v`) by three JVPs.
pub fn jacobian<T: Scalar, F: NormalField<T> + ?Sized>(field: &F, p: &Vec3<T>) -> Mat3<T> {
    value_and_jacobian(field, p).1
}

/// `v(p)` and [`jacobian`], from the same three JVPs.
pub(crate) fn value_and_jacobian<T: Scalar, F: NormalField<T> + ?Sized>(
    field: &F,
    p: &Vec3<T>,
) -> (Vec3<T>, Mat3<T>) {
    let e = |i: usize| {
        let mut v = Vec3::zero();
        match i {
            0 => v.x = T::one(),
            1 => v.y = T::one(),
            _ => v.z = T::one(),
        }
        field.normal_and_jvp(p, &v)
    };
    let ((v, c0), (_, c1), (_, c2)) = (e(0), e(1), e(2));
    let j = [
        Vec3::new(c0.x.clone(), c1.x.clone(), c2.x.clone()),
        Vec3::new(c0.y.clone(), c1.y.clone(), c2.y.clone()),
        Vec3::new(c0.z, c1.z, c2.z),
    ];
    (v, j)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_band_quadric_knows_its_hole_and_no_other_quadric_has_one() {
        let field = |n: [f64; 6]| LieField::<f64>::new(&Invariant::from_numbers(&n).unwrap());
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        // x² + y² − 100 z² = 1: waist 1, axis z.
        let flange = field([1.0, 1.0, -100.0, 0.0, 0.0, 0.0])
            .hole_through([1.0, 0.0, 0.0])
            .unwrap();
        let [o, e] = flange.axis();
        assert_eq!(o, [0.0; 3]);
        assert!(e[0] == 0.0 && e[1] == 0.0 && e[2].abs() == 1.0);
        assert!(close(flange.waist(), 1.0));
        // x² + y²/4 = 1: the waist's shorter semi-axis.
        let cylinder = field([1.0, 0.25, 0.0, 0.0, 0.0, 0.0])
            .hole_through([0.0, 2.0, 0.0])
            .unwrap();
        assert!(close(cylinder.waist(), 1.0));
        // An ellipsoid, a two-sheet hyperboloid, a cone, a twisted field: none.
        assert!(field([1.0, 4.0, 16.0, 0.0, 0.0, 0.0])
            .hole_through([1.0, 0.0, 0.0])
            .is_none());
        assert!(field([1.0, 1.0, -1.0, 0.0, 0.0, 0.0])
            .hole_through([0.0, 0.0, 2.0])
            .is_none());
        assert!(field([1.0, 1.0, -1.0, 0.0, 0.0, 0.0])
            .hole_through([0.6, 0.8, 1.0])
            .is_none());
        assert!(field([1.0, 1.0, -1.0, 0.3, 0.5, 0.7])
            .hole_through([1.0, 0.0, 0.0])
            .is_none());
    }

    #[test]
    fn jvp_matches_the_closed_form_derivative() {
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        let f = LieField::<f64>::new(&inv);
        let p = Vec3::new(0.3, -0.7, 0.5);
        let w = Vec3::new(0.2, 0.1, -0.4);
        let (_, jw) = f.normal_and_jvp(&p, &w);
        // J w = A w + B (2 p∘w)
        let two_pw = Vec3::new(2.0 * p.x * w.x, 2.0 * p.y * w.y, 2.0 * p.z * w.z);
        let want = &mat_vec(f.a(), &w) + &mat_vec(f.b(), &two_pw);
        for i in 0..3 {
            assert!((jw[i] - want[i]).abs() < 1e-15);
        }
    }

    #[test]
    fn written_out_jvp_rounds_exactly_like_a_dual_number_pass() {
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        let f = LieField::<f64>::new(&inv);
        let (a, b) = (f.a().clone(), f.b().clone());
        // The same field through dual numbers: A p + B (p∘p).
        let dual = FnField::new(move |p: &Vec3<Dual<f64>>| {
            let lift = |m: &Mat3<f64>, q: &Vec3<Dual<f64>>| {
                let row = |r: &Vec3<f64>| {
                    let mut acc = q.x.scale(&r.x);
                    acc += q.y.scale(&r.y);
                    acc += q.z.scale(&r.z);
                    acc
                };
                Vec3::new(row(&m[0]), row(&m[1]), row(&m[2]))
            };
            let squares = Vec3::new(
                p.x.clone() * p.x.clone(),
                p.y.clone() * p.y.clone(),
                p.z.clone() * p.z.clone(),
            );
            let mut v = lift(&a, p);
            v += &lift(&b, &squares);
            v
        });
        for (p, w) in [
            ([0.3, -0.7, 0.5], [0.2, 0.1, -0.4]),
            ([1.7e3, 2.5e-4, -0.9], [-0.6, 0.8, 1e-9]),
        ] {
            let (p, w) = (Vec3::from_f64(p), Vec3::from_f64(w));
            assert_eq!(f.normal_and_jvp(&p, &w), dual.normal_and_jvp(&p, &w));
        }
    }

    #[test]
    fn only_fields_more_precise_than_f64_offer_an_f64_copy() {
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        assert!(LieField::<f32>::new(&inv).in_f64().is_none());
        assert!(LieField::<f64>::new(&inv).in_f64().is_none());
        assert!(LieField::<Dual<f64>>::new(&inv).in_f64().is_none());
    }

    #[cfg(feature = "mpfr")]
    #[test]
    fn an_mpfr_field_offers_its_f64_rounding() {
        use crate::scalar::Mpfr;
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        let fine = LieField::<Mpfr<256>>::new(&inv);
        let coarse = fine.in_f64().expect("an f64 copy");
        let p = Vec3::new(0.3, -0.7, 0.5);
        let want = fine.normal(&Vec3::from_f64(p.to_f64())).to_f64();
        let got = coarse.normal(&p).to_f64();
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() <= 1e-15 * want[i].abs().max(1.0));
        }
    }

    #[test]
    fn linear_invariant_gives_v_equal_a_p() {
        let inv = Invariant::from_numbers(&[2.0, 3.0, 4.0, 0.0, 0.0, 0.0]).unwrap();
        let f = LieField::<f64>::new(&inv);
        let v = f.normal(&Vec3::new(1.0, 1.0, 1.0));
        assert_eq!(v.to_f64(), [2.0, 3.0, 4.0]);
    }

    #[test]
    fn seeded_field_differentiates_with_respect_to_an_invariant_number() {
        let inv = Invariant::from_numbers(&[2.0, 3.0, 4.0, 0.0, 0.0, 0.0]).unwrap();
        let f = LieField::<f64>::seeded(&inv, 1); // d/dλ2
        let p = Vec3::new(
            Dual::constant(1.0),
            Dual::constant(5.0),
            Dual::constant(1.0),
        );
        let v = f.normal(&p);
        assert_eq!((v.x.eps, v.y.eps, v.z.eps), (0.0, 5.0, 0.0));
    }
}
