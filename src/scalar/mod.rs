//! Scalars: the one trait the whole pipeline is generic over, and its implementations.
//!
//! [`Scalar`] is implemented for `f32`, `f64`, the forward-mode dual number [`Dual<T>`]
//! (itself generic over any `Scalar`, so `Dual<Dual<f64>>` and `Dual<Mpfr<256>>` work) and,
//! with the `mpfr` feature, the arbitrary-precision `Mpfr<BITS>`.
//!
//! The trait is `Clone`-based rather than `Copy`-based because an MPFR float owns heap
//! memory. For `f32` and `f64` a clone is a register copy, so generic code compiled for
//! `f64` is the code one would write by hand.
//!
//! ```
//! use liemesh::scalar::{Dual, Scalar};
//! // d/dx (x² sin x) at x = 2, by one forward-mode pass.
//! let x = Dual::variable(2.0_f64);
//! let y = x.clone() * x.clone() * x.sin();
//! let exact = 2.0 * 2.0 * 2.0_f64.sin() + 4.0 * 2.0_f64.cos();
//! assert!((y.eps - exact).abs() < 1e-14);
//! ```

mod dual;
#[cfg(feature = "mpfr")]
mod mpfr;
mod vec3;

pub use dual::Dual;
#[cfg(feature = "mpfr")]
pub use mpfr::Mpfr;
pub use vec3::Vec3;

use std::fmt::{Debug, Display};
use std::ops::{AddAssign, DivAssign, MulAssign, Neg, SubAssign};

/// A real number type the mesher can run on.
///
/// Besides field arithmetic (from [`num_traits::Num`]) it needs the handful of elementary
/// functions the algorithm uses, conversion to and from `f64` (discrete decisions and the
/// output are made in `f64`), and [`Scalar::unit_roundoff`] so that tolerances can follow
/// the working precision.
///
/// The compound assignments by reference (`x *= &y`) are what generic hot code uses: MPFR
/// then works in place without copying the right operand, and for `f64` they are the
/// plain operations.
pub trait Scalar:
    Clone
    + Debug
    + Display
    + PartialOrd
    + num_traits::Num
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + for<'a> AddAssign<&'a Self>
    + for<'a> SubAssign<&'a Self>
    + for<'a> MulAssign<&'a Self>
    + Send
    + Sync
    + 'static
{
    /// The value nearest to `x` (exact for every `f64` when the type is at least as precise).
    fn from_f64(x: f64) -> Self;
    /// The nearest `f64` (the real part for dual numbers).
    fn to_f64(&self) -> f64;
    /// `self · o` as a new value. The default copies `self` and multiplies in place; MPFR
    /// overrides it to write the product straight into a fresh number (the same rounding,
    /// one copy fewer). Hot generic code multiplies through this.
    #[inline(always)]
    fn product(&self, o: &Self) -> Self {
        let mut r = self.clone();
        r *= o;
        r
    }
    /// `self += a·b`, rounding the product and then the sum (not a fused multiply-add,
    /// so it is exactly `*self += &a.product(b)`). MPFR overrides it to form the product
    /// in a reused scratch number instead of a fresh one.
    #[inline(always)]
    fn add_product(&mut self, a: &Self, b: &Self) {
        *self += &a.product(b);
    }
    /// `self -= a·b`, rounded like [`Scalar::add_product`].
    #[inline(always)]
    fn sub_product(&mut self, a: &Self, b: &Self) {
        *self -= &a.product(b);
    }
    /// Square root.
    fn sqrt(&self) -> Self;
    /// Sine (radians).
    fn sin(&self) -> Self;
    /// Cosine (radians).
    fn cos(&self) -> Self;
    /// Sine and cosine together: one call where the type computes both at once (MPFR),
    /// exactly `(self.sin(), self.cos())` otherwise.
    #[inline(always)]
    fn sin_cos(&self) -> (Self, Self) {
        (self.sin(), self.cos())
    }
    /// Tangent (radians).
    fn tan(&self) -> Self;
    /// Four-quadrant arc tangent of `self / x`.
    fn atan2(&self, x: &Self) -> Self;
    /// Absolute value.
    fn abs(&self) -> Self;
    /// Exponential, `e^self` (Gaussian blobs, soft unions).
    fn exp(&self) -> Self;
    /// Natural logarithm (NaN below zero, −∞ at zero, as `f64::ln`).
    fn ln(&self) -> Self;
    /// `self` to the real power `p`, as `f64::powf` (superquadrics' `|x|^p`).
    fn powf(&self, p: f64) -> Self;
    /// `true` unless the value (or any part of it) is infinite or NaN.
    fn is_finite(&self) -> bool;
    /// Unit roundoff of the type (half the machine epsilon), as an `f64`.
    fn unit_roundoff() -> f64;
    /// A short name for reports, e.g. `"f64"` or `"Mpfr<256>"`.
    fn type_name() -> String;
}

