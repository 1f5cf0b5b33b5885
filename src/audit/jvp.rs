//! Correctness of the Jacobian-vector product `J_v(p) w` (DESIGN.md §4 "AD prediction").
//!
//! Three references, on pseudo-random points of `[−1.5, 1.5]³` and random unit directions:
//!
//! - [`jvp_vs_double_double`] (no MPFR needed): the `Dual<f64>` JVP of a `LieField<f64>`
//!   against the closed form `J w = A w + B (2 p∘w)` of the model (lift `ℓ(p) = (p, p∘p)`)
//!   evaluated in double-double arithmetic from the *same* `f64` matrices. This isolates the
//!   rounding of the dual-number pass.
//! - `jvp_vs_mpfr` (feature `mpfr`): the `Dual<f64>` JVP of `LieField<f64>` against the JVP of
//!   `LieField<Mpfr<256>>` (a `Dual<Mpfr<256>>` pass, with `A`, `B` built in MPFR from the
//!   invariant). This includes the rounding of the `f64` matrices.
//! - `jvp_vs_central_difference` (feature `mpfr`): the `Dual<Mpfr<256>>` JVP against the central difference
//!   `(v(p + h w) − v(p − h w)) / 2h` of `LieField<Mpfr<512>>` with `h = 2^-100`: exact for
//!   the quadratic fields of this model up to rounding (≈2^-412), and within `h² ≈ 6e-61` of
//!   the derivative for any smooth field.
//!
//! Errors are the largest component error relative to `|J w|`, in ulps of `f64`
//! (`2^-52`) for the `f64` checks.

use super::prediction::Probe;
use super::{Row, XorShift64};
use crate::model::{Invariant, LieField, NormalField};
use crate::scalar::Vec3;

/// Bound of the `Dual<f64>` JVP error, in ulps of `f64` relative to `|J w|`.
pub const F64_ULPS: f64 = 4.0;
/// Bound of the relative difference between the `Dual<Mpfr<256>>` JVP and the `Mpfr<512>`
/// central difference.
pub const CENTRAL_DIFFERENCE_BOUND: f64 = 1e-60;
/// The central-difference step is `2^CENTRAL_DIFFERENCE_STEP_EXPONENT`.
pub const CENTRAL_DIFFERENCE_STEP_EXPONENT: i32 = -100;
/// Probes per invariant.
pub const PROBES: usize = 64;
/// How many random linear invariants [`super::run_all`] checks.
pub const RANDOM_INVARIANTS: usize = 4;
/// Seed of the probe and invariant generators.
pub const SEED: u64 = 0x5EED_0002;

/// One `f64` ulp: the machine epsilon `2^-52`.
const ULP: f64 = f64::EPSILON;

/// `count` random linear invariants: `|λi| ∈ [0.3, 2]` with random signs, angles in `[−π, π]`.
pub fn random_linear_invariants(count: usize, seed: u64) -> Vec<Invariant> {
    use std::f64::consts::PI;
    let mut rng = XorShift64::new(seed ^ 0x011A_EA12);
    (0..count)
        .map(|_| {
            let mut n = [0.0; 6];
            for x in &mut n[0..3] {
                let sign = if rng.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
                *x = sign * rng.uniform(0.3, 2.0);
            }
            for x in &mut n[3..6] {
                *x = rng.uniform(-PI, PI);
            }
            Invariant::from_numbers(&n).expect("finite numbers")
        })
        .collect()
}

/// [`PROBES`] points of `[−1.5, 1.5]³` with unit directions.
pub fn probes(seed: u64) -> Vec<Probe> {
    let mut rng = XorShift64::new(seed);
    (0..PROBES)
        .map(|_| Probe {
            point: rng.in_cube(1.5),
            direction: rng.unit_vector(),
        })
        .collect()
}

/// The probes of invariant number `i` of a list.
fn probes_of(i: usize) -> Vec<Probe> {
    probes(SEED.wrapping_add(1000 * i as u64))
}

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// A double-double accumulator `hi + lo` (about 104 bits).
#[derive(Clone, Copy, Default)]
struct DoubleDouble(f64, f64);

