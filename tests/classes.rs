//! One property per class of surface the model describes, meshed from default parameters
//! only (an invariant or a field, and a point `p0` on the surface), at random sizes, shapes,
//! orientations and starting points:
//!
//! | class | what every mesh must be |
//! |---|---|
//! | ellipsoids (any scale, any axis order, any pose) | valid, closed, χ = 2 |
//! | elliptic cylinders along any axis, in any pose | valid; a band (χ = 0, two boundary loops) in at least 95% of cases |
//! | hyperboloids of one sheet, in any pose | valid; a band (χ = 0, two boundary loops) in at least 95% of cases |
//! | flared hyperboloids of one sheet (flange 4:1 to 10:1 against the waist), in any pose, from the waist out onto the flange | valid, no face across the waist; a band, or the run says where it stopped short (a hole or a budget) |
//! | elliptic cylinders and hyperboloids of one sheet, in any pose, from 10 to 300 times their size out along the axis | valid; a band (χ = 0, two boundary loops) in at least 95% of cases |
//! | hyperboloids of two sheets, in any pose | valid, one sheet: a disc |
//! | cones, in any pose | valid; one nappe (χ = 1 with one loop, or χ = 0 with two: meeting at or stopping short of the apex) in at least 95% of cases |
//! | linear invariants with non-zero angles (non-integrable) | valid, at least 200 triangles; at most a fifth `MeshError::Empty` |
//! | 18-number Hamiltonian invariants, entries in [−1, 1], p0 at 10⁻² to 10² from the origin | valid, at least 200 triangles |
//! | 12-number Hamiltonian invariants with diagonal `A` (cubics), p0 at 10⁻² to 10² from the origin | valid, vertices on the level set; at most a fifth `MeshError::Empty` |
//! | tori (a `FnField`; R/a from 1.1 to 16) | valid; closed with χ = 0 in at least 95% of cases |
//! | tori with an elliptic tube about a tilted axis (a `FnField`; R/a from 1.1 to 16) | valid; closed with χ = 0 in at least 95% of cases |
//!
//! "Valid" is [`liemesh::mesh::Validation::is_valid`]: manifold, consistently oriented, no
//! degenerate face and no self-intersection, decided exactly. The mesher itself refuses to
//! return an invalid mesh (`MeshError::Invalid`), so the tests also check that the report
//! agrees with a fresh validation and with [`Topology`].
//!
//! Cases come from a fixed seed per class so that the suite is reproducible;
//! `PROPTEST_CASES=<n>` runs `n` cases per class and `PROPTEST_RNG_SEED=<n>` explores others.

use crate::fuzz_checks::faces_across_axis;
use liemesh::mesh::Mesh;
use liemesh::model::{AngleReading, FnField, Invariant, LieField, NormalField};
use liemesh::quality::Topology;
use liemesh::scalar::{Dual, Scalar, Vec3};
use liemesh::{run, MeshError, MeshParams, MeshRun};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};

/// Cases per class unless `PROPTEST_CASES` says otherwise: enough to meet every class's
/// awkward members in CI time.
const CASES: u32 = 24;

/// The points budget of the 18-number Hamiltonian cases: their swept surfaces take from
/// milliseconds to minutes with the default budget (see docs/status.md).
const HAMILTONIAN_POINTS: usize = 40_000;

/// The share of cylinders, one-sheet hyperboloids and cones (in percent) allowed to come out
/// valid but with the wrong topology (an extra hole left where fronts met): measured at 0, 1
/// and 0 of 256 cases with these seeds, see docs/status.md. Every mesh must still be valid.
const BAND_MISSES: u32 = 5;

/// The share of round tori (in percent) allowed to come out valid but not closed (a few small
/// holes left where fronts met, or an open tube): measured at 0 of 256 cases (a quarter of
/// them fat), see docs/status.md.
const TORUS_MISSES: u32 = 5;

/// The same for tilted tori with an elliptic tube: measured at 1 of 256 cases.
const TILTED_TORUS_MISSES: u32 = 5;

/// The largest angle between a face and the field normal at its centroid allowed on
/// ellipsoids and tori, degrees (the default β band turns the normal 4°–8° a step). Measured
/// at 24.7° at most over 256 cases of each (`PROPTEST_CASES=256`, this file's seeds and
/// `PROPTEST_RNG_SEED=777001`); tori reached 86° before the stitching's front was held to
/// 30° of tilt on seams. Cubics are not held to a bound (their singular points are not
/// known to the test).
const MAX_FACE_NORMAL_ERROR_DEG: f64 = 45.0;

