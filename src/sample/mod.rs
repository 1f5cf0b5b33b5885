//! The fan of integral curves from `p0` (paper Steps 2, 6, 7): the sample points.
//!
//! Curves advance together, the one with the smallest arc length first, so that the curves
//! alive at any moment form a front around `p0`. Neighbours on the front (in order of their
//! chart angle θ) are compared after every step: the proposed method inserts a curve between
//! two that drifted more than `gap` steps apart (Step 6) and ends one that came closer than
//! `merge` steps. Every method ends a curve at the maximum radius, outside the bounding box, on
//! a budget, at a singular point, and — when closing is on — when the new point runs into
//! points other curves laid down far away in the chart (the surface closed up behind them).

mod grid;

use crate::error::MeshError;
use crate::geom::vec3::{dist, dot, sub};
use crate::mesh::Provenance;
use crate::model::{bend_has_singular_point, LocalShape};
use crate::params::{MeshParams, Method, Mode, Resolved};
use crate::progress::{Progress, Stage, SAMPLING_REPORT_EVERY};
use crate::scalar::{Scalar, Vec3};
use crate::trace::{self, StepConfig, StepLimit};
use crate::NormalField;
use grid::Grid;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// How a curve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum CurveEnd {
    /// Reached the maximum geodesic radius.
    Radius,
    /// Left the bounding box.
    BoundingBox,
    /// Ran into points of curves far away in the chart: the surface closed.
    Collision,
    /// Came too close to a neighbouring curve (proposed method).
    Merge,
    /// Met a singular point (vanishing normal, no tangent direction, non-finite value), or
    /// the step floor `dt_min` where the surface may have one (a cone's apex), or no chord
    /// ([`StepStop::NoChord`](crate::trace::StepStop::NoChord)) beside one.
    Singular,
    /// A budget ran out: points, steps per curve, Newton's iterations for a chord at every
    /// length tried ([`StepStop::NoChord`](crate::trace::StepStop::NoChord)) where no
    /// singular point accounts for the bend, or the step
    /// floor `dt_min` at a bend with no singular point: on a surface known to have none
    /// ([`NormalField::is_regular_through`]: an ellipsoid's rim or a flared hyperboloid's
    /// waist bending more sharply than that step can follow), or, on a field integrable at
    /// `p0`, where the nearest zero of the field is off the surface or too far to account for
    /// the bend (the same waist written as a closure, an elliptic cone's sharp sides).
    Budget,
}

/// How many curves ended for each reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CurveEnds {
    /// At the maximum geodesic radius.
    pub radius: usize,
    /// Leaving the bounding box.
    pub bounding_box: usize,
    /// Running onto the surface other curves swept (fronts meeting).
    pub collision: usize,
    /// Too close to a neighbouring curve.
    pub merge: usize,
    /// At a singular point.
    pub singular: usize,
    /// On a budget.
    pub budget: usize,
}

/// One integral curve of the fan.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Chart angle at `p0`, radians in `[0, 2π)`.
    pub theta: f64,
    /// Indices of its points in order (the first is `p0` for the initial fan, the inserted
    /// point for an inserted curve).
    pub points: Vec<u32>,
    /// For an inserted curve: the curve whose step triggered the insertion.
    pub parent: Option<u32>,
    /// How it ended.
    pub end: CurveEnd,
}

/// Per-point record of the step that produced it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepRecord {
    /// Step length Δt that led to this point (0 for curve starts).
    pub dt: f64,
    /// Predicted normal-turn angle α of that step, radians (0 for curve starts).
    pub alpha_predicted: f64,
    /// Retries (paper) or Newton iterations (default).
    pub iterations: u32,
    /// Limit the step ran into.
    pub limit: StepLimit,
}

/// The sample points of one run, in the working scalar type.
#[derive(Clone, Debug)]
pub struct Samples<T> {
    /// Points; index 0 is `p0`.
    pub points: Vec<Vec3<T>>,
    /// Unit field normal at each point.
    pub normals: Vec<Vec3<T>>,
    /// Where each point came from.
    pub provenance: Vec<Provenance>,
    /// The step that produced each point.
    pub steps: Vec<StepRecord>,
    /// The curves.
    pub curves: Vec<Curve>,
    /// Chart frame at `p0`: `e1` (from `w00`), `e2 = n0 × e1`, `n0`.
    pub frame: [[f64; 3]; 3],
    /// Whether the point budget stopped the run.
    pub hit_point_budget: bool,
}

impl<T> Samples<T> {
    /// The sample point a vertex of provenance `pr` is, if it is one (not a point added to
    /// close the surface or by refinement).
    pub(crate) fn point_of(&self, pr: &Provenance) -> Option<u32> {
        self.curves
            .get(pr.curve as usize)
            .and_then(|c| c.points.get(pr.step as usize))
            .copied()
    }

