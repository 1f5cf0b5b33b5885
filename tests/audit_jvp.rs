//! Audit: the dual-number Jacobian-vector product is correct to a few ulps of the working
//! precision (DESIGN.md §4 "AD prediction"), on the linear and the Hamiltonian model.

use liemesh::audit::jvp::{
    self, double_double_jvp, error_vs_double_double, random_linear_invariants, RANDOM_INVARIANTS,
    SEED,
};
use liemesh::model::{Invariant, LieField, NormalField};
use liemesh::preset::Preset;
use liemesh::scalar::Vec3;

fn fig6() -> Vec<Invariant> {
    vec![Preset::Fig6.invariant()]
}

fn linear() -> Vec<Invariant> {
    random_linear_invariants(RANDOM_INVARIANTS, SEED)
}

#[test]
fn dual_f64_jvp_is_within_4_ulp_of_double_double_closed_form_on_fig6_field() {
    let e = error_vs_double_double(&fig6());
    assert!(e <= jvp::F64_ULPS, "{e} ulp");
}

#[test]
fn dual_f64_jvp_is_within_4_ulp_of_double_double_closed_form_on_linear_fields() {
    let e = error_vs_double_double(&linear());
    assert!(e <= jvp::F64_ULPS, "{e} ulp");
    assert!(jvp::jvp_vs_double_double(&linear(), None).pass);
}

#[test]
fn jvp_audit_detects_a_one_in_a_million_jvp_error() {
    // The measure must be sharp enough to see a small error: perturb the dual JVP by 1e-6
    // relative and compare against the same reference.
    let inv = Preset::Fig6.invariant();
    let field = LieField::<f64>::new(&inv);
    let probe = &jvp::probes(SEED)[0];
    let (_, jw) = field.normal_and_jvp(
        &Vec3::from_f64(probe.point),
        &Vec3::from_f64(probe.direction),
    );
    let want = double_double_jvp(&field, probe.point, probe.direction);
    let norm = want.iter().map(|c| c.0 * c.0).sum::<f64>().sqrt();
    let bad = jw.scale(&(1.0 + 1e-6)).to_f64();
    let err = (0..3)
        .map(|k| ((bad[k] - want[k].0) - want[k].1).abs() / norm / f64::EPSILON)
        .fold(0.0, f64::max);
    assert!(err > jvp::F64_ULPS, "{err}");
}

#[test]
fn sphere_jvp_is_the_direction_itself() {
    let field = LieField::<f64>::new(&Preset::Fig3.invariant());
    let w = Vec3::new(0.3, -0.4, 0.5);
    let (_, jw) = field.normal_and_jvp(&Vec3::new(0.1, 0.2, 0.9), &w);
    assert_eq!(jw, w);
}

#[cfg(feature = "mpfr")]
mod mpfr {
    use super::*;
    use liemesh::scalar::{Mpfr, Scalar};

    #[test]
    fn dual_f64_jvp_is_within_4_ulp_of_dual_mpfr256_on_fig6_field() {
        let e = jvp::error_vs_mpfr(&fig6());
        assert!(e <= jvp::F64_ULPS, "{e} ulp");
    }

    #[test]
    fn dual_f64_jvp_is_within_4_ulp_of_dual_mpfr256_on_linear_fields() {
        let e = jvp::error_vs_mpfr(&linear());
        assert!(e <= jvp::F64_ULPS, "{e} ulp");
    }

    #[test]
    fn dual_mpfr256_jvp_matches_mpfr512_central_difference_within_1e_60() {
        for invs in [fig6(), linear()] {
            let e = jvp::error_vs_central_difference(&invs);
            assert!(e <= jvp::CENTRAL_DIFFERENCE_BOUND, "{e}");
            // Not trivially zero either: the two precisions round differently.
            assert!(e > 0.0);
        }
    }

    #[test]
    fn double_double_reference_agrees_with_mpfr_to_1e_28() {
        // The no-MPFR reference is itself checked against MPFR on the same f64 matrices.
        let inv = Preset::Fig6.invariant();
        let field = LieField::<f64>::new(&inv);
        let (a, b) = (field.a(), field.b());
        for probe in jvp::probes(SEED) {
            let dd = double_double_jvp(&field, probe.point, probe.direction);
            let m = |x: f64| Mpfr::<256>::from_f64(x);
            let (p, w) = (probe.point, probe.direction);
            for i in 0..3 {
                let mut exact = m(0.0);
                for j in 0..3 {
                    exact += m(a[i][j]) * m(w[j]) + m(b[i][j]) * m(2.0) * m(p[j]) * m(w[j]);
                }
                let err = (m(dd[i].0) + m(dd[i].1) - exact.clone()).abs().to_f64();
                assert!(err <= 1e-28 * (1.0 + exact.abs().to_f64()), "{err}");
            }
        }
    }
}