/// That bound on bands, discs and cones (cylinders, hyperboloids; on cones the faces
/// clear of the apex by [`APEX_CLEARANCE`]). Measured over the same cases at 47.6° at most on
/// cylinders (one cylinder at this file's seed: a well-shaped face of the last round's
/// ear clipping, across the sharp ends of a 15:5 ellipse where samples are sparse),
/// 31.1° on one-sheet and 23.0° on two-sheet hyperboloids, 46.1° on cones; a thin cylinder
/// reached 85.9° before the flips were held to 30° of tilt.
const MAX_FACE_NORMAL_ERROR_OPEN_DEG: f64 = 60.0;

/// How far a cone's face must keep from the apex to be held to a bound, in its own longest
/// edges: the faces at the apex span normals up to 163° apart (a sliver beside a curve that
/// stopped there; 57.8° at most one longest edge out).
const APEX_CLEARANCE: f64 = 2.0;

fn runner(seed: u64) -> TestRunner {
    let mut config = Config {
        failure_persistence: None,
        // A failing case is reported as drawn: shrinking reruns the mesher hundreds of times.
        max_shrink_iters: 0,
        ..Config::default()
    };
    if config.rng_seed == RngSeed::Random {
        config.rng_seed = RngSeed::Fixed(seed);
    }
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = CASES;
    }
    TestRunner::new(config)
}

/// What a class's meshes must look like beyond validity.
#[derive(Clone, Copy, Debug)]
enum Shape {
    /// Closed, of the given Euler characteristic.
    Closed(i64),
    /// A band: χ = 0 and two boundary loops.
    Band,
    /// A disc: χ = 1, one boundary loop.
    Disc,
    /// One nappe of a cone: χ = 1 with one boundary loop (meeting at the apex), or an annulus
    /// stopping short of the apex (χ = 0, two loops).
    Nappe,
    /// Whatever the swept surface is, as long as it has at least this many triangles.
    Swept(usize),
}

impl Shape {
    /// How many boundary loops the whole surface has (a band two, a disc one; else none).
    fn own_loops(self) -> usize {
        match self {
            Shape::Band => 2,
            Shape::Disc => 1,
            _ => 0,
        }
    }
}

/// Meshes `field` from `p0` with default parameters and checks validity and `shape`.
fn check<F: NormalField<f64>>(
    field: &F,
    p0: [f64; 3],
    shape: Shape,
    what: &str,
) -> Result<MeshRun<f64>, TestCaseError> {
    check_with(field, MeshParams::at(p0), shape, what)
}

/// [`check`] with parameters of one's own.
fn check_with<F: NormalField<f64>>(
    field: &F,
    params: MeshParams,
    shape: Shape,
    what: &str,
) -> Result<MeshRun<f64>, TestCaseError> {
    let p0 = params.p0;
    let run =
        run(field, &params).map_err(|e| TestCaseError::fail(format!("{what}, p0 {p0:?}: {e}")))?;
    let mesh: &Mesh = &run.mesh;
    let validation = mesh.validate();
    let topology = Topology::of(mesh);
    let context = format!(
        "{what}, p0 {p0:?}: {} triangles, χ {}, {} boundary loops, {} components",
        topology.faces,
        topology.euler_characteristic,
        topology.boundary_loops,
        validation.components
    );
    prop_assert!(validation.is_valid(), "{context}: invalid: {validation}");
    prop_assert!(run.validation.is_valid(), "{context}: report says invalid");
    prop_assert_eq!(validation.components, 1, "{}", context);
    prop_assert_eq!(
        validation.euler_characteristic,
        topology.euler_characteristic,
        "{}",
        context
    );
    // A swept (non-integrable) surface may have curves that wind on until a budget stops
    // them; the report says so. Every other class must come out whole: a cone's curves end
    // at its apex as at a singular point, on the step floor or where no chord balances the
    // field's turn beside it.
    // A torus whose stitching ran out of its budget is reported as cut short and counted as
    // a miss below when it did not close.
    let may_be_cut_short = matches!(shape, Shape::Swept(_))
        || (matches!(shape, Shape::Closed(0)) && run.stitched.budget_hit);
    if !may_be_cut_short {
        prop_assert!(
            run.cut_short().is_empty(),
            "{context}: cut short: {:?}",
            run.cut_short()
        );
    }
    // Surface fidelity (DESIGN §4): on the integrable classes every face lies within a bound
    // of the field normal at its centroid; on a cone, every face clear of the apex (the
    // origin: the class's cones are centred), about which faces span normals far apart.
    let fidelity = match shape {
        Shape::Closed(_) => Some((
            liemesh::quality::face_normal_error(field, mesh).0,
            MAX_FACE_NORMAL_ERROR_DEG,
        )),
        Shape::Band | Shape::Disc => Some((
            liemesh::quality::face_normal_error(field, mesh).0,
            MAX_FACE_NORMAL_ERROR_OPEN_DEG,
        )),
        Shape::Nappe => Some((
            face_normal_error_away_from(field, mesh, [0.0; 3], APEX_CLEARANCE),
            MAX_FACE_NORMAL_ERROR_OPEN_DEG,
        )),
        Shape::Swept(_) => None,
    };
    if let Some((worst, bound)) = fidelity {
        prop_assert!(
            worst <= bound,
            "{context}: a face {worst:.1}° off the surface"
        );
    }
    let (chi, loops) = (topology.euler_characteristic, topology.boundary_loops);
    let fits = match shape {
        Shape::Closed(expected) => topology.closed && chi == expected,
        Shape::Band => chi == 0 && loops == 2,
        Shape::Disc => chi == 1 && loops == 1,
        Shape::Nappe => (chi == 1 && loops == 1) || (chi == 0 && loops == 2),
        Shape::Swept(least) => topology.faces >= least,
    };
    // The run tells a hole (a boundary loop where the surface goes on) from its own rim: a
    // surface that came out whole has none (a disc with a hole has a band's χ and loops),
    // a closed one that did not close has one at least.
    let holes = run.stitched.holes;
    match shape {
        Shape::Closed(_) | Shape::Band | Shape::Disc if fits => {
            prop_assert_eq!(holes, 0, "{}: holes reported", context)
        }
        Shape::Closed(_)
            if !topology.closed
                && run.cut_short().is_empty()
                && run.samples.ends().singular == 0 =>
        {
            prop_assert!(holes > 0, "{context}: open, yet no hole reported")
        }
        // More boundary loops than a whole band or disc has: the extra ones are holes, and
        // the run must say so.
        Shape::Band | Shape::Disc if loops > shape.own_loops() && run.cut_short().is_empty() => {
            prop_assert!(
                holes > 0,
                "{context}: an extra boundary loop, yet no hole reported"
            )
        }
        _ => {}
    }
    if !fits {
        if let Some(misses) = MISSES.with(|m| m.get()) {
            // A class whose topology is not yet always right (see the module table): the
            // miss is counted, the mesh is still valid.
            MISSES.with(|m| m.set(Some(misses + 1)));
            eprintln!("{context}: expected {shape:?}, {holes} holes (counted)");
            return Ok(run);
        }
    }
    prop_assert!(fits, "{context}: expected {shape:?}");
    Ok(run)
}

