//! Audit: the same mesh computed in different scalar types agrees, point for point and decision
//! for decision (DESIGN.md §4 "Scalar agreement").

use liemesh::audit::scalars::{self, compare, run_preset, Agreement};
use liemesh::model::LieField;
use liemesh::preset::Preset;
use liemesh::scalar::Dual;

fn assert_identical_decisions(a: &Agreement) {
    assert_eq!(
        a.decision_differences,
        0,
        "{} vs {}: {}",
        a.scalar,
        a.reference,
        a.decisions_note()
    );
    assert_eq!(a.points, a.reference_points);
    assert_eq!(a.curves, a.reference_curves);
    assert!(!a.prefix_only);
}

fn assert_within(a: &Agreement, bound: f64) {
    let e = a.relative_error();
    assert!(
        e <= bound,
        "{} vs {}: vertex error {e:e} of the mesh size exceeds {bound:e} ({})",
        a.scalar,
        a.reference,
        a.vertex_note()
    );
    assert!(a.compared > 0);
}

fn dual_vs_f64(preset: Preset) -> Agreement {
    let dual = run_preset::<Dual<f64>>(preset).expect("dual run");
    let f = run_preset::<f64>(preset).expect("f64 run");
    compare(&dual, &f)
}

#[test]
fn fig3_dual_real_part_is_bit_identical_to_f64() {
    let a = dual_vs_f64(Preset::Fig3);
    assert_identical_decisions(&a);
    assert_eq!(a.differing_points, 0, "{}", a.vertex_note());
    assert_eq!(a.max_error, 0.0);
}

#[test]
fn fig6_dual_real_part_is_bit_identical_to_f64() {
    let a = dual_vs_f64(Preset::Fig6);
    assert_identical_decisions(&a);
    assert_eq!(a.differing_points, 0, "{}", a.vertex_note());
}

#[test]
fn decision_comparison_reports_where_runs_part_and_why() {
    // Two runs that really decide differently: fig6 with a smaller geodesic radius ends its
    // curves earlier. The comparison must say so rather than report agreement.
    let preset = Preset::Fig6;
    let mut short = preset.params();
    short.max_radius = Some(0.8 * preset.params().max_radius.expect("presets give it"));
    let run = liemesh::run(&LieField::<Dual<f64>>::new(&preset.invariant()), &short).unwrap();
    let reference = run_preset::<f64>(preset).unwrap();
    let a = compare(&run, &reference);
    assert!(a.decision_differences > 0);
    assert!(a.prefix_only);
    assert!(a.parting.is_some() && a.first_parting.is_some());
    let first = a.first_decision.clone().expect("a differing decision");
    assert!(
        first.contains("ended by Radius in Dual<f64> and continued in f64"),
        "{first}"
    );
    assert!(a.decisions_note().contains(&first));
    let rows = scalars::agreement_rows(preset.name(), &a, scalars::F64_BOUND, false);
    assert!(!rows[0].pass, "the decision row must fail: {:?}", rows[0]);
    assert!(rows[1].note.contains("common prefix"), "{}", rows[1].note);
}

#[cfg(not(feature = "mpfr"))]
#[test]
fn fig3_and_fig6_f32_meshes_agree_with_f64_within_1e_3_of_their_size() {
    for preset in [Preset::Fig3, Preset::Fig6] {
        let a = compare(
            &run_preset::<f32>(preset).unwrap(),
            &run_preset::<f64>(preset).unwrap(),
        );
        assert_within(&a, scalars::F32_BOUND);
    }
}

#[cfg(feature = "mpfr")]
mod mpfr {
    use super::*;
    use liemesh::scalar::Mpfr;
    use std::sync::OnceLock;

    /// Every type compared with `Mpfr<256>`, computed once per preset and shared by the tests.
    struct Audit {
        f32: Agreement,
        f64: Agreement,
        dual: Agreement,
        mpfr64: Agreement,
    }

