//! Exact orientation predicates for any finite `f64` input.
//!
//! `robust` (Shewchuk's adaptive predicates) is exact only while none of its intermediate
//! products overflows or underflows. Every coordinate that is a multiple of 2⁻³⁰⁰ and smaller
//! than 2³⁰⁰ in magnitude keeps all of orient3d's degree-3 terms multiples of 2⁻⁹⁰⁰ below
//! 2⁹¹⁰: far from both ends of the exponent range, so there `robust` is exact ([`InRange`]).
//! Other inputs are scaled by a power of two (exact, and the signs do not change) when their
//! spread of exponents fits that window, and otherwise decided with integer arithmetic
//! ([`Checked`]). In front of both, a floating-point filter whose error bound accounts for
//! underflow decides most such input at the cost of one plain evaluation. Signs are `i8` in
//! {−1, 0, 1}.

use robust::{Coord, Coord3D};

/// A point in space.
pub(crate) type P3 = [f64; 3];

/// Exponent bounds of the window in which `robust` is exact: `|x| < 2^FAST_TOP` and `x` a
/// multiple of `2^FAST_LOW`.
const FAST_TOP: i32 = 300;
const FAST_LOW: i32 = -300;

/// Orientation predicates, exact on the inputs the implementation accepts.
pub(crate) trait Orient: Copy {
    /// What [`Orient::side`] needs of a plane, computed once for several points.
    type Plane: Copy + Send + Sync;
    /// Sign of `det[b − a, c − a, d − a]`: positive when `d` lies on the side of the plane
    /// `abc` that `(b − a) × (c − a)` points to.
    fn orient3d(self, a: P3, b: P3, c: P3, d: P3) -> i8;
    /// The plane through `a, b, c`, for [`Orient::side`].
    fn plane(self, a: P3, b: P3, c: P3) -> Self::Plane;
    /// `orient3d(a, b, c, d)` for the plane of [`Orient::plane`]`(a, b, c)`.
    fn side(self, plane: &Self::Plane, d: P3) -> i8;
    /// The points `a, b, c` the plane was made from.
    fn plane_corners(self, plane: &Self::Plane) -> &[P3; 3];
    /// Sign of `(b − a) × (c − a)`: positive when `a, b, c` turn counter-clockwise.
    fn orient2d(self, a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8;
}

/// `robust` directly: exact only if every coordinate passed lies in the window
/// (see [`Exponents::in_window`]); callers check that once for a whole point set.
#[derive(Clone, Copy, Debug)]
pub(crate) struct InRange;

/// Exact for every finite input: checks the window on each call and scales or falls back to
/// integer arithmetic outside it. Non-finite input answers 0.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Checked;

#[inline]
fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

#[inline]
fn c3(p: P3) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

#[inline]
fn c2(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Shewchuk's first error bound of orient3d, `(7 + 56ε)ε` with `ε = 2⁻⁵³`.
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * f64::EPSILON / 2.0) * f64::EPSILON / 2.0;

/// A plane for [`InRange::side`]: its corners, and the normal `n = (b − a) × (c − a)` with
/// the absolute values of its products, as orient3d's first stage computes them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FilteredPlane {
    corners: [P3; 3],
    n: P3,
    magnitude: P3,
}

