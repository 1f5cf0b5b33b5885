//! Audit: the first-order AD prediction of the normal (paper eq. 8–9) is `O(Δt²)` accurate on
//! the non-linear fig4–6 field and exact on linear fields (DESIGN.md §4 "AD prediction").

use liemesh::audit::prediction::{
    self, linear_prediction_exact, loglog_slope, prediction_angles, prediction_order, probes,
    slopes, Probe, SLOPE_TOLERANCE,
};
use liemesh::audit::{jvp, XorShift64};
use liemesh::model::{LieField, NormalField};
use liemesh::preset::Preset;
use liemesh::scalar::Vec3;

fn assert_slopes_near_two(slopes: &[f64]) {
    assert!(!slopes.is_empty());
    for (i, s) in slopes.iter().enumerate() {
        assert!(
            (s - 2.0).abs() <= SLOPE_TOLERANCE,
            "probe {i}: log-log slope {s} is not within {SLOPE_TOLERANCE} of 2 (all: {slopes:?})"
        );
    }
}

#[test]
fn fig6_prediction_error_shrinks_as_dt_squared_in_f64() {
    assert_slopes_near_two(&slopes::<f64>(&[Preset::Fig6.invariant()]));
    let row = prediction_order::<f64>(&[Preset::Fig6.invariant()], Some("fig6"));
    assert!(row.pass, "{row:?}");
}

#[cfg(feature = "mpfr")]
#[test]
fn fig6_prediction_error_shrinks_as_dt_squared_in_mpfr256() {
    use liemesh::scalar::Mpfr;
    assert_slopes_near_two(&slopes::<Mpfr<256>>(&[Preset::Fig6.invariant()]));
    let row = prediction_order::<Mpfr<256>>(&[Preset::Fig6.invariant()], Some("fig6"));
    assert!(row.pass, "{row:?}");
}

#[test]
fn fig6_prediction_error_is_second_order_not_exact() {
    // The error must actually be there (a quadratic field is not predicted exactly) and shrink
    // by about 4 per halving of Δt.
    let inv = Preset::Fig6.invariant();
    let field = LieField::<f64>::new(&inv);
    for probe in probes(&inv, prediction::SEED) {
        let samples = prediction_angles(&field, &probe).expect("probes have a tangent plane");
        for pair in samples.windows(2) {
            let ratio = pair[0].1 / pair[1].1;
            assert!(
                pair[1].1 > 0.0 && (3.0..5.5).contains(&ratio),
                "halving Δt from 2^{} divided the error by {ratio}",
                pair[0].0
            );
        }
    }
}

#[test]
fn sphere_prediction_is_exact_to_working_precision_in_f64() {
    let row = linear_prediction_exact::<f64>(&[Preset::Fig3.invariant()], Some("fig3"));
    assert!(row.pass, "{row:?}");
}

#[cfg(feature = "mpfr")]
#[test]
fn sphere_prediction_is_exact_to_working_precision_in_mpfr256() {
    use liemesh::scalar::Mpfr;
    let row = linear_prediction_exact::<Mpfr<256>>(&[Preset::Fig3.invariant()], Some("fig3"));
    assert!(row.pass, "{row:?}");
    assert!(row.measured <= prediction::LINEAR_ULPS);
}

#[test]
fn random_linear_prediction_is_exact_to_a_few_ulps_in_f64() {
    let invs = jvp::random_linear_invariants(jvp::RANDOM_INVARIANTS, jvp::SEED);
    let row = linear_prediction_exact::<f64>(&invs, None);
    assert!(row.pass, "{row:?}");
}

#[cfg(feature = "mpfr")]
#[test]
fn random_linear_prediction_is_exact_to_a_few_ulps_in_mpfr256() {
    use liemesh::scalar::Mpfr;
    let invs = jvp::random_linear_invariants(jvp::RANDOM_INVARIANTS, jvp::SEED);
    let row = linear_prediction_exact::<Mpfr<256>>(&invs, None);
    assert!(row.pass, "{row:?}");
}

/// The fig6 field with a JVP that is 0.1 % off: the prediction is then only first-order.
struct SlightlyWrongJvp(LieField<f64>);

impl NormalField<f64> for SlightlyWrongJvp {
    fn normal(&self, p: &Vec3<f64>) -> Vec3<f64> {
        self.0.normal(p)
    }
    fn normal_and_jvp(&self, p: &Vec3<f64>, w: &Vec3<f64>) -> (Vec3<f64>, Vec3<f64>) {
        let (v, jw) = self.0.normal_and_jvp(p, w);
        (v, jw.scale(&1.001))
    }
}

#[test]
fn prediction_order_audit_detects_a_wrong_jvp() {
    let inv = Preset::Fig6.invariant();
    let wrong = SlightlyWrongJvp(LieField::new(&inv));
    let mut rng = XorShift64::new(3);
    let probe = Probe {
        point: liemesh::preset::FIG46_P0,
        direction: rng.unit_vector(),
    };
    let slope = loglog_slope(&prediction_angles(&wrong, &probe).unwrap());
    assert!(
        (slope - 2.0).abs() > SLOPE_TOLERANCE,
        "a 0.1 % JVP error must break the Δt² order; slope {slope}"
    );
}

#[test]
fn loglog_slope_fits_power_laws_and_rejects_zero_errors() {
    let quad: Vec<(f64, f64)> = (3..=12)
        .map(|k| (-k as f64, 3.0 * (-2.0 * k as f64).exp2()))
        .collect();
    assert!((loglog_slope(&quad) - 2.0).abs() < 1e-12);
    let with_zero = [(-3.0, 1e-3), (-4.0, 0.0)];
    assert!(loglog_slope(&with_zero).is_nan());
}