thread_local! {
    /// Topology misses counted instead of failing, when `Some` (see [`tolerating`]).
    static MISSES: std::cell::Cell<Option<u32>> = const { std::cell::Cell::new(None) };
}

/// Runs `body` counting topology misses instead of failing on them, and fails when more
/// than `percent` of `cases` missed. Validity is never tolerated.
fn tolerating(percent: u32, body: impl FnOnce() -> u32) {
    MISSES.with(|m| m.set(Some(0)));
    let cases = body();
    let misses = MISSES.with(|m| m.take()).unwrap_or(0);
    assert!(
        misses * 100 <= percent * cases,
        "{misses} of {cases} meshes had the wrong topology (at most {percent}% allowed)"
    );
}

/// The largest `|F(v) − level|` over the vertices for the quadric `F = Σ λₖ (R v)ₖ²`.
fn quadric_drift(mesh: &Mesh, lambda: [f64; 3], r: &[[f64; 3]; 3], level: f64) -> f64 {
    mesh.vertices
        .iter()
        .map(|&v| {
            let q = apply(r, v);
            ((0..3).map(|k| lambda[k] * q[k] * q[k]).sum::<f64>() - level).abs()
        })
        .fold(0.0, f64::max)
}

/// The quadric `Σ λₖ (R p)ₖ² = level` turned by `R = Rx Ry Rz(angles)`: a linear invariant
/// in the posed-quadric reading (`A = Rᵀ diag(λ) R`), axis-aligned when the angles are zero.
fn posed(lambda: [f64; 3], angles: [f64; 3]) -> LieField<f64> {
    let numbers = [
        lambda[0], lambda[1], lambda[2], angles[0], angles[1], angles[2],
    ];
    let invariant = Invariant::from_numbers(&numbers).expect("six numbers");
    LieField::new(&invariant.with_reading(AngleReading::Quadric))
}

/// `R = Rx(θ) Ry(φ) Rz(ψ)` as rows.
fn rotation(angles: [f64; 3]) -> [[f64; 3]; 3] {
    Invariant::row_matrix(&[1.0, 1.0, 1.0, angles[0], angles[1], angles[2]]).map(|r| r.to_f64())
}

fn apply(r: &[[f64; 3]; 3], p: [f64; 3]) -> [f64; 3] {
    r.map(|row| row[0] * p[0] + row[1] * p[1] + row[2] * p[2])
}

fn apply_transposed(r: &[[f64; 3]; 3], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|j| r[0][j] * p[0] + r[1][j] * p[1] + r[2][j] * p[2])
}

