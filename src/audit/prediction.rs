//! The order of the AD prediction (paper eq. 8–9, DESIGN.md §4 "AD prediction").
//!
//! At a point `p` with unit tangent `w`, the stepper predicts the normal at `p + Δt w` as
//! `v(p) + Δt J_v(p) w` from one forward-mode JVP. The audit measures the angle between that
//! prediction and the exact `v(p + Δt w)`, both evaluated in the scalar type under test, for
//! `Δt = 2^-3 … 2^-12`:
//!
//! - for a non-linear field the error is `O(Δt²)`: the slope of `log angle` against
//!   `log Δt`, fitted by least squares, must lie in `[2 − 0.1, 2 + 0.1]` at every probe;
//! - for a linear field (`B = 0`) the prediction is exact, so the angle must stay within a
//!   few ulps of the working precision.
//!
//! Probes are pseudo-random points of the cube `[−1, 1]³` where the field is not small, with
//! random directions projected onto the tangent plane in the working precision.

use super::{Row, XorShift64};
use crate::model::{Invariant, LieField, NormalField};
use crate::scalar::{Scalar, Vec3};
use crate::trace;

/// `Δt = 2^-k` for these `k`.
pub const DT_EXPONENTS: std::ops::RangeInclusive<i32> = 3..=12;
/// The fitted slope must be within this distance of 2.
pub const SLOPE_TOLERANCE: f64 = 0.1;
/// Bound on the linear field's prediction angle, in ulps (machine epsilons) of the scalar.
pub const LINEAR_ULPS: f64 = 8.0;
/// Probe points per invariant.
pub const POINTS: usize = 8;
/// Directions per probe point.
pub const DIRECTIONS: usize = 2;
/// Seed of the probe generator.
pub const SEED: u64 = 0x5EED_0001;

/// A point and a direction (projected onto the tangent plane before use).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The point `p`.
    pub point: [f64; 3],
    /// The direction, not necessarily tangent nor unit.
    pub direction: [f64; 3],
}

/// `true` when the invariant's field is linear (`B = 0`, so `v = A p`).
pub fn is_linear(invariant: &Invariant) -> bool {
    LieField::<f64>::new(invariant)
        .b()
        .iter()
        .all(|r| r.x == 0.0 && r.y == 0.0 && r.z == 0.0)
}

/// [`POINTS`] × [`DIRECTIONS`] probes for `invariant`: points of `[−1, 1]³` where
/// `|v(p)| ≥ 0.05` (so that the normal direction is well defined), each with random
/// directions.
pub fn probes(invariant: &Invariant, seed: u64) -> Vec<Probe> {
    let field = LieField::<f64>::new(invariant);
    let mut rng = XorShift64::new(seed);
    let mut out = Vec::with_capacity(POINTS * DIRECTIONS);
    let mut points = 0;
    while points < POINTS {
        let p = rng.in_cube(1.0);
        let v = NormalField::<f64>::normal(&field, &Vec3::from_f64(p));
        if v.norm() < 0.05 {
            continue;
        }
        points += 1;
        for _ in 0..DIRECTIONS {
            out.push(Probe {
                point: p,
                direction: rng.unit_vector(),
            });
        }
    }
    out
}

/// `(log2 Δt, angle)` between the prediction `v + Δt J w` and the exact `v(p + Δt w)` for
/// every `Δt = 2^-k`, `k ∈` [`DT_EXPONENTS`], computed in `T`; `None` when the probe has no
/// normal or no tangent direction.
pub fn prediction_angles<T: Scalar, F: NormalField<T>>(
    field: &F,
    probe: &Probe,
) -> Option<Vec<(f64, f64)>> {
    prediction_angles_at(field, probe, 1.0)
}