    /// How many curves ended for each reason.
    pub fn ends(&self) -> CurveEnds {
        let mut e = CurveEnds::default();
        for c in &self.curves {
            *match c.end {
                CurveEnd::Radius => &mut e.radius,
                CurveEnd::BoundingBox => &mut e.bounding_box,
                CurveEnd::Collision => &mut e.collision,
                CurveEnd::Merge => &mut e.merge,
                CurveEnd::Singular => &mut e.singular,
                CurveEnd::Budget => &mut e.budget,
            } += 1;
        }
        e
    }
}

impl<T: Scalar> Samples<T> {
    /// Chart position `(s cos θ, s sin θ)` of point `i`.
    pub fn chart(&self, i: usize) -> [f64; 2] {
        let pr = &self.provenance[i];
        [pr.s * pr.theta.cos(), pr.s * pr.theta.sin()]
    }

    /// Whether every curve ended by collision or merge (no boundary was reached):
    /// the front closed up and the surface is closed.
    pub fn front_closed(&self) -> bool {
        self.curves
            .iter()
            .all(|c| matches!(c.end, CurveEnd::Collision | CurveEnd::Merge))
            && self.curves.iter().any(|c| c.end == CurveEnd::Collision)
    }
}

/// Closure test: a new point ends its curve when it is nearer than this many step lengths
/// to a point that lies far away in the chart.
const COLLISION_RADIUS: f64 = 0.6;

/// The fence around a point laid far away in the chart: a disc in its tangent plane of this
/// many step lengths (the larger of the two curves' steps) in radius…
const FENCE_RADIUS: f64 = 1.0;
/// …and this many in half-thickness.
const FENCE_THICKNESS: f64 = 0.35;
/// The fence's radius about the points of the curves beside the one stepping, at about its
/// arc length (see [`Beside`]): the closure test's.
const BESIDE_FENCE_RADIUS: f64 = COLLISION_RADIUS;

/// The curves on either side of a step and the step's arc length (previous method only).
/// Where its curves converge (towards a sphere's far pole), neighbours at the same arc
/// length come closer in space than a step while the chart, which spaces them by `s·Δθ`,
/// calls them far apart: the full fence would stop every other curve there a few steps
/// early, leaving long gaps for the stitching to bridge (fig2's far cap: 1 % quantile of
/// smallest angles 18.0° instead of 24.1°, longest edge 0.48 instead of 0.36). Their points
/// at about the same arc length are fenced at the closure test's smaller radius instead, as
/// before the fence. (The proposed method's merge rule ends converging neighbours; letting
/// them come closer there left the ellipsoids' smallest angles 2–4° lower.)
#[derive(Clone, Copy)]
struct Beside {
    curves: [u32; 2],
    s: f64,
}

impl Beside {
    /// Whether the point of provenance `pr` is on a curve beside the step, within two steps
    /// of length `len` of its arc length.
    fn beside(&self, pr: &Provenance, len: f64) -> bool {
        self.curves.contains(&pr.curve) && (pr.s - self.s).abs() <= 2.0 * len
    }
}

/// A bound on squared distances beyond which the distance (`d².sqrt()`, as `dist` computes
/// it) certainly exceeds `limit`, so that most candidates of a query are rejected without a
/// square root and with the same answer.
///
/// `sqrt` is correctly rounded and monotone: if `d² > limit²·(1 + 2⁻⁵⁰)` then
/// `√d² > limit·(1 + 2⁻⁵²) ≥ nextup(limit)`, which the rounding keeps. The bound computed here,
/// `limit·limit·(1 + 2⁻⁴⁹)` with two roundings, is at least that while `limit²` is a normal
/// number; otherwise (underflow, zero, NaN) it is infinite and rejects nothing.
fn squared_bound_beyond(limit: f64) -> f64 {
    let square = limit * limit;
    if square >= f64::MIN_POSITIVE {
        square * (1.0 + 8.0 * f64::EPSILON)
    } else {
        f64::INFINITY
    }
}

/// No curve: a neighbour not yet known.
const NO_CURVE: u32 = u32::MAX;

/// Steps a curve waits before inserting on a side again after a curve it inserted there
/// merged at once.
const COOLDOWN_STEPS: f64 = 4.0;

/// An inserted curve starts halfway to its neighbour along one chord, but only when the
/// normals of the two turn apart by at most this many times the insertion threshold (`gap` ×
/// β_max), and they are at most [`MAX_INSERT_SPAN`] times the insertion gap apart. Farther
/// apart, the two are neighbours only in the order of the curves (the curves between them
/// ended, or they came round a closed surface, such as a torus, different ways): their
/// midpoint is no place between them, and a chord that long leaves the level set on fields
/// that are not cubic.
const MAX_INSERT_TURN: f64 = 2.0;
/// See [`MAX_INSERT_TURN`]: in insertion gaps (`gap` × the longer of the two curves' last
/// steps).
const MAX_INSERT_SPAN: f64 = 4.0;