macro_rules! impl_scalar_for_float {
    ($t:ty, $name:expr) => {
        impl Scalar for $t {
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn to_f64(&self) -> f64 {
                *self as f64
            }
            #[inline(always)]
            fn sqrt(&self) -> Self {
                <$t>::sqrt(*self)
            }
            #[inline(always)]
            fn sin(&self) -> Self {
                <$t>::sin(*self)
            }
            #[inline(always)]
            fn cos(&self) -> Self {
                <$t>::cos(*self)
            }
            #[inline(always)]
            fn tan(&self) -> Self {
                <$t>::tan(*self)
            }
            #[inline(always)]
            fn atan2(&self, x: &Self) -> Self {
                <$t>::atan2(*self, *x)
            }
            #[inline(always)]
            fn abs(&self) -> Self {
                <$t>::abs(*self)
            }
            #[inline(always)]
            fn exp(&self) -> Self {
                <$t>::exp(*self)
            }
            #[inline(always)]
            fn ln(&self) -> Self {
                <$t>::ln(*self)
            }
            #[inline(always)]
            fn powf(&self, p: f64) -> Self {
                <$t>::powf(*self, p as $t)
            }
            #[inline(always)]
            fn is_finite(&self) -> bool {
                <$t>::is_finite(*self)
            }
            fn unit_roundoff() -> f64 {
                (<$t>::EPSILON as f64) / 2.0
            }
            fn type_name() -> String {
                $name.to_string()
            }
        }
    };
}

impl_scalar_for_float!(f32, "f32");
impl_scalar_for_float!(f64, "f64");

/// Returns the larger of two scalars (the first if they compare equal or unordered).
#[inline(always)]
pub fn max<T: Scalar>(a: T, b: T) -> T {
    if b > a {
        b
    } else {
        a
    }
}

/// Returns the smaller of two scalars (the first if they compare equal or unordered).
#[inline(always)]
pub fn min<T: Scalar>(a: T, b: T) -> T {
    if b < a {
        b
    } else {
        a
    }
}

/// The scalar types the command line can run the mesher on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum ScalarKind {
    /// IEEE single precision.
    F32,
    /// IEEE double precision.
    F64,
    /// `Dual<f64>`: the real part is the mesh, the dual part is carried along.
    Dual,
    /// `Mpfr<256>` (needs the `mpfr` feature).
    Mpfr,
}

impl ScalarKind {
    /// All kinds this build can run (`Mpfr` only with the `mpfr` feature).
    pub fn available() -> Vec<ScalarKind> {
        let mut kinds = vec![ScalarKind::F32, ScalarKind::F64, ScalarKind::Dual];
        if cfg!(feature = "mpfr") {
            kinds.push(ScalarKind::Mpfr);
        }
        kinds
    }

    /// The lowercase name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            ScalarKind::F32 => "f32",
            ScalarKind::F64 => "f64",
            ScalarKind::Dual => "dual",
            ScalarKind::Mpfr => "mpfr",
        }
    }
}

impl std::fmt::Display for ScalarKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
