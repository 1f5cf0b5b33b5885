//! A three-vector over any [`Scalar`].

use super::Scalar;
use std::ops::{Add, AddAssign, Index, Mul, Neg, Sub, SubAssign};

/// A vector of three scalars, the only vector type the generic pipeline uses.
///
/// Kept separate from `nalgebra` so that the generic hot path needs nothing but the
/// [`Scalar`] trait; the `f64` post-processing (fits, SVD) converts to `nalgebra`.
#[derive(Clone, Debug, PartialEq)]
pub struct Vec3<T> {
    /// First component.
    pub x: T,
    /// Second component.
    pub y: T,
    /// Third component.
    pub z: T,
}

impl<T: Scalar> Vec3<T> {
    /// A vector from its components.
    #[inline(always)]
    pub fn new(x: T, y: T, z: T) -> Self {
        Vec3 { x, y, z }
    }
    /// The zero vector.
    #[inline(always)]
    pub fn zero() -> Self {
        Vec3::new(T::zero(), T::zero(), T::zero())
    }
    /// Converts from `f64` components.
    #[inline(always)]
    pub fn from_f64(v: [f64; 3]) -> Self {
        Vec3::new(T::from_f64(v[0]), T::from_f64(v[1]), T::from_f64(v[2]))
    }
    /// Converts to `f64` components (the real part for dual numbers).
    #[inline(always)]
    pub fn to_f64(&self) -> [f64; 3] {
        [self.x.to_f64(), self.y.to_f64(), self.z.to_f64()]
    }
    /// Dot product.
    #[inline(always)]
    pub fn dot(&self, o: &Self) -> T {
        let mut r = self.x.product(&o.x);
        r.add_product(&self.y, &o.y);
        r.add_product(&self.z, &o.z);
        r
    }
    /// Cross product.
    #[inline(always)]
    pub fn cross(&self, o: &Self) -> Self {
        let minor = |a: &T, b: &T, c: &T, d: &T| {
            let mut r = a.product(b);
            r.sub_product(c, d);
            r
        };
        Vec3::new(
            minor(&self.y, &o.z, &self.z, &o.y),
            minor(&self.z, &o.x, &self.x, &o.z),
            minor(&self.x, &o.y, &self.y, &o.x),
        )
    }
    /// Squared Euclidean norm.
    #[inline(always)]
    pub fn norm_squared(&self) -> T {
        self.dot(self)
    }
    /// Euclidean norm.
    #[inline(always)]
    pub fn norm(&self) -> T {
        self.norm_squared().sqrt()
    }
    /// Multiplies every component by `k`.
    #[inline(always)]
    pub fn scale(&self, k: &T) -> Self {
        Vec3::new(self.x.product(k), self.y.product(k), self.z.product(k))
    }
    /// `self + k·o`, the workhorse of the stepper.
    #[inline(always)]
    pub fn add_scaled(&self, k: &T, o: &Self) -> Self {
        // `k·o + self` is `self + k·o` exactly: IEEE addition and multiplication commute.
        let term = |a: &T, b: &T| {
            let mut r = k.product(b);
            r += a;
            r
        };
        Vec3::new(
            term(&self.x, &o.x),
            term(&self.y, &o.y),
            term(&self.z, &o.z),
        )
    }
    /// `self += k·o` in place, rounded exactly like [`Vec3::add_scaled`].
    #[inline(always)]
    pub fn add_scaled_assign(&mut self, k: &T, o: &Self) {
        self.x.add_product(k, &o.x);
        self.y.add_product(k, &o.y);
        self.z.add_product(k, &o.z);
    }
    /// `self -= k·o` in place, rounded exactly like `self.add_scaled(&-k, o)`.
    #[inline(always)]
    pub fn sub_scaled_assign(&mut self, k: &T, o: &Self) {
        self.x.sub_product(k, &o.x);
        self.y.sub_product(k, &o.y);
        self.z.sub_product(k, &o.z);
    }
    /// The unit vector along `self` and the norm, or `None` when the norm is zero or not finite.
    #[inline(always)]
    pub fn normalize(&self) -> Option<(Self, T)> {
        let n = self.norm();
        if n.is_finite() && n > T::zero() {
            let inv = T::one() / n.clone();
            Some((self.scale(&inv), n))
        } else {
            None
        }
    }
    /// The angle between two non-zero vectors, in radians (`atan2(|a×b|, a·b)`, accurate
    /// for small and near-π angles alike).
    #[inline(always)]
    pub fn angle_to(&self, o: &Self) -> T {
        self.cross(o).norm().atan2(&self.dot(o))
    }
    /// `true` when all components are finite.
    #[inline(always)]
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    /// Applies `f` to each component.
    #[inline(always)]
    pub fn map<U: Scalar>(&self, mut f: impl FnMut(&T) -> U) -> Vec3<U> {
        Vec3::new(f(&self.x), f(&self.y), f(&self.z))
    }
}

impl<T: Scalar> AddAssign<&Vec3<T>> for Vec3<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: &Vec3<T>) {
        self.x += &o.x;
        self.y += &o.y;
        self.z += &o.z;
    }
}
impl<T: Scalar> SubAssign<&Vec3<T>> for Vec3<T> {
    #[inline(always)]
    fn sub_assign(&mut self, o: &Vec3<T>) {
        self.x -= &o.x;
        self.y -= &o.y;
        self.z -= &o.z;
    }
}

impl<T: Scalar> Index<usize> for Vec3<T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, i: usize) -> &T {
        match i {
            0 => &self.x,
            1 => &self.y,
            _ => &self.z,
        }
    }
}

impl<T: Scalar> Add for &Vec3<T> {
    type Output = Vec3<T>;
    #[inline(always)]
    fn add(self, o: Self) -> Vec3<T> {
        let mut r = self.clone();
        r += o;
        r
    }
}
impl<T: Scalar> Add for Vec3<T> {
    type Output = Vec3<T>;
    #[inline(always)]
    fn add(self, o: Self) -> Vec3<T> {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl<T: Scalar> Sub for &Vec3<T> {
    type Output = Vec3<T>;
    #[inline(always)]
    fn sub(self, o: Self) -> Vec3<T> {
        let mut r = self.clone();
        r -= o;
        r
    }
}
impl<T: Scalar> Sub for Vec3<T> {
    type Output = Vec3<T>;
    #[inline(always)]
    fn sub(self, o: Self) -> Vec3<T> {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl<T: Scalar> Neg for Vec3<T> {
    type Output = Vec3<T>;
    #[inline(always)]
    fn neg(self) -> Vec3<T> {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}
impl<T: Scalar> Mul<&T> for &Vec3<T> {
    type Output = Vec3<T>;
    #[inline(always)]
    fn mul(self, k: &T) -> Vec3<T> {
        self.scale(k)
    }
}