    fn audit(preset: Preset) -> &'static Audit {
        static FIG3: OnceLock<Audit> = OnceLock::new();
        static FIG6: OnceLock<Audit> = OnceLock::new();
        let cell = match preset {
            Preset::Fig3 => &FIG3,
            Preset::Fig6 => &FIG6,
            _ => unreachable!("the tests audit fig3 and fig6"),
        };
        cell.get_or_init(|| {
            let reference = run_preset::<Mpfr<256>>(preset).expect("Mpfr<256> run");
            Audit {
                f32: compare(&run_preset::<f32>(preset).unwrap(), &reference),
                f64: compare(&run_preset::<f64>(preset).unwrap(), &reference),
                dual: compare(&run_preset::<Dual<f64>>(preset).unwrap(), &reference),
                mpfr64: compare(&run_preset::<Mpfr<64>>(preset).unwrap(), &reference),
            }
        })
    }

    #[test]
    fn fig3_f64_mesh_agrees_with_mpfr256_within_1e_10_of_its_size() {
        assert_within(&audit(Preset::Fig3).f64, scalars::F64_BOUND);
    }

    #[test]
    fn fig6_f64_mesh_agrees_with_mpfr256_within_1e_10_of_its_size() {
        assert_within(&audit(Preset::Fig6).f64, scalars::F64_BOUND);
    }

    #[test]
    fn fig3_dual_real_part_agrees_with_mpfr256_within_1e_10_of_its_size() {
        assert_within(&audit(Preset::Fig3).dual, scalars::DUAL_BOUND);
    }

    #[test]
    fn fig6_dual_real_part_agrees_with_mpfr256_within_1e_10_of_its_size() {
        assert_within(&audit(Preset::Fig6).dual, scalars::DUAL_BOUND);
    }

    #[test]
    fn fig3_mpfr64_mesh_agrees_with_mpfr256_within_1e_13_of_its_size() {
        assert_within(&audit(Preset::Fig3).mpfr64, scalars::MPFR64_BOUND);
    }

    #[test]
    fn fig6_mpfr64_mesh_agrees_with_mpfr256_within_1e_13_of_its_size() {
        assert_within(&audit(Preset::Fig6).mpfr64, scalars::MPFR64_BOUND);
    }

    #[test]
    fn fig3_f32_mesh_agrees_with_mpfr256_within_1e_3_of_its_size() {
        assert_within(&audit(Preset::Fig3).f32, scalars::F32_BOUND);
    }

    #[test]
    fn fig6_f32_mesh_agrees_with_mpfr256_within_1e_3_of_its_size() {
        assert_within(&audit(Preset::Fig6).f32, scalars::F32_BOUND);
    }

    #[test]
    fn fig3_discrete_decisions_are_identical_in_f64_dual_and_mpfr64() {
        let a = audit(Preset::Fig3);
        for x in [&a.f64, &a.dual, &a.mpfr64] {
            assert_identical_decisions(x);
        }
    }

    #[test]
    fn fig6_discrete_decisions_are_identical_in_f64_dual_and_mpfr64() {
        let a = audit(Preset::Fig6);
        for x in [&a.f64, &a.dual, &a.mpfr64] {
            assert_identical_decisions(x);
        }
    }

    #[test]
    fn f32_decisions_are_reported_identical_or_with_the_parting_point() {
        // f32 decisions are informative (see `liemesh::audit::scalars`): either identical, or
        // the note names the first point where the runs part, and the vertex error was then
        // measured on the common prefix only.
        for preset in [Preset::Fig3, Preset::Fig6] {
            let a = &audit(preset).f32;
            if a.decision_differences == 0 {
                assert!(!a.prefix_only);
            } else {
                assert!(
                    a.parting.is_some() && a.prefix_only,
                    "{}",
                    a.decisions_note()
                );
            }
        }
    }

    #[test]
    fn fig3_and_fig6_audit_rows_all_pass() {
        for preset in [Preset::Fig3, Preset::Fig6] {
            for row in scalars::scalar_agreement(preset) {
                assert!(row.pass, "{row:?}");
            }
        }
    }
}
