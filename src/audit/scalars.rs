//! Scalar agreement (DESIGN.md §4): the whole mesh of a preset, or of any field that can be
//! built in every scalar type ([`EveryScalar`]), computed in `f32`, `f64`, `Dual<f64>` (its
//! real part) and `Mpfr<64>`, against the same mesh in `Mpfr<256>`.
//!
//! Two figures per scalar type and preset:
//!
//! - **decisions**: the discrete choices of the sampler — which curve every sample point lies
//!   on and at which step, how many points each curve has, which curves were inserted (and
//!   from which parent), and how each curve ended. Measured as the number of differences
//!   (points whose `(curve, step)` exists in one run only, curves whose end or parent differ,
//!   curves present in one run only). When they differ, the note names the first sample
//!   point where the runs part and why (e.g. `curve 17 step 4 ended by Merge in f32 and
//!   continued in Mpfr<256>`).
//! - **vertex error**: the largest distance between a sample point and its reference,
//!   computed exactly in the reference precision, relative to the diagonal of the reference
//!   mesh's bounding box. When the decisions differ, only the common prefix of the point
//!   sequence (before the first parting point) is compared, and the note says so.
//!
//! **`f32` decisions are informative**: its unit roundoff (6e-8) is within reach of the
//! thresholds the sampler compares against (the β band, the gap, merge and collision
//! distances), so an `f32` run may legitimately decide differently near a threshold. Its
//! decision row therefore passes whatever it finds, and the note reports what it found
//! (identical, or where and why the runs part); its vertex row still has to meet its bound.
//! For `f64`, `Dual<f64>` and `Mpfr<64>` any decision difference fails the row.
//!
//! One more row compares `Dual<f64>` with `f64` directly: the real part of a dual run performs
//! the same floating-point operations as the `f64` run, so it must be bit-identical
//! (decisions and coordinates). It needs no MPFR. Without the `mpfr` feature the `f32` rows
//! use `f64` as their reference.

use super::Row;
use crate::model::{EveryScalar, LieField};
use crate::preset::Preset;
use crate::sample::Samples;
use crate::scalar::{Dual, Scalar};
use crate::MeshParams;
use crate::{MeshError, MeshRun};
use std::collections::{HashMap, HashSet};

/// Bound on the `f32` vertex error relative to the mesh size.
pub const F32_BOUND: f64 = 1e-3;
/// Bound on the `f64` vertex error relative to the mesh size.
pub const F64_BOUND: f64 = 1e-10;
/// Bound on the `Dual<f64>` (real part) vertex error relative to the mesh size.
pub const DUAL_BOUND: f64 = 1e-10;
/// Bound on the `Mpfr<64>` vertex error relative to the mesh size.
pub const MPFR64_BOUND: f64 = 1e-13;

/// Exact conversion of a scalar into a reference type at least as precise (the real part for
/// dual numbers), so that differences are measured without extra rounding.
pub trait Widen<R: Scalar>: Scalar {
    /// `self` in the reference type, exactly.
    fn widen(&self) -> R;
}

impl Widen<f64> for f32 {
    fn widen(&self) -> f64 {
        *self as f64
    }
}
impl Widen<f64> for f64 {
    fn widen(&self) -> f64 {
        *self
    }
}
impl Widen<f64> for Dual<f64> {
    fn widen(&self) -> f64 {
        self.re
    }
}

#[cfg(feature = "mpfr")]
mod widen_mpfr {
    use super::Widen;
    use crate::scalar::{Dual, Mpfr, Scalar};

    impl Widen<Mpfr<256>> for f32 {
        fn widen(&self) -> Mpfr<256> {
            Mpfr::from_f64(*self as f64)
        }
    }
    impl Widen<Mpfr<256>> for f64 {
        fn widen(&self) -> Mpfr<256> {
            Mpfr::from_f64(*self)
        }
    }
    impl Widen<Mpfr<256>> for Dual<f64> {
        fn widen(&self) -> Mpfr<256> {
            Mpfr::from_f64(self.re)
        }
    }
    impl Widen<Mpfr<256>> for Mpfr<64> {
        fn widen(&self) -> Mpfr<256> {
            Mpfr::with_val(&self.0)
        }
    }
    impl Widen<Mpfr<256>> for Mpfr<256> {
        fn widen(&self) -> Mpfr<256> {
            self.clone()
        }
    }
}

