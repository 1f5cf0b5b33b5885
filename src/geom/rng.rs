//! A small deterministic random number generator for the audits' sample points.

/// Marsaglia's xorshift64* generator: deterministic, seedable, no dependency. Good enough to
/// spread audit probes; not for anything that needs statistical quality guarantees.
///
/// ```
/// use liemesh::audit::XorShift64;
/// let mut a = XorShift64::new(7);
/// let mut b = XorShift64::new(7);
/// assert_eq!(a.next_u64(), b.next_u64());
/// let x = a.uniform(-1.0, 1.0);
/// assert!((-1.0..1.0).contains(&x));
/// ```
#[derive(Clone, Debug)]
pub struct XorShift64(u64);

impl XorShift64 {
    /// A generator from a seed (a zero seed is replaced by a fixed non-zero one).
    pub fn new(seed: u64) -> Self {
        // Scramble the seed so that small seeds do not start in a low-entropy state.
        let s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
        XorShift64(if s == 0 { 0x2545_F491_4F6C_DD1D } else { s })
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A uniform number in `[0, 1)` with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform number in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A point uniform in the cube `[−h, h]³`.
    pub fn in_cube(&mut self, h: f64) -> [f64; 3] {
        [
            self.uniform(-h, h),
            self.uniform(-h, h),
            self.uniform(-h, h),
        ]
    }

    /// A unit vector uniform on the sphere (by rejection from the cube).
    pub fn unit_vector(&mut self) -> [f64; 3] {
        loop {
            let v = self.in_cube(1.0);
            let r2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            if r2 > 1e-4 && r2 <= 1.0 {
                let r = r2.sqrt();
                return [v[0] / r, v[1] / r, v[2] / r];
            }
        }
    }
}