impl Orient for InRange {
    type Plane = FilteredPlane;
    #[inline]
    fn orient3d(self, a: P3, b: P3, c: P3, d: P3) -> i8 {
        // robust's orient3d is det[a − d, b − d, c − d] = −det[b − a, c − a, d − a].
        -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
    }
    #[inline]
    fn plane(self, a: P3, b: P3, c: P3) -> FilteredPlane {
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let (yz, zy) = (u[1] * w[2], u[2] * w[1]);
        let (zx, xz) = (u[2] * w[0], u[0] * w[2]);
        let (xy, yx) = (u[0] * w[1], u[1] * w[0]);
        FilteredPlane {
            corners: [a, b, c],
            n: [yz - zy, zx - xz, xy - yx],
            magnitude: [
                yz.abs() + zy.abs(),
                zx.abs() + xz.abs(),
                xy.abs() + yx.abs(),
            ],
        }
    }
    /// `det[b − a, c − a, d − a] = (d − a) · n`, evaluated exactly as orient3d's first stage
    /// evaluates the transposed determinant (each entry one rounded difference, the same
    /// expression tree), so the same error bound `O3D_ERRBOUND_A · permanent` holds; only
    /// when it does not decide the sign does `robust` run in full.
    #[inline]
    fn side(self, pl: &FilteredPlane, d: P3) -> i8 {
        let a = pl.corners[0];
        let x = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        let det = x[0] * pl.n[0] + x[1] * pl.n[1] + x[2] * pl.n[2];
        let permanent = pl.magnitude[0] * x[0].abs()
            + pl.magnitude[1] * x[1].abs()
            + pl.magnitude[2] * x[2].abs();
        let bound = O3D_ERRBOUND_A * permanent;
        if det > bound {
            1
        } else if -det > bound {
            -1
        } else {
            self.orient3d(a, pl.corners[1], pl.corners[2], d)
        }
    }
    #[inline]
    fn plane_corners(self, pl: &FilteredPlane) -> &[P3; 3] {
        &pl.corners
    }
    #[inline]
    fn orient2d(self, a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
        sign(robust::orient2d(c2(a), c2(b), c2(c)))
    }
}

impl Orient for Checked {
    type Plane = [P3; 3];
    fn plane(self, a: P3, b: P3, c: P3) -> [P3; 3] {
        [a, b, c]
    }
    fn side(self, pl: &[P3; 3], d: P3) -> i8 {
        self.orient3d(pl[0], pl[1], pl[2], d)
    }
    fn plane_corners(self, pl: &[P3; 3]) -> &[P3; 3] {
        pl
    }
    fn orient3d(self, a: P3, b: P3, c: P3, d: P3) -> i8 {
        if a.iter()
            .chain(&b)
            .chain(&c)
            .chain(&d)
            .all(|&x| surely_in_window(x))
        {
            return InRange.orient3d(a, b, c, d);
        }
        if let Some(s) = filter::orient3d(a, b, c, d) {
            return s;
        }
        let e = Exponents::of(a.iter().chain(&b).chain(&c).chain(&d).copied());
        match e.plan() {
            Plan::NonFinite => 0,
            Plan::Direct => InRange.orient3d(a, b, c, d),
            Plan::Scale(k) => {
                let s = |p: P3| p.map(|x| scale(x, k));
                InRange.orient3d(s(a), s(b), s(c), s(d))
            }
            Plan::Integers => exact::orient3d(a, b, c, d),
        }
    }
    fn orient2d(self, a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
        if a.iter().chain(&b).chain(&c).all(|&x| surely_in_window(x)) {
            return InRange.orient2d(a, b, c);
        }
        if let Some(s) = filter::orient2d(a, b, c) {
            return s;
        }
        let e = Exponents::of(a.iter().chain(&b).chain(&c).copied());
        match e.plan() {
            Plan::NonFinite => 0,
            Plan::Direct => InRange.orient2d(a, b, c),
            Plan::Scale(k) => {
                let s = |p: [f64; 2]| p.map(|x| scale(x, k));
                InRange.orient2d(s(a), s(b), s(c))
            }
            Plan::Integers => exact::orient2d(a, b, c),
        }
    }
}

/// `2^(FAST_LOW + 52)`: every `f64` at least this large in magnitude is a multiple of
/// `2^FAST_LOW` (its lowest mantissa bit is at most 52 places below its leading one).
const FAST_LOW_NORMAL: f64 = f64::from_bits(((FAST_LOW + 52 + 1023) as u64) << 52);