/// Axis-aligned in a quarter of the cases, else turned by random angles (radians).
fn pose() -> impl Strategy<Value = [f64; 3]> {
    use std::f64::consts::PI;
    prop_oneof![
        1 => Just([0.0; 3]),
        3 => prop::array::uniform3(-PI..PI),
    ]
}

/// `signs` placed on random semi-axes in [0.5, 2] times `10^scale`, in a random axis order:
/// the quadric's λ.
fn quadric_lambda() -> impl Strategy<Value = ([f64; 3], usize, f64)> {
    (prop::array::uniform3(0.5f64..2.0), 0usize..3, -2.0f64..2.0)
        .prop_map(|(axes, perm, scale)| (axes, perm, 10f64.powf(scale)))
        .prop_map(|(axes, perm, s)| {
            let mut l = [0.0; 3];
            for k in 0..3 {
                l[(k + perm) % 3] = 1.0 / (axes[k] * s).powi(2);
            }
            (l, perm, s)
        })
}

/// A direction with every component in [−1, 1] and length at least 0.2.
fn direction() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-1.0f64..1.0).prop_filter("not too short", |d| {
        d.iter().map(|x| x * x).sum::<f64>() > 0.04
    })
}

/// A [`direction`] scaled to 10⁻² to 10² times its length: a starting point for the
/// Hamiltonian classes, whose fields are not the same shape at every scale (their terms
/// differ in degree), so each distance from the origin is another surface.
fn at_any_distance() -> impl Strategy<Value = [f64; 3]> {
    (direction(), -2.0f64..2.0).prop_map(|(d, scale)| d.map(|x| x * 10f64.powf(scale)))
}

/// Runs a quadric class: `signs[k]` multiplies the k-th (permuted) λ; `level` is F at p0; the
/// quadric is turned by a random [`pose`].
fn quadric_class(seed: u64, signs: [f64; 3], level: f64, shape: Shape, name: &str) -> u32 {
    let strategy = (quadric_lambda(), direction(), pose()).prop_filter_map(
        "p0 on the surface",
        move |((l, perm, s), d, angles)| {
            let mut lambda = [0.0; 3];
            for k in 0..3 {
                lambda[(k + perm) % 3] = l[(k + perm) % 3] * signs[k];
            }
            let p0 = on_quadric(lambda, level, d, s)?;
            Some((lambda, angles, p0))
        },
    );
    let mut runner = runner(seed);
    let cases = runner.config().cases;
    runner
        .run(&strategy, |(lambda, angles, p0)| {
            let r = rotation(angles);
            let field = posed(lambda, angles);
            let run = check(
                &field,
                apply_transposed(&r, p0),
                shape,
                &format!("{name} λ {lambda:?} angles {angles:?}"),
            )?;
            // A band goes round its axis (the λ that is not of the level's sign): the field
            // knows it, and no face spans the waist across it.
            if let Some(k) = (0..3)
                .find(|&k| lambda[k] * level <= 0.0)
                .filter(|_| matches!(shape, Shape::Band))
            {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                let axis = apply_transposed(&r, e);
                let hole = field.hole_through(apply_transposed(&r, p0));
                let [a, b] = hole.map(|h| h.axis()).unwrap_or_default();
                let along = &Vec3::from_f64(b) - &Vec3::from_f64(a);
                let parallel =
                    norm(along.cross(&Vec3::from_f64(axis))) <= 1e-9 * norm(along.clone());
                prop_assert!(
                    hole.is_some() && parallel,
                    "{name}: hole {hole:?}, axis {axis:?}"
                );
                let across = faces_across_axis(&run.mesh, [[0.0; 3], axis]);
                prop_assert_eq!(across, 0, "{}: faces across the waist", name);
            }
            // Integrable: the vertices stay on the quadric to rounding (relative to F's size).
            let drift = quadric_drift(&run.mesh, lambda, &r, level);
            let size = (0..3).map(|k| lambda[k].abs() * p0[k] * p0[k]).sum::<f64>();
            prop_assert!(drift <= 1e-9 * size.max(1e-300), "{name}: drift {drift:e}");
            Ok(())
        })
        .unwrap();
    cases
}

/// The point on `Σ λₖ xₖ² = level` along direction `d` from the origin (for a cone,
/// `level = 0`, solved for the coordinate with negative λ), at most `3 s` from the origin.
fn on_quadric(lambda: [f64; 3], level: f64, d: [f64; 3], s: f64) -> Option<[f64; 3]> {
    let q: f64 = (0..3).map(|k| lambda[k] * d[k] * d[k]).sum();
    let p = if level == 0.0 {
        let neg = (0..3).find(|&k| lambda[k] < 0.0)?;
        let rest: f64 = (0..3)
            .filter(|&k| k != neg)
            .map(|k| lambda[k] * d[k] * d[k])
            .sum();
        let mut p = d.map(|x| x * s);
        p[neg] = s * (rest / -lambda[neg]).sqrt().copysign(d[neg]);
        p
    } else {
        // Away from the asymptotic directions, where p0 would be far out.
        if q * level < 0.05 * (0..3).map(|k| lambda[k].abs() * d[k] * d[k]).sum::<f64>() {
            return None;
        }
        let t = (level / q).sqrt();
        d.map(|x| x * t)
    };
    let r = p.iter().map(|x| x * x).sum::<f64>().sqrt();
    (r <= 3.0 * s && r >= 0.2 * s && p.iter().all(|x| x.is_finite())).then_some(p)
}

