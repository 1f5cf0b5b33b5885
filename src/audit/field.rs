//! The audits of any field that can be built in every scalar type ([`EveryScalar`]): an
//! invariant from a file, or a formula of one's own ([`crate::model::Formula`]).
//!
//! The preset audits probe the unit cube; a field of one's own lives at its own scale and
//! place, so [`audit_field`] probes where the surface is: points of its `f64` mesh, with
//! steps scaled to the run's own initial step Δt₀ (the prediction is checked for
//! `Δt = 8 Δt₀ · 2^-k`, `k` in [`DT_EXPONENTS`]). Rows:
//!
//! | check | scalar | bound |
//! |---|---|---|
//! | the mesh is valid (manifold, oriented, no degenerate face, no self-intersection) | `f64` | 0 defects |
//! | prediction order: `max(0, 2 − slope)` of the prediction error where the field is not linear along the probe; rounding only where it is | `f64`, `Mpfr<256>` | [`SLOPE_TOLERANCE`] |
//! | the `f64` dual-number JVP against the `Mpfr<256>` one, relative to `\|J w\|` | `Dual<f64>` | [`F64_JVP_BOUND`] |
//! | the `Mpfr<256>` dual-number JVP against an `Mpfr<512>` central difference | `Dual<Mpfr<256>>` | [`CENTRAL_DIFFERENCE_BOUND`] |
//! | the whole mesh in `f32`, `f64`, `Dual<f64>`, `Mpfr<64>` against `Mpfr<256>` | each | see [`super::scalars`] |
//!
//! The MPFR rows need the `mpfr` feature.

use super::prediction::{loglog_slope, prediction_angles_at, Probe, DT_EXPONENTS};
use super::{Row, XorShift64};
use crate::model::{EveryScalar, NormalField};
use crate::scalar::Scalar;
use crate::{MeshParams, MeshRun};

pub use super::prediction::SLOPE_TOLERANCE;

/// Bound on the `f64` JVP's error relative to `|J w|`. A formula of one's own may cancel
/// (a torus's `|p|² + R² − a² − 2R²`), so the bound is not the few ulps of the linear
/// model's `A w`: it allows an amplification of about 10⁴.
pub const F64_JVP_BOUND: f64 = 1e-12;
/// Bound on the `Mpfr<256>` JVP's difference from the `Mpfr<512>` central difference, relative
/// to `|J w|` (the step is `2^-100` of the initial step, so the truncation is about `2^-200`).
pub const CENTRAL_DIFFERENCE_BOUND: f64 = 1e-50;
/// Probe points (mesh vertices) and directions per point.
pub const POINTS: usize = 16;
/// Directions per probe point.
pub const DIRECTIONS: usize = 2;
/// A probe whose prediction angle stays within this many ulps of the working precision at
/// every step is along a direction where the field is linear: exact, no slope to fit.
pub const LINEAR_ULPS: f64 = 64.0;
/// Seed of the probe directions.
pub const SEED: u64 = 0x5EED_0003;

/// Every audit of `field` meshed with `params`; `label` names the field in the rows.
pub fn audit_field<S: EveryScalar>(field: &S, params: &MeshParams, label: &str) -> Vec<Row> {
    let name = Some(label);
    let run = match crate::run(&field.in_scalar::<f64>(), params) {
        Ok(run) => run,
        Err(e) => {
            return vec![Row::failed(
                "mesh valid [defects]",
                "f64",
                name,
                0.0,
                format!("the f64 run failed: {e}"),
            )]
        }
    };
    let mut rows = vec![validity_row(&run, label)];
    let probes = probes_on(&run);
    let length = 8.0 * run.params.dt;
    rows.push(prediction_row::<f64, _>(
        &field.in_scalar::<f64>(),
        &probes,
        length,
        label,
    ));
    #[cfg(feature = "mpfr")]
    {
        use crate::scalar::Mpfr;
        rows.push(prediction_row::<Mpfr<256>, _>(
            &field.in_scalar::<Mpfr<256>>(),
            &probes,
            length,
            label,
        ));
        rows.push(with_mpfr::jvp_vs_mpfr(field, &probes, label));
        rows.push(with_mpfr::jvp_vs_central_difference(
            field, &probes, length, label,
        ));
    }
    rows.extend(super::scalars::scalar_agreement_of(field, params, label));
    rows
}

fn validity_row<T>(run: &MeshRun<T>, label: &str) -> Row {
    let v = &run.validation;
    let defects = v.non_manifold_edges.count
        + v.non_manifold_vertices.count
        + v.orientation_flips.count
        + v.degenerate_faces.count
        + v.out_of_range_faces.count
        + v.non_finite_vertices.count
        + v.self_intersections.count;
    Row::at_most(
        "mesh valid [defects]",
        "f64",
        Some(label),
        defects as f64,
        0.0,
        format!("{} triangles: {v}", run.mesh.triangles.len()),
    )
}

