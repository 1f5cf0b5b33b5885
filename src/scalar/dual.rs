//! Forward-mode dual numbers `re + eps·ε` with `ε² = 0`.

use super::Scalar;
use num_traits::{Num, One, Zero};
use std::fmt;
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Rem, Sub, SubAssign};

/// A forward-mode dual number: a value `re` and one directional derivative `eps`.
///
/// Generic over any [`Scalar`], so it nests (`Dual<Dual<f64>>`) and runs at arbitrary
/// precision (`Dual<Mpfr<256>>`). Comparisons look at the real part only, which is what
/// makes discrete decisions of an algorithm run on duals identical to the real run.
///
/// ```
/// use liemesh::scalar::{Dual, Scalar};
/// let x = Dual::new(3.0_f64, 1.0);
/// let y = (x.clone() * x).sqrt(); // |x|, derivative 1
/// assert_eq!(y.re, 3.0);
/// assert!((y.eps - 1.0).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dual<T> {
    /// The value.
    pub re: T,
    /// The derivative along the seeded direction.
    pub eps: T,
}

impl<T: Scalar> Dual<T> {
    /// A dual number from its value and derivative.
    #[inline(always)]
    pub fn new(re: T, eps: T) -> Self {
        Dual { re, eps }
    }
    /// A constant (derivative zero).
    #[inline(always)]
    pub fn constant(re: T) -> Self {
        Dual { re, eps: T::zero() }
    }
    /// The independent variable (derivative one).
    #[inline(always)]
    pub fn variable(re: T) -> Self {
        Dual { re, eps: T::one() }
    }
    /// Multiplies both parts by a plain scalar (cheaper than a dual product).
    #[inline(always)]
    pub fn scale(&self, k: &T) -> Self {
        Dual::new(self.re.product(k), self.eps.product(k))
    }
}

impl<T: Scalar> fmt::Display for Dual<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} + {}ε", self.re, self.eps)
    }
}

impl<T: Scalar> PartialOrd for Dual<T> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        self.re.partial_cmp(&other.re)
    }
}

impl<T: Scalar> Add for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Dual::new(self.re + o.re, self.eps + o.eps)
    }
}
impl<T: Scalar> Sub for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Dual::new(self.re - o.re, self.eps - o.eps)
    }
}
impl<T: Scalar> Mul for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, o: Self) -> Self {
        self *= &o;
        self
    }
}
impl<T: Scalar> Div for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        // (u/v)' = (u' − w v') / v with w = u/v  (the paper's Table 1).
        let w = self.re / o.re.clone();
        let eps = (self.eps - w.clone() * o.eps) / o.re;
        Dual::new(w, eps)
    }
}
impl<T: Scalar> Rem for Dual<T> {
    type Output = Self;
    fn rem(self, o: Self) -> Self {
        // x mod y = x − y·trunc(x/y); the derivative of trunc is zero almost everywhere.
        let q = (self.re.clone() / o.re.clone()).to_f64().trunc();
        let q = T::from_f64(q);
        Dual::new(self.re - q.clone() * o.re, self.eps - q * o.eps)
    }
}
impl<T: Scalar> Neg for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Dual::new(-self.re, -self.eps)
    }
}
impl<T: Scalar> AddAssign for Dual<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        self.re += o.re;
        self.eps += o.eps;
    }
}
impl<T: Scalar> SubAssign for Dual<T> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        self.re -= o.re;
        self.eps -= o.eps;
    }
}
impl<T: Scalar> AddAssign<&Dual<T>> for Dual<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: &Self) {
        self.re += &o.re;
        self.eps += &o.eps;
    }
}
impl<T: Scalar> SubAssign<&Dual<T>> for Dual<T> {
    #[inline(always)]
    fn sub_assign(&mut self, o: &Self) {
        self.re -= &o.re;
        self.eps -= &o.eps;
    }
}
impl<T: Scalar> MulAssign<&Dual<T>> for Dual<T> {
    /// `(a + a'ε)(b + b'ε) = ab + (a'b + ab')ε`.
    #[inline(always)]
    fn mul_assign(&mut self, o: &Self) {
        self.eps *= &o.re;
        self.eps.add_product(&self.re, &o.eps);
        self.re *= &o.re;
    }
}
impl<T: Scalar> MulAssign for Dual<T> {
    #[inline(always)]
    fn mul_assign(&mut self, o: Self) {
        let lhs = std::mem::replace(self, Dual::zero());
        *self = lhs * o;
    }
}
impl<T: Scalar> DivAssign for Dual<T> {
    #[inline(always)]
    fn div_assign(&mut self, o: Self) {
        let lhs = std::mem::replace(self, Dual::zero());
        *self = lhs / o;
    }
}

impl<T: Scalar> Zero for Dual<T> {
    fn zero() -> Self {
        Dual::new(T::zero(), T::zero())
    }
    fn is_zero(&self) -> bool {
        self.re.is_zero() && self.eps.is_zero()
    }
}
impl<T: Scalar> One for Dual<T> {
    fn one() -> Self {
        Dual::new(T::one(), T::zero())
    }
}
impl<T: Scalar> Num for Dual<T> {
    type FromStrRadixErr = T::FromStrRadixErr;
    fn from_str_radix(s: &str, radix: u32) -> Result<Self, Self::FromStrRadixErr> {
        T::from_str_radix(s, radix).map(Dual::constant)
    }
}