#[test]
fn ellipsoids_close_with_euler_characteristic_two() {
    quadric_class(0xe11, [1.0, 1.0, 1.0], 1.0, Shape::Closed(2), "ellipsoid");
}

#[test]
fn cylinders_along_any_axis_are_bands() {
    tolerating(BAND_MISSES, || {
        quadric_class(0xc71, [1.0, 1.0, 0.0], 1.0, Shape::Band, "cylinder")
    });
}

#[test]
fn one_sheet_hyperboloids_are_bands() {
    tolerating(BAND_MISSES, || {
        quadric_class(
            0x4791,
            [1.0, 1.0, -1.0],
            1.0,
            Shape::Band,
            "one-sheet hyperboloid",
        )
    });
}

/// Cases of the flared class unless `PROPTEST_CASES` says otherwise: its runs take seconds.
const FLARED_CASES: u32 = 6;

/// `x² + y² − c z² = 1` with `c` from 16 to 100, turned by a random pose, from `p0` at height
/// `f / √c` (f from 0.2 to 5: from beside the waist far out onto the flange) at a random
/// angle round the axis. Not yet always a band (docs/status.md, "Flared one-sheet
/// hyperboloids"), but never closed off across the waist, and never short of a band without
/// saying so.
#[test]
fn flared_one_sheet_hyperboloids_never_span_their_waist() {
    let strategy = (
        16.0f64..100.0,
        0.2f64..5.0,
        0.0f64..std::f64::consts::TAU,
        pose(),
    );
    let mut runner = runner(0xf1a);
    if std::env::var_os("PROPTEST_CASES").is_none() {
        runner = TestRunner::new(Config {
            cases: FLARED_CASES,
            ..runner.config().clone()
        });
    }
    runner
        .run(&strategy, |(c, f, turn, angles)| {
            let lambda = [1.0, 1.0, -c];
            let r = rotation(angles);
            let field = posed(lambda, angles);
            let z = f / c.sqrt();
            let rho = (1.0 + c * z * z).sqrt();
            let p0 = [rho * turn.cos(), rho * turn.sin(), z];
            let what = format!("c {c}, f {f}, turn {turn}, angles {angles:?}");
            let run = run(&field, &MeshParams::at(apply_transposed(&r, p0)))
                .map_err(|e| TestCaseError::fail(format!("{what}: {e}")))?;
            let validation = run.mesh.validate();
            prop_assert!(validation.is_valid(), "{what}: {validation}");
            let axis = apply_transposed(&r, [0.0, 0.0, 1.0]);
            let across = faces_across_axis(&run.mesh, [[0.0; 3], axis]);
            prop_assert_eq!(across, 0, "{}: faces across the waist", what);
            let band = validation.euler_characteristic == 0 && validation.boundary_loops == 2;
            prop_assert!(
                band || run.stitched.holes > 0 || !run.cut_short().is_empty(),
                "{what}: {validation}, no hole reported and not cut short"
            );
            Ok(())
        })
        .unwrap();
}

#[test]
fn two_sheet_hyperboloids_are_one_disc() {
    quadric_class(
        0x4792,
        [-1.0, -1.0, 1.0],
        1.0,
        Shape::Disc,
        "two-sheet hyperboloid",
    );
}

#[test]
fn cones_are_one_nappe() {
    tolerating(BAND_MISSES, || {
        quadric_class(0xc0e, [1.0, 1.0, -1.0], 0.0, Shape::Nappe, "cone")
    });
}

/// Bands started far out along their axis, 10 to 300 times their size from the waist: the
/// automatic extent and steps follow the band's width there, not `|p0|` (a unit cylinder
/// from 100 up its axis was a million triangles, a hyperboloid from as far out ran into the
/// point budget with holes).
#[test]
fn bands_from_far_along_their_axis_are_bands() {
    tolerating(BAND_MISSES, far_bands);
}