/// Where the field is not integrable, a curve is inserted only where its neighbours are at
/// least this fraction of their gap in space apart in the chart (`s` × their angle apart):
/// this cuts the pile-up of a folded sweep from 100,876 curves to 9,898. Integrable fields
/// are left alone: tilted tori, whose curves come round the tube close in θ, need those
/// curves to close, and 23 of 256 stayed open with the limit (at 1% or 0.1%, 5–9 of 24).
const MIN_CHART_SPREAD: f64 = 1e-4;

/// A step clamped at `dt_min` whose predicted turn exceeds this many `β_max` ends its curve
/// as singular.
const SINGULAR_TURN: f64 = 2.0;

/// Curves are advanced in order of arc length measured in units of `dt_min / ORDER_RESOLUTION`
/// (ties by curve id), not of the exact `f64` arc length: curves that symmetry gives equal arc
/// lengths (every curve on the sphere) would otherwise be ordered by rounding noise, and the
/// order decides insertions, merges and collisions, so `f32`, `f64` and MPFR runs would make
/// different discrete decisions. The quantum is far above the rounding noise of the arc length
/// in every supported scalar type (≈1e-7 in `f32`) and far below the smallest step.
const ORDER_RESOLUTION: f64 = 64.0;

struct Live<T> {
    p: Vec3<T>,
    carry: Vec3<T>,
    dt: T,
    s: f64,
    left: u32,
    right: u32,
    active: bool,
    /// Paper mode: how far explicit Euler has carried the curve off the surface, estimated
    /// as `Σ Δt·α/2` (a chord of length Δt across a turn of α leaves the arc by about that).
    drift: f64,
    /// `(cos θ, sin θ)` of the curve's angle at `p0`: its points' chart direction.
    chart_dir: [f64; 2],
    /// Arc length below which this curve inserts no curve on its left (0) and right (1)
    /// side: set when a curve it inserted there merged right away (see [`COOLDOWN_STEPS`]).
    cooldown: [f64; 2],
    /// For an inserted curve: its parent and whether it lies on the parent's right.
    inserted_from: Option<(u32, bool)>,
    /// The neighbour on the right (0) and left (1) at the last step and the lateral gap to it
    /// then (measured only while merging is on): curves of the fan do not merge while they
    /// move apart.
    last_gap: [(u32, f64); 2],
}

/// Samples the surface of `field` from `params.p0` (paper Steps 2–7).
pub fn sample<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &MeshParams,
) -> Result<Samples<T>, MeshError> {
    sample_resolved(field, &params.resolve::<T, F>(field)?, &|_| {})
}

/// [`sample`] with the parameters already resolved, reporting its progress to `observe`.
pub(crate) fn sample_resolved<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    observe: &dyn Fn(Progress),
) -> Result<Samples<T>, MeshError> {
    let cfg = StepConfig::<T>::new(params);
    let p0 = Vec3::<T>::from_f64(params.p0);
    let v0 = field.normal(&p0);
    let Some((n0, _)) = v0.normalize() else {
        return Err(MeshError::no_normal_at(params.p0, v0.to_f64()));
    };
    let w00 = Vec3::<T>::from_f64(params.w00);
    let Some(e1) = trace::project_tangent(&w00, &n0) else {
        return Err(MeshError::DirectionParallelToNormal {
            w00: params.w00,
            normal: v0.to_f64(),
        });
    };
    let e2 = n0.cross(&e1);
    let frame = [e1.to_f64(), e2.to_f64(), n0.to_f64()];

    let thetas: Vec<f64> = match params.method {
        Method::Previous => (0..params.curves)
            .map(|j| std::f64::consts::TAU * j as f64 / params.curves as f64)
            .collect(),
        // Step 2: first points p0 + Δt w at least Δt apart ⇔ directions at least 60° apart.
        Method::Proposed => (0..6)
            .map(|j| std::f64::consts::FRAC_PI_3 * j as f64)
            .collect(),
    };

    let mut s = Sampler {
        field,
        params,
        cfg,
        out: Samples {
            points: vec![p0.clone()],
            normals: Vec::new(),
            provenance: vec![Provenance {
                curve: 0,
                step: 0,
                s: 0.0,
                theta: 0.0,
            }],
            steps: vec![StepRecord::default()],
            curves: Vec::new(),
            frame,
            hit_point_budget: false,
        },
        pos: vec![params.p0],
        no_singular_point: field.is_regular_through(params.p0),
        level_set: LocalShape::at::<T, F>(field, params.p0).is_some_and(|s| s.is_integrable()),
        nrm: vec![n0.to_f64()],
        chart: vec![[0.0, 0.0]],
        live: Vec::new(),
        heap: BinaryHeap::new(),
        grid: Grid::new(params.dt.max(1e-300)),
        drift: Vec::new(),
        max_drift: 0.0,
        observe,
    };
    if params.mode == Mode::Paper {
        s.drift.push(0.0);
    }
    s.grid.push(&s.pos);
    let n = thetas.len() as u32;
    for (j, &theta) in thetas.iter().enumerate() {
        let j = j as u32;
        let dir = e1
            .scale(&T::from_f64(theta.cos()))
            .add_scaled(&T::from_f64(theta.sin()), &e2);
        s.out.curves.push(Curve {
            theta,
            points: vec![0],
            parent: None,
            end: CurveEnd::Budget,
        });
        let (left, right) = ((j + n - 1) % n, (j + 1) % n);
        s.live.push(Live {
            p: p0.clone(),
            carry: dir,
            dt: T::from_f64(params.dt),
            s: 0.0,
            left,
            right,
            active: true,
            drift: 0.0,
            chart_dir: [theta.cos(), theta.sin()],
            cooldown: [0.0; 2],
            inserted_from: None,
            // Every curve of the fan starts at p0, no gap from its neighbours.
            last_gap: [(right, 0.0), (left, 0.0)],
        });
        s.heap.push(Reverse((s.order_key(0.0), j)));
    }
    s.run();
    let Sampler { mut out, .. } = s;
    out.normals = out
        .points
        .iter()
        .map(|p| {
            trace::unit_normal(field, p)
                .map(|(_, n, _)| n)
                .unwrap_or_else(|_| Vec3::zero())
        })
        .collect();
    Ok(out)
}