/// `2^FAST_TOP`.
const FAST_TOP_BOUND: f64 = f64::from_bits(((FAST_TOP + 1023) as u64) << 52);

/// A cheap sufficient test that `x` lies in the window where [`InRange`] is exact (zero, or
/// `2^(FAST_LOW + 52) ≤ |x| < 2^FAST_TOP`): two comparisons instead of [`Exponents`]'s bit
/// counts. NaN and infinities fail it. Values it rejects may still be in the window; the
/// callers then decide through [`Exponents`] as before, so the answers do not change.
#[inline]
fn surely_in_window(x: f64) -> bool {
    let m = x.abs();
    m == 0.0 || (FAST_LOW_NORMAL..FAST_TOP_BOUND).contains(&m)
}

/// The exponent spread of a set of numbers: the largest `floor(log2 |x|)` and the smallest
/// exponent of a lowest set bit, over the non-zero finite values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Exponents {
    /// Largest `floor(log2 |x|)` (`i32::MIN` if every value is zero).
    pub top: i32,
    /// Smallest exponent of a lowest set bit (`i32::MAX` if every value is zero).
    pub low: i32,
    /// Whether some value was NaN or infinite.
    pub non_finite: bool,
}

/// What a predicate does with its input.
enum Plan {
    NonFinite,
    Direct,
    Scale(i32),
    Integers,
}

impl Exponents {
    /// The spread of `xs`.
    pub fn of(xs: impl IntoIterator<Item = f64>) -> Exponents {
        let mut e = Exponents {
            top: i32::MIN,
            low: i32::MAX,
            non_finite: false,
        };
        for x in xs {
            e.add(x);
        }
        e
    }

    /// Takes `x` into account.
    #[inline]
    pub fn add(&mut self, x: f64) {
        if !x.is_finite() {
            self.non_finite = true;
        } else if let Some((m, exp)) = decompose(x) {
            self.top = self.top.max(exp + 63 - m.leading_zeros() as i32);
            self.low = self.low.min(exp + m.trailing_zeros() as i32);
        }
    }

    /// Whether every value is finite and in the window where [`InRange`] is exact.
    pub fn in_window(&self) -> bool {
        !self.non_finite && self.top < FAST_TOP && self.low >= FAST_LOW
    }

    /// A power of two `k` such that every value times `2^k` is in the window (exactly: the
    /// scaled values neither overflow nor underflow), if the spread allows it.
    pub fn window_scale(&self) -> Option<i32> {
        if self.non_finite {
            return None;
        }
        if self.top == i32::MIN {
            return Some(0);
        }
        if self.top - self.low >= FAST_TOP - FAST_LOW {
            return None;
        }
        // Centre the spread in the window; both ends then stay inside it.
        let k = -((self.top + self.low).div_euclid(2));
        let ok = self.top + k < FAST_TOP && self.low + k >= FAST_LOW;
        ok.then_some(k)
    }

    fn plan(&self) -> Plan {
        if self.non_finite {
            Plan::NonFinite
        } else if self.in_window() {
            Plan::Direct
        } else if let Some(k) = self.window_scale() {
            Plan::Scale(k)
        } else {
            Plan::Integers
        }
    }
}

/// `x = ±m · 2^exp` with an integer `m > 0`, for finite non-zero `x`.
#[inline]
fn decompose(x: f64) -> Option<(u64, i32)> {
    let bits = x.to_bits();
    let field = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    match field {
        0 if frac == 0 => None,
        0 => Some((frac, -1074)),
        0x7ff => None,
        _ => Some((frac | (1u64 << 52), field - 1075)),
    }
}

/// `x · 2^k`, exact when the result neither overflows nor underflows (two steps, so that
/// `2^k` itself need not be representable).
pub(crate) fn scale(x: f64, k: i32) -> f64 {
    let h = k / 2;
    x * pow2(h) * pow2(k - h)
}

