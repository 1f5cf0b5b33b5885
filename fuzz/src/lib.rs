//! Input decoders and output checks of the cargo-fuzz targets (`fuzz/fuzz_targets/*.rs`).
//!
//! This file is the `liemesh-fuzz` crate's library, and the very same file is compiled into
//! the main crate's tests with `#[path = ".../fuzz/src/lib.rs"] mod fuzz_checks;`: the corpus
//! replay in `tests/fuzz_corpus.rs` (on stable Rust), the output checks in
//! `tests/properties.rs`, `tests/snapshots.rs` and others, and the library's own unit tests.
//! So it uses liemesh only through its public API (as `liemesh::...`), and depends on nothing
//! but liemesh, `arbitrary`, `robust` and `spade`.
//!
//! Every fuzz target is one function `fn(&[u8]) -> Result<(), Violation>` of this file
//! ([`TARGETS`]): the fuzz binary calls it and panics on a [`Violation`], and the replay test
//! calls the very same function on every committed corpus file, so both read the bytes the
//! same way (through [`arbitrary::Unstructured`] and `arbitrary_take_rest`) and check the
//! same invariants. A `Violation` names the broken invariant; a panic inside the library is
//! a failure as well (the fuzzer reports it as a crash, the replay test catches it).
//!
//! | target | input | checked |
//! |---|---|---|
//! | [`mesher`] | a [`MesherInput`]: an invariant and parameters near a preset's, or raw | [`check_run`] |
//! | [`triangulate`] | a [`TriangulateInput`]: samples from a short run or synthetic, then edited (NaN, infinities, duplicates, collinear points, huge/tiny values, inconsistent curves) | [`check_triangulation`] |
//! | [`invariant_file`] | bytes as an invariant file, a PLY and an OBJ file | [`check_invariant_file`], [`check_read_mesh`] |

use arbitrary::{Arbitrary, Unstructured};
#[cfg(feature = "toml")]
use liemesh::io::invariant_file::{InvariantFile, InvariantFileError};
use liemesh::io::{read_obj, read_ply, write_obj, write_ply, PlyEncoding};
use liemesh::model::{Invariant, InvariantError, LieField};
use liemesh::preset::Preset;
use liemesh::quality::Topology;
use liemesh::sample::{Curve, CurveEnd, Samples, StepRecord};
use liemesh::scalar::Vec3;
use liemesh::trace::StepLimit;
use liemesh::triangulate::{ChartTriangulation, Mesh, Provenance};
use liemesh::{Angle, MeshError, MeshParams, MeshRun, Method, Mode, NormalField, Resolved};
use std::collections::{HashMap, HashSet};
use std::fmt;
#[cfg(feature = "toml")]
use std::path::Path;