struct Sampler<'a, T, F> {
    field: &'a F,
    params: &'a Resolved,
    cfg: StepConfig<T>,
    out: Samples<T>,
    /// `f64` copies of the points for the geometric tests.
    pos: Vec<[f64; 3]>,
    /// Unit normals of the points in `f64` (the step's first-order prediction for stepped
    /// points): the tangent planes the fence tests steps against.
    nrm: Vec<[f64; 3]>,
    /// Chart positions of the points (as [`Samples::chart`] computes them), cached so that
    /// the closure test does no trigonometry per neighbour.
    chart: Vec<[f64; 2]>,
    live: Vec<Live<T>>,
    heap: BinaryHeap<Reverse<(u64, u32)>>,
    grid: Grid,
    /// Paper mode only (empty otherwise): each point's curve drift when it was laid down.
    drift: Vec<f64>,
    /// The largest entry of `drift`.
    max_drift: f64,
    /// Where progress is reported (every [`SAMPLING_REPORT_EVERY`] passes of [`Self::run`]).
    observe: &'a dyn Fn(Progress),
    /// Whether the field knows its surface has no singular point
    /// ([`NormalField::is_regular_through`]): a step that cannot follow the bend at `dt_min`
    /// then ends its curve on the step floor ([`CurveEnd::Budget`]), not at a singular point.
    no_singular_point: bool,
    /// Whether the field is integrable at `p0`: the surface is a level set, and a bend the
    /// step floor cannot follow is asked whether a singular point of it is near
    /// ([`bend_has_singular_point`]).
    level_set: bool,
}