/// How one run compares with a reference run of the same preset.
#[derive(Clone, Debug, PartialEq)]
pub struct Agreement {
    /// Scalar type of the run.
    pub scalar: String,
    /// Scalar type of the reference.
    pub reference: String,
    /// Sample points of the run.
    pub points: usize,
    /// Sample points of the reference.
    pub reference_points: usize,
    /// Curves of the run.
    pub curves: usize,
    /// Curves of the reference.
    pub reference_curves: usize,
    /// Inserted curves (with a parent) of the reference.
    pub reference_inserted: usize,
    /// Number of discrete decisions that differ (0 when they all agree).
    pub decision_differences: usize,
    /// The first sample index whose `(curve, step)` differs, if any (also set when only the
    /// processing order differs).
    pub first_parting: Option<usize>,
    /// What happened at `first_parting`.
    pub parting: Option<String>,
    /// The earliest differing discrete decision (a curve ended, continued, inserted or not),
    /// described, e.g. `curve 17 step 4 ended by Merge in f32 and continued in Mpfr<256>`.
    pub first_decision: Option<String>,
    /// Sample points whose errors were measured.
    pub compared: usize,
    /// Whether only the common prefix before `first_parting` was compared.
    pub prefix_only: bool,
    /// Compared points whose coordinates are not identical to the reference's.
    pub differing_points: usize,
    /// Largest distance between a compared point and its reference.
    pub max_error: f64,
    /// Bounding-box diagonal of the reference mesh.
    pub diagonal: f64,
    /// Triangles of one mesh that the other lacks (counted both ways, each triangle up to
    /// rotation of its vertex order), or `None` when the point sequences differ so that the
    /// vertex numbers cannot be compared. Informative only: the triangulation works on the
    /// `f64` positions, and where four points are cocircular in exact arithmetic a last-bit
    /// change of a coordinate picks the other diagonal. The previous method on the sphere
    /// (fig1, fig2) is made of such quads: its curves leave `p0` at uniform angles and, by
    /// symmetry, reach equal arc lengths together, so consecutive rings and neighbouring
    /// curves form isosceles trapezoids, which are cyclic.
    pub triangle_differences: Option<usize>,
}

impl Agreement {
    /// `max_error / diagonal`.
    pub fn relative_error(&self) -> f64 {
        self.max_error / self.diagonal
    }

    /// A few words on the triangles.
    pub fn triangles_note(&self) -> String {
        match self.triangle_differences {
            Some(0) => "triangles identical".to_string(),
            Some(n) => format!("{n} triangles differ"),
            None => "triangles not compared".to_string(),
        }
    }

    /// A one-line account of the decisions.
    pub fn decisions_note(&self) -> String {
        let tri = self.triangles_note();
        if self.decision_differences == 0 {
            return match &self.parting {
                None => format!(
                    "identical: {} points, {} curves ({} inserted), same ends; {tri}",
                    self.reference_points, self.reference_curves, self.reference_inserted
                ),
                Some(why) => format!(
                    "same steps, curves and ends, processing order differs from point {}: {why}; {tri}",
                    self.first_parting.unwrap_or(0)
                ),
            };
        }
        let mut note = format!(
            "{} differences ({} vs {} points, {} vs {} curves)",
            self.decision_differences,
            self.points,
            self.reference_points,
            self.curves,
            self.reference_curves
        );
        if let Some(first) = &self.first_decision {
            note.push_str(&format!("; first differing decision: {first}"));
        }
        if let (Some(i), Some(why)) = (self.first_parting, &self.parting) {
            note.push_str(&format!("; the point sequences part at point {i}: {why}"));
        }
        note
    }

    /// A one-line account of the vertex comparison.
    pub fn vertex_note(&self) -> String {
        let scope = if self.prefix_only {
            format!(
                "common prefix of {} points only (the decisions part at point {})",
                self.compared,
                self.first_parting.unwrap_or(0)
            )
        } else {
            format!("all {} points", self.compared)
        };
        format!(
            "max |p − p_ref| = {:.3e} over {scope}, bbox diagonal {:.4}",
            self.max_error, self.diagonal
        )
    }
}

fn key(s: &crate::Provenance) -> (u32, u32) {
    (s.curve, s.step)
}

