//! Property tests of the whole mesher over random linear and Hamiltonian invariants, initial
//! points and parameters near the paper's (DESIGN.md §4).
//!
//! Every case runs `liemesh::run` in `f64` and hands the result to
//! `check_run` of `fuzz/src/lib.rs`, the same check the `mesher` fuzz target uses. It holds
//! when the run returns a typed `MeshError` that fits the input (exactly the error
//! `MeshParams::resolve` gives for invalid parameters; a singular `p0`, a direction along the
//! normal, an untriangulable sample set or no surviving triangle for valid ones), or a mesh
//! with
//!
//! - a passing validation (an embedded, consistently oriented 2-manifold, decided exactly);
//! - no NaN, no degenerate (repeated index, zero area) or duplicate triangle, no unused vertex;
//! - every edge in at most two triangles and consistent orientation ([`Topology`]);
//! - every accepted step's predicted α inside `[β_min, β_max]` unless the step reports a
//!   limit (clamp or budget);
//! - the budgets respected: at most `max_points` points, `max_curves` curves,
//!   `max_steps + 1` points per curve;
//! - consistent bookkeeping (provenance, arc lengths, radius and bounding box) and a chart
//!   triangulation that is counter-clockwise and Delaunay off the constraints.
//!
//! A panic anywhere fails the case. Cases come from a fixed seed so that the suite is
//! reproducible; `PROPTEST_RNG_SEED=<n>` explores others and `PROPTEST_CASES=<n>` changes
//! their number. Each property also asserts that enough of its cases produced a mesh, so that
//! it cannot pass by rejecting everything.
//!
//! [`Topology`]: liemesh::quality::Topology

// The fuzz targets' checks (see `tests/suite.rs`).
use crate::fuzz_checks::check_run;
use liemesh::model::{Invariant, LieField};
use liemesh::preset::{Preset, FIG46_INVARIANT};
use liemesh::sample::CurveEnd;
use liemesh::{Angle, MeshParams, MeshRun, Method, Mode};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};
use std::cell::Cell;
use std::f64::consts::PI;

const SEED: u64 = 0x11e_3e54;