/// `2^k` for `k` in the normal range (clamped to it).
fn pow2(k: i32) -> f64 {
    let k = k.clamp(-1022, 1023);
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// A floating-point filter in front of the integer arithmetic: the determinant evaluated in
/// `f64` with a bound on its error, the sign taken only where the bound decides it.
///
/// Outside the window products may underflow, which Shewchuk's relative bound does not cover:
/// a product that underflows is off by at most half the smallest subnormal (`TINY / 2`),
/// absolutely, and a difference that underflows is exact. Propagated through the outer
/// products, that adds at most `TINY · (Σ|uᵢ| + 2)` to orient3d's error (`TINY` to
/// orient2d's), doubled here for the rounding of the bound itself. Overflow shows as an
/// infinite bound or a NaN determinant, and then the filter declines, as it does whenever
/// `|det|` is not above the bound (exact zeros included).
mod filter {
    use super::{sign, P3};

    const EPS: f64 = f64::EPSILON / 2.0;
    /// The smallest positive subnormal, 2⁻¹⁰⁷⁴.
    const TINY: f64 = f64::from_bits(1);
    /// Shewchuk's `o3derrboundA` and `ccwerrboundA`.
    const ORIENT3D_BOUND: f64 = (7.0 + 56.0 * EPS) * EPS;
    const ORIENT2D_BOUND: f64 = (3.0 + 16.0 * EPS) * EPS;

    /// The sign of `det[b − a, c − a, d − a]` if the filter can certify it.
    #[inline]
    pub(super) fn orient3d(a: P3, b: P3, c: P3, d: P3) -> Option<i8> {
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        let (p12, p21) = (v[1] * w[2], v[2] * w[1]);
        let (p02, p20) = (v[0] * w[2], v[2] * w[0]);
        let (p01, p10) = (v[0] * w[1], v[1] * w[0]);
        let det = u[0] * (p12 - p21) - u[1] * (p02 - p20) + u[2] * (p01 - p10);
        let permanent = u[0].abs() * (p12.abs() + p21.abs())
            + u[1].abs() * (p02.abs() + p20.abs())
            + u[2].abs() * (p01.abs() + p10.abs());
        let underflow = 2.0 * TINY * (u[0].abs() + u[1].abs() + u[2].abs() + 2.0);
        let bound = ORIENT3D_BOUND * permanent + underflow;
        (det.abs() > bound && bound.is_finite()).then(|| sign(det))
    }

    /// The sign of `(b − a) × (c − a)` if the filter can certify it.
    #[inline]
    pub(super) fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Option<i8> {
        let left = (b[0] - a[0]) * (c[1] - a[1]);
        let right = (b[1] - a[1]) * (c[0] - a[0]);
        let det = left - right;
        let bound = ORIENT2D_BOUND * (left.abs() + right.abs()) + 2.0 * TINY;
        (det.abs() > bound && bound.is_finite()).then(|| sign(det))
    }
}

/// Integer arithmetic for inputs outside the window: every finite `f64` is an integer times
/// `2^low`, so the determinants are integer polynomials, evaluated on sign-magnitude big
/// integers. Slow (microseconds), and only reached for spreads of exponents wider than 600.
mod exact {
    use super::{decompose, P3};
    use std::cmp::Ordering;

    /// A signed integer: little-endian 64-bit limbs without trailing zeros (zero is empty).
    #[derive(Clone, Debug, Default, PartialEq, Eq)]
    struct Int {
        neg: bool,
        mag: Vec<u64>,
    }

    impl Int {
        /// `x / 2^low` for a finite `x` that is a multiple of `2^low`.
        fn from_f64(x: f64, low: i32) -> Int {
            let Some((m, exp)) = decompose(x) else {
                return Int::default();
            };
            // Odd mantissa: `low` may lie above `exp` when m has trailing zeros.
            let (m, exp) = (m >> m.trailing_zeros(), exp + m.trailing_zeros() as i32);
            let shift = (exp - low) as usize;
            let (limb, bit) = (shift / 64, shift % 64);
            let mut mag = vec![0u64; limb + 2];
            mag[limb] = m << bit;
            if bit > 0 {
                mag[limb + 1] = m >> (64 - bit);
            }
            trim(&mut mag);
            Int { neg: x < 0.0, mag }
        }

        fn sign(&self) -> i8 {
            match (self.mag.is_empty(), self.neg) {
                (true, _) => 0,
                (false, true) => -1,
                (false, false) => 1,
            }
        }

        fn neg(mut self) -> Int {
            if !self.mag.is_empty() {
                self.neg = !self.neg;
            }
            self
        }

        fn add(&self, o: &Int) -> Int {
            if self.neg == o.neg {
                return Int {
                    neg: self.neg,
                    mag: add_mag(&self.mag, &o.mag),
                };
            }
            match cmp_mag(&self.mag, &o.mag) {
                Ordering::Equal => Int::default(),
                Ordering::Greater => Int {
                    neg: self.neg,
                    mag: sub_mag(&self.mag, &o.mag),
                },
                Ordering::Less => Int {
                    neg: o.neg,
                    mag: sub_mag(&o.mag, &self.mag),
                },
            }
        }

        fn sub(&self, o: &Int) -> Int {
            self.add(&o.clone().neg())
        }

        fn mul(&self, o: &Int) -> Int {
            if self.mag.is_empty() || o.mag.is_empty() {
                return Int::default();
            }
            let mut r = vec![0u64; self.mag.len() + o.mag.len()];
            for (i, &a) in self.mag.iter().enumerate() {
                let mut carry = 0u128;
                for (j, &b) in o.mag.iter().enumerate() {
                    let t = a as u128 * b as u128 + r[i + j] as u128 + carry;
                    r[i + j] = t as u64;
                    carry = t >> 64;
                }
                r[i + o.mag.len()] = carry as u64;
            }
            trim(&mut r);
            Int {
                neg: self.neg != o.neg,
                mag: r,
            }
        }
    }

    fn trim(v: &mut Vec<u64>) {
        while v.last() == Some(&0) {
            v.pop();
        }
    }

    fn cmp_mag(a: &[u64], b: &[u64]) -> Ordering {
        a.len()
            .cmp(&b.len())
            .then_with(|| a.iter().rev().cmp(b.iter().rev()))
    }

    fn add_mag(a: &[u64], b: &[u64]) -> Vec<u64> {
        let (a, b) = if a.len() >= b.len() { (a, b) } else { (b, a) };
        let mut r = Vec::with_capacity(a.len() + 1);
        let mut carry = 0u64;
        for (i, &x) in a.iter().enumerate() {
            let (s1, c1) = x.overflowing_add(b.get(i).copied().unwrap_or(0));
            let (s2, c2) = s1.overflowing_add(carry);
            r.push(s2);
            carry = (c1 || c2) as u64;
        }
        r.push(carry);
        trim(&mut r);
        r
    }

    /// `a − b` for `|a| ≥ |b|`.
    fn sub_mag(a: &[u64], b: &[u64]) -> Vec<u64> {
        let mut r = Vec::with_capacity(a.len());
        let mut borrow = 0u64;
        for (i, &x) in a.iter().enumerate() {
            let (d1, b1) = x.overflowing_sub(b.get(i).copied().unwrap_or(0));
            let (d2, b2) = d1.overflowing_sub(borrow);
            r.push(d2);
            borrow = (b1 || b2) as u64;
        }
        trim(&mut r);
        r
    }

    fn lowest(xs: &[f64]) -> i32 {
        xs.iter()
            .filter_map(|&x| decompose(x))
            .map(|(m, e)| e + m.trailing_zeros() as i32)
            .min()
            .unwrap_or(0)
    }

    /// Sign of `det[b − a, c − a, d − a]` for finite input.
    pub(super) fn orient3d(a: P3, b: P3, c: P3, d: P3) -> i8 {
        let all = [a, b, c, d].concat();
        let low = lowest(&all);
        let int = |p: P3| p.map(|x| Int::from_f64(x, low));
        let (a, b, c, d) = (int(a), int(b), int(c), int(d));
        let diff = |p: &[Int; 3]| [p[0].sub(&a[0]), p[1].sub(&a[1]), p[2].sub(&a[2])];
        let (u, v, w) = (diff(&b), diff(&c), diff(&d));
        let minor = |i: usize, j: usize| v[i].mul(&w[j]).sub(&v[j].mul(&w[i]));
        let det = u[0]
            .mul(&minor(1, 2))
            .sub(&u[1].mul(&minor(0, 2)))
            .add(&u[2].mul(&minor(0, 1)));
        det.sign()
    }

    /// Sign of `(b − a) × (c − a)` for finite input.
    pub(super) fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
        let low = lowest(&[a, b, c].concat());
        let int = |p: [f64; 2]| p.map(|x| Int::from_f64(x, low));
        let (a, b, c) = (int(a), int(b), int(c));
        let u = [b[0].sub(&a[0]), b[1].sub(&a[1])];
        let v = [c[0].sub(&a[0]), c[1].sub(&a[1])];
        u[0].mul(&v[1]).sub(&u[1].mul(&v[0])).sign()
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn integers_add_subtract_and_multiply_across_limbs() {
            let a = Int::from_f64(2f64.powi(100), 0);
            let b = Int::from_f64(-3.0, 0);
            assert_eq!(a.mul(&b).add(&a.mul(&Int::from_f64(3.0, 0))).sign(), 0);
            assert_eq!(a.add(&b).sub(&a).sub(&b).sign(), 0);
            assert_eq!(b.sub(&a).sign(), -1);
            let big = Int::from_f64(f64::MAX, -1074);
            let tiny = Int::from_f64(f64::from_bits(1), -1074);
            assert_eq!(big.mul(&big).sub(&big.mul(&big).add(&tiny)).sign(), -1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::rng::XorShift64;

    #[test]
    fn conventions() {
        let (o, x, y, z) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(InRange.orient3d(o, x, y, z), 1);
        assert_eq!(Checked.orient3d(o, y, x, z), -1);
        assert_eq!(Checked.orient3d(o, x, y, [3.0, -2.0, 0.0]), 0);
        assert_eq!(InRange.orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1);
        assert_eq!(Checked.orient2d([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]), -1);
        assert_eq!(Checked.orient3d(o, x, y, [0.0, 0.0, f64::NAN]), 0);
    }

    #[test]
    fn exponents_and_window() {
        let e = Exponents::of([1.0, -0.75, 0.0]);
        assert_eq!((e.top, e.low), (0, -2));
        assert!(e.in_window());
        let tiny = Exponents::of([1e-200, 3e-200]);
        assert!(!tiny.in_window());
        let k = tiny.window_scale().unwrap();
        assert!(Exponents::of([scale(1e-200, k), scale(3e-200, k)]).in_window());
        assert_eq!(Exponents::of([1e300, 1e-300]).window_scale(), None);
        assert!(Exponents::of([f64::INFINITY]).non_finite);
        assert_eq!(scale(3.0, 2000), 3.0 * 2f64.powi(1000) * 2f64.powi(1000));
    }

    /// The quick window test admits only values in the window, and admits the usual ones.
    #[test]
    fn the_quick_window_test_is_sufficient() {
        assert_eq!(FAST_LOW_NORMAL, 2f64.powi(FAST_LOW + 52));
        assert_eq!(FAST_TOP_BOUND, 2f64.powi(FAST_TOP));
        let edges = [
            0.0,
            -0.0,
            1.0,
            -0.3,
            FAST_LOW_NORMAL,
            -FAST_LOW_NORMAL,
            f64::from_bits(FAST_LOW_NORMAL.to_bits() - 1),
            f64::from_bits(FAST_LOW_NORMAL.to_bits() + 1),
            FAST_TOP_BOUND,
            f64::from_bits(FAST_TOP_BOUND.to_bits() - 1),
            -f64::from_bits(FAST_TOP_BOUND.to_bits() - 1),
            f64::MIN_POSITIVE,
            f64::from_bits(1),
            f64::MAX,
            f64::INFINITY,
            f64::NAN,
        ];
        let mut rng = XorShift64::new(11);
        let random = (0..20_000).map(|_| f64::from_bits(rng.next_u64()));
        for x in edges.into_iter().chain(random) {
            if surely_in_window(x) {
                assert!(Exponents::of([x]).in_window(), "{x:e}");
            }
        }
        assert!([0.0, 1.0, -0.3, 1e-70, 1e90]
            .into_iter()
            .all(surely_in_window));
    }

    /// The filtered side test agrees with the exact orientation, also where the filter
    /// cannot decide (points on and an ulp off the plane).
    #[test]
    fn the_plane_filter_agrees_with_orient3d() {
        let mut rng = XorShift64::new(17);
        let mut undecided = 0;
        for i in 0..20_000 {
            let (a, b, c) = (rng.in_cube(1.0), rng.in_cube(1.0), rng.in_cube(1.0));
            let mut d = rng.in_cube(1.0);
            if i % 2 == 0 {
                // A point of the plane z = a.z, or one ulp off it.
                let (a, b, c) = ([a[0], a[1], 0.5], [b[0], b[1], 0.5], [c[0], c[1], 0.5]);
                let z = f64::from_bits(0.5f64.to_bits() + (i as u64 % 3)).min(0.5000001);
                d[2] = if i % 4 == 0 { z } else { -z + 1.0 };
                let pl = InRange.plane(a, b, c);
                assert_eq!(InRange.side(&pl, d), exact::orient3d(a, b, c, d));
                undecided += (InRange.side(&pl, d) == 0) as usize;
                continue;
            }
            let pl = InRange.plane(a, b, c);
            assert_eq!(InRange.side(&pl, d), exact::orient3d(a, b, c, d));
            assert_eq!(
                Checked.side(&Checked.plane(a, b, c), d),
                exact::orient3d(a, b, c, d)
            );
        }
        assert!(undecided > 1000, "{undecided}");
    }

    /// Where the filter decides, it agrees with the integer arithmetic: on coordinates spread
    /// over the whole exponent range (subnormals included), on nearly degenerate input (a
    /// fourth point a few units in the last place off a plane), and on mesh-like input with a
    /// few tiny coordinates (what sends a mesh out of the window). It decides most of the
    /// last kind, which is what makes it worth having.
    #[test]
    fn the_filter_agrees_with_the_integers_where_it_decides() {
        let mut rng = XorShift64::new(11);
        let signed = |rng: &mut XorShift64, x: f64| {
            if rng.next_u64().is_multiple_of(2) {
                x
            } else {
                -x
            }
        };
        let wild = |rng: &mut XorShift64| match rng.next_u64() % 8 {
            0 => 0.0,
            1 => {
                let x = f64::from_bits(rng.next_u64() % (1 << 20));
                signed(rng, x)
            }
            _ => {
                let e = (rng.next_u64() % 2090) as i32 - 1070;
                scale(rng.in_cube(1.0)[0], e.min(1020))
            }
        };
        let (mut decided, mut mesh_like) = (0, 0);
        for i in 0..30_000 {
            let mut p: Vec<P3> = (0..4)
                .map(|_| [wild(&mut rng), wild(&mut rng), wild(&mut rng)])
                .collect();
            match i % 3 {
                0 => {
                    // Four points in a plane through the origin, the last nudged off it.
                    let s = scale(1.0, (rng.next_u64() % 1200) as i32 - 600);
                    for q in p.iter_mut() {
                        let r = rng.in_cube(1.0);
                        *q = [r[0] * s, r[1] * s, (r[0] + r[1]) * s];
                    }
                    let bits = p[3][2].to_bits();
                    p[3][2] = f64::from_bits(bits.wrapping_add(rng.next_u64() % 5).wrapping_sub(2));
                }
                1 => {
                    // A mesh at some scale, with a few coordinates far below it.
                    let s = scale(1.0, (rng.next_u64() % 200) as i32 - 100);
                    for q in p.iter_mut() {
                        *q = rng.in_cube(s);
                        for x in q.iter_mut() {
                            if rng.next_u64().is_multiple_of(6) {
                                let e = -((rng.next_u64() % 1000) as i32) - 100;
                                *x = scale(*x, e);
                            }
                        }
                    }
                    mesh_like += 1;
                }
                _ => {}
            }
            let x = exact::orient3d(p[0], p[1], p[2], p[3]);
            if let Some(f) = filter::orient3d(p[0], p[1], p[2], p[3]) {
                assert_eq!(f, x, "{p:?}");
                decided += (i % 3 == 1) as usize;
            }
            let q = |v: P3| [v[0], v[1]];
            let x2 = exact::orient2d(q(p[0]), q(p[1]), q(p[2]));
            if let Some(f) = filter::orient2d(q(p[0]), q(p[1]), q(p[2])) {
                assert_eq!(f, x2, "{p:?}");
            }
        }
        assert!(decided * 10 > mesh_like * 9, "{decided} of {mesh_like}");
    }

    /// The three evaluations (robust, robust after scaling, integers) agree on random and on
    /// exactly coplanar input, and the integer path decides spreads robust cannot.
    #[test]
    fn the_three_paths_agree() {
        let mut rng = XorShift64::new(5);
        for i in 0..2000 {
            let mut p: Vec<P3> = (0..4).map(|_| rng.in_cube(1.0)).collect();
            if i % 3 == 0 {
                // All four in a plane z = const: exactly coplanar.
                for k in 1..4 {
                    p[k][2] = p[0][2];
                }
            }
            if i % 5 == 0 {
                p[2] = p[1];
            }
            let fast = InRange.orient3d(p[0], p[1], p[2], p[3]);
            assert_eq!(fast, exact::orient3d(p[0], p[1], p[2], p[3]));
            let k = 700 - (i % 1400);
            let s = |q: P3| q.map(|x| scale(x, k));
            assert_eq!(fast, Checked.orient3d(s(p[0]), s(p[1]), s(p[2]), s(p[3])));
            let q = |v: P3| [v[0], v[1]];
            let f2 = InRange.orient2d(q(p[0]), q(p[1]), q(p[3]));
            assert_eq!(f2, exact::orient2d(q(p[0]), q(p[1]), q(p[3])));
        }
        // A plane through the origin, a point 2^-1000 above it and coordinates near 2^1000:
        // robust would underflow or overflow; the integer path is exact.
        let (a, b, c) = ([0.0; 3], [1e300, 0.0, 0.0], [0.0, 1e300, 0.0]);
        assert_eq!(Checked.orient3d(a, b, c, [1e300, 1e300, 1e-300]), 1);
        assert_eq!(Checked.orient3d(a, b, c, [1e300, 1e300, -1e-300]), -1);
        assert_eq!(Checked.orient3d(a, b, c, [1e300, 1e300, 0.0]), 0);
        assert_eq!(
            Checked.orient2d([0.0, 0.0], [1e300, 1e-300], [-1e300, -1e-300]),
            0
        );
        assert_eq!(
            Checked.orient2d([0.0, 0.0], [1e300, 1e-300], [-1e300, 0.0]),
            1
        );
    }
}