/// Why two sample sequences part at index `i`.
fn parting_reason<T: Scalar, R: Scalar>(t: &Samples<T>, r: &Samples<R>, i: usize) -> String {
    let (tn, rn) = (T::type_name(), R::type_name());
    let kt = t.provenance.get(i).map(key);
    let kr = r.provenance.get(i).map(key);
    // A curve that one run continued and the other ended or never had.
    let explain =
        |k: (u32, u32), here: &str, other_curves: &[crate::sample::Curve], other: &str| {
            let (c, s) = k;
            match other_curves.get(c as usize) {
                None => Some(format!(
                    "curve {c} (inserted) exists in {here} and not in {other}"
                )),
                Some(oc) if oc.points.len() <= s as usize => Some(format!(
                    "curve {c} step {s} ended by {:?} in {other} and continued in {here}",
                    oc.end
                )),
                _ => None,
            }
        };
    if let Some(why) = kr.and_then(|k| explain(k, &rn, &t.curves, &tn)) {
        return why;
    }
    if let Some(why) = kt.and_then(|k| explain(k, &tn, &r.curves, &rn)) {
        return why;
    }
    let show = |k: Option<(u32, u32)>| match k {
        Some((c, s)) => format!("curve {c} step {s}"),
        None => "nothing".to_string(),
    };
    format!(
        "{tn} takes {} where {rn} takes {} (same curves, different processing order)",
        show(kt),
        show(kr)
    )
}

/// The earliest discrete decision on which two runs differ, described, with the sample index
/// (in the run that has the point) where it shows.
fn first_decision<T: Scalar, R: Scalar>(t: &Samples<T>, r: &Samples<R>) -> Option<String> {
    use crate::sample::Curve;
    let (tn, rn) = (T::type_name(), R::type_name());
    let mut found: Vec<(u32, String)> = Vec::new();
    let origin = |c: &Curve| match c.parent {
        Some(p) => format!("inserted from curve {p}"),
        None => "initial".to_string(),
    };
    for (c, (a, b)) in t.curves.iter().zip(&r.curves).enumerate() {
        let (la, lb) = (a.points.len(), b.points.len());
        if a.parent != b.parent {
            found.push((
                a.points[0].min(b.points[0]),
                format!(
                    "curve {c} is {} in {tn} and {} in {rn}",
                    origin(a),
                    origin(b)
                ),
            ));
        } else if la != lb {
            let (short, short_name, long, long_name) = if la < lb {
                (a, &tn, b, &rn)
            } else {
                (b, &rn, a, &tn)
            };
            let k = short.points.len();
            found.push((
                long.points[k],
                format!(
                    "curve {c} step {k} ended by {:?} in {short_name} and continued in {long_name}",
                    short.end
                ),
            ));
        } else if a.end != b.end {
            found.push((
                *a.points.last().unwrap_or(&0),
                format!(
                    "curve {c} ended by {:?} in {tn} and by {:?} in {rn}",
                    a.end, b.end
                ),
            ));
        }
    }
    let n = t.curves.len().min(r.curves.len());
    for (c, extra, here) in t
        .curves
        .iter()
        .enumerate()
        .skip(n)
        .map(|(c, x)| (c, x, &tn))
        .chain(
            r.curves
                .iter()
                .enumerate()
                .skip(n)
                .map(|(c, x)| (c, x, &rn)),
        )
    {
        found.push((
            extra.points[0],
            format!("curve {c} ({}) exists in {here} only", origin(extra)),
        ));
    }
    found
        .into_iter()
        .min_by_key(|(i, _)| *i)
        .map(|(i, why)| format!("{why} (point {i})"))
}