fn far_bands() -> u32 {
    let strategy = (
        quadric_lambda(),
        pose(),
        0.0f64..std::f64::consts::TAU,
        1.0f64..2.5,
        prop::bool::ANY,
    );
    let mut runner = runner(0xfa5);
    let cases = runner.config().cases;
    runner
        .run(&strategy, |((l, _, s), angles, phi, decades, cylinder)| {
            let lambda = [l[0], l[1], if cylinder { 0.0 } else { -l[2] }];
            // At height h up the axis, the point of the cross-section at angle phi.
            let h = s * 10f64.powf(decades);
            let across = lambda[0] * phi.cos().powi(2) + lambda[1] * phi.sin().powi(2);
            let r = ((1.0 - lambda[2] * h * h) / across).sqrt();
            let p0 = [r * phi.cos(), r * phi.sin(), h];
            let rotation = rotation(angles);
            let what = format!("far band λ {lambda:?} angles {angles:?}");
            check(
                &posed(lambda, angles),
                apply_transposed(&rotation, p0),
                Shape::Band,
                &what,
            )?;
            Ok(())
        })
        .unwrap();
    cases
}

/// Stitching a swept (non-integrable) surface joins what the curves swept; it never takes
/// away more triangles than it adds (it cannot place new points to replace them).
fn stitching_kept_the_sweep(run: &MeshRun<f64>, what: &str) -> Result<(), TestCaseError> {
    let s = run.stitched;
    prop_assert!(
        s.added >= s.removed,
        "{what}, p0 {:?}: stitching added {} triangles and removed {}",
        run.params.given.p0,
        s.added,
        s.removed
    );
    Ok(())
}

#[test]
fn non_integrable_linear_invariants_sweep_an_embedded_surface() {
    let angle = (-1.0f64..1.0).prop_filter("non-zero", |a: &f64| a.abs() > 0.05);
    let strategy = (
        prop::array::uniform3(0.3f64..3.0),
        (angle.clone(), angle.clone(), angle),
        direction(),
    );
    let empty = std::cell::Cell::new(0u32);
    let mut runner = runner(0x11e);
    let cases = runner.config().cases;
    runner
        .run(&strategy, |(lambda, (theta, phi, psi), p0)| {
            let numbers = [lambda[0], lambda[1], lambda[2], theta, phi, psi];
            let field = LieField::new(&Invariant::from_numbers(&numbers).expect("six numbers"));
            // Where the swept surface folds right at p0, no triangle survives: a typed
            // error, counted below.
            if let Err(MeshError::Empty { .. }) = run(&field, &MeshParams::at(p0)) {
                empty.set(empty.get() + 1);
                return Ok(());
            }
            let what = format!("linear {numbers:?}");
            let run = check(&field, p0, Shape::Swept(200), &what)?;
            stitching_kept_the_sweep(&run, &what)
        })
        .unwrap();
    at_most_a_fifth_empty(empty.get(), cases, "fields");
}

#[test]
fn hamiltonian_invariants_sweep_an_embedded_surface() {
    let strategy = (prop::collection::vec(-1.0f64..1.0, 18), at_any_distance());
    runner(0x4a1)
        .run(&strategy, |(numbers, p0)| {
            let field = LieField::new(&Invariant::from_numbers(&numbers).expect("18 numbers"));
            // A points budget bounds the time of the slow ones (a run cut short says so,
            // and must still be valid and large enough).
            let mut params = MeshParams::at(p0);
            params.max_points = HAMILTONIAN_POINTS;
            let what = format!("Hamiltonian {numbers:?}");
            let run = check_with(&field, params, Shape::Swept(200), &what)?;
            stitching_kept_the_sweep(&run, &what)
        })
        .unwrap();
}

/// Far from the origin a Hamiltonian field's normal can turn by 90° within one step of the
/// length its first-order prediction chose (found by a random run from the command line):
/// the steps are cut where the turn they made overshoots the band, so the chart's triangles
/// between the curves follow the sheet instead of folding (94 triangles before, of 2,162
/// samples; about 6,000 now).
#[test]
fn a_hamiltonian_sweep_far_from_the_origin_keeps_its_samples() {
    let numbers = [
        2.296011632360676,
        0.4833191825604534,
        0.6994745725365695,
        0.0,
        0.0,
        0.0,
        0.8720751868395571,
        -0.09229501528020623,
        0.1382164160502941,
        -0.1615754613560152,
        -0.989055351346602,
        -0.8494352084297687,
    ];
    let field = LieField::new(&Invariant::from_numbers(&numbers).expect("12 numbers"));
    let p0 = [2.4813957873005688, -56.13008784042256, 52.44911828685591];
    let what = "Hamiltonian far from the origin";
    let run = check(&field, p0, Shape::Swept(2000), what).unwrap();
    stitching_kept_the_sweep(&run, what).unwrap();
}