/// Runs `cases` cases of `strategy` through the mesher; returns (meshes, errors, meshes for
/// which `mark` holds).
fn run_cases(
    cases: u32,
    strategy: impl Strategy<Value = (Vec<f64>, MeshParams)>,
    mark: impl Fn(&MeshRun<f64>) -> bool,
) -> (usize, usize, usize) {
    let mut config = Config {
        failure_persistence: None,
        max_shrink_iters: 256,
        ..Config::default()
    };
    if config.rng_seed == RngSeed::Random {
        config.rng_seed = RngSeed::Fixed(SEED);
    }
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = cases;
    }
    let (ok, err, marked) = (Cell::new(0), Cell::new(0), Cell::new(0));
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |(numbers, params)| {
        let invariant = Invariant::from_numbers(&numbers)
            .map_err(|e| TestCaseError::fail(format!("bad strategy: {e}")))?;
        let field = LieField::<f64>::new(&invariant);
        let result = liemesh::run(&field, &params);
        check_run(&field, &params, &result).map_err(|v| TestCaseError::fail(v.0))?;
        match result {
            Ok(run) => {
                ok.set(ok.get() + 1);
                marked.set(marked.get() + usize::from(mark(&run)));
            }
            Err(_) => err.set(err.get() + 1),
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    (ok.get(), err.get(), marked.get())
}

/// A property that passes by rejecting everything proves nothing: at least half of the cases
/// must give a mesh.
fn assert_most_cases_mesh(ok: usize, err: usize) {
    assert!(
        ok >= (ok + err) / 2,
        "only {ok} of {} cases meshed",
        ok + err
    );
}

/// Random invariants from `invariants` with parameters near either of two presets must give
/// valid meshes or typed errors, and mostly meshes.
fn invariants_give_valid_meshes_or_typed_errors(
    invariants: impl Strategy<Value = Vec<f64>>,
    presets: [Preset; 2],
) {
    let strategy = (
        invariants,
        prop_oneof![
            params_near(presets[0], 20_000),
            params_near(presets[1], 20_000)
        ],
    );
    let (ok, err, _) = run_cases(256, strategy, |_| true);
    assert_most_cases_mesh(ok, err);
}

/// A linear invariant: λ's of either sign around the paper's magnitudes, any angles.
fn linear_invariant() -> impl Strategy<Value = Vec<f64>> {
    (
        prop::array::uniform3(prop_oneof![0.2..2.0f64, -2.0..-0.2f64]),
        prop::array::uniform3(-PI..PI),
    )
        .prop_map(|(l, a)| vec![l[0], l[1], l[2], a[0], a[1], a[2]])
}

/// A Hamiltonian invariant: 12 numbers in the paper's text order or 18 numbers near Table 2.
fn hamiltonian_invariant() -> impl Strategy<Value = Vec<f64>> {
    prop_oneof![
        prop::collection::vec(-1.0..1.0f64, 12),
        prop::collection::vec(-0.3..0.3f64, 18).prop_map(|d| FIG46_INVARIANT
            .iter()
            .zip(d)
            .map(|(a, b)| a + b)
            .collect()),
    ]
}

/// Parameters near `preset`'s, with small budgets (at most `max_points` points).
fn params_near(preset: Preset, max_points: usize) -> impl Strategy<Value = MeshParams> {
    let base = preset.params();
    let shape = (
        prop_oneof![
            Just((Method::Proposed, base.curves)),
            (3usize..40).prop_map(|curves| (Method::Previous, curves))
        ],
        prop_oneof![Just(Mode::Default), Just(Mode::Paper)],
        prop::array::uniform3(-0.3..0.3f64),
        prop::array::uniform3(-1.0..1.0f64),
        any::<bool>(),
    );
    let steps = (
        0.02..0.3f64,
        2.0..6.0f64,
        2.0..6.0f64,
        1.1..2.0f64,
        0.3..0.9f64,
        1.5..3.0f64,
        0.0..0.7f64,
    );
    let terminal = (0.5..10.0f64, 1.5..10.0f64);
    let budget = (50..=max_points, 6usize..2000, 5usize..500, 1usize..=64);
    (shape, steps, terminal, budget).prop_map(
        move |(
            ((method, curves), mode, dp, w, close),
            (dt, bmin, bwidth, grow, shrink, gap, merge),
            (max_radius, bounding_box),
            (max_points, max_curves, max_steps, max_retries),
        )| {
            let mut p = base.clone();
            p.method = method;
            p.curves = curves;
            p.mode = mode;
            p.p0 = [base.p0[0] + dp[0], base.p0[1] + dp[1], base.p0[2] + dp[2]];
            p.w00 = Some([1.0 + 0.5 * w[0], w[1], w[2]]);
            p.dt = Some(dt);
            p.beta_min = Angle::from_degrees(bmin);
            p.beta_max = Angle::from_degrees(bmin + bwidth);
            p.grow = grow;
            p.shrink = shrink;
            p.gap = gap;
            p.merge = merge.min(0.45 * gap);
            p.max_radius = Some(max_radius);
            p.bounding_box = Some(bounding_box);
            p.close = close;
            p.max_points = max_points;
            p.max_curves = max_curves;
            p.max_steps = max_steps;
            p.max_retries = max_retries;
            p
        },
    )
}

#[test]
fn linear_invariants_give_valid_meshes_or_typed_errors() {
    invariants_give_valid_meshes_or_typed_errors(linear_invariant(), [Preset::Fig3, Preset::Fig1]);
}

#[test]
fn hamiltonian_invariants_give_valid_meshes_or_typed_errors() {
    invariants_give_valid_meshes_or_typed_errors(
        hamiltonian_invariant(),
        [Preset::Fig6, Preset::Fig4],
    );
}

#[test]
fn refinement_keeps_meshes_valid_and_reports_what_it_leaves() {
    // `check_run` also counts the refined vertices and the faces over the bound, and holds
    // them against the refinement's report.
    let refined = (params_near(Preset::Fig3, 5_000), 0.5..6.0f64).prop_map(|(mut p, deg)| {
        p.max_normal_error = Some(Angle::from_degrees(deg));
        p
    });
    let strategy = (
        prop_oneof![linear_invariant(), hamiltonian_invariant()],
        refined,
    );
    let (ok, err, split) = run_cases(96, strategy, |run| {
        run.refinement.is_some_and(|r| r.added > 0)
    });
    assert_most_cases_mesh(ok, err);
    assert!(split >= ok / 4, "only {split} of {ok} meshes were refined");
}

#[test]
fn tight_budgets_are_respected() {
    // Budgets small enough that most runs hit one of them.
    let strategy = (
        prop_oneof![linear_invariant(), hamiltonian_invariant()],
        (params_near(Preset::Fig3, 300), 1usize..20, 1usize..40).prop_map(
            |(mut p, curves, steps)| {
                p.max_curves = curves.max(match p.method {
                    Method::Previous => p.curves,
                    Method::Proposed => 6,
                });
                p.max_steps = steps;
                p
            },
        ),
    );
    let (ok, err, hit) = run_cases(256, strategy, |run| {
        run.samples.hit_point_budget || run.samples.curves.iter().any(|c| c.end == CurveEnd::Budget)
    });
    assert_most_cases_mesh(ok, err);
    assert!(hit >= ok / 2, "only {hit} of {ok} meshes ran into a budget");
}

#[test]
fn invalid_parameters_give_the_validation_error() {
    // One parameter pushed out of its allowed range: the run must return exactly the error
    // `MeshParams::resolve` names, for every invariant.
    let broken = (params_near(Preset::Fig3, 2_000), 0usize..13, -2.0..2.0f64).prop_map(
        |(mut p, which, x)| {
            match which {
                0 => p.dt = Some(-x.abs()),
                1 => p.dt_min = Some(0.0),
                2 => p.dt_max = p.dt_min.map(|d| d * 0.5),
                3 => p.beta_min = Angle::from_radians(p.beta_max.radians() + x.abs()),
                4 => p.beta_max = Angle::from_radians(PI / 2.0 + x.abs()),
                5 => p.grow = 1.0 - x.abs(),
                6 => p.shrink = 1.0 + x.abs(),
                7 => p.merge = p.gap,
                8 => p.p0[1] = f64::NAN,
                9 => p.max_radius = Some(-x.abs()),
                10 => p.max_points = 0,
                11 => p.max_normal_error = Some(Angle::from_radians(PI / 2.0 + x.abs())),
                _ => {
                    p.method = Method::Previous;
                    p.curves = 2;
                }
            }
            p
        },
    );
    let strategy = (
        prop_oneof![linear_invariant(), hamiltonian_invariant()],
        broken,
    );
    // `check_run` asserts that each error is exactly `params.resolve(&field)`'s.
    let (ok, err, _) = run_cases(128, strategy, |_| true);
    assert_eq!(ok, 0, "invalid parameters produced a mesh");
    assert!(err > 0);
}

#[test]
fn the_presets_themselves_pass_the_checks() {
    for preset in [Preset::Fig1, Preset::Fig3, Preset::Fig4, Preset::Fig6] {
        let mut params = preset.params();
        params.max_points = 20_000;
        let field = LieField::<f64>::new(&preset.invariant());
        let result = liemesh::run(&field, &params);
        check_run(&field, &params, &result).unwrap_or_else(|v| panic!("{preset}: {v}"));
        assert!(result.is_ok(), "{preset}: {result:?}");
    }
}

/// A field that hides its `f64` copy, so every Newton iteration of a chord runs in MPFR.
#[cfg(feature = "mpfr")]
struct FullPrecisionOnly<F>(F);

#[cfg(feature = "mpfr")]
impl<T: liemesh::scalar::Scalar, F: liemesh::NormalField<T>> liemesh::NormalField<T>
    for FullPrecisionOnly<F>
{
    fn normal(&self, p: &liemesh::scalar::Vec3<T>) -> liemesh::scalar::Vec3<T> {
        self.0.normal(p)
    }
    fn normal_and_jvp(
        &self,
        p: &liemesh::scalar::Vec3<T>,
        w: &liemesh::scalar::Vec3<T>,
    ) -> (liemesh::scalar::Vec3<T>, liemesh::scalar::Vec3<T>) {
        self.0.normal_and_jvp(p, w)
    }
    fn size_through(&self, p0: [f64; 3]) -> Option<f64> {
        self.0.size_through(p0)
    }
}

/// The `Mpfr<256>` chord solved in `f64` first and refined (with its predicted stops and its
/// last value-only step) lands where the solve that runs every iteration at 256 bits lands,
/// for random invariants, points, directions and step lengths.
#[cfg(feature = "mpfr")]
#[test]
fn mpfr_chords_seeded_in_f64_agree_with_the_full_precision_solve() {
    use liemesh::scalar::{Mpfr, Scalar, Vec3};
    use liemesh::trace::{step, StepConfig, StepLimit};
    type M = Mpfr<256>;
    let strategy = (
        prop_oneof![linear_invariant(), hamiltonian_invariant()],
        prop::array::uniform3(-1.0..1.0f64),
        prop::array::uniform3(-1.0..1.0f64),
        // Up to long chords, where Newton in f64 can wander to another root of G first.
        prop_oneof![0.01..0.3f64, 0.3..3.0f64],
    );
    let config = Config {
        cases: 96,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(SEED),
        ..Config::default()
    };
    // Every length of the preset is given: resolving on its own field only checks them.
    let fig6 = Preset::Fig6
        .params()
        .resolve::<f64, _>(&LieField::<f64>::new(&Preset::Fig6.invariant()))
        .unwrap();
    let compared = Cell::new(0);
    TestRunner::new(config)
        .run(&strategy, |(numbers, p, w, dt)| {
            let invariant = Invariant::from_numbers(&numbers)
                .map_err(|e| TestCaseError::fail(format!("bad strategy: {e}")))?;
            let seeded = LieField::<M>::new(&invariant);
            let full = FullPrecisionOnly(seeded.clone());
            let cfg = StepConfig::<M>::new(&fig6);
            let (p, w, dt) = (Vec3::<M>::from_f64(p), Vec3::from_f64(w), M::from_f64(dt));
            match (
                step(&seeded, &cfg, &p, &w, &dt),
                step(&full, &cfg, &p, &w, &dt),
            ) {
                (Ok(a), Ok(b)) if a.limit != StepLimit::Budget && b.limit != StepLimit::Budget => {
                    let gap = (&a.point - &b.point).norm().to_f64();
                    let scale = 1.0 + p.norm().to_f64() + a.dt.to_f64();
                    prop_assert!(gap <= 1e-70 * scale, "points differ by {gap:e}");
                    prop_assert!(a.iterations <= b.iterations);
                    compared.set(compared.get() + 1);
                }
                (Err(a), Err(b)) => prop_assert_eq!(a, b),
                _ => {}
            }
            Ok(())
        })
        .unwrap();
    assert!(
        compared.get() >= 48,
        "only {} chords compared",
        compared.get()
    );
}

/// In the default mode every step is a chord that balances Simpson's rule,
/// `(v(p) + 4 v(m) + v(q))·(q − p) = 0`, to rounding: on random fields far from integrable,
/// with β bands up to 30°–60°, where the chord at the band's Δt can have no root and the step
/// is halved instead (`StepLimit::Budget`) — never a point wherever Newton's method stopped.
#[test]
fn default_mode_steps_balance_simpsons_rule_even_where_the_chord_is_halved() {
    use liemesh::scalar::Vec3;
    use liemesh::trace::StepLimit;
    use liemesh::NormalField;
    let strategy = (
        prop::collection::vec(-1.0..1.0f64, 12),
        prop::array::uniform3(-1.0..1.0f64),
        4.0..30.0f64,
    );
    let config = Config {
        cases: 512,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(SEED),
        ..Config::default()
    };
    let (checked, halved) = (Cell::new(0), Cell::new(0));
    TestRunner::new(config)
        .run(&strategy, |(numbers, p0, beta_min)| {
            let invariant = Invariant::from_numbers(&numbers)
                .map_err(|e| TestCaseError::fail(format!("bad strategy: {e}")))?;
            let field = LieField::<f64>::new(&invariant);
            let mut params = Preset::Fig6.params();
            params.p0 = p0;
            params.beta_min = Angle::from_degrees(beta_min);
            params.beta_max = Angle::from_degrees(2.0 * beta_min);
            params.max_points = 3_000;
            let Ok(samples) = liemesh::sample::sample(&field, &params) else {
                return Ok(());
            };
            for curve in &samples.curves {
                for pair in curve.points.windows(2) {
                    let [p, q] = [pair[0], pair[1]].map(|i| &samples.points[i as usize]);
                    let m = p.add_scaled(&0.5, &(q - p));
                    let [a, b, c] = [p, &m, q].map(|x: &Vec3<f64>| field.normal(x));
                    let chord = (q - p).normalize().unwrap().0;
                    let g = (&(&a + &b.scale(&4.0)) + &c).dot(&chord);
                    let size = a.norm() + 4.0 * b.norm() + c.norm();
                    prop_assert!(
                        g.abs() <= 1e-10 * size,
                        "step to point {} leaves Simpson's rule unbalanced by {:e}",
                        pair[1],
                        g.abs() / size
                    );
                    checked.set(checked.get() + 1);
                }
            }
            let budget = samples
                .steps
                .iter()
                .filter(|s| s.limit == StepLimit::Budget);
            halved.set(halved.get() + budget.count());
            Ok(())
        })
        .unwrap();
    assert!(checked.get() >= 10_000, "only {} steps", checked.get());
    assert!(
        halved.get() > 0,
        "no step was halved: the property is not exercised"
    );
}
