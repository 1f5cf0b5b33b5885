//! Arbitrary-precision scalars over MPFR (`rug::Float`), behind the `mpfr` feature.

use super::Scalar;
use num_traits::{Num, One, Zero};
use rug::float::Constant;
use rug::ops::Pow;
use rug::Float;
use std::cell::RefCell;
use std::fmt;
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Rem, Sub, SubAssign};

/// An MPFR float with `BITS` bits of mantissa, rounding to nearest.
///
/// The precision is part of the type, so every operation knows it without a context and
/// `Mpfr<256>` and `Mpfr<64>` can never be mixed by accident. Operations work in place on
/// the left operand, so a chain of arithmetic allocates no more than needed.
///
/// ```
/// use liemesh::scalar::{Mpfr, Scalar};
/// let third = Mpfr::<256>::from_f64(1.0) / Mpfr::from_f64(3.0);
/// let back = third * Mpfr::from_f64(3.0) - Mpfr::from_f64(1.0);
/// assert!(back.abs().to_f64() < 1e-70);
/// ```
#[derive(Clone, PartialEq, PartialOrd)]
pub struct Mpfr<const BITS: u32>(pub Float);

impl<const BITS: u32> Mpfr<BITS> {
    /// Wraps any value `rug` can convert, rounded to `BITS` bits.
    pub fn with_val<V>(v: V) -> Self
    where
        Float: rug::Assign<V>,
    {
        Mpfr(Float::with_val(BITS, v))
    }
    /// π to the working precision.
    pub fn pi() -> Self {
        Mpfr(Float::with_val(BITS, Constant::Pi))
    }
    /// `2^k` exactly.
    pub fn exp2i(k: i32) -> Self {
        Mpfr(Float::with_val(BITS, Float::with_val(BITS, 2).pow(k)))
    }
}

thread_local! {
    /// The product in `add_product` / `sub_product`: one number per thread, reused, so an
    /// accumulation allocates nothing (re-created only when the precision changes).
    static SCRATCH: RefCell<Float> = RefCell::new(Float::new(64));
}

/// `acc ± a·b` with the product rounded to `BITS` in the thread's scratch number.
#[inline]
fn accumulate_product<const BITS: u32>(acc: &mut Float, a: &Float, b: &Float, subtract: bool) {
    SCRATCH.with(|scratch| {
        let mut t = scratch.borrow_mut();
        if t.prec() != BITS {
            *t = Float::new(BITS);
        }
        rug::Assign::assign(&mut *t, a * b);
        if subtract {
            *acc -= &*t;
        } else {
            *acc += &*t;
        }
    });
}

impl<const BITS: u32> fmt::Debug for Mpfr<BITS> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Mpfr<{BITS}>({})", self.0)
    }
}
impl<const BITS: u32> fmt::Display for Mpfr<BITS> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

macro_rules! binop {
    ($tr:ident, $m:ident, $tra:ident, $ma:ident, $op:tt) => {
        impl<const BITS: u32> $tr for Mpfr<BITS> {
            type Output = Self;
            #[inline]
            fn $m(mut self, o: Self) -> Self {
                self.0 $op &o.0;
                self
            }
        }
        impl<const BITS: u32> $tra for Mpfr<BITS> {
            #[inline]
            fn $ma(&mut self, o: Self) {
                self.0 $op &o.0;
            }
        }
        impl<const BITS: u32> $tra<&Mpfr<BITS>> for Mpfr<BITS> {
            #[inline]
            fn $ma(&mut self, o: &Self) {
                self.0 $op &o.0;
            }
        }
    };
}
binop!(Add, add, AddAssign, add_assign, +=);
binop!(Sub, sub, SubAssign, sub_assign, -=);
binop!(Mul, mul, MulAssign, mul_assign, *=);
binop!(Div, div, DivAssign, div_assign, /=);

impl<const BITS: u32> Rem for Mpfr<BITS> {
    type Output = Self;
    fn rem(mut self, o: Self) -> Self {
        self.0 %= &o.0;
        self
    }
}
impl<const BITS: u32> Neg for Mpfr<BITS> {
    type Output = Self;
    fn neg(self) -> Self {
        Mpfr(-self.0)
    }
}
impl<const BITS: u32> Zero for Mpfr<BITS> {
    fn zero() -> Self {
        Mpfr(Float::new(BITS))
    }
    fn is_zero(&self) -> bool {
        self.0.is_zero()
    }
}
impl<const BITS: u32> One for Mpfr<BITS> {
    fn one() -> Self {
        Mpfr(Float::with_val(BITS, 1))
    }
}

/// Error for [`Num::from_str_radix`] on [`Mpfr`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseMpfrError(String);
impl fmt::Display for ParseMpfrError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "not a number MPFR can read: {}", self.0)
    }
}
impl std::error::Error for ParseMpfrError {}