/// [`POINTS`] vertices of the mesh spread over its vertex list, with [`DIRECTIONS`] random
/// unit directions each.
pub fn probes_on<T>(run: &MeshRun<T>) -> Vec<Probe> {
    let v = &run.mesh.vertices;
    let mut rng = XorShift64::new(SEED);
    let count = POINTS.min(v.len());
    (0..count)
        .flat_map(|i| {
            let point = v[i * v.len() / count];
            (0..DIRECTIONS)
                .map(|_| Probe {
                    point,
                    direction: rng.unit_vector(),
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The prediction-order row in `T`: at each probe, either the prediction is exact to
/// rounding ([`LINEAR_ULPS`]) at every step, or the log-log slope of its error, fitted over
/// the finer half of the steps where the error is above a thousand ulps, is at least
/// 2 − [`SLOPE_TOLERANCE`] (second order or better).
pub fn prediction_row<T: Scalar, F: NormalField<T>>(
    field: &F,
    probes: &[Probe],
    length: f64,
    label: &str,
) -> Row {
    let ulp = 2.0 * T::unit_roundoff();
    let (mut worst, mut linear, mut fitted, mut missing) = (0.0_f64, 0, 0, 0);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for probe in probes {
        let Some(samples) = prediction_angles_at(field, probe, length) else {
            missing += 1;
            continue;
        };
        if samples.iter().all(|&(_, a)| a <= LINEAR_ULPS * ulp) {
            linear += 1;
            continue;
        }
        let above: Vec<(f64, f64)> = samples
            .into_iter()
            .filter(|&(_, a)| a > 1e3 * ulp)
            .collect();
        // Order is what the error does as Δt shrinks: the fit takes the finer half of those
        // steps (at least 3). At the coarsest, higher-order terms still bend the curve where
        // the surface curves fast: on a torus's inner equator the error fell by 2.9, 2.6 and
        // 3.4 over the first halvings and by 3.7 to 3.99 over the last six.
        let finest = &above[(above.len() / 2).min(above.len().saturating_sub(3))..];
        let slope = if finest.len() >= 3 {
            loglog_slope(finest)
        } else {
            f64::NAN
        };
        fitted += 1;
        lo = lo.min(slope);
        hi = hi.max(slope);
        // At least second order: where the second derivative of v along w is parallel to v
        // (a torus's outer equator, along the circle) the angle error is O(Δt³).
        let d = (2.0 - slope).max(0.0);
        worst = if d.is_nan() || worst.is_nan() {
            f64::NAN
        } else {
            worst.max(d)
        };
    }
    if missing > 0 {
        worst = f64::NAN;
    }
    Row::at_most(
        "prediction order deficit max(0, 2−slope)",
        T::type_name(),
        Some(label),
        worst,
        SLOPE_TOLERANCE,
        format!(
            "angle(v+Δt·Jw, v(p+Δt·w)), Δt = {length:.3e}·2^-{}…2^-{}, at {} mesh probes: {fitted} fitted{}, {linear} exact to {LINEAR_ULPS} ulp{}",
            DT_EXPONENTS.start(),
            DT_EXPONENTS.end(),
            probes.len(),
            if fitted > 0 {
                format!(" (slopes in [{lo:.4}, {hi:.4}])")
            } else {
                String::new()
            },
            if missing > 0 {
                format!(", {missing} without a normal or tangent")
            } else {
                String::new()
            }
        ),
    )
}

#[cfg(feature = "mpfr")]
mod with_mpfr {
    use super::*;
    use crate::scalar::{Mpfr, Vec3};

    fn worst_of(worst: f64, err: f64) -> f64 {
        if err.is_nan() || worst.is_nan() {
            f64::NAN
        } else {
            worst.max(err)
        }
    }

    /// The `f64` JVP against the `Mpfr<256>` JVP of the same field, relative to `|J w|`.
    pub fn jvp_vs_mpfr<S: EveryScalar>(field: &S, probes: &[Probe], label: &str) -> Row {
        let coarse = field.in_scalar::<f64>();
        let fine = field.in_scalar::<Mpfr<256>>();
        let mut worst = 0.0_f64;
        for probe in probes {
            let (_, got) = coarse.normal_and_jvp(
                &Vec3::from_f64(probe.point),
                &Vec3::from_f64(probe.direction),
            );
            let (_, want) = fine.normal_and_jvp(
                &Vec3::from_f64(probe.point),
                &Vec3::from_f64(probe.direction),
            );
            let norm = want.norm();
            for k in 0..3 {
                let err = ((Mpfr::<256>::from_f64(got[k]) - want[k].clone()).abs() / norm.clone())
                    .to_f64();
                worst = worst_of(worst, err);
            }
        }
        Row::at_most(
            "JVP vs Dual<Mpfr<256>> [rel]",
            "Dual<f64>",
            Some(label),
            worst,
            F64_JVP_BOUND,
            format!(
                "max |Δ(Jw)_i|/|Jw| over {} mesh probes; the field built in f64 and in Mpfr<256>",
                probes.len()
            ),
        )
    }

    /// The `Mpfr<256>` JVP against the `Mpfr<512>` central difference with step
    /// `length · 2^-100`.
    pub fn jvp_vs_central_difference<S: EveryScalar>(
        field: &S,
        probes: &[Probe],
        length: f64,
        label: &str,
    ) -> Row {
        let coarse = field.in_scalar::<Mpfr<256>>();
        let fine = field.in_scalar::<Mpfr<512>>();
        let h = Mpfr::<512>::from_f64(length) * Mpfr::<512>::exp2i(-100);
        let two_h = h.clone() + h.clone();
        let mut worst = 0.0_f64;
        for probe in probes {
            let (_, jw) = coarse.normal_and_jvp(
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
                worst = worst_of(worst, err);
            }
        }
        Row::at_most(
            "JVP vs Mpfr<512> central diff [rel]",
            "Dual<Mpfr<256>>",
            Some(label),
            worst,
            CENTRAL_DIFFERENCE_BOUND,
            format!(
                "max |Δ(Jw)_i|/|Jw| over {} mesh probes; h = {length:.3e}·2^-100",
                probes.len()
            ),
        )
    }
}