impl<T: Scalar, F: NormalField<T>> Sampler<'_, T, F> {
    /// Whether a bend of radius `radius` at `p` that no step can follow ends its curve as at a
    /// singular point rather than on a budget: not on a surface known to have none; on a
    /// field integrable at `p0`, only where a zero of the field on the level set accounts for
    /// the bend ([`bend_has_singular_point`]; a cone's apex); on any other field, always.
    fn singular_bend(&self, p: [f64; 3], radius: f64) -> bool {
        !self.no_singular_point
            && (!self.level_set || bend_has_singular_point(self.field, p, radius))
    }

    /// The heap key of a curve at arc length `s` (see [`ORDER_RESOLUTION`]).
    fn order_key(&self, s: f64) -> u64 {
        (s * ORDER_RESOLUTION / self.params.dt_min).floor() as u64
    }

    fn run(&mut self) {
        let budget = &**self.params;
        // Every pass either adds a point or ends a curve, so this bound is never the binding
        // one; it is here so that the loop visibly terminates.
        let max_passes = budget.max_points + 2 * budget.max_curves + 16;
        for pass in 0..max_passes {
            if pass % SAMPLING_REPORT_EVERY == 0 {
                let (points, curves) = (self.out.points.len(), self.out.curves.len());
                (self.observe)(Progress::at(Stage::Sampling, points, curves, 0));
            }
            let Some(Reverse((_, c))) = self.heap.pop() else {
                return;
            };
            if let Some(end) = self.advance(c) {
                self.end_curve(c, end);
            } else {
                let s = self.live[c as usize].s;
                self.heap.push(Reverse((self.order_key(s), c)));
            }
        }
        // Budget exhausted: end what is still running.
        while let Some(Reverse((_, c))) = self.heap.pop() {
            self.end_curve(c, CurveEnd::Budget);
        }
    }

    fn end_curve(&mut self, c: u32, end: CurveEnd) {
        // An inserted curve that merges within a step or two was inserted where neighbours
        // shear past each other: its parent waits before inserting on that side again, or it
        // would insert (and lose) a curve at every step.
        if end == CurveEnd::Merge && self.out.curves[c as usize].points.len() <= 2 {
            if let Some((parent, right)) = self.live[c as usize].inserted_from {
                let live = &mut self.live[parent as usize];
                let wait = live.s + COOLDOWN_STEPS * live.dt.to_f64();
                live.cooldown[usize::from(right)] = wait;
            }
        }
        let (l, r) = (self.live[c as usize].left, self.live[c as usize].right);
        self.live[c as usize].active = false;
        self.out.curves[c as usize].end = end;
        if l != c {
            self.live[l as usize].right = r;
            self.live[r as usize].left = l;
        }
    }

    /// One step of curve `c`; `Some(reason)` ends the curve.
    fn advance(&mut self, c: u32) -> Option<CurveEnd> {
        let ci = c as usize;
        let budget = &**self.params;
        if self.out.points.len() >= budget.max_points {
            self.out.hit_point_budget = true;
            return Some(CurveEnd::Budget);
        }
        if self.out.curves[ci].points.len() > budget.max_steps {
            return Some(CurveEnd::Budget);
        }
        let live = &self.live[ci];
        let step = match trace::step(self.field, &self.cfg, &live.p, &live.carry, &live.dt) {
            Ok(s) => s,
            // No chord balances how fast the field turns over even the shortest step: beside
            // a singular point of the surface (a cone's apex) that is the point's doing, as
            // at the step floor below; elsewhere a budget ended the curve.
            // (On a field not integrable at `p0` nothing tells, and a budget it is.)
            Err(trace::StepStop::NoChord) => {
                let p = live.p.to_f64();
                let singular = self.level_set
                    && LocalShape::at::<T, F>(self.field, p)
                        .is_some_and(|shape| self.singular_bend(p, shape.radius_of_curvature()));
                return Some(if singular {
                    CurveEnd::Singular
                } else {
                    CurveEnd::Budget
                });
            }
            Err(_) => return Some(CurveEnd::Singular),
        };
        let len = step.dt.to_f64();
        let q = step.point.to_f64();
        // A step clamped at the smallest length that still turns the normal by more than
        // twice the band's top may be at a singular point (a cone's apex): the field's
        // curvature grows without bound there, and the next step would jump across it. On a
        // surface known to have none, or at a bend no zero of the field on the surface
        // accounts for, it is a bend sharper than `dt_min` resolves (the rim of an ellipsoid
        // flatter than the fitted clamps, a sharply flared hyperboloid's waist, an elliptic
        // cone's sharp side): the step floor ended the curve, and the run says so.
        if step.limit == StepLimit::Clamped
            && len <= self.params.dt_min * (1.0 + 1e-9)
            && step.alpha_predicted > SINGULAR_TURN * self.params.beta_max.radians()
        {
            let singular = self.singular_bend(live.p.to_f64(), len / step.alpha_predicted);
            return Some(if singular {
                CurveEnd::Singular
            } else {
                CurveEnd::Budget
            });
        }
        let s_new = live.s + len;
        if s_new > self.params.max_radius {
            return Some(CurveEnd::Radius);
        }
        let bb = self.params.bounding_box;
        if q.iter().any(|x| x.abs() > bb) {
            return Some(CurveEnd::BoundingBox);
        }
        let theta = self.out.curves[ci].theta;
        let dir = live.chart_dir;
        let chart_q = [s_new * dir[0], s_new * dir[1]];
        let drift = live.drift + 0.5 * len * step.alpha_predicted;
        let normal = (!self.drift.is_empty()).then(|| step.normal.to_f64());
        if self.params.close
            && match normal {
                // Paper mode: curves drift off the surface, by different amounts.
                Some(_) => self.collides(q, chart_q, len, normal, drift),
                None => {
                    let beside = (self.params.method == Method::Previous).then_some(Beside {
                        curves: [live.left, live.right],
                        s: s_new,
                    });
                    self.crosses(live.p.to_f64(), q, chart_q, len, beside)
                }
            }
        {
            return Some(CurveEnd::Collision);
        }
        let proposed = self.params.method == Method::Proposed;
        let (left, right) = (live.left, live.right);
        let mut gaps = [(NO_CURVE, f64::INFINITY); 2];
        if proposed && self.params.merge > 0.0 {
            for (side, k) in [right, left].into_iter().enumerate() {
                if k == c {
                    continue;
                }
                let gap = self.lateral_gap(k, q).0;
                // Two curves of the fan at p0 do not merge while they move apart: they leave
                // p0 sin 60° ≈ 0.87 of a step from each other's lines, and a merge threshold
                // up to gap/2 would end all but one there. (Other curves merge as they did.)
                let (was, before) = self.live[ci].last_gap[side];
                let fan = self.live[ci].inserted_from.is_none()
                    && self.live[k as usize].inserted_from.is_none();
                let apart = fan && was == k && gap > before;
                if gap < self.params.merge * len && !apart {
                    return Some(CurveEnd::Merge);
                }
                gaps[side] = (k, gap);
            }
        }

        // Accept.
        let index = self.out.points.len() as u32;
        let step_index = self.out.curves[ci].points.len() as u32;
        self.out.points.push(step.point.clone());
        self.out.provenance.push(Provenance {
            curve: c,
            step: step_index,
            s: s_new,
            theta,
        });
        self.out.steps.push(StepRecord {
            dt: len,
            alpha_predicted: step.alpha_predicted,
            iterations: step.iterations,
            limit: step.limit,
        });
        self.out.curves[ci].points.push(index);
        self.pos.push(q);
        self.nrm.push(step.next_normal);
        self.chart.push(chart_q);
        self.grid.push(&self.pos);
        if !self.drift.is_empty() {
            self.drift.push(drift);
            self.max_drift = self.max_drift.max(drift);
        }
        let live = &mut self.live[ci];
        live.last_gap = gaps;
        live.drift = drift;
        live.p = step.point;
        live.carry = step.carry;
        live.dt = step.dt;
        live.s = s_new;

        if proposed {
            // With two curves left alive both sides face the same neighbour, but the gap is
            // on one side only (the narrower in θ): inserting on both would put two curves on
            // the same start point.
            let (l, r) = (self.live[ci].left, self.live[ci].right);
            let ring_of_two = l == r && l != c;
            let right_narrower = {
                let (tc, tk) = (theta, self.out.curves[r as usize].theta);
                (tk - tc).rem_euclid(std::f64::consts::TAU) <= std::f64::consts::PI
            };
            for side_right in [true, false] {
                if ring_of_two && side_right != right_narrower {
                    continue;
                }
                let live = &self.live[ci];
                let k = if side_right { live.right } else { live.left };
                if k == c
                    || self.out.curves.len() >= budget.max_curves
                    || live.s < live.cooldown[usize::from(side_right)]
                {
                    continue;
                }
                let (gap, target, s_target) = self.lateral_gap(k, q);
                // Apart by more than `gap` steps, or with normals turned apart by more than
                // `gap` times the band's top: where a curve runs along a flat direction its
                // steps are long, and only the normals tell that its neighbours diverge.
                let last_k = *self.out.curves[k as usize]
                    .points
                    .last()
                    .expect("curves start with one point");
                let turn = dot(self.nrm[index as usize], self.nrm[last_k as usize])
                    .clamp(-1.0, 1.0)
                    .acos();
                if gap > self.params.gap * len
                    || (gap > self.params.merge * len.min(self.params.dt_max) * 2.0
                        && turn > self.params.gap * self.params.beta_max.radians())
                {
                    self.insert_between(c, k, side_right, q, target, s_target, len);
                }
            }
        }
        None
    }

    /// The closure test: a point nearer than `COLLISION_RADIUS` steps whose chart position is
    /// much farther away than its distance in space, i.e. the surface came back on itself.
    ///
    /// In paper mode (`normal` given: the unit normal near `q`), explicit Euler has carried
    /// both curves off the surface, by different amounts on a surface that is not a sphere, so
    /// that curves meeting on the far side pass over each other: there the distance along
    /// the normal may also be as large as both curves' drift estimates together.
    fn collides(
        &self,
        q: [f64; 3],
        chart_q: [f64; 2],
        len: f64,
        normal: Option<[f64; 3]>,
        drift_q: f64,
    ) -> bool {
        let radius = COLLISION_RADIUS * len;
        // Points about as far off as this one (curves that meet have come a similar way),
        // within a few steps: a search out to the largest drift anywhere would visit most of
        // the mesh at every step.
        let reach = match normal {
            Some(_) => radius + (2.0 * drift_q).min(4.0 * len),
            None => radius,
        };
        let beyond_reach = squared_bound_beyond(reach);
        self.grid.any_near(q, reach, |j, pj| {
            let e = sub(q, pj);
            let d2 = dot(e, e);
            // Farther than `reach` (≥ `radius`): not near in either mode.
            if d2 > beyond_reach {
                return false;
            }
            let d = d2.sqrt();
            // Far in the chart first: most points this near are not.
            let cj = self.chart[j as usize];
            let dc = ((cj[0] - chart_q[0]).powi(2) + (cj[1] - chart_q[1]).powi(2)).sqrt();
            if dc <= 2.0 * d + len {
                return false;
            }
            match normal {
                None => d < radius,
                Some(n) => {
                    let along = dot(e, n);
                    let across = (d * d - along * along).max(0.0).sqrt();
                    // Only points within `reach`, so that the answer does not depend on
                    // how the grid happens to bucket the points beyond it.
                    d <= reach
                        && across < radius
                        && along.abs() < radius + drift_q + self.drift[j as usize]
                }
            }
        })
    }

    /// The fence: whether the step `p → q` comes onto the sheet that curves far away in the
    /// chart already swept — it ends within a thin disc about one of their points (in that
    /// point's tangent plane), or passes through such a disc. Fronts that meet head-on (a
    /// sphere's far side), side by side (an inserted curve beside the other side of a
    /// cylinder's seam) or at an angle (a non-integrable field's sheet turning back through
    /// itself) all stop there, before they overlap or cross what is laid.
    fn crosses(
        &self,
        p: [f64; 3],
        q: [f64; 3],
        chart_q: [f64; 2],
        len: f64,
        beside: Option<Beside>,
    ) -> bool {
        // Every point within the fence radius of the segment is within this of its middle.
        let e = sub(q, p);
        let half = 0.5 * dot(e, e).sqrt();
        let mid = [p[0] + 0.5 * e[0], p[1] + 0.5 * e[1], p[2] + 0.5 * e[2]];
        let radius = FENCE_RADIUS * len;
        let thickness = FENCE_THICKNESS * len;
        let reach = half + radius;
        let limit = half + reach;
        let beyond_limit = squared_bound_beyond(limit);
        self.grid.any_near(mid, reach, |j, xj| {
            let j = j as usize;
            let to_q = sub(q, xj);
            let dq2 = dot(to_q, to_q);
            // Most candidates lie beyond the limit: rejected without the square root.
            if dq2 > beyond_limit {
                return false;
            }
            let dq = dq2.sqrt();
            if dq > limit {
                return false;
            }
            // Far in the chart: not this curve's own recent points nor its neighbours' (most
            // of the points this near, so this test goes first).
            let cj = self.chart[j];
            let dc = ((cj[0] - chart_q[0]).powi(2) + (cj[1] - chart_q[1]).powi(2)).sqrt();
            if dc <= 2.0 * dq + 2.0 * len {
                return false;
            }
            let nj = self.nrm[j];
            let (sp, sq) = (dot(sub(p, xj), nj), dot(sub(q, xj), nj));
            let radius = match beside {
                Some(b) if b.beside(&self.out.provenance[j], len) => BESIDE_FENCE_RADIUS * len,
                _ => radius,
            };
            let onto = sq.abs() < thickness && dq < radius;
            let through = || {
                ((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0)) && {
                    let t = sp / (sp - sq);
                    let c = [p[0] + t * e[0], p[1] + t * e[1], p[2] + t * e[2]];
                    dist(c, xj) < radius
                }
            };
            onto || through()
        })
    }

    /// Distance from `q` to curve `k` across it: to the line of its last segment (so that a
    /// neighbour one step behind does not look farther away than it is), or to its only point.
    /// Also returns the foot point and its arc length.
    fn lateral_gap(&self, k: u32, q: [f64; 3]) -> (f64, [f64; 3], f64) {
        let pts = &self.out.curves[k as usize].points;
        let last = *pts.last().expect("curves start with one point") as usize;
        let x1 = self.pos[last];
        let s1 = self.out.provenance[last].s;
        if pts.len() < 2 {
            return (dist(q, x1), x1, s1);
        }
        let prev = pts[pts.len() - 2] as usize;
        let x0 = self.pos[prev];
        let t = sub(x1, x0);
        let tt = dot(t, t);
        if tt <= 0.0 {
            return (dist(q, x1), x1, s1);
        }
        let u = dot(sub(q, x1), t) / tt;
        let foot = [x1[0] + u * t[0], x1[1] + u * t[1], x1[2] + u * t[2]];
        let s_foot = s1 + u * tt.sqrt();
        (dist(q, foot), foot, s_foot)
    }

    /// The foot of `q` on the line of curve `k`'s last segment (or its only point), in the
    /// working precision.
    fn foot_on(&self, k: u32, q: &Vec3<T>) -> Vec3<T> {
        let pts = &self.out.curves[k as usize].points;
        let x1 = &self.out.points[*pts.last().expect("curves start with one point") as usize];
        if pts.len() < 2 {
            return x1.clone();
        }
        let x0 = &self.out.points[pts[pts.len() - 2] as usize];
        let t = x1 - x0;
        let tt = t.norm_squared();
        if tt.is_zero() {
            return x1.clone();
        }
        let u = (q - x1).dot(&t) / tt;
        x1.add_scaled(&u, &t)
    }

    /// Step 6: a new curve between `c` (which just stepped to `q`) and its neighbour `k`.
    #[allow(clippy::too_many_arguments)]
    fn insert_between(
        &mut self,
        c: u32,
        k: u32,
        k_is_right: bool,
        q: [f64; 3],
        target: [f64; 3],
        s_target: f64,
        len: f64,
    ) {
        use std::f64::consts::TAU;
        let (tc, tk) = (
            self.out.curves[c as usize].theta,
            self.out.curves[k as usize].theta,
        );
        // Angular distance going counter-clockwise from c to k (right) or from k to c (left).
        let span = if k_is_right {
            (tk - tc).rem_euclid(TAU)
        } else {
            (tc - tk).rem_euclid(TAU)
        };
        if span < 1e-9 || self.out.points.len() >= self.params.max_points {
            return;
        }
        let theta = if k_is_right {
            tc + span / 2.0
        } else {
            tc - span / 2.0
        }
        .rem_euclid(TAU);
        // In the working precision, so that dual numbers carry derivatives through insertion.
        let _ = (q, target);
        let live_c = &self.live[c as usize];
        let foot = self.foot_on(k, &live_c.p);
        let d = &foot - &live_c.p;
        let [last_c, last_k] = [c, k].map(|i| {
            *self.out.curves[i as usize]
                .points
                .last()
                .expect("curves start with one point") as usize
        });
        let turn = dot(self.nrm[last_k], self.nrm[last_c])
            .clamp(-1.0, 1.0)
            .acos();
        let step = self.out.steps[last_k].dt.max(len);
        let norm = d.norm();
        let gap = norm.to_f64();
        if turn > MAX_INSERT_TURN * self.params.gap * self.params.beta_max.radians()
            || gap > MAX_INSERT_SPAN * self.params.gap * step
        {
            return;
        }
        let s = 0.5 * (self.live[c as usize].s + s_target);
        // Two curves a gap apart in space but with almost the same θ: on a field that is not
        // integrable, the chart is singular there (a fold of the swept sheet), and a curve
        // between them would be as close to both in the chart. Bisecting on would not
        // separate them; it would only pile up curves (one twisted field laid a million
        // points at one θ so). (The field is probed only in that rare case.)
        if s * span < MIN_CHART_SPREAD * gap
            && LocalShape::at::<T, F>(self.field, live_c.p.to_f64())
                .is_none_or(|shape| !shape.is_integrable())
        {
            return;
        }
        let half = norm * T::from_f64(0.5);
        let start = match trace::step_fixed(self.field, &self.cfg, &live_c.p, &d, &half) {
            Ok(p) => p,
            Err(_) => return,
        };
        let start_f = start.to_f64();
        // The terminal conditions hold for inserted points as for stepped ones.
        let bb = self.params.bounding_box;
        if s > self.params.max_radius || start_f.iter().any(|x| x.abs() > bb) {
            return;
        }
        let chart_dir = [theta.cos(), theta.sin()];
        let chart = [s * chart_dir[0], s * chart_dir[1]];
        let drift = 0.5 * (self.live[c as usize].drift + self.live[k as usize].drift);
        let Ok((_, start_normal, _)) = trace::unit_normal(self.field, &start) else {
            return;
        };
        let start_normal = start_normal.to_f64();
        let normal = (!self.drift.is_empty()).then_some(start_normal);
        if self.params.close
            && match normal {
                Some(_) => self.collides(start_f, chart, len, normal, drift),
                // (Only the proposed method inserts curves.)
                None => self.crosses(start_f, start_f, chart, len, None),
            }
        {
            return;
        }
        let carry = (&self.live[c as usize].carry + &self.live[k as usize].carry)
            .normalize()
            .map(|(u, _)| u)
            .unwrap_or_else(|| self.live[c as usize].carry.clone());
        let id = self.out.curves.len() as u32;
        let index = self.out.points.len() as u32;
        self.out.points.push(start.clone());
        self.out.provenance.push(Provenance {
            curve: id,
            step: 0,
            s,
            theta,
        });
        self.out.steps.push(StepRecord::default());
        self.out.curves.push(Curve {
            theta,
            points: vec![index],
            parent: Some(c),
            end: CurveEnd::Budget,
        });
        self.pos.push(start_f);
        self.nrm.push(start_normal);
        self.chart.push(chart);
        self.grid.push(&self.pos);
        if !self.drift.is_empty() {
            self.drift.push(drift);
        }
        let (left, right) = if k_is_right { (c, k) } else { (k, c) };
        self.live.push(Live {
            p: start,
            carry,
            dt: self.live[c as usize].dt.clone(),
            s,
            left,
            right,
            active: true,
            drift,
            chart_dir,
            cooldown: [0.0; 2],
            inserted_from: Some((c, k_is_right)),
            last_gap: [(NO_CURVE, f64::INFINITY); 2],
        });
        self.live[left as usize].right = id;
        self.live[right as usize].left = id;
        self.heap.push(Reverse((self.order_key(s), id)));
    }
}