impl<const BITS: u32> Num for Mpfr<BITS> {
    type FromStrRadixErr = ParseMpfrError;
    fn from_str_radix(s: &str, radix: u32) -> Result<Self, ParseMpfrError> {
        let parsed = Float::parse_radix(s, radix as i32)
            .map_err(|e| ParseMpfrError(format!("{s:?}: {e}")))?;
        Ok(Mpfr(Float::with_val(BITS, parsed)))
    }
}

impl<const BITS: u32> Scalar for Mpfr<BITS> {
    fn from_f64(x: f64) -> Self {
        Mpfr(Float::with_val(BITS, x))
    }
    fn to_f64(&self) -> f64 {
        self.0.to_f64()
    }
    #[inline]
    fn product(&self, o: &Self) -> Self {
        Mpfr(Float::with_val(BITS, &self.0 * &o.0))
    }
    #[inline]
    fn add_product(&mut self, a: &Self, b: &Self) {
        accumulate_product::<BITS>(&mut self.0, &a.0, &b.0, false);
    }
    #[inline]
    fn sub_product(&mut self, a: &Self, b: &Self) {
        accumulate_product::<BITS>(&mut self.0, &a.0, &b.0, true);
    }
    fn sqrt(&self) -> Self {
        Mpfr(self.0.clone().sqrt())
    }
    fn sin(&self) -> Self {
        Mpfr(self.0.clone().sin())
    }
    fn cos(&self) -> Self {
        Mpfr(self.0.clone().cos())
    }
    fn sin_cos(&self) -> (Self, Self) {
        let (s, c) = self.0.clone().sin_cos(Float::new(BITS));
        (Mpfr(s), Mpfr(c))
    }
    fn tan(&self) -> Self {
        Mpfr(self.0.clone().tan())
    }
    fn atan2(&self, x: &Self) -> Self {
        Mpfr(self.0.clone().atan2(&x.0))
    }
    fn abs(&self) -> Self {
        Mpfr(self.0.clone().abs())
    }
    fn exp(&self) -> Self {
        Mpfr(self.0.clone().exp())
    }
    fn ln(&self) -> Self {
        Mpfr(self.0.clone().ln())
    }
    fn powf(&self, p: f64) -> Self {
        Mpfr(self.0.clone().pow(p))
    }
    fn is_finite(&self) -> bool {
        self.0.is_finite()
    }
    fn unit_roundoff() -> f64 {
        2f64.powi(-(BITS as i32))
    }
    fn type_name() -> String {
        format!("Mpfr<{BITS}>")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precision_is_carried_by_the_type() {
        let x = Mpfr::<256>::from_f64(2.0).sqrt();
        assert_eq!(x.0.prec(), 256);
        let back = x.clone() * x - Mpfr::from_f64(2.0);
        assert!(back.abs().to_f64() < 1e-75);
    }

    #[test]
    fn products_and_accumulations_round_like_the_operators() {
        fn check<const BITS: u32>(a: f64, b: f64, c: f64) {
            let third = Mpfr::<BITS>::from_f64(1.0) / Mpfr::from_f64(3.0);
            let (a, b) = (
                Mpfr::<BITS>::from_f64(a) * third.clone(),
                Mpfr::from_f64(b).sqrt(),
            );
            let c = Mpfr::<BITS>::from_f64(c) / third;
            assert_eq!(a.product(&b), a.clone() * b.clone());
            let mut sum = c.clone();
            sum.add_product(&a, &b);
            assert_eq!(sum, c.clone() + a.clone() * b.clone());
            let mut difference = c.clone();
            difference.sub_product(&a, &b);
            assert_eq!(difference, c - a * b);
            assert_eq!(sum.0.prec(), BITS);
        }
        // Alternating precisions on one thread re-creates the shared scratch number.
        for (a, b, c) in [(0.7, 2.0, -1.5), (-3e5, 7e-3, 0.25), (1e-30, 5.0, 1e-29)] {
            check::<256>(a, b, c);
            check::<64>(a, b, c);
            check::<256>(c, b, a);
        }
    }

    #[test]
    fn pi_matches_atan2() {
        let pi = Mpfr::<128>::pi();
        let a = Mpfr::<128>::zero().atan2(&Mpfr::from_f64(-1.0));
        assert!((pi - a).abs().to_f64() < 1e-37);
    }

    #[test]
    fn exp_ln_and_powf_agree_with_f64_and_invert_each_other() {
        let x = Mpfr::<256>::from_f64(0.7);
        for (got, want) in [
            (x.exp().to_f64(), 0.7_f64.exp()),
            (x.ln().to_f64(), 0.7_f64.ln()),
            (x.powf(2.5).to_f64(), 0.7_f64.powf(2.5)),
        ] {
            assert!(
                (got - want).abs() <= 2.0 * f64::EPSILON * want.abs(),
                "{got} vs {want}"
            );
        }
        let back = x.ln().exp();
        assert!((back - x).abs().to_f64() < 1e-75);
    }
}