#[test]
fn hamiltonian_cubics_stay_on_their_level_set() {
    // λ11 λ12 λ13 λ21 λ22 λ23 λ31 λ32 λ33 θ1 φ1 ψ1 with θ1 = φ1 = ψ1 = 0: A, B, C diagonal.
    let strategy = (prop::collection::vec(-1.0f64..1.0, 9), at_any_distance());
    let empty = std::cell::Cell::new(0u32);
    let mut runner = runner(0xc0b);
    let cases = runner.config().cases;
    runner
        .run(&strategy, |(lambdas, p0)| {
            let mut numbers = lambdas.clone();
            numbers.extend([0.0; 3]);
            let invariant = Invariant::from_numbers(&numbers).expect("12 numbers");
            let field = LieField::<f64>::new(&invariant);
            // Where the chart of the samples folds right at p0, no triangle survives: a typed
            // error, counted below.
            if let Err(MeshError::Empty { .. }) = run(&field, &MeshParams::at(p0)) {
                empty.set(empty.get() + 1);
                return Ok(());
            }
            let run = check(&field, p0, Shape::Swept(1), &format!("cubic {numbers:?}"))?;
            // The field is the gradient of a cubic; the mesh must stay on p0's level set,
            // which we read from the normal field's potential along straight paths: compare
            // the line integral of the normal from p0 to each vertex with zero.
            let worst = run
                .mesh
                .vertices
                .iter()
                .map(|v| line_integral(&field, p0, *v).abs())
                .fold(0.0, f64::max);
            let scale = norm(field.normal(&Vec3::new(p0[0], p0[1], p0[2])));
            prop_assert!(
                worst <= 1e-7 * scale.max(1.0),
                "cubic: level drift {worst:e}"
            );
            Ok(())
        })
        .unwrap();
    at_most_a_fifth_empty(empty.get(), cases, "cubics");
}

/// The largest angle between a face and the field normal at its centroid, degrees, over the
/// faces whose corners all lie farther than `clearance` times the face's longest edge from
/// `point` (a singular point, about which the faces must span normals far apart).
fn face_normal_error_away_from<F: NormalField<f64>>(
    field: &F,
    mesh: &Mesh,
    point: [f64; 3],
    clearance: f64,
) -> f64 {
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let mut worst = 0.0_f64;
    for t in &mesh.triangles {
        let c = t.map(|i| mesh.vertices[i as usize]);
        let longest = (0..3)
            .map(|k| dist(c[k], c[(k + 1) % 3]))
            .fold(0.0, f64::max);
        if c.iter().all(|&v| dist(v, point) > clearance * longest) {
            worst = worst.max(liemesh::quality::face_error_deg(c, |x| field.normal(x)));
        }
    }
    worst
}

fn norm(v: Vec3<f64>) -> f64 {
    (v.x * v.x + v.y * v.y + v.z * v.z).sqrt()
}

/// `∫ n · dx` along the straight segment from `a` to `b` (Gauss–Legendre, 8 points per
/// piece, 16 pieces): the potential difference for a gradient field of a cubic, exact up to
/// rounding since the integrand is a polynomial of degree 2 in the parameter.
fn line_integral<F: NormalField<f64>>(field: &F, a: [f64; 3], b: [f64; 3]) -> f64 {
    // Two-point Gauss–Legendre is exact for degree ≤ 3.
    let nodes = [0.5 - 0.5 / 3f64.sqrt(), 0.5 + 0.5 / 3f64.sqrt()];
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    nodes
        .iter()
        .map(|&t| {
            let p = Vec3::new(a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]);
            let n = field.normal(&p);
            0.5 * (n.x * d[0] + n.y * d[1] + n.z * d[2])
        })
        .sum()
}

/// The gradient (halved) of `((ρ − R)/a)² + (z/b)²` with `ρ = √(x² + y²)`, in coordinates
/// turned by `tilt` about the x axis: a torus with an elliptic tube (`a = b`: a round one).
fn torus_field<T: Scalar>(
    big: f64,
    a: f64,
    b: f64,
    tilt: f64,
) -> impl Fn(&Vec3<Dual<T>>) -> Vec3<Dual<T>> + Sync {
    let (c, s) = (tilt.cos(), tilt.sin());
    move |p: &Vec3<Dual<T>>| {
        let k = |x: f64| Dual::constant(T::from_f64(x));
        // Body coordinates: (x, y', z') = (x, c y + s z, −s y + c z).
        let x = p.x.clone();
        let y = k(c) * p.y.clone() + k(s) * p.z.clone();
        let z = k(-s) * p.y.clone() + k(c) * p.z.clone();
        let rho = (x.clone() * x.clone() + y.clone() * y.clone()).sqrt();
        let radial = (rho.clone() - k(big)) / (k(a * a) * rho);
        let (gx, gy, gz) = (radial.clone() * x, radial * y, z / k(b * b));
        // Back to world coordinates (the transpose of the turn).
        Vec3::new(
            gx,
            k(c) * gy.clone() - k(s) * gz.clone(),
            k(s) * gy + k(c) * gz,
        )
    }
}