impl<T: Scalar> Scalar for Dual<T> {
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        Dual::constant(T::from_f64(x))
    }
    #[inline(always)]
    fn to_f64(&self) -> f64 {
        self.re.to_f64()
    }
    /// The same operations, in the same order, as `*self * o`.
    #[inline(always)]
    fn product(&self, o: &Self) -> Self {
        let mut eps = self.eps.product(&o.re);
        eps.add_product(&self.re, &o.eps);
        Dual::new(self.re.product(&o.re), eps)
    }
    #[inline(always)]
    fn sqrt(&self) -> Self {
        let r = self.re.sqrt();
        let eps = self.eps.clone() / (r.clone() + r.clone());
        Dual::new(r, eps)
    }
    #[inline(always)]
    fn sin_cos(&self) -> (Self, Self) {
        let (s, c) = self.re.sin_cos();
        let sin_eps = self.eps.clone() * c.clone();
        let cos_eps = -(self.eps.clone() * s.clone());
        (Dual::new(s, sin_eps), Dual::new(c, cos_eps))
    }
    #[inline(always)]
    fn sin(&self) -> Self {
        Dual::new(self.re.sin(), self.eps.clone() * self.re.cos())
    }
    #[inline(always)]
    fn cos(&self) -> Self {
        Dual::new(self.re.cos(), -(self.eps.clone() * self.re.sin()))
    }
    #[inline(always)]
    fn tan(&self) -> Self {
        let t = self.re.tan();
        let d = T::one() + t.clone() * t.clone();
        Dual::new(t, self.eps.clone() * d)
    }
    #[inline(always)]
    fn atan2(&self, x: &Self) -> Self {
        // d atan2(y, x) = (x dy − y dx) / (x² + y²)
        let (y, x) = (self, x);
        let r2 = x.re.clone() * x.re.clone() + y.re.clone() * y.re.clone();
        let eps = (x.re.clone() * y.eps.clone() - y.re.clone() * x.eps.clone()) / r2;
        Dual::new(y.re.atan2(&x.re), eps)
    }
    #[inline(always)]
    fn abs(&self) -> Self {
        if self.re < T::zero() {
            -self.clone()
        } else {
            self.clone()
        }
    }
    #[inline(always)]
    fn exp(&self) -> Self {
        let e = self.re.exp();
        Dual::new(e.clone(), self.eps.clone() * e)
    }
    #[inline(always)]
    fn ln(&self) -> Self {
        Dual::new(self.re.ln(), self.eps.clone() / self.re.clone())
    }
    #[inline(always)]
    fn powf(&self, p: f64) -> Self {
        // d(x^p) = p x^(p−1) dx, written so that it is 0, not 0·∞, at x = 0 for p > 1.
        let slope = self.re.powf(p - 1.0) * T::from_f64(p);
        Dual::new(self.re.powf(p), self.eps.clone() * slope)
    }
    #[inline(always)]
    fn is_finite(&self) -> bool {
        self.re.is_finite() && self.eps.is_finite()
    }
    fn unit_roundoff() -> f64 {
        T::unit_roundoff()
    }
    fn type_name() -> String {
        format!("Dual<{}>", T::type_name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_of_elementary_functions_match_closed_forms() {
        let x = Dual::variable(0.7_f64);
        let checks = [
            (x.sin().eps, 0.7_f64.cos()),
            (x.cos().eps, -0.7_f64.sin()),
            (x.tan().eps, 1.0 / 0.7_f64.cos().powi(2)),
            (x.sqrt().eps, 0.5 / 0.7_f64.sqrt()),
            ((Dual::constant(1.0) / x.clone()).eps, -1.0 / 0.49),
            (x.atan2(&Dual::constant(2.0)).eps, 2.0 / (4.0 + 0.49)),
            (x.exp().eps, 0.7_f64.exp()),
            (x.ln().eps, 1.0 / 0.7),
            (x.powf(2.5).eps, 2.5 * 0.7_f64.powf(1.5)),
        ];
        for (got, want) in checks {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
    }

    #[test]
    fn a_power_above_one_has_slope_zero_at_zero() {
        // |x|^p of a superquadric at x = 0: 0, not 0·∞ = NaN.
        let d = Dual::variable(0.0_f64).powf(4.0);
        assert_eq!((d.re, d.eps), (0.0, 0.0));
    }

    #[test]
    fn nested_duals_give_second_derivatives() {
        // f(x) = x³, f'' = 6x.
        let x = Dual::new(Dual::variable(2.0_f64), Dual::constant(1.0));
        let y = x.clone() * x.clone() * x;
        assert_eq!(y.eps.eps, 12.0);
    }

    #[test]
    fn comparisons_use_the_real_part_only() {
        assert!(Dual::new(1.0_f64, 100.0) < Dual::new(2.0, -100.0));
    }
}