/// `a − b`.
fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a × b`.
fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A broken output invariant: what was expected and what was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Violation(pub String);

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Violation {}

macro_rules! ensure {
    ($cond:expr, $($msg:tt)+) => {
        let holds: bool = $cond;
        if !holds {
            return Err(Violation(format!($($msg)+)));
        }
    };
}

/// A fuzz target: decodes the bytes, runs one stage, checks its output.
pub type Target = fn(&[u8]) -> Result<(), Violation>;

/// The fuzz targets by name (the names of `fuzz/fuzz_targets/*.rs` and `fuzz/corpus/*`).
pub const TARGETS: [(&str, Target); 3] = [
    ("mesher", mesher),
    ("triangulate", triangulate),
    ("invariant_file", invariant_file),
];

/// Point budget of the `Small` budget of the fuzz inputs.
pub const FUZZ_MAX_POINTS: usize = 800;

// ---------------------------------------------------------------------------------------------
// Numbers
// ---------------------------------------------------------------------------------------------

/// A number derived from a preset's value (`base`), so that most inputs stay near the paper's
/// figures while the fuzzer can still reach any `f64`.
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub enum Num {
    /// The base value itself (what an exhausted input decodes to).
    Keep,
    /// `base · 2^(k/32)`: a factor in [1/16, 16).
    Scale(i8),
    /// `base + k/64`: a shift in [−2, 2).
    Shift(i8),
    /// Any `f64`, including NaN and the infinities.
    Raw(f64),
}

impl Num {
    /// The number, given the preset's value.
    pub fn apply(self, base: f64) -> f64 {
        match self {
            Num::Keep => base,
            Num::Scale(k) => base * (f64::from(k) / 32.0).exp2(),
            Num::Shift(k) => base + f64::from(k) / 64.0,
            Num::Raw(x) => x,
        }
    }
}

/// A coordinate for the triangulation target: small, fine-grained, special or raw.
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub enum Coord {
    /// `k/16`.
    Small(i8),
    /// `k · 2^-20`.
    Fine(i32),
    /// One of [`SPECIAL_VALUES`].
    Special(u8),
    /// Any `f64`.
    Raw(f64),
}

/// NaN, infinities, signed zeros, extremes, subnormals and spade's coordinate limits.
pub const SPECIAL_VALUES: [f64; 18] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    1e300,
    -1e300,
    1e-300,
    -1e-300,
    f64::MIN_POSITIVE,
    5e-324,
    f64::MAX,
    f64::MIN,
    spade::MAX_ALLOWED_VALUE,
    spade::MIN_ALLOWED_VALUE,
    1e-40,
    1e30,
    1.0,
];

impl Coord {
    /// The value.
    pub fn value(self) -> f64 {
        match self {
            Coord::Small(k) => f64::from(k) / 16.0,
            Coord::Fine(k) => f64::from(k) * (-20f64).exp2(),
            Coord::Special(i) => SPECIAL_VALUES[i as usize % SPECIAL_VALUES.len()],
            Coord::Raw(x) => x,
        }
    }
}

fn coords3(c: [Coord; 3]) -> [f64; 3] {
    [c[0].value(), c[1].value(), c[2].value()]
}

// ---------------------------------------------------------------------------------------------
// Target (a): mesher
// ---------------------------------------------------------------------------------------------

/// The invariant of a [`MesherInput`].
#[derive(Arbitrary, Clone, Debug, PartialEq)]
pub enum InvariantInput {
    /// The preset's own invariant.
    Preset,
    /// 6 numbers (linear), derived from the first row of the preset's.
    Linear([Num; 6]),
    /// 12 numbers (the paper's text order), derived from the preset's.
    Text([Num; 12]),
    /// 18 numbers (Table 2's rows), derived from the preset's.
    Table([Num; 18]),
    /// Any count of any numbers (mostly rejected by [`Invariant::from_numbers`]).
    Numbers(Vec<f64>),
}

/// The curve layout of a [`MesherInput`].
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub enum MethodInput {
    /// The preset's.
    Preset,
    /// The proposed method.
    Proposed,
    /// The previous method with this many curves (0, 1, 2 are rejected).
    Previous(u8),
}

/// The budgets of a [`MesherInput`]: small, so that every run is quick.
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub enum BudgetInput {
    /// [`FUZZ_MAX_POINTS`] points, 120 curves, 200 steps per curve, 64 retries.
    Small,
    /// Each value modulo a small bound (0 is allowed and rejected by validation).
    Custom {
        /// Points, modulo [`FUZZ_MAX_POINTS`]` + 1`.
        points: u16,
        /// Curves, modulo 129.
        curves: u16,
        /// Steps per curve, modulo 401.
        steps: u16,
        /// Retries, modulo 65.
        retries: u8,
    },
}

impl BudgetInput {
    /// The budgets: `(max_points, max_curves, max_steps, max_retries)`.
    pub fn budgets(self) -> (usize, usize, usize, usize) {
        match self {
            BudgetInput::Small => (FUZZ_MAX_POINTS, 120, 200, 64),
            BudgetInput::Custom {
                points,
                curves,
                steps,
                retries,
            } => (
                points as usize % (FUZZ_MAX_POINTS + 1),
                curves as usize % 129,
                steps as usize % 401,
                retries as usize % 65,
            ),
        }
    }

    /// Sets the budgets of `params`.
    pub fn apply(self, params: &mut MeshParams) {
        let (points, curves, steps, retries) = self.budgets();
        params.max_points = points;
        params.max_curves = curves;
        params.max_steps = steps;
        params.max_retries = retries;
    }
}

/// Input of the `mesher` target. An empty input is fig1 with [`BudgetInput::Small`]; a single
/// byte `k` is preset `k mod 6`.
#[derive(Arbitrary, Clone, Debug, PartialEq)]
pub struct MesherInput {
    /// Preset the numbers are derived from (`preset mod 6`).
    pub preset: u8,
    /// The invariant.
    pub invariant: InvariantInput,
    /// The curve layout.
    pub method: MethodInput,
    /// Paper mode instead of default mode.
    pub paper: bool,
    /// Whether to close closed surfaces (`None`: the preset's).
    pub close: Option<bool>,
    /// Initial point.
    pub p0: [Num; 3],
    /// Initial direction.
    pub w00: [Num; 3],
    /// Δt, dt_min, dt_max.
    pub steps: [Num; 3],
    /// β_min, β_max (radians).
    pub band: [Num; 2],
    /// δ, δ'.
    pub factors: [Num; 2],
    /// gap, merge.
    pub thresholds: [Num; 2],
    /// max_radius, bounding_box.
    pub terminal: [Num; 2],
    /// Budgets.
    pub budget: BudgetInput,
    /// Refinement to a normal-error bound, derived from [`FUZZ_NORMAL_ERROR_DEG`] (`None`:
    /// none, what an exhausted input decodes to).
    pub refine: Option<Num>,
}

/// The normal-error bound, degrees, that [`MesherInput::refine`] derives its bound from.
pub const FUZZ_NORMAL_ERROR_DEG: f64 = 2.0;

impl MesherInput {
    /// The preset the numbers are derived from.
    pub fn base(&self) -> Preset {
        Preset::ALL[self.preset as usize % Preset::ALL.len()]
    }

    /// The invariant numbers.
    pub fn numbers(&self) -> Vec<f64> {
        let base = self.base().invariant();
        let rows = base.rows();
        let table: Vec<f64> = rows.iter().flatten().copied().collect();
        let text: Vec<f64> = (0..3)
            .map(|i| rows[i][0])
            .chain((0..3).map(|i| rows[i][1]))
            .chain((0..3).map(|i| rows[i][2]))
            .chain(rows[0][3..6].iter().copied())
            .collect();
        let derive = |nums: &[Num], base: &[f64]| -> Vec<f64> {
            nums.iter().zip(base).map(|(n, &b)| n.apply(b)).collect()
        };
        match &self.invariant {
            InvariantInput::Preset => table,
            InvariantInput::Linear(n) => derive(n, &table[0..6]),
            InvariantInput::Text(n) => derive(n, &text),
            InvariantInput::Table(n) => derive(n, &table),
            InvariantInput::Numbers(v) => v.clone(),
        }
    }

    /// The parameters. The presets give every length and `w00`, so each is derived from the
    /// preset's value; a length a preset left automatic would stay automatic.
    pub fn params(&self) -> MeshParams {
        let base = self.base().params();
        let n3 = |n: [Num; 3], b: [f64; 3]| [n[0].apply(b[0]), n[1].apply(b[1]), n[2].apply(b[2])];
        let opt = |n: Num, b: Option<f64>| b.map(|b| n.apply(b));
        let angle = |n: Num, b: Angle| Angle::from_radians(n.apply(b.radians()));
        let mut p = base.clone();
        match self.method {
            MethodInput::Preset => {}
            MethodInput::Proposed => p.method = Method::Proposed,
            MethodInput::Previous(c) => {
                p.method = Method::Previous;
                p.curves = c as usize;
            }
        }
        if self.paper {
            p.mode = Mode::Paper;
        }
        p.p0 = n3(self.p0, base.p0);
        p.w00 = base.w00.map(|w| n3(self.w00, w));
        p.dt = opt(self.steps[0], base.dt);
        p.dt_min = opt(self.steps[1], base.dt_min);
        p.dt_max = opt(self.steps[2], base.dt_max);
        p.beta_min = angle(self.band[0], base.beta_min);
        p.beta_max = angle(self.band[1], base.beta_max);
        p.grow = self.factors[0].apply(base.grow);
        p.shrink = self.factors[1].apply(base.shrink);
        p.gap = self.thresholds[0].apply(base.gap);
        p.merge = self.thresholds[1].apply(base.merge);
        p.max_radius = opt(self.terminal[0], base.max_radius);
        p.bounding_box = opt(self.terminal[1], base.bounding_box);
        p.close = self.close.unwrap_or(base.close);
        self.budget.apply(&mut p);
        p.max_normal_error = self
            .refine
            .map(|n| Angle::from_radians(n.apply(FUZZ_NORMAL_ERROR_DEG.to_radians())));
        p
    }
}

/// Target (a): decodes a [`MesherInput`], runs [`liemesh::run`] in `f64` and checks the result
/// with [`check_run`]. Invalid invariant numbers must be rejected by
/// [`Invariant::from_numbers`] exactly when they are not 6, 12 or 18 finite numbers with a
/// non-zero λ (the others are angles: the 4th to 6th of each six, the last three of twelve).
pub fn mesher(data: &[u8]) -> Result<(), Violation> {
    let Ok(input) = MesherInput::arbitrary_take_rest(Unstructured::new(data)) else {
        return Ok(());
    };
    let numbers = input.numbers();
    let is_lambda = |i: usize| {
        if numbers.len() == 12 {
            i < 9
        } else {
            i % 6 < 3
        }
    };
    let some_lambda = (0..numbers.len()).any(|i| is_lambda(i) && numbers[i] != 0.0);
    let expected_ok = matches!(numbers.len(), 6 | 12 | 18)
        && numbers.iter().all(|x| x.is_finite())
        && some_lambda;
    let invariant = match Invariant::from_numbers(&numbers) {
        Ok(inv) => inv,
        Err(e) => {
            ensure!(
                !expected_ok,
                "valid invariant numbers {numbers:?} were rejected: {e}"
            );
            ensure!(
                matches!(
                    e,
                    InvariantError::WrongCount(_)
                        | InvariantError::NonFinite { .. }
                        | InvariantError::ZeroField
                ),
                "unexpected error {e:?}"
            );
            return Ok(());
        }
    };
    ensure!(
        expected_ok,
        "invalid invariant numbers {numbers:?} were accepted"
    );
    let params = input.params();
    let field = LieField::<f64>::new(&invariant);
    let result = liemesh::run(&field, &params);
    check_run(&field, &params, &result).map_err(|v| Violation(format!("{v}\ninput: {input:?}")))
}

/// Checks everything a meshing run promises:
///
/// - parameters that do not resolve on `field` give exactly the error
///   [`MeshParams::resolve`] gives; ones that resolve give a mesh, with those resolved
///   parameters, or one of the errors that depend on the field's course
///   ([`MeshError::SingularInitialPoint`], [`MeshError::FieldMagnitude`],
///   [`MeshError::BendAtInitialPoint`], [`MeshError::DirectionParallelToNormal`],
///   [`MeshError::PointBudgetTooSmall`],
///   [`MeshError::Triangulation`], [`MeshError::Empty`]), never [`MeshError::Invalid`];
/// - the samples satisfy [`check_samples`] (budgets, step band, bookkeeping);
/// - the chart triangulation satisfies [`check_chart`];
/// - the run's validation passes, and so does a validation of the mesh it returned (an
///   embedded, consistently oriented 2-manifold, possibly with boundary, decided exactly);
/// - the mesh satisfies [`check_mesh`] (no NaN, no degenerate or duplicate triangles, manifold,
///   consistently oriented), has at most as many triangles as the chart and closing
///   triangulations and the stitching added (triangles of no area in space are left out), and
///   its vertices are the run's working-precision vertices rounded to `f64`;
/// - refinement ([`MeshParams::max_normal_error`]) counts the vertices it added and the faces
///   of `field` it left over the bound correctly, and adds at most two faces per vertex;
/// - no face has the axis of a hole the field knows ([`NormalField::hole_through`]) pass
///   through it.
pub fn check_run(
    field: &impl NormalField<f64>,
    params: &MeshParams,
    result: &Result<MeshRun<f64>, MeshError>,
) -> Result<(), Violation> {
    let resolved = params.resolve::<f64, _>(field);
    let run = match (resolved.as_ref(), result) {
        (Err(expected), Err(got)) => {
            // Compared as text: the errors carry the offending value, which may be NaN.
            ensure!(
                std::mem::discriminant(expected) == std::mem::discriminant(got)
                    && expected.to_string() == got.to_string(),
                "invalid parameters should give `{expected}`, got `{got}`"
            );
            return Ok(());
        }
        (Err(expected), Ok(_)) => {
            return Err(Violation(format!(
                "invalid parameters ({expected}) gave a mesh"
            )))
        }
        (Ok(_), Err(e)) => {
            ensure!(
                !matches!(e, MeshError::Invalid(_)),
                "the mesh failed validation: `{e}`"
            );
            ensure!(
                matches!(
                    e,
                    MeshError::SingularInitialPoint { .. }
                        | MeshError::FieldMagnitude { .. }
                        | MeshError::BendAtInitialPoint { .. }
                        | MeshError::PointBudgetTooSmall { .. }
                        | MeshError::DirectionParallelToNormal { .. }
                        | MeshError::Triangulation(_)
                        | MeshError::Empty { .. }
                ),
                "valid parameters gave the parameter error `{e}`"
            );
            ensure!(!e.to_string().is_empty(), "empty error message");
            return Ok(());
        }
        (Ok(resolved), Ok(run)) => {
            // Compared as text: NaN-safe. A run whose automatic steps were too long samples
            // again with Δt, dt_min and dt_max a sixteenth as long, twice at most (`run`), and
            // reports the lengths it used.
            let reported = format!("{:?}", run.params);
            let mut shorter = resolved.clone();
            let mut fits = reported == format!("{shorter:?}");
            for _ in 0..2 {
                shorter.dt /= 16.0;
                shorter.dt_min /= 16.0;
                shorter.dt_max /= 16.0;
                fits |= reported == format!("{shorter:?}");
            }
            ensure!(
                fits,
                "the run reports the parameters {reported}, resolving them gives {resolved:?}"
            );
            run
        }
    };
    let params = &run.params;
    check_samples(params, &run.samples)?;
    let n = run.samples.points.len();
    check_chart(&run.chart, n)?;
    ensure!(
        run.validation.is_valid(),
        "the run's validation fails: {}",
        run.validation
    );
    let validation = run.mesh.validate();
    ensure!(
        validation.is_valid(),
        "the mesh returned fails validation: {validation}"
    );
    ensure!(
        validation.faces == run.mesh.triangles.len()
            && validation.faces == run.validation.faces
            && validation.euler_characteristic == run.validation.euler_characteristic,
        "the run's validation ({} faces, χ = {}) does not describe the {} faces returned \
         (validated again: {validation})",
        run.validation.faces,
        run.validation.euler_characteristic,
        run.mesh.triangles.len()
    );
    check_mesh(&run.mesh)?;
    // Holes are boundary loops (loops touching at a vertex counted once): a closed mesh has
    // none, and an open one no more than it has loops.
    ensure!(
        run.stitched.holes <= run.validation.boundary_loops
            && (run.stitched.holes == 0 || !run.validation.is_closed()),
        "{} holes reported for a mesh with {} boundary loops ({})",
        run.stitched.holes,
        run.validation.boundary_loops,
        run.validation
    );
    // No face meets the axis of a hole the field knows (a band's waist): such a face spans
    // the hole.
    if let Some(hole) = field.hole_through(params.p0) {
        let across = faces_across_axis(&run.mesh, hole.axis());
        ensure!(
            across == 0,
            "{across} faces span the hole: its axis {:?} passes through them",
            hole.axis()
        );
    }
    ensure!(
        run.vertices.len() == run.mesh.vertices.len()
            && run
                .vertices
                .iter()
                .zip(&run.mesh.vertices)
                .all(|(v, m)| v.to_f64() == *m),
        "the working-precision vertices ({}) are not the mesh's ({}) rounded to f64",
        run.vertices.len(),
        run.mesh.vertices.len()
    );
    // Each vertex that refinement added split one or two faces in two; faces removed later
    // (crossings undone, pinches cut) may take some of them with them.
    let refined = (run.mesh.provenance.iter())
        .filter(|p| p.curve == Provenance::REFINED_CURVE)
        .count();
    ensure!(
        refined <= run.refinement.map_or(0, |r| r.added),
        "refinement says it added {:?} vertices, the mesh has {refined}",
        run.refinement
    );
    ensure!(
        run.mesh.triangles.len()
            <= run.chart.triangles.len()
                + run.chart.closing.len()
                + run.stitched.added
                + 2 * refined,
        "the mesh has {} triangles, more than the charts' {} + {}, the {} stitched and two per \
         refined vertex ({refined})",
        run.mesh.triangles.len(),
        run.chart.triangles.len(),
        run.chart.closing.len(),
        run.stitched.added
    );
    if let (Some(limit), Some(r)) = (params.max_normal_error, run.refinement) {
        let over = (run.mesh.triangles.iter())
            .filter(|t| {
                let corners = t.map(|i| run.mesh.vertices[i as usize]);
                liemesh::quality::face_error_deg(corners, |c| field.normal(c)) > limit.degrees()
            })
            .count();
        ensure!(
            over == r.over_limit,
            "refinement says {} faces are over {}°, the mesh has {over}",
            r.over_limit,
            limit.degrees()
        );
    }
    Ok(())
}

/// How many faces of `mesh` the line through the two points `axis` passes through, decided
/// in floating point, independently of the mesher's exact test: the line against each edge
/// (Plücker) with a margin of rounding's order, and only faces it passes clearly inside of.
pub fn faces_across_axis(mesh: &Mesh, [o, far]: [[f64; 3]; 2]) -> usize {
    let along = sub3(far, o);
    let norm = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    let inside = |t: &[u32; 3]| {
        let c = t.map(|i| sub3(mesh.vertices[i as usize], o));
        let side = |k: usize| {
            let (p, q) = (c[k], c[(k + 1) % 3]);
            let m = cross3(p, q);
            let s = along[0] * m[0] + along[1] * m[1] + along[2] * m[2];
            let margin = 1e-9 * norm(along) * norm(p) * norm(q);
            (s > margin) as i8 - (s < -margin) as i8
        };
        let s = [side(0), side(1), side(2)];
        s[0] != 0 && s[0] == s[1] && s[1] == s[2]
    };
    mesh.triangles.iter().filter(|t| inside(t)).count()
}

/// Checks the sampler's output against `params`:
///
/// - points, normals, provenance and step records have one entry per point, all finite;
/// - budgets: at most `max_points` points and `max_curves` curves, at most `max_steps + 1`
///   points per curve;
/// - every point but `p0` is on exactly one curve, where its provenance says (curve, step),
///   with the curve's θ; arc lengths add up the step lengths and stay within `max_radius`;
/// - every accepted step (`dt > 0`, exactly the points with `step > 0`) lies in the bounding
///   box and has its predicted α inside `[β_min, β_max]` unless its limit says otherwise.
pub fn check_samples(params: &Resolved, s: &Samples<f64>) -> Result<(), Violation> {
    let n = s.points.len();
    ensure!(n >= 1, "no sample points");
    ensure!(
        s.normals.len() == n && s.provenance.len() == n && s.steps.len() == n,
        "{n} points but {} normals, {} provenance entries, {} step records",
        s.normals.len(),
        s.provenance.len(),
        s.steps.len()
    );
    let b = &**params;
    ensure!(
        n <= b.max_points,
        "{n} points exceed the budget max_points = {}",
        b.max_points
    );
    ensure!(
        s.curves.len() <= b.max_curves,
        "{} curves exceed the budget max_curves = {}",
        s.curves.len(),
        b.max_curves
    );
    for (i, (p, nrm)) in s.points.iter().zip(&s.normals).enumerate() {
        ensure!(
            p.is_finite() && nrm.is_finite(),
            "point {i} = {:?} or its normal {:?} is not finite",
            p.to_f64(),
            nrm.to_f64()
        );
    }
    let mut seen = vec![0u32; n];
    for (c, curve) in s.curves.iter().enumerate() {
        ensure!(
            curve.points.len() <= b.max_steps + 1,
            "curve {c} has {} points, more than max_steps + 1 = {}",
            curve.points.len(),
            b.max_steps + 1
        );
        ensure!(!curve.points.is_empty(), "curve {c} has no points");
        let mut prev_s = None;
        for (k, &i) in curve.points.iter().enumerate() {
            let i = i as usize;
            ensure!(i < n, "curve {c} names point {i} of {n}");
            seen[i] += 1;
            let pr = &s.provenance[i];
            if i != 0 {
                ensure!(
                    pr.curve as usize == c && pr.step as usize == k && pr.theta == curve.theta,
                    "point {i} is step {k} of curve {c} (θ = {}) but its provenance says {pr:?}",
                    curve.theta
                );
            }
            let st = &s.steps[i];
            if k > 0 {
                ensure!(st.dt > 0.0, "step {k} of curve {c} has Δt = {}", st.dt);
                if let Some(ps) = prev_s {
                    ensure!(
                        pr.s == ps + st.dt,
                        "arc length of point {i}: {} ≠ {ps} + {}",
                        pr.s,
                        st.dt
                    );
                }
            } else {
                ensure!(st.dt == 0.0, "curve {c} starts with a step record {st:?}");
            }
            prev_s = Some(pr.s);
        }
    }
    for (i, &count) in seen.iter().enumerate().skip(1) {
        ensure!(count == 1, "point {i} lies on {count} curves");
    }
    for (i, st) in s.steps.iter().enumerate() {
        check_step(params, i, st, s.points[i].to_f64(), &s.provenance[i])?;
    }
    Ok(())
}

fn check_step(
    params: &Resolved,
    i: usize,
    st: &StepRecord,
    p: [f64; 3],
    pr: &Provenance,
) -> Result<(), Violation> {
    ensure!(
        pr.s.is_finite() && pr.theta.is_finite() && pr.s <= params.max_radius,
        "point {i} (step {} of curve {}): arc length {} beyond max_radius {} (or not finite, \
         θ = {})",
        pr.step,
        pr.curve,
        pr.s,
        params.max_radius,
        pr.theta
    );
    let bb = params.bounding_box;
    ensure!(
        i == 0 || p.iter().all(|x| x.abs() <= bb),
        "point {i} = {p:?} (step {} of curve {}) lies outside the bounding box ±{bb}",
        pr.step,
        pr.curve
    );
    if st.dt <= 0.0 {
        return Ok(());
    }
    let (beta_min, beta_max) = (params.beta_min.radians(), params.beta_max.radians());
    ensure!(
        st.limit != StepLimit::None
            || (st.alpha_predicted >= beta_min && st.alpha_predicted <= beta_max),
        "point {i}: accepted step with α = {}° outside [{}°, {}°] and no limit reported ({st:?})",
        st.alpha_predicted.to_degrees(),
        params.beta_min.degrees(),
        params.beta_max.degrees()
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Mesh and chart checks
// ---------------------------------------------------------------------------------------------

/// Checks a mesh produced by the mesher: the [`Mesh`] invariants (equal lengths, indices in
/// range, all values finite), every vertex used, no repeated index, no zero-area triangle,
/// no triangle twice (in any rotation or orientation), and per [`Topology`] every edge in at
/// most two triangles and consistent orientation.
pub fn check_mesh(mesh: &Mesh) -> Result<(), Violation> {
    check_mesh_data(mesh)?;
    let mut used = vec![false; mesh.vertices.len()];
    let mut distinct = HashSet::with_capacity(mesh.triangles.len());
    for (k, t) in mesh.triangles.iter().enumerate() {
        ensure!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "triangle {k} = {t:?} repeats a vertex"
        );
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let n = cross3(sub3(b, a), sub3(c, a));
        ensure!(
            n != [0.0; 3],
            "triangle {k} = {t:?} has zero area: {a:?} {b:?} {c:?}"
        );
        let mut key = *t;
        key.sort_unstable();
        ensure!(distinct.insert(key), "triangle {k} = {t:?} appears twice");
        for &v in t {
            used[v as usize] = true;
        }
    }
    if let Some(v) = used.iter().position(|&u| !u) {
        return Err(Violation(format!("vertex {v} is in no triangle")));
    }
    let topo = Topology::of(mesh);
    ensure!(
        topo.non_manifold_edges == 0,
        "{} edges are in more than two triangles ({topo:?})",
        topo.non_manifold_edges
    );
    ensure!(
        topo.orientation_flips == 0,
        "{} interior edges join triangles of opposite orientation ({topo:?})",
        topo.orientation_flips
    );
    Ok(())
}

/// The [`Mesh`] invariants alone: equal vector lengths, indices in range, finite values.
pub fn check_mesh_data(mesh: &Mesh) -> Result<(), Violation> {
    let n = mesh.vertices.len();
    ensure!(
        mesh.normals.len() == n && mesh.provenance.len() == n,
        "{n} vertices but {} normals and {} provenance entries",
        mesh.normals.len(),
        mesh.provenance.len()
    );
    for (k, t) in mesh.triangles.iter().enumerate() {
        ensure!(
            t.iter().all(|&v| (v as usize) < n),
            "triangle {k} = {t:?} indexes past the {n} vertices"
        );
    }
    for i in 0..n {
        let (p, nm, pr) = (mesh.vertices[i], mesh.normals[i], mesh.provenance[i]);
        ensure!(
            p.iter().chain(&nm).all(|x| x.is_finite()) && pr.s.is_finite() && pr.theta.is_finite(),
            "vertex {i} has a non-finite value: {p:?} {nm:?} {pr:?}"
        );
    }
    Ok(())
}

/// Checks the chart triangulation of `n` samples: indices in range, every chart-1 triangle
/// strictly counter-clockwise in the chart (exact orientation test), no triangle twice, and
/// [`check_chart_delaunay`].
pub fn check_chart(chart: &ChartTriangulation, n: usize) -> Result<(), Violation> {
    ensure!(
        chart.chart.len() == n,
        "{} chart positions for {n} samples",
        chart.chart.len()
    );
    for (what, list) in [("chart", &chart.triangles), ("closing", &chart.closing)] {
        for (k, t) in list.iter().enumerate() {
            ensure!(
                t.iter().all(|&v| (v as usize) < n),
                "{what} triangle {k} = {t:?} indexes past the {n} samples"
            );
        }
    }
    ensure!(
        chart.front.iter().all(|&v| (v as usize) < n),
        "the front {:?} indexes past the {n} samples",
        chart.front
    );
    let mut distinct = HashSet::new();
    for (k, t) in chart.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| chart.chart[i as usize]);
        ensure!(
            orient2d(a, b, c) > 0.0,
            "chart triangle {k} = {t:?} is not counter-clockwise: {a:?} {b:?} {c:?}"
        );
        let mut key = *t;
        key.sort_unstable();
        ensure!(
            distinct.insert(key),
            "chart triangle {k} = {t:?} appears twice"
        );
    }
    check_chart_delaunay(chart)?;
    Ok(())
}

/// Exact orientation: positive when `a, b, c` turn counter-clockwise.
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let p = |v: [f64; 2]| robust::Coord { x: v[0], y: v[1] };
    robust::orient2d(p(a), p(b), p(c))
}

/// Exact in-circle test: positive when `d` lies strictly inside the circle through the
/// counter-clockwise `a, b, c`.
pub fn incircle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
    let p = |v: [f64; 2]| robust::Coord { x: v[0], y: v[1] };
    robust::incircle(p(a), p(b), p(c), p(d))
}

/// The empty-circumcircle property of the chart-1 triangulation, in the form a constrained
/// Delaunay triangulation guarantees: for every edge shared by two chart triangles that is
/// not a constraint, neither opposite vertex lies strictly inside the other triangle's
/// circumcircle (exact predicates). Constraints are the front polygon's edges; an edge lying
/// on a front edge (a piece of a constraint split at a vertex on it) counts as one.
///
/// Returns the number of edges checked.
pub fn check_chart_delaunay(chart: &ChartTriangulation) -> Result<usize, Violation> {
    let pos = &chart.chart;
    let m = chart.front.len();
    let front_edges: Vec<(usize, usize)> = (0..m)
        .map(|i| (chart.front[i] as usize, chart.front[(i + 1) % m] as usize))
        .collect();
    let on_segment = |p: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        orient2d(a, b, p) == 0.0
            && p[0] >= a[0].min(b[0])
            && p[0] <= a[0].max(b[0])
            && p[1] >= a[1].min(b[1])
            && p[1] <= a[1].max(b[1])
    };
    let constrained = |u: usize, v: usize| {
        m >= 2
            && front_edges.iter().any(|&(a, b)| {
                (a, b) == (u, v)
                    || (a, b) == (v, u)
                    || (on_segment(pos[u], pos[a], pos[b]) && on_segment(pos[v], pos[a], pos[b]))
            })
    };
    // Directed edge (a, b) → the vertex opposite it in the triangle that holds it.
    let mut opposite: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * chart.triangles.len());
    for t in &chart.triangles {
        for k in 0..3 {
            opposite.insert((t[k], t[(k + 1) % 3]), t[(k + 2) % 3]);
        }
    }
    let mut checked = 0;
    for t in &chart.triangles {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            if a > b {
                continue; // each shared edge once
            }
            let Some(&d) = opposite.get(&(b, a)) else {
                continue; // boundary edge of the kept triangles
            };
            if constrained(a as usize, b as usize) {
                continue;
            }
            let p = |i: u32| pos[i as usize];
            let (ab_c, ba_d) = (
                incircle(p(a), p(b), p(c), p(d)),
                incircle(p(b), p(a), p(d), p(c)),
            );
            ensure!(
                ab_c <= 0.0 && ba_d <= 0.0,
                "edge ({a}, {b}) is not locally Delaunay: vertex {d} {:?} is inside the \
                 circumcircle of ({a}, {b}, {c}) or {c} {:?} inside that of ({b}, {a}, {d})",
                p(d),
                p(c)
            );
            checked += 1;
        }
    }
    Ok(checked)
}

// ---------------------------------------------------------------------------------------------
// Target (b): triangulate
// ---------------------------------------------------------------------------------------------

/// A chart position of a synthetic sample.
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub enum ChartInput {
    /// Polar: arc length `s` and angle θ as the provenance stores them.
    Polar {
        /// Arc length.
        s: Coord,
        /// Angle.
        theta: Coord,
    },
    /// Cartesian `(x, y)`, converted to `s = |(x, y)|`, `θ = atan2(y, x)`.
    Cartesian {
        /// x.
        x: Coord,
        /// y.
        y: Coord,
    },
    /// On the line `y = x/2`: `(k/8, k/16)` (collinear point sets).
    OnLine(i8),
    /// The same chart position as an earlier sample (duplicates).
    SameAs(u16),
}

/// One synthetic sample point.
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub struct PointInput {
    /// Position in space.
    pub position: [Coord; 3],
    /// Position in the chart.
    pub chart: ChartInput,
}

/// Where the samples of a [`TriangulateInput`] come from.
#[derive(Arbitrary, Clone, Debug, PartialEq)]
pub enum SamplesInput {
    /// A short run of the sampler on a preset (`preset mod 6`, `16 + 2 · points` points at most).
    Preset {
        /// Preset index.
        preset: u8,
        /// Point budget parameter.
        points: u8,
    },
    /// Synthetic samples: `p0` at the origin, then the given points cut into curves of the
    /// given lengths (`len mod 16 + 1`), ends picked by `ends[k] mod 6`.
    Synthetic {
        /// The points after `p0`.
        points: Vec<PointInput>,
        /// Curve lengths.
        lengths: Vec<u8>,
        /// Curve ends.
        ends: Vec<u8>,
        /// Give every point its curve's θ (as the sampler does).
        share_theta: bool,
    },
}

/// An edit applied to samples before triangulation. Indices are taken modulo the length of
/// what they index, except in [`SampleEdit::PushIndex`].
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq)]
pub enum SampleEdit {
    /// Replace a point's position.
    SetPoint(u16, [Coord; 3]),
    /// Replace a point's chart position (s, θ).
    SetChart(u16, Coord, Coord),
    /// Copy one point's chart position to another (duplicate in the chart).
    CopyChart(u16, u16),
    /// Copy one point's position to another (duplicate in space).
    CopyPoint(u16, u16),
    /// Replace a normal.
    SetNormal(u16, [Coord; 3]),
    /// Change how a curve ended (`mod 6`).
    SetEnd(u16, u8),
    /// Change a curve's θ.
    SetTheta(u16, Coord),
    /// Append a raw point index (possibly out of range) to a curve.
    PushIndex(u16, u32),
    /// Remove all points of a curve.
    ClearCurve(u16),
    /// Remove a curve.
    RemoveCurve(u16),
    /// Cut the normals to this many.
    TruncateNormals(u16),
    /// Cut the provenance to this many.
    TruncateProvenance(u16),
    /// Cut the points to this many.
    TruncatePoints(u16),
}

/// Input of the `triangulate` target.
#[derive(Arbitrary, Clone, Debug, PartialEq)]
pub struct TriangulateInput {
    /// Whether to close closed surfaces.
    pub close: bool,
    /// Whether to flip edges towards a Delaunay mesh on the surface.
    pub improve: bool,
    /// The samples.
    pub samples: SamplesInput,
    /// Edits applied in order.
    pub edits: Vec<SampleEdit>,
}

const ENDS: [CurveEnd; 6] = [
    CurveEnd::Radius,
    CurveEnd::BoundingBox,
    CurveEnd::Collision,
    CurveEnd::Merge,
    CurveEnd::Singular,
    CurveEnd::Budget,
];

fn pick(i: u16, len: usize) -> Option<usize> {
    (len > 0).then(|| i as usize % len)
}

impl TriangulateInput {
    /// Builds the samples (before the edits).
    pub fn base_samples(&self) -> Samples<f64> {
        match &self.samples {
            SamplesInput::Preset { preset, points } => {
                let p = Preset::ALL[*preset as usize % Preset::ALL.len()];
                let mut params = p.params();
                params.max_points = 16 + 2 * *points as usize;
                let field = LieField::<f64>::new(&p.invariant());
                liemesh::sample::sample(&field, &params).expect("presets sample")
            }
            SamplesInput::Synthetic {
                points,
                lengths,
                ends,
                share_theta,
            } => synthetic(points, lengths, ends, *share_theta),
        }
    }

    /// Builds the samples and applies the edits.
    pub fn samples(&self) -> Samples<f64> {
        let mut s = self.base_samples();
        for e in &self.edits {
            apply_edit(&mut s, e);
        }
        s
    }
}

fn synthetic(points: &[PointInput], lengths: &[u8], ends: &[u8], share: bool) -> Samples<f64> {
    let mut s = Samples {
        points: vec![Vec3::zero()],
        normals: vec![Vec3::new(0.0, 0.0, 1.0)],
        provenance: vec![Provenance::default()],
        steps: vec![StepRecord::default()],
        curves: Vec::new(),
        frame: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        hit_point_budget: false,
    };
    let mut charts: Vec<(f64, f64)> = vec![(0.0, 0.0)];
    for p in points {
        let pos = coords3(p.position);
        let (sv, th) = match p.chart {
            ChartInput::Polar { s, theta } => (s.value(), theta.value()),
            ChartInput::Cartesian { x, y } => {
                let (x, y) = (x.value(), y.value());
                (x.hypot(y), y.atan2(x))
            }
            ChartInput::OnLine(k) => {
                let (x, y) = (f64::from(k) / 8.0, f64::from(k) / 16.0);
                (x.hypot(y), y.atan2(x))
            }
            ChartInput::SameAs(j) => charts[j as usize % charts.len()],
        };
        charts.push((sv, th));
        s.points.push(Vec3::from_f64(pos));
        let len = (pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2]).sqrt();
        let normal = if len > 0.0 && len.is_finite() {
            [pos[0] / len, pos[1] / len, pos[2] / len]
        } else {
            [0.0, 0.0, 1.0]
        };
        s.normals.push(Vec3::from_f64(normal));
        s.provenance.push(Provenance {
            curve: 0,
            step: 0,
            s: sv,
            theta: th,
        });
        s.steps.push(StepRecord {
            dt: 0.1,
            alpha_predicted: 0.1,
            iterations: 1,
            limit: StepLimit::None,
        });
    }
    // Cut the points after p0 into curves; every curve starts at p0.
    let mut next = 1usize;
    let mut k = 0usize;
    while next < s.points.len() {
        let len = lengths.get(k).map_or(4, |&l| l as usize % 16 + 1);
        let end = ENDS[ends.get(k).map_or(0, |&e| e as usize % 6)];
        let stop = (next + len).min(s.points.len());
        let theta = s.provenance[next].theta;
        let mut pts = vec![0u32];
        for (step, i) in (next..stop).enumerate() {
            pts.push(i as u32);
            let pr = &mut s.provenance[i];
            pr.curve = k as u32;
            pr.step = step as u32 + 1;
            if share {
                pr.theta = theta;
            }
        }
        s.curves.push(Curve {
            theta,
            points: pts,
            parent: None,
            end,
        });
        next = stop;
        k += 1;
    }
    s
}

fn apply_edit(s: &mut Samples<f64>, e: &SampleEdit) {
    let np = s.points.len();
    let nc = s.curves.len();
    match *e {
        SampleEdit::SetPoint(i, c) => {
            if let Some(i) = pick(i, np) {
                s.points[i] = Vec3::from_f64(coords3(c));
            }
        }
        SampleEdit::SetChart(i, sv, th) => {
            if let Some(i) = pick(i, s.provenance.len()) {
                s.provenance[i].s = sv.value();
                s.provenance[i].theta = th.value();
            }
        }
        SampleEdit::CopyChart(a, b) => {
            if let (Some(a), Some(b)) = (pick(a, s.provenance.len()), pick(b, s.provenance.len())) {
                s.provenance[b].s = s.provenance[a].s;
                s.provenance[b].theta = s.provenance[a].theta;
            }
        }
        SampleEdit::CopyPoint(a, b) => {
            if let (Some(a), Some(b)) = (pick(a, np), pick(b, np)) {
                s.points[b] = s.points[a].clone();
            }
        }
        SampleEdit::SetNormal(i, c) => {
            if let Some(i) = pick(i, s.normals.len()) {
                s.normals[i] = Vec3::from_f64(coords3(c));
            }
        }
        SampleEdit::SetEnd(c, end) => {
            if let Some(c) = pick(c, nc) {
                s.curves[c].end = ENDS[end as usize % 6];
            }
        }
        SampleEdit::SetTheta(c, th) => {
            if let Some(c) = pick(c, nc) {
                s.curves[c].theta = th.value();
            }
        }
        SampleEdit::PushIndex(c, i) => {
            if let Some(c) = pick(c, nc) {
                s.curves[c].points.push(i);
            }
        }
        SampleEdit::ClearCurve(c) => {
            if let Some(c) = pick(c, nc) {
                s.curves[c].points.clear();
            }
        }
        SampleEdit::RemoveCurve(c) => {
            if let Some(c) = pick(c, nc) {
                s.curves.remove(c);
            }
        }
        SampleEdit::TruncateNormals(k) => s.normals.truncate(k as usize),
        SampleEdit::TruncateProvenance(k) => s.provenance.truncate(k as usize),
        SampleEdit::TruncatePoints(k) => s.points.truncate(k as usize),
    }
}

/// Target (b): decodes a [`TriangulateInput`], triangulates its samples and checks the result
/// with [`check_triangulation`].
pub fn triangulate(data: &[u8]) -> Result<(), Violation> {
    let Ok(input) = TriangulateInput::arbitrary_take_rest(Unstructured::new(data)) else {
        return Ok(());
    };
    let samples = input.samples();
    let result = liemesh::triangulate::triangulate(&samples, input.close, input.improve);
    check_triangulation(&samples, &result).map_err(|v| Violation(format!("{v}\ninput: {input:?}")))
}

/// Checks a triangulation of arbitrary samples: either a [`MeshError::Triangulation`] with a
/// message, or a mesh meeting the [`Mesh`] invariants (indices in range, no NaN, equal lengths)
/// with no repeated index, a chart triangulation meeting [`check_chart`], and — when no
/// closing chart was added — no triangle twice, no edge in more than two triangles and
/// consistent orientation.
pub fn check_triangulation(
    samples: &Samples<f64>,
    result: &Result<(Mesh, ChartTriangulation), MeshError>,
) -> Result<(), Violation> {
    let (mesh, chart) = match result {
        Err(MeshError::Triangulation(msg)) => {
            ensure!(!msg.is_empty(), "empty triangulation error message");
            return Ok(());
        }
        Err(e) => return Err(Violation(format!("unexpected error kind: {e:?}"))),
        Ok(r) => r,
    };
    check_mesh_data(mesh)?;
    check_chart(chart, samples.points.len())?;
    for (k, t) in mesh.triangles.iter().enumerate() {
        ensure!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "triangle {k} = {t:?} repeats a vertex"
        );
    }
    // Chart 1 alone is a planar triangulation, manifold and counter-clockwise, and the edge
    // flips must keep it so. The closing chart is only stitched on correctly when the samples
    // really close up: samples that claim to (every curve ended by collision) but lie flat
    // overlap chart 1, so no topology is promised for them.
    if chart.closing.is_empty() {
        let mut distinct = HashSet::new();
        for (k, t) in mesh.triangles.iter().enumerate() {
            let mut key = *t;
            key.sort_unstable();
            ensure!(distinct.insert(key), "triangle {k} = {t:?} appears twice");
        }
        let topo = Topology::of(mesh);
        ensure!(
            topo.non_manifold_edges == 0 && topo.orientation_flips == 0,
            "non-manifold or inconsistently oriented mesh without a closing chart: {topo:?}"
        );
    }
    ensure!(
        mesh.triangles.len() <= chart.triangles.len() + chart.closing.len(),
        "the mesh has {} triangles, more than the charts' {} + {}",
        mesh.triangles.len(),
        chart.triangles.len(),
        chart.closing.len()
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Target (c): invariant files and mesh files
// ---------------------------------------------------------------------------------------------

/// Target (c): the bytes as an invariant file (when they are UTF-8), as a PLY file and as an
/// OBJ file; see `check_invariant_file` and [`check_read_mesh`]. The invariant-file part needs
/// liemesh's `toml` feature (this crate's `toml` feature, on by default, turns it on; in the
/// main crate's tests it is liemesh's own feature).
pub fn invariant_file(data: &[u8]) -> Result<(), Violation> {
    #[cfg(feature = "toml")]
    if let Ok(text) = std::str::from_utf8(data) {
        let path = Path::new("fuzz.toml");
        check_invariant_file(&InvariantFile::parse(text, path), "fuzz.toml")?;
    }
    check_read_mesh(MeshFileKind::Ply, &read_ply(data))?;
    check_read_mesh(MeshFileKind::Obj, &read_obj(data))?;
    Ok(())
}

/// Checks a parsed invariant file: a valid one has 6 or 18 finite numbers that rebuild the
/// same invariant, and parameters that resolve on the invariant's field or give an error with
/// a message; an error message is one non-empty line naming the file.
#[cfg(feature = "toml")]
pub fn check_invariant_file(
    result: &Result<InvariantFile, InvariantFileError>,
    file_name: &str,
) -> Result<(), Violation> {
    match result {
        Ok(f) => {
            let numbers = f.invariant.numbers();
            ensure!(
                matches!(numbers.len(), 6 | 18) && numbers.iter().all(|x| x.is_finite()),
                "accepted invariant numbers {numbers:?}"
            );
            let again = Invariant::from_numbers(&numbers)
                .map_err(|e| Violation(format!("{numbers:?} do not parse again: {e}")))?;
            ensure!(
                again == f.invariant,
                "{numbers:?} rebuild {again:?}, not {:?}",
                f.invariant
            );
            let field = LieField::<f64>::new(&f.invariant);
            if let Err(e) = f.params.resolve::<f64, _>(&field) {
                ensure!(
                    !e.to_string().is_empty(),
                    "empty error message resolving the file's parameters"
                );
            }
        }
        Err(e) => {
            let msg = e.to_string();
            ensure!(
                !msg.is_empty() && !msg.contains('\n') && msg.contains(file_name),
                "the error message should be one line naming '{file_name}': {msg:?}"
            );
        }
    }
    Ok(())
}

/// Which mesh reader produced a result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFileKind {
    /// [`read_ply`].
    Ply,
    /// [`read_obj`].
    Obj,
}

/// Checks what a mesh reader returned: a mesh meeting the [`Mesh`] invariants that writes and
/// reads back bit-identically (PLY in binary and ASCII, OBJ), or an error with a message.
pub fn check_read_mesh(
    kind: MeshFileKind,
    result: &Result<Mesh, liemesh::io::IoError>,
) -> Result<(), Violation> {
    let mesh = match result {
        Err(e) => {
            ensure!(!e.to_string().is_empty(), "empty {kind:?} error message");
            return Ok(());
        }
        Ok(m) => m,
    };
    check_mesh_data(mesh).map_err(|v| Violation(format!("{kind:?} reader: {v}")))?;
    let encodings: &[Option<PlyEncoding>] = match kind {
        MeshFileKind::Ply => &[
            Some(PlyEncoding::BinaryLittleEndian),
            Some(PlyEncoding::Ascii),
        ],
        MeshFileKind::Obj => &[None],
    };
    for &enc in encodings {
        let mut bytes = Vec::new();
        let written = match enc {
            Some(e) => write_ply(mesh, &mut bytes, e),
            None => write_obj(mesh, &mut bytes),
        };
        written
            .map_err(|e| Violation(format!("a mesh read as {kind:?} cannot be written: {e}")))?;
        let back = match enc {
            Some(_) => read_ply(&bytes[..]),
            None => read_obj(&bytes[..]),
        }
        .map_err(|e| Violation(format!("{kind:?} ({enc:?}) output does not read back: {e}")))?;
        ensure!(
            same_bits(mesh, &back),
            "{kind:?} ({enc:?}) round trip changed the mesh"
        );
    }
    Ok(())
}

/// Bitwise equality of two meshes (NaN-safe, tells −0 from +0).
pub fn same_bits(a: &Mesh, b: &Mesh) -> bool {
    let v = |m: &Mesh| -> Vec<u64> {
        m.vertices
            .iter()
            .chain(&m.normals)
            .flatten()
            .map(|x| x.to_bits())
            .chain(m.provenance.iter().flat_map(|p| {
                [
                    p.s.to_bits(),
                    p.theta.to_bits(),
                    p.curve.into(),
                    p.step.into(),
                ]
            }))
            .collect()
    };
    a.triangles == b.triangles
        && a.vertices.len() == b.vertices.len()
        && a.normals.len() == b.normals.len()
        && a.provenance.len() == b.provenance.len()
        && v(a) == v(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_mesher_input_is_fig1_with_the_small_budget() {
        let input = MesherInput::arbitrary_take_rest(Unstructured::new(&[])).unwrap();
        assert_eq!(input.base(), Preset::Fig1);
        let mut expected = Preset::Fig1.params();
        BudgetInput::Small.apply(&mut expected);
        assert_eq!(input.params(), expected);
        assert_eq!(input.numbers(), Preset::Fig1.invariant().numbers());
    }

    #[test]
    fn a_chart_with_a_non_delaunay_edge_is_reported() {
        // A thin rhombus split along its long diagonal (0, 2): vertex 3 lies inside the
        // circumcircle of (0, 1, 2).
        let chart = ChartTriangulation {
            chart: vec![[0.0, 0.0], [1.0, -0.1], [2.0, 0.0], [1.0, 0.1]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            front: vec![],
            closing: vec![],
        };
        assert!(check_chart_delaunay(&chart).is_err());
        let flipped = ChartTriangulation {
            triangles: vec![[0, 1, 3], [1, 2, 3]],
            ..chart.clone()
        };
        assert_eq!(check_chart_delaunay(&flipped), Ok(1));
        // The same edge as a constraint (front edge) is allowed.
        let constrained = ChartTriangulation {
            front: vec![0, 2],
            ..chart
        };
        assert_eq!(check_chart_delaunay(&constrained), Ok(0));
    }

    #[test]
    fn mesh_checks_catch_each_defect() {
        let mesh = Mesh {
            vertices: vec![
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, -1.0, 0.0],
            ],
            normals: vec![[0.0, 0.0, 1.0]; 5],
            triangles: vec![[0, 1, 2], [0, 2, 3], [1, 0, 4]],
            provenance: vec![Provenance::default(); 5],
        };
        assert_eq!(check_mesh(&mesh), Ok(()));
        let broken = |f: &dyn Fn(&mut Mesh)| {
            let mut m = mesh.clone();
            f(&mut m);
            check_mesh(&m).is_err()
        };
        assert!(broken(&|m| m.vertices[1][0] = f64::NAN));
        assert!(broken(&|m| m.triangles[1] = [0, 2, 2]));
        assert!(broken(&|m| m.triangles[1] = [2, 1, 0]));
        assert!(broken(&|m| m.triangles[1] = [0, 2, 4]));
        assert!(broken(&|m| m.triangles[1] = [0, 3, 2]));
        // Collinear with vertices 0 and 2: zero area.
        assert!(broken(&|m| m.vertices[3] = [0.0, 2.0, 0.0]));
        // The first triangle again, rotated.
        assert!(broken(&|m| m.triangles.push([1, 2, 0])));
        // A third triangle on the edge (0, 1).
        assert!(broken(&|m| m.triangles.push([0, 1, 3])));
        // An unused vertex.
        assert!(broken(&|m| m.triangles.truncate(2)));
        assert!(broken(&|m| {
            m.normals.pop();
        }));
    }
}