/// Compares a run with a reference run: decisions, then vertex errors (in `R`, exactly).
pub fn compare<T: Widen<R>, R: Scalar>(run: &MeshRun<T>, reference: &MeshRun<R>) -> Agreement {
    let (t, r) = (&run.samples, &reference.samples);
    let n = t.points.len().min(r.points.len());
    let first_parting = (0..n)
        .find(|&i| key(&t.provenance[i]) != key(&r.provenance[i]))
        .or((t.points.len() != r.points.len()).then_some(n));

    // Decisions.
    let kt: HashSet<(u32, u32)> = t.provenance.iter().map(key).collect();
    let kr: HashSet<(u32, u32)> = r.provenance.iter().map(key).collect();
    let mut differences = kt.symmetric_difference(&kr).count();
    differences += t.curves.len().abs_diff(r.curves.len());
    differences += t
        .curves
        .iter()
        .zip(&r.curves)
        .filter(|(a, b)| a.end != b.end || a.parent != b.parent || a.theta != b.theta)
        .count();
    differences += usize::from(t.hit_point_budget != r.hit_point_budget);

    // Vertex errors: matched by (curve, step) when the decisions agree, else over the common
    // prefix of the sequences.
    let pairs: Vec<(usize, usize)> = if differences == 0 {
        let index: HashMap<(u32, u32), usize> = t
            .provenance
            .iter()
            .enumerate()
            .map(|(j, p)| (key(p), j))
            .collect();
        r.provenance
            .iter()
            .enumerate()
            .map(|(i, p)| (index[&key(p)], i))
            .collect()
    } else {
        let end = first_parting.unwrap_or(n);
        (0..end).map(|i| (i, i)).collect()
    };
    let mut max_error = R::zero();
    let mut differing_points = 0;
    for &(j, i) in &pairs {
        let (a, b) = (&t.points[j], &r.points[i]);
        let d = [
            a.x.widen() - b.x.clone(),
            a.y.widen() - b.y.clone(),
            a.z.widen() - b.z.clone(),
        ];
        let e = (d[0].clone() * d[0].clone()
            + d[1].clone() * d[1].clone()
            + d[2].clone() * d[2].clone())
        .sqrt();
        if !e.is_zero() {
            differing_points += 1;
        }
        // A NaN (incomparable) also replaces the maximum, so that it shows.
        if !matches!(
            e.partial_cmp(&max_error),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        ) {
            max_error = e;
        }
    }

    let v = &reference.mesh.vertices;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in v {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();

    Agreement {
        scalar: T::type_name(),
        reference: R::type_name(),
        points: t.points.len(),
        reference_points: r.points.len(),
        curves: t.curves.len(),
        reference_curves: r.curves.len(),
        reference_inserted: r.curves.iter().filter(|c| c.parent.is_some()).count(),
        decision_differences: differences,
        first_parting,
        parting: first_parting.map(|i| parting_reason(t, r, i)),
        first_decision: (differences > 0).then(|| first_decision(t, r)).flatten(),
        compared: pairs.len(),
        prefix_only: differences != 0,
        differing_points,
        max_error: max_error.to_f64(),
        diagonal,
        triangle_differences: first_parting
            .is_none()
            .then(|| triangle_differences(&run.mesh.triangles, &reference.mesh.triangles)),
    }
}

/// Triangles in one list and not the other (both ways), each up to rotation.
fn triangle_differences(a: &[[u32; 3]], b: &[[u32; 3]]) -> usize {
    let canon = |t: &[u32; 3]| {
        let m = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
        [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
    };
    let sa: HashSet<[u32; 3]> = a.iter().map(canon).collect();
    let sb: HashSet<[u32; 3]> = b.iter().map(canon).collect();
    sa.symmetric_difference(&sb).count()
}

/// Runs the whole pipeline of `preset` in `T`.
pub fn run_preset<T: Scalar>(preset: Preset) -> Result<MeshRun<T>, MeshError> {
    crate::run(&LieField::<T>::new(&preset.invariant()), &preset.params())
}

/// Runs the whole pipeline of `field` built in `T`.
pub fn run_in<T: Scalar, S: EveryScalar>(
    field: &S,
    params: &MeshParams,
) -> Result<MeshRun<T>, MeshError> {
    crate::run(&field.in_scalar::<T>(), params)
}

/// The decision and vertex rows of one comparison, labelled `label` (a preset's name or the
/// audited field's). `informative` makes the decision row pass whatever it finds (the `f32`
/// choice documented in the module).
pub fn agreement_rows(
    label: &str,
    agreement: &Agreement,
    bound: f64,
    informative: bool,
) -> Vec<Row> {
    let name = Some(label);
    let mut decisions = Row::at_most(
        format!("decisions vs {} [differences]", agreement.reference),
        agreement.scalar.clone(),
        name,
        agreement.decision_differences as f64,
        0.0,
        agreement.decisions_note(),
    );
    if informative {
        decisions.pass = true;
        decisions.note = format!(
            "informative (f32 rounding may flip threshold decisions): {}",
            decisions.note
        );
    }
    let vertices = Row::at_most(
        format!("vertex error vs {} / bbox diagonal", agreement.reference),
        agreement.scalar.clone(),
        name,
        agreement.relative_error(),
        bound,
        agreement.vertex_note(),
    );
    vec![decisions, vertices]
}

/// Compares a run (or its error) with a reference into rows; a failed run gives failed rows.
fn rows_for<T: Widen<R>, R: Scalar>(
    label: &str,
    run: &Result<MeshRun<T>, MeshError>,
    reference: &MeshRun<R>,
    bound: f64,
    informative: bool,
) -> Vec<Row> {
    match run {
        Ok(run) => agreement_rows(label, &compare(run, reference), bound, informative),
        Err(e) => vec![Row::failed(
            format!("mesh vs {}", R::type_name()),
            T::type_name(),
            Some(label),
            bound,
            format!("the {} run failed: {e}", T::type_name()),
        )],
    }
}

/// The `Dual<f64>` real part against `f64`: measured as decision differences plus points
/// whose coordinates are not bit-identical, bound 0.
pub fn dual_matches_f64(
    label: &str,
    dual: &Result<MeshRun<Dual<f64>>, MeshError>,
    f64_run: &Result<MeshRun<f64>, MeshError>,
) -> Row {
    let check = "real part ≡ f64 [differences]";
    match (dual, f64_run) {
        (Ok(d), Ok(f)) => {
            let a = compare(d, f);
            Row::at_most(
                check,
                "Dual<f64>",
                Some(label),
                (a.decision_differences + a.differing_points) as f64,
                0.0,
                format!(
                    "{} decision differences, {} of {} points not bit-identical; {}",
                    a.decision_differences,
                    a.differing_points,
                    a.compared,
                    a.triangles_note()
                ),
            )
        }
        (Err(e), _) | (_, Err(e)) => Row::failed(
            check,
            "Dual<f64>",
            Some(label),
            0.0,
            format!("a run failed: {e}"),
        ),
    }
}

/// Every scalar-agreement row of `preset`: see [`scalar_agreement_of`].
pub fn scalar_agreement(preset: Preset) -> Vec<Row> {
    scalar_agreement_of(&preset.invariant(), &preset.params(), preset.name())
}

/// Every scalar-agreement row of `field` meshed with `params`, labelled `label`: decisions
/// and vertex error of `f32`, `f64`, `Dual<f64>` and `Mpfr<64>` against `Mpfr<256>` (with the
/// `mpfr` feature; without it, of `f32` against `f64`), and the `Dual<f64>` ≡ `f64` row.
pub fn scalar_agreement_of<S: EveryScalar>(
    field: &S,
    params: &MeshParams,
    label: &str,
) -> Vec<Row> {
    let f32_run = run_in::<f32, S>(field, params);
    let f64_run = run_in::<f64, S>(field, params);
    let dual_run = run_in::<Dual<f64>, S>(field, params);
    let mut rows = Vec::new();

    #[cfg(feature = "mpfr")]
    {
        use crate::scalar::Mpfr;
        match run_in::<Mpfr<256>, S>(field, params) {
            Ok(reference) => {
                rows.extend(rows_for(label, &f32_run, &reference, F32_BOUND, true));
                rows.extend(rows_for(label, &f64_run, &reference, F64_BOUND, false));
                rows.extend(rows_for(label, &dual_run, &reference, DUAL_BOUND, false));
                let mpfr64 = run_in::<Mpfr<64>, S>(field, params);
                rows.extend(rows_for(label, &mpfr64, &reference, MPFR64_BOUND, false));
            }
            Err(e) => rows.push(Row::failed(
                "mesh vs Mpfr<256>",
                "Mpfr<256>",
                Some(label),
                0.0,
                format!("the reference run failed: {e}"),
            )),
        }
    }
    #[cfg(not(feature = "mpfr"))]
    {
        match &f64_run {
            Ok(reference) => rows.extend(rows_for(label, &f32_run, reference, F32_BOUND, true)),
            Err(e) => rows.push(Row::failed(
                "mesh vs f64",
                "f64",
                Some(label),
                0.0,
                format!("the reference run failed: {e}"),
            )),
        }
    }

    rows.push(dual_matches_f64(label, &dual_run, &f64_run));
    rows
}