/// The point at tube angle `v` and around-angle `u` on the torus of [`torus_field`].
fn on_torus(big: f64, a: f64, b: f64, tilt: f64, u: f64, v: f64) -> [f64; 3] {
    let rho = big + a * v.cos();
    let (x, y, z) = (rho * u.cos(), rho * u.sin(), b * v.sin());
    let (c, s) = (tilt.cos(), tilt.sin());
    [x, c * y - s * z, s * y + c * z]
}

/// The largest relative drift `|F − 1|` off a torus: each chord is corrected onto its level
/// set by Gauss–Legendre's five-point rule, exact for potentials of degree ten, and the
/// torus's is not a polynomial (measured over 256 round and 256 tilted elliptic tori: median
/// 6.8e-14, worst 1.0e-9 on a fat flattened tube; with Boole's rule, at 64 cases each, median
/// 1.3e-10, worst 3.3e-8).
const TORUS_DRIFT: f64 = 1e-8;

fn torus_class(seed: u64, elliptic: bool) -> u32 {
    let tau = std::f64::consts::TAU;
    // A quarter of the tori are fat: the ring barely wider than the tube (R/a 1.1 to 2.5),
    // where `p0` on the inner equator lies near the origin, far inside the surface's reach.
    let strategy = (
        (1.5f64..4.0, 0.25f64..0.6, 1.1f64..2.5, 0..4u8),
        0.5f64..1.5,
        -2.0f64..2.0,
        0.0f64..tau,
        0.0f64..tau,
        -1.0f64..1.0,
    );
    runner(seed)
        .run(
            &strategy,
            |((big, tube, fat, pick), aspect, scale, u, v, tilt)| {
                let tube = if pick == 0 { big / fat } else { tube };
                let s = 10f64.powf(scale);
                let (a, b) = if elliptic {
                    (tube * s, tube * aspect * s)
                } else {
                    (tube * s, tube * s)
                };
                let tilt = if elliptic { tilt } else { 0.0 };
                let big = big * s;
                let field = FnField::new(torus_field::<f64>(big, a, b, tilt));
                let p0 = on_torus(big, a, b, tilt, u, v);
                let what = format!("torus R {big} a {a} b {b} tilt {tilt}");
                let run = check(&field, p0, Shape::Closed(0), &what)?;
                // On the torus to rounding: ((ρ − R)/a)² + (z/b)² = 1 in body coordinates.
                let (c, sn) = (tilt.cos(), tilt.sin());
                let worst = run
                    .mesh
                    .vertices
                    .iter()
                    .map(|w| {
                        let (x, y, z) = (w[0], c * w[1] + sn * w[2], -sn * w[1] + c * w[2]);
                        let rho = (x * x + y * y).sqrt();
                        (((rho - big) / a).powi(2) + (z / b).powi(2) - 1.0).abs()
                    })
                    .fold(0.0, f64::max);
                prop_assert!(worst <= TORUS_DRIFT, "{what}: drift {worst:e}");
                Ok(())
            },
        )
        .unwrap();
    runner(seed).config().cases
}

#[test]
fn tori_close_with_euler_characteristic_zero() {
    tolerating(TORUS_MISSES, || torus_class(0x7051, false));
}

#[test]
fn tilted_elliptic_tori_close_with_euler_characteristic_zero() {
    tolerating(TILTED_TORUS_MISSES, || torus_class(0x7052, true));
}

#[test]
fn the_unit_sphere_invariant_meshes_alike_at_any_radius_and_from_an_axis() {
    let field = posed([1.0, 1.0, 1.0], [0.0; 3]);
    let mut counts = Vec::new();
    for p0 in [
        [0.0, 0.0, 1e-3],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 1e3],
        [1.0, 0.0, 0.0],
    ] {
        let run = run(&field, &MeshParams::at(p0)).expect("a sphere meshes");
        assert!(
            run.validation.is_valid() && run.validation.is_closed(),
            "p0 {p0:?}"
        );
        assert_eq!(run.validation.euler_characteristic, 2, "p0 {p0:?}");
        assert!(
            run.cut_short().is_empty(),
            "p0 {p0:?}: {:?}",
            run.cut_short()
        );
        counts.push(run.mesh.triangles.len() as f64);
    }
    let (lo, hi) = counts
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), &c| (l.min(c), h.max(c)));
    assert!(
        hi <= 1.01 * lo,
        "triangle counts {counts:?} differ by more than 1%"
    );
}

/// Fails when more than a fifth of `cases` gave `MeshError::Empty`.
fn at_most_a_fifth_empty(empty: u32, cases: u32, what: &str) {
    assert!(
        empty * 5 <= cases,
        "{empty} of {cases} {what} gave no mesh (at most a fifth allowed)"
    );
}