impl DoubleDouble {
    fn add(self, x: f64) -> Self {
        let (s, e) = two_sum(self.0, x);
        let (hi, lo) = two_sum(s, e + self.1);
        DoubleDouble(hi, lo)
    }
}

/// The closed-form JVP `A w + B (2 p∘w)` of `field` (its own `f64` matrices) in
/// double-double arithmetic, as `(hi, lo)` per component: accurate to about `2^-100` of the
/// sum of the magnitudes of its terms.
pub fn double_double_jvp(field: &LieField<f64>, p: [f64; 3], w: [f64; 3]) -> [(f64, f64); 3] {
    let (a, b) = (field.a(), field.b());
    let mut out = [(0.0, 0.0); 3];
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = DoubleDouble::default();
        for j in 0..3 {
            let (h, l) = two_prod(a[i][j], w[j]);
            acc = acc.add(h).add(l);
            // 2 p_j w_j exactly as h2 + l2, then b_ij times it.
            let (h2, l2) = two_prod(2.0 * p[j], w[j]);
            let (h3, l3) = two_prod(b[i][j], h2);
            acc = acc.add(h3).add(l3).add(b[i][j] * l2);
        }
        *o = (acc.0, acc.1);
    }
    out
}

/// The `Dual<f64>` JVP of `field` at a probe.
fn dual_f64_jvp(field: &LieField<f64>, probe: &Probe) -> [f64; 3] {
    let (_, jw) = field.normal_and_jvp(
        &Vec3::from_f64(probe.point),
        &Vec3::from_f64(probe.direction),
    );
    jw.to_f64()
}

/// Largest component error of the `Dual<f64>` JVP against the double-double closed form, in
/// ulps of `f64` relative to `|J w|`, over every probe of every invariant.
pub fn error_vs_double_double(invariants: &[Invariant]) -> f64 {
    let mut worst = 0.0_f64;
    for (i, inv) in invariants.iter().enumerate() {
        let field = LieField::<f64>::new(inv);
        for probe in probes_of(i) {
            let got = dual_f64_jvp(&field, &probe);
            let want = double_double_jvp(&field, probe.point, probe.direction);
            let norm = want.iter().map(|c| c.0 * c.0).sum::<f64>().sqrt();
            for k in 0..3 {
                // got − hi is exact when they are close (Sterbenz), then − lo.
                let err = ((got[k] - want[k].0) - want[k].1).abs() / norm / ULP;
                worst = if err.is_nan() {
                    f64::NAN
                } else {
                    worst.max(err)
                };
            }
        }
    }
    worst
}

/// Audit row: the `Dual<f64>` JVP against the double-double closed form (no MPFR needed).
pub fn jvp_vs_double_double(invariants: &[Invariant], preset: Option<&str>) -> Row {
    let worst = error_vs_double_double(invariants);
    Row::at_most(
        "JVP vs double-double [f64 ulp]",
        "Dual<f64>",
        preset,
        worst,
        F64_ULPS,
        format!(
            "max |Δ(Jw)_i|/|Jw| over {} probes on {} invariant(s); reference A w + B(2p∘w) from the same f64 matrices",
            PROBES * invariants.len(),
            invariants.len()
        ),
    )
}

#[cfg(feature = "mpfr")]
pub use with_mpfr::*;

#[cfg(feature = "mpfr")]
mod with_mpfr {
    use super::*;
    use crate::scalar::{Mpfr, Scalar};