/// [`prediction_angles`] with the steps `Δt = length · 2^-k`, for a surface of size `length`.
pub fn prediction_angles_at<T: Scalar, F: NormalField<T>>(
    field: &F,
    probe: &Probe,
    length: f64,
) -> Option<Vec<(f64, f64)>> {
    let p = Vec3::<T>::from_f64(probe.point);
    let (_, n, _) = trace::unit_normal(field, &p).ok()?;
    let w = trace::project_tangent(&Vec3::from_f64(probe.direction), &n)?;
    let (v, jw) = field.normal_and_jvp(&p, &w);
    Some(
        DT_EXPONENTS
            .map(|k| {
                let dt = T::from_f64(length * (-k as f64).exp2());
                let predicted = v.add_scaled(&dt, &jw);
                let exact = field.normal(&p.add_scaled(&dt, &w));
                (-k as f64, predicted.angle_to(&exact).to_f64())
            })
            .collect(),
    )
}

/// Least-squares slope of `log2 y` against `x` for `(x, y)` pairs (NaN when a `y` is not
/// positive, which a caller must treat as a failure).
pub fn loglog_slope(samples: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> = samples.iter().map(|&(x, y)| (x, y.log2())).collect();
    if pts.iter().any(|(_, ly)| !ly.is_finite()) || pts.len() < 2 {
        return f64::NAN;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// The fitted slope of every probe of every invariant, in `T`.
pub fn slopes<T: Scalar>(invariants: &[Invariant]) -> Vec<f64> {
    let mut out = Vec::new();
    for (i, inv) in invariants.iter().enumerate() {
        let field = LieField::<T>::new(inv);
        for probe in probes(inv, SEED + i as u64) {
            out.push(match prediction_angles(&field, &probe) {
                Some(samples) => loglog_slope(&samples),
                None => f64::NAN,
            });
        }
    }
    out
}

/// Audit row: the prediction error of a non-linear field shrinks as `Δt²` (measured: the
/// largest `|slope − 2|` over all probes, bound [`SLOPE_TOLERANCE`]).
pub fn prediction_order<T: Scalar>(invariants: &[Invariant], preset: Option<&str>) -> Row {
    let slopes = slopes::<T>(invariants);
    let worst = slopes
        .iter()
        .map(|s| (s - 2.0).abs())
        .fold(0.0_f64, |m, d| {
            if d.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(d)
            }
        });
    let lo = slopes.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = slopes.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Row::at_most(
        "prediction order |slope−2|",
        T::type_name(),
        preset,
        worst,
        SLOPE_TOLERANCE,
        format!(
            "angle(v+Δt·Jw, v(p+Δt·w)) vs Δt=2^-{}…2^-{}, {} probes: log-log slopes in [{lo:.4}, {hi:.4}]",
            DT_EXPONENTS.start(),
            DT_EXPONENTS.end(),
            slopes.len()
        ),
    )
}

/// Audit row: for a linear field the prediction is exact, so its angle to the exact normal
/// is rounding only (measured: the largest angle in ulps of `T`, bound [`LINEAR_ULPS`]).
pub fn linear_prediction_exact<T: Scalar>(invariants: &[Invariant], preset: Option<&str>) -> Row {
    let ulp = 2.0 * T::unit_roundoff();
    let mut worst = 0.0_f64;
    let mut count = 0;
    let mut missing = 0;
    for (i, inv) in invariants.iter().enumerate() {
        let field = LieField::<T>::new(inv);
        for probe in probes(inv, SEED + i as u64) {
            match prediction_angles(&field, &probe) {
                Some(samples) => {
                    for (_, angle) in samples {
                        worst = if angle.is_nan() {
                            f64::NAN
                        } else {
                            worst.max(angle / ulp)
                        };
                        count += 1;
                    }
                }
                None => missing += 1,
            }
        }
    }
    if missing > 0 {
        worst = f64::NAN;
    }
    Row::at_most(
        "linear prediction angle [ulp]",
        T::type_name(),
        preset,
        worst,
        LINEAR_ULPS,
        format!(
            "v = A p: angle(v+Δt·Jw, v(p+Δt·w)) over {count} (probe, Δt) pairs on {} invariant(s), 1 ulp = {ulp:.3e}{}",
            invariants.len(),
            if missing > 0 {
                format!("; {missing} probes had no normal or tangent")
            } else {
                String::new()
            }
        ),
    )
}