    /// Largest component error of the `Dual<f64>` JVP of `LieField<f64>` against the
    /// `Dual<Mpfr<256>>` JVP of `LieField<Mpfr<256>>`, in ulps of `f64` relative to `|J w|`.
    pub fn error_vs_mpfr(invariants: &[Invariant]) -> f64 {
        let mut worst = 0.0_f64;
        for (i, inv) in invariants.iter().enumerate() {
            let field = LieField::<f64>::new(inv);
            let reference = LieField::<Mpfr<256>>::new(inv);
            for probe in probes_of(i) {
                let got = dual_f64_jvp(&field, &probe);
                let (_, want) = reference.normal_and_jvp(
                    &Vec3::from_f64(probe.point),
                    &Vec3::from_f64(probe.direction),
                );
                let norm = want.norm();
                for (k, g) in got.iter().enumerate() {
                    let err = ((Mpfr::<256>::from_f64(*g) - want[k].clone()).abs() / norm.clone())
                        .to_f64()
                        / ULP;
                    worst = if err.is_nan() {
                        f64::NAN
                    } else {
                        worst.max(err)
                    };
                }
            }
        }
        worst
    }

    /// Audit row: the `Dual<f64>` JVP against the `Dual<Mpfr<256>>` JVP.
    pub fn jvp_vs_mpfr(invariants: &[Invariant], preset: Option<&str>) -> Row {
        let worst = error_vs_mpfr(invariants);
        Row::at_most(
            "JVP vs Dual<Mpfr<256>> [f64 ulp]",
            "Dual<f64>",
            preset,
            worst,
            F64_ULPS,
            format!(
                "max |Δ(Jw)_i|/|Jw| over {} probes on {} invariant(s); LieField<f64> vs LieField<Mpfr<256>> (matrices built in each precision)",
                PROBES * invariants.len(),
                invariants.len()
            ),
        )
    }

    /// Largest component difference, relative to `|J w|`, between the `Dual<Mpfr<256>>` JVP
    /// and the `Mpfr<512>` central difference with step `2^`[`CENTRAL_DIFFERENCE_STEP_EXPONENT`].
    pub fn error_vs_central_difference(invariants: &[Invariant]) -> f64 {
        let h = Mpfr::<512>::exp2i(CENTRAL_DIFFERENCE_STEP_EXPONENT);
        let two_h = h.clone() + h.clone();
        let mut worst = 0.0_f64;
        for (i, inv) in invariants.iter().enumerate() {
            let field = LieField::<Mpfr<256>>::new(inv);
            let fine = LieField::<Mpfr<512>>::new(inv);
            for probe in probes_of(i) {
                let (_, jw) = field.normal_and_jvp(
                    &Vec3::from_f64(probe.point),
                    &Vec3::from_f64(probe.direction),
                );
                let (p, w) = (
                    Vec3::<Mpfr<512>>::from_f64(probe.point),
                    Vec3::<Mpfr<512>>::from_f64(probe.direction),
                );
                let plus = fine.normal(&p.add_scaled(&h, &w));
                let minus = fine.normal(&p.add_scaled(&-h.clone(), &w));
                let cd = (plus - minus).scale(&(Mpfr::<512>::from_f64(1.0) / two_h.clone()));
                let norm = cd.norm();
                for k in 0..3 {
                    let got = Mpfr::<512>::with_val(&jw[k].0);
                    let err = ((got - cd[k].clone()).abs() / norm.clone()).to_f64();
                    worst = if err.is_nan() {
                        f64::NAN
                    } else {
                        worst.max(err)
                    };
                }
            }
        }
        worst
    }

    /// Audit row: the `Dual<Mpfr<256>>` JVP against the `Mpfr<512>` central difference.
    pub fn jvp_vs_central_difference(invariants: &[Invariant], preset: Option<&str>) -> Row {
        let worst = error_vs_central_difference(invariants);
        Row::at_most(
            "JVP vs Mpfr<512> central diff [rel]",
            "Dual<Mpfr<256>>",
            preset,
            worst,
            CENTRAL_DIFFERENCE_BOUND,
            format!(
                "max |Δ(Jw)_i|/|Jw| over {} probes on {} invariant(s); h = 2^{CENTRAL_DIFFERENCE_STEP_EXPONENT}",
                PROBES * invariants.len(),
                invariants.len()
            ),
        )
    }
}
