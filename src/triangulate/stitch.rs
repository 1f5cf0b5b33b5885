//! Where fronts meet: the boundary of the chart triangulation stitched to itself.
//!
//! The curves leave `p0` as one front. Where the surface closes up behind them — a sphere's far
//! side, the back of a cylinder, the seams of a torus, the far side of a cone's apex — the
//! front runs into itself, and the sampler's fence stops the curves about one step short of
//! what the other side already laid. The chart triangulation is then a disc whose boundary
//! faces itself across gaps about one step wide. This stage closes those gaps the way an
//! advancing-front mesher closes its front (the "fence" family of DESIGN.md §2): it adds
//! triangles between a boundary edge and a boundary vertex in front of it, best first, each one
//! only if
//!
//! - it lies in the open wedge of all three of its corners (it covers nothing already covered),
//! - it faces the way the field does (its normal within [`FRONT_TILT_DEG`] of the corners'
//!   field normals on a seam of an integrable surface other than an ellipsoid,
//!   [`MAX_TILT_DEG`] elsewhere) and is not a sliver (smallest angle at least
//!   [`MIN_ANGLE_DEG`]),
//! - its new edges are no longer than [`REACH`] local edge lengths,
//! - it keeps every edge on at most two triangles, and
//! - it meets no existing triangle other than along the edges and corners it shares with them
//!   (an exact test).
//!
//! Before the front advances, each hole between fronts that met (no vertex of its loop ended a
//! curve on a terminal condition) of more than [`SMALL_HOLE`] edges, on an integrable field, is
//! offered to a chart of its own (below): refined with new points at the mesh's spacing around
//! it (a far cap), else the loop's constrained Delaunay triangulation alone (a slit where
//! converging curves ended side by side), each patch going in only if its triangles keep
//! [`MIN_ANGLE_DEG`] but at the loop's own corners (a refined patch may leave out the few,
//! at most one in [`THIN_SHARE`], that spade's refinement leaves thin in a notch of the loop:
//! the front closes their small holes). A loop that touches itself at a vertex is followed
//! round the hole past it. A sphere's far cap traced from a pole closes so, at a fraction of
//! the front's cost and with better shaped triangles; what no chart fits (bands, seams,
//! twisted holes) is left to the front. First, on such a field, islands go: components of at
//! most [`ISLAND`] chart triangles with no vertex on a terminal boundary, left between dropped
//! chart triangles where many curves converge, which would force slivers between them and the
//! rest.
//!
//! A new point of the front is placed where the triangle on its edge would be equilateral,
//! reached from the edge's first end by two half chords: where the potential is not cubic a
//! chord's truncation error is of the fifth order in its length.
//!
//! Candidates that glue edges — whose new edges are already boundary edges the other way round,
//! as when a gap is zipped shut or a hole's last triangle goes in — go first; among equals the
//! best-shaped. Each round runs twice over the front: first only triangles with no angle below
//! [`GOOD_ANGLE_DEG`] that leave, at each corner, either no wedge or one at least that wide
//! beside them (a sliver of a wedge would force a sliver of a triangle into it later), then
//! the rest down to [`MIN_ANGLE_DEG`] under the same rule. Where that leaves fronts that met
//! unstitched on an integrable field, the stitching is run again from the chart's mesh with
//! every triangle down to [`MIN_ANGLE_DEG`] competing from the start and no rule on the
//! leftover wedges, and the result with less open boundary is kept (`triangulate::stitch`).
//!
//! Topology follows from the samples: a disc whose whole boundary meets itself closes into a
//! sphere, one whose two opposite arcs meet becomes a band, one whose boundary meets in two
//! pairs of arcs becomes a torus; boundary that faces nothing (a geodesic radius, the bounding
//! box) stays boundary.
//!
//! Where the front leaves boundary open between fronts that met, the stitching is tried once
//! more from the chart's triangles with the samples the chart left without one offered as
//! *free* vertices: candidates like boundary vertices (a triangle on one has the whole wedge
//! there), obstacles to triangles that would pass over them, at their own sample spacing, with
//! near-duplicates of the mesh or of each other left out. The front then advances through the
//! samples where the chart's triangles were dropped over a long stretch (the far side of a
//! thin torus's ring), instead of growing its own points across it; the try with less open
//! boundary is kept (`triangulate::stitch`).
//!
//! A hole of one missing triangle that no ear closes (its corners on both sides of a bend
//! sharper than the triangles, such as a flattened ellipsoid's rim) takes that triangle if it
//! faces the same side as each corner's normal and meets nothing, however far it tilts.
//!
//! Where holes are left that no ear closes (triangles twisted around them), the triangles
//! around them are removed and the front runs again, over a few rounds that each open one ring
//! wider (only on an integrable field: without new points the removed triangles could not be
//! replaced, and a swept surface would only shrink). A round may leave more open than the one
//! before (a twist that re-forms farther out), so the best state is kept: better is no more
//! boundary loops and no more edges on holes between fronts that met, and fewer of one. When
//! the last round is worse than the best one, both go through the step below and the result
//! nearer closing (fewer loops, then fewer hole edges) is kept; that step itself is taken back
//! where it leaves a worse state than it found.
//!
//! Holes that the front leaves open between fronts that met (no vertex of theirs ended a curve
//! on a terminal condition) are, on an integrable field, filled through a chart of their own at
//! the end: the hole's loop is projected onto the plane across its mean field normal,
//! triangulated there by spade's constrained Delaunay refinement with the loop's edges kept
//! whole, and the new points are put on the surface by short chords. The patch goes in only if
//! it stays a graph over that plane, faces the field and meets nothing (exact test); a hole
//! whose patch does not fit is opened one ring of triangles wider and tried again.
//!
//! A triangle may touch a boundary vertex from outside its fan (a bridge across a gap); that
//! vertex is pinched until the gaps beside the bridge are closed too. Pinches that remain at the
//! end are cut apart by removing the fewer triangles of the vertex.

use super::proximity::{FaceGrid, PointGrid};
use crate::geom::intersect::{faces_intersect, triangle_meets_line};
use crate::geom::rows::{compressed_rows, rows_by_corner};
use crate::geom::union_find::UnionFind;
use crate::geom::vec3::{cross, dist, dot, sub, turn_about, FastHash};
use crate::mesh::{Mesh, Provenance};
use crate::par;
use crate::params::Mode;
use crate::scalar::{Scalar, Vec3};
use crate::trace::{self, StepConfig};
use crate::NormalField;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation as _};
use std::collections::{BinaryHeap, HashMap, HashSet};

/// Candidate vertices lie within this many local edge lengths of both ends of the edge.
pub(crate) const REACH: f64 = 2.2;
/// Boundary loops of at most this many edges left after stitching are closed if they can be.
pub(crate) const SMALL_HOLE: usize = 12;
/// The longest loop left after ear clipping that is filled by a fan around a new point.
const FAN_HOLE: usize = 6;
/// The longest loop left after ear clipping and fans that may be closed by triangles across
/// a bend sharper than they are ([`Stitcher::bent_triangulation`]).
const BENT_HOLE: usize = 8;
/// A triangle with an angle below this many degrees closing a small hole is a sliver whose
/// normal is not tested.
const SLIVER_DEG: f64 = 3.0;
/// Other boundary vertices must keep this many local edge lengths away from a stitched
/// triangle.
const CLEARANCE: f64 = 0.2;
/// Score of a new point's triangle: an existing vertex whose triangle scores more (a glued
/// edge, or a smallest angle above about 26°) is taken instead.
const NEW_POINT_SCORE: f64 = 0.45;
/// A new point, and the middle of its triangle, keep this many edge lengths away from the
/// triangles already there (other than those at the edge's ends).
const HOVER: f64 = 0.4;
/// The most drift a hop toward a new point of the front may have, relative to its length
/// ([`trace::chord_drift`]); a hop over it is split in two.
const HOP_DRIFT: f64 = 1e-4;

/// The most hops the way to a new point of the front is taken in.
const MAX_HOPS: u32 = 16;

/// A new point's field normal must be within 45° of its edge's.
const NEW_POINT_TURN_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// Other vertices of a loop keep this fraction of an ear's longest edge away from it.
const EAR_CLEARANCE: f64 = 0.02;
/// The proximity tests' budget: this many triangles and points visited per triangle and
/// boundary edge the chart gave, plus [`VISITS_FLOOR`] (the free vertices' filter in
/// [`Stitcher::new`] has the same budget). The gallery's surfaces use at most a twentieth of
/// it; on a surface whose triangles differ in size by orders of magnitude (a hyperboloid
/// with a 10:1 waist) each test can visit much of the mesh, and the run is then cut short
/// and says so, instead of running for minutes.
const VISITS_PER_TRIANGLE: u64 = 400;
/// The floor is what a mesh of tens of thousands of triangles may spend: a flared one-sheet
/// hyperboloid (`λ = (25.1, 31.7, −227.6)`, posed, 11,854 triangles) was cut short at
/// 11.5M visits with a floor of 2²³; without a budget it took 13.1M, in a run of 0.85 s.
const VISITS_FLOOR: u64 = 1 << 25;
/// Candidates examined per boundary edge: the nearest ones.
const MAX_CANDIDATES: usize = 24;
/// An edge's nearest points are searched for afresh, rather than updated with the points
/// filed since they were found, once more than this many were (a search visits about as
/// many).
const TOP_UP: usize = 48;
/// Smallest angle of a stitched triangle, degrees.
pub(crate) const MIN_ANGLE_DEG: f64 = 12.0;
/// Smallest angle of a stitched triangle in each round's first pass, degrees: the
/// triangles that make no angle below it go in first, and only what they leave is stitched
/// down to [`MIN_ANGLE_DEG`] (a seam of 12°–20° triangles, relaxed, kept angles below 15°).
pub(crate) const GOOD_ANGLE_DEG: f64 = 20.0;
/// Largest angle between a stitched triangle's normal and its corners' mean field normal,
/// degrees.
pub(crate) const MAX_TILT_DEG: f64 = 60.0;
/// [`MAX_TILT_DEG`] for the front's triangles on a field integrable at `p0`, degrees. A
/// triangle across a bend tilts from its corners' normals by about half the bend: at 60°,
/// the front glued corners a fifth of a thin tube's girth apart where fronts met along a
/// seam (a cylinder's face 48° off the surface, a torus's 86°). Ellipsoids, whose fronts
/// meet round a cap, triangles on the end of a curve stopped at a singular point, chart
/// patches and the last small holes keep the wider limit: a far tip can bend more sharply
/// than the triangles there (`[1, 20, 400]` from `(1, 0, 0)`), a cone's apex turns the
/// normals faster than any triangle can follow, and patches held to 30° left a tanglecube's
/// neck open.
const FRONT_TILT_DEG: f64 = 30.0;

/// What stitching where fronts met did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Stitched {
    /// Triangles added.
    pub added: usize,
    /// Vertices added (on the surface, where a gap or hole had none to connect).
    pub vertices: usize,
    /// Triangles removed: around holes that were opened and stitched again, and to cut
    /// pinched vertices apart.
    pub removed: usize,
    /// Whether the operation budget ran out before no candidate was left, leaving boundary
    /// between fronts that met unstitched. (A round cut short whose holes the charts of the
    /// last step then filled leaves none: the mesh is as stitched as without the budget.)
    pub budget_hit: bool,
    /// Boundary loops of the returned mesh with no vertex where a curve ended on a terminal
    /// condition, at a singular point or on a budget, nor within the shorter of its longest
    /// boundary edge and the longest step of the bounding box or the geodesic radius (loops
    /// touching at a vertex count as one): holes where the surface goes on and the mesh does
    /// not. On a surface integrable at `p0`, fronts that met and were not stitched; on a swept
    /// surface, also where it was cut back (its folds, or the sheet about to cross itself).
    /// Round a hole the field knows ([`NormalField::hole_through`]), also each loop that does
    /// not go round it and has a vertex off that rim: a band that did not close round its
    /// waist.
    #[cfg_attr(feature = "serde", serde(default))]
    pub holes: usize,
}

type EdgeMap<V> = HashMap<(u32, u32), V, FastHash>;

/// The directed edges of the triangles, as a set.
///
/// The chart's edges are filed once in compressed rows by source (no hashing), a removed one
/// overwritten by [`GONE`]; edges added later are kept in lists by source.
struct EdgeSet {
    /// The targets of the chart's edges from `u` are `targets[start[u]..start[u + 1]]`.
    start: Vec<u32>,
    targets: Vec<u32>,
    /// The targets of the other edges, by source (empty beyond its length).
    added: Vec<Vec<u32>>,
}

/// A chart edge's target once the edge is removed (no vertex has this id).
const GONE: u32 = u32::MAX;

impl EdgeSet {
    /// The edges of `tris`, whose corners are below `vertices`.
    fn new(vertices: usize, tris: &[[u32; 3]]) -> Self {
        let (start, targets) = rows_by_corner(tris, vertices, |t, k| tris[t][(k + 1) % 3])
            .expect("the triangles' corners are vertices of the mesh");
        EdgeSet {
            start,
            targets,
            added: Vec::new(),
        }
    }

    /// The chart's edges from `u`, by target.
    fn chart_row(&self, u: u32) -> &[u32] {
        let u = u as usize;
        match (self.start.get(u), self.start.get(u + 1)) {
            (Some(&s), Some(&e)) => &self.targets[s as usize..e as usize],
            _ => &[],
        }
    }

    fn contains(&self, u: u32, v: u32) -> bool {
        self.chart_row(u).contains(&v) || self.added.get(u as usize).is_some_and(|l| l.contains(&v))
    }

    fn insert(&mut self, u: u32, v: u32) {
        if self.contains(u, v) {
            return;
        }
        let u = u as usize;
        if u >= self.added.len() {
            self.added.resize(u + 1, Vec::new());
        }
        self.added[u].push(v);
    }

    /// The targets of the edges from `u`.
    fn from(&self, u: u32) -> impl Iterator<Item = u32> + '_ {
        let added = self.added.get(u as usize).map_or(&[][..], |l| &l[..]);
        self.chart_row(u)
            .iter()
            .chain(added)
            .copied()
            .filter(|&t| t != GONE)
    }

    /// Whether some edge leaves `u` (whether `u` is on a triangle).
    fn any_from(&self, u: u32) -> bool {
        self.chart_row(u).iter().any(|&t| t != GONE)
            || self.added.get(u as usize).is_some_and(|l| !l.is_empty())
    }

    fn remove(&mut self, u: u32, v: u32) {
        let u = u as usize;
        if let (Some(&s), Some(&e)) = (self.start.get(u), self.start.get(u + 1)) {
            // (Every copy, should the chart list an edge twice.)
            for t in &mut self.targets[s as usize..e as usize] {
                if *t == v {
                    *t = GONE;
                }
            }
        }
        if let Some(l) = self.added.get_mut(u) {
            l.retain(|&w| w != v);
        }
    }
}

/// The boundary edges at each vertex and the vertices' local scales, kept for the vertices
/// that have been on the boundary (a few thousand of a mesh's vertices): a slot per vertex
/// and a record per boundary vertex.
struct Boundary {
    /// Each vertex's index in `records`, or [`NO_RECORD`].
    slot: Vec<u32>,
    records: Vec<BoundaryVertex>,
}

/// The slot of a vertex without a record (out of bounds of any `records`).
const NO_RECORD: u32 = u32::MAX;

struct BoundaryVertex {
    vertex: u32,
    /// The targets of the boundary edges from the vertex.
    outs: Vec<u32>,
    /// The sources of the boundary edges into the vertex.
    ins: Vec<u32>,
    /// Mean length of the edges at the vertex (at the start, or when added); `None` until
    /// set.
    scale: Option<f64>,
}

impl Boundary {
    /// No boundary edges on `vertices` vertices.
    fn new(vertices: usize) -> Self {
        Boundary {
            slot: vec![NO_RECORD; vertices],
            records: Vec::new(),
        }
    }

    fn record(&self, v: u32) -> Option<&BoundaryVertex> {
        self.records.get(self.slot[v as usize] as usize)
    }

    fn record_mut(&mut self, v: u32) -> &mut BoundaryVertex {
        let slot = &mut self.slot[v as usize];
        if *slot == NO_RECORD {
            *slot = self.records.len() as u32;
            self.records.push(BoundaryVertex {
                vertex: v,
                outs: Vec::new(),
                ins: Vec::new(),
                scale: None,
            });
        }
        &mut self.records[*slot as usize]
    }

    /// The targets of the boundary edges from `v`.
    fn outs(&self, v: u32) -> &[u32] {
        self.record(v).map_or(&[], |r| &r.outs)
    }

    /// The sources of the boundary edges into `v`.
    fn ins(&self, v: u32) -> &[u32] {
        self.record(v).map_or(&[], |r| &r.ins)
    }

    fn scale(&self, v: u32) -> Option<f64> {
        self.record(v).and_then(|r| r.scale)
    }

    fn set_scale(&mut self, v: u32, h: f64) {
        self.record_mut(v).scale = Some(h);
    }

    /// Sets each boundary vertex's scale to the mean length of the edges at it, those of
    /// triangles `tris` of points `pos`.
    fn set_mean_scales(&mut self, pos: &[[f64; 3]], tris: &[[u32; 3]]) {
        let mut sums = vec![(0.0, 0u32); self.records.len()];
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                if self.slot[a] == NO_RECORD && self.slot[b] == NO_RECORD {
                    continue;
                }
                let l = dist(pos[a], pos[b]);
                for v in [a, b] {
                    if let Some(e) = sums.get_mut(self.slot[v] as usize) {
                        e.0 += l;
                        e.1 += 1;
                    }
                }
            }
        }
        for (r, (sum, n)) in self.records.iter_mut().zip(sums) {
            r.scale = Some(if n > 0 { sum / n as f64 } else { 0.0 });
        }
    }

    /// Adds the boundary edge `a → b`.
    fn insert(&mut self, a: u32, b: u32) {
        self.record_mut(a).outs.push(b);
        self.record_mut(b).ins.push(a);
    }

    /// Removes the boundary edge `a → b` (its first copy); whether it was there.
    fn remove(&mut self, a: u32, b: u32) -> bool {
        let Some(ra) = self.records.get_mut(self.slot[a as usize] as usize) else {
            return false;
        };
        if !remove(&mut ra.outs, b) {
            return false;
        }
        // (`ins` mirrors `outs`: every change to one is made to the other.)
        let rb = &mut self.records[self.slot[b as usize] as usize];
        remove(&mut rb.ins, a);
        true
    }

    /// The boundary edges, in no particular order.
    fn edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.records
            .iter()
            .flat_map(|r| r.outs.iter().map(move |&b| (r.vertex, b)))
    }

    /// How many boundary edges there are.
    fn edge_count(&self) -> usize {
        self.records.iter().map(|r| r.outs.len()).sum()
    }

    /// Makes room for a new vertex (with no record).
    fn push_vertex(&mut self) {
        self.slot.push(NO_RECORD);
    }

    /// Takes the last vertex back (a vertex on trial, which has no record).
    fn pop_vertex(&mut self) {
        self.slot.pop();
    }
}

/// Where a vertex stands with respect to the surface's own boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Rim {
    /// Not at the end of a curve that ended on a boundary.
    Open,
    /// The end of a curve that reached the geodesic radius or the bounding box: the surface
    /// ends near it, but new points within the terminal conditions may still go beside it.
    Terminal,
    /// The end of a curve at a singular point or on a budget: no new point goes beside it.
    Barren,
}

/// A removed triangle, until the end of the stitching.
const DEAD: [u32; 3] = [u32::MAX; 3];

/// Holes left between fronts that met, of at most this many edges, are filled through a chart
/// of their own (see [`Stitcher::fill_by_chart`]). A sphere's far cap traced from its pole
/// has 704 edges at 10⁵ triangles (ragged: curves converging on the far pole end at scattered
/// distances from it) and about 1,300 at 7·10⁵.
const CHART_HOLE: usize = 4096;
/// A hole filled through its own chart: every corner's field normal, and every new point's,
/// within this many degrees of the hole's mean normal (the surface there is a graph over the
/// chart's plane).
const CHART_TURN_DEG: f64 = 70.0;
/// Components of at most this many triangles with no vertex on a terminal boundary are
/// dropped before stitching (see [`Stitcher::drop_islands`]).
const ISLAND: usize = 8;
/// How a hole's chart is triangulated (see [`Stitcher::fill_by_chart`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Patch {
    /// Refined by spade to [`CHART_ANGLE_DEG`], with new points inside the hole.
    Refined,
    /// The loop's constrained Delaunay triangulation alone, no new point: a slit between two
    /// fronts that ended side by side is zipped so, where refinement would crowd points into
    /// it.
    Plain,
}

/// Times a hole that its chart could not fill is opened one ring wider and tried again.
const CHART_ATTEMPTS: usize = 4;
/// Most chords a new point of a hole's chart is reached by (each at most the loop's mean
/// edge length).
const CHART_HOPS: usize = 64;
/// A refined hole's chart may leave out at most one in this many of its triangles, those
/// below the front's smallest angle (see [`Stitcher::fill_by_chart`]).
const THIN_SHARE: usize = 64;
/// A new point of a hole's chart is over its chart position to within this many hops
/// (see [`Stitcher::lift`]).
const LIFT_TOLERANCE: f64 = 1e-3;
/// A hole's chart positions are multiples of this many of its mean edge length (2⁻²⁴).
const CHART_SNAP: f64 = 1.0 / (1u32 << 24) as f64;
/// Smallest angle spade's refinement aims for inside a hole's chart, degrees.
const CHART_ANGLE_DEG: f64 = 25.0;

/// Times the stitching opens holes that stayed open and runs again.
const REDO_ROUNDS: usize = 5;
/// Holes of at most this many edges are opened and stitched again.
const REDO_HOLE: usize = 48;

/// Above any angle as computed (`atan2` of a non-negative `y` is at most π): bounds the part
/// of a score after its glue.
const MAX_MIN_ANGLE: f64 = 3.5;

/// A triangle's smallest angle as its score counts it: rounded to a multiple of 2⁻³² rad, so
/// that triangles whose angles differ only by rounding (symmetric ones, such as the far cap
/// of a sphere traced from its pole, where four curve ends lie on one circle) tie, and the
/// tie goes by vertex ids. The choice is then the same in every working precision (`f64`
/// and `Mpfr<256>` samples differ in their last bits), not the rounding's.
fn quantized(angle: f64) -> f64 {
    const QUANTUM: f64 = 1.0 / (1u64 << 32) as f64;
    (angle / QUANTUM).round() * QUANTUM
}

/// The candidate vertex of an edge that is not there yet: the edge's new point.
const NEW: u32 = u32::MAX;

/// A candidate: triangle `(b, a, x)` on the boundary edge `a → b` (`x` may be [`NEW`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    score: f64,
    a: u32,
    b: u32,
    x: u32,
    version: u32,
}

impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        // Best score first; ties by the smallest vertex ids, so the order is deterministic.
        self.score
            .total_cmp(&other.score)
            .then_with(|| (other.a, other.b, other.x).cmp(&(self.a, self.b, self.x)))
    }
}

/// What the stitching may do beyond connecting existing vertices.
pub(crate) struct Growth<'f, T, F> {
    /// The field, to place new points on the surface.
    pub(crate) field: &'f F,
    /// The step rule new points are placed with (a chord from an edge's end).
    pub(crate) cfg: StepConfig<T>,
    /// New points must stay in the box `|x| ≤ bounding_box`…
    pub(crate) bounding_box: f64,
    /// …and within this geodesic radius (estimated from the edge's ends).
    pub(crate) max_radius: f64,
    /// Most vertices the mesh may have.
    pub(crate) max_vertices: usize,
    /// Whether new points may be placed at all (only where the field is integrable: on a
    /// non-integrable field there is no surface between the fronts to place them on).
    pub(crate) new_points: bool,
    /// Whether each round first stitches only well-shaped triangles ([`GOOD_ANGLE_DEG`]) and
    /// keeps every corner's leftover wedge at least the floor wide; without it, every
    /// triangle down to [`MIN_ANGLE_DEG`] competes from the start (the fallback where the
    /// well-shaped seam leaves fronts unstitched).
    pub(crate) well_shaped: bool,
    /// Whether the surface is known to be an ovaloid (closed and convex: an ellipsoid,
    /// [`NormalField::semi_axes_through`]), on which every hole left between fronts bounds a
    /// disc, so that a small one may be closed across a bend sharper than its triangles
    /// ([`Stitcher::bent_triangulation`]). Elsewhere a small loop can ring a whole missing
    /// handle (a tanglecube's), which a disc across it would close off.
    pub(crate) ovaloid: bool,
    /// A line through a hole of the surface that no triangle may meet
    /// ([`NormalField::hole_through`]): the stitching never closes a band off across its
    /// waist.
    pub(crate) axis: Option<[[f64; 3]; 2]>,
}

/// Stitches the boundary of `mesh` (triangles counter-clockwise about the field normals) to
/// itself where it faces itself, adding vertices on the surface where a gap has none to
/// connect; see the module docs. `work` holds the vertices in the working precision and
/// grows with them; `rim[v]` says whether vertex `v` ended a curve on a terminal condition or
/// where the surface cannot be continued
/// (a geodesic radius, the bounding box, a singular point, a budget): no new point is placed
/// beyond those. `free` lists the vertices on no triangle offered as free vertices, with their
/// sample spacing (see the module docs).
///
/// Returns what it did, and how many boundary edges are left with neither end on such a rim:
/// boundary between fronts that met and were not stitched.
pub(crate) fn stitch<T: Scalar, F: NormalField<T>>(
    mesh: &mut Mesh,
    work: &mut Vec<Vec3<T>>,
    rim: &[Rim],
    free: &[(u32, f64)],
    growth: &Growth<'_, T, F>,
) -> (Stitched, usize) {
    let mut s = Stitcher::new(mesh, work, rim, free, growth);
    let mut out = Stitched::default();
    let visit_budget =
        VISITS_PER_TRIANGLE * (s.tris.len() + s.boundary_edges()) as u64 + VISITS_FLOOR;
    // The vertices whose boundary edges the next round looks at (all, at first; around the
    // holes that were opened, later).
    let mut opened: Option<HashSet<u32, FastHash>> = None;
    let mut best: Option<Snapshot<T>> = None;
    // Holes between fronts that met which a chart of their own fills (a sphere's far cap, a
    // slit where converging curves ended side by side) are filled first: the advancing front
    // is left only what no chart fits. The patches are held to the front's smallest angle;
    // small holes are the front's own (its scored triangles close them as cheaply).
    if s.growth.new_points {
        // Islands of chart triangles in a hole are dropped first: the front (or the chart)
        // fills round nothing there rather than squeezing slivers between them and the rest.
        out.removed += s.drop_islands(ISLAND);
        let floor = MIN_ANGLE_DEG.to_radians();
        for ring in s.open_loops(CHART_HOLE) {
            if ring.len() <= SMALL_HOLE {
                continue;
            }
            // (Left unrefined, or refined at its loop's edge length, which is twice the mesh's
            // where curve ends lie far apart, fig3's far cap came out coarse: its largest
            // face-normal error 3.3° against 2.5°.)
            let filled = s
                .fill_by_chart(&ring, Patch::Refined, floor)
                .or_else(|| s.fill_by_chart(&ring, Patch::Plain, floor));
            if let Some((triangles, vertices)) = filled {
                out.added += triangles;
                out.vertices += vertices;
            }
        }
    }
    for round in 0..=REDO_ROUNDS {
        // (Each free vertex takes about two triangles to take in.)
        let budget = 8 * (s.boundary_edges() + 2 * s.free_left()) + 64;
        let mut steps = 0;
        // Two passes: the well-shaped triangles first, then what they leave down to the
        // smallest angle allowed.
        let floors: &[f64] = if s.growth.well_shaped {
            &[GOOD_ANGLE_DEG, MIN_ANGLE_DEG]
        } else {
            &[MIN_ANGLE_DEG]
        };
        for &floor in floors {
            s.set_floor(floor);
            let edges: Vec<(u32, u32)> = match &opened {
                None => s.boundary_edge_list(),
                Some(near) => {
                    for (&(a, b), memo) in &mut s.memos {
                        if near.contains(&a) || near.contains(&b) {
                            memo.rejected.clear();
                        }
                    }
                    s.boundary_edge_list()
                        .into_iter()
                        .filter(|(a, b)| near.contains(a) || near.contains(b))
                        .collect()
                }
            };
            for (a, b) in edges {
                s.refresh(a, b);
            }
            s.advance_front(&mut out, &mut steps, budget, visit_budget);
            if out.budget_hit {
                break;
            }
        }
        let last = round == REDO_ROUNDS;
        out.added += s.fill_holes(if last { REDO_HOLE } else { SMALL_HOLE });
        // Holes left between fronts that met (no vertex on a terminal boundary) are often
        // twisted: the triangles around them overlap it. Those triangles go, and the
        // stitching runs again on the larger hole.
        // Without new points (a non-integrable field) an opened hole can only be refilled
        // from the vertices around it: opening ring after ring would take away swept surface
        // it can never give back (one random field lost half its triangles so).
        if round == REDO_ROUNDS || out.budget_hit || !s.growth.new_points {
            break;
        }
        let mut stuck = s.stuck_loops();
        // Vertices still pinched by a bridge whose gaps did not close: opened too.
        let touched = s.touched();
        let pinched = pinched_fans(&s.tris, |v| {
            touched.get(v as usize).copied().unwrap_or(false)
        })
        .0;
        if !pinched.is_empty() {
            stuck.push(pinched);
        }
        if stuck.is_empty() {
            break;
        }
        // Opening may leave more than it closes (a twist that re-forms a ring farther out):
        // the best state so far is kept to fall back on.
        let open_now = s.open_boundary();
        if best.as_ref().is_none_or(|b| open_now.better_than(&b.open)) {
            best = Some(s.snapshot(&out));
        }
        let (removed, near) = s.open_around(&stuck, round + 1);
        out.removed += removed.len();
        opened = Some(near);
    }
    // Holes that are still open between fronts that met are filled through charts of their
    // own. If the last rounds left a worse state than the best one, both go through the
    // charts and the result nearer closing is kept: the charts may merge the last state's
    // larger holes into the surface's boundary (a cone's apex), or close the best state's
    // small ones.
    match best.filter(|b| b.open.better_than(&s.open_boundary())) {
        None => (s, out) = s.charts_or_keep(out, mesh, free),
        Some(best) => {
            let last = s.snapshot(&out);
            (s, out) = s.restore(best, mesh, free);
            (s, out) = s.charts_or_keep(out, mesh, free);
            let from_best = s.snapshot(&out);
            (s, out) = s.restore(last, mesh, free);
            (s, out) = s.charts_or_keep(out, mesh, free);
            if from_best.open.closer_than(&s.open_boundary()) {
                (s, out) = s.restore(from_best, mesh, free);
            }
        }
    }
    // Pinches left after the last round are cut apart (only stitched triangles' vertices can
    // be pinched).
    let touched = s.touched();
    let (_, cut) = pinched_fans(&s.tris, |v| {
        touched.get(v as usize).copied().unwrap_or(false)
    });
    for &f in &cut {
        s.remove_triangle(f);
    }
    out.removed += cut.len();
    let open = s
        .boundary
        .edges()
        .filter(|&(a, b)| s.rim[a as usize] == Rim::Open && s.rim[b as usize] == Rim::Open)
        .count();
    // A round cut short whose leftovers the charts then filled left nothing undone.
    if open == 0 {
        out.budget_hit = false;
    }
    let Stitcher {
        pos,
        nrm,
        prov,
        mut tris,
        ..
    } = s;
    tris.retain(|t| *t != DEAD);
    mesh.vertices = pos;
    mesh.normals = nrm;
    mesh.provenance = prov;
    mesh.triangles = tris;
    (out, open)
}

/// What is left open (see [`Stitcher::open_boundary`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct OpenBoundary {
    /// Boundary components: the surface's own boundary and every hole.
    loops: usize,
    /// Edges on holes between fronts that met.
    hole_edges: usize,
}

impl OpenBoundary {
    /// Whether this is nearer closing than `other` on both counts and strictly on one: a
    /// state with fewer but larger holes, or more but smaller ones, is not.
    fn better_than(&self, other: &OpenBoundary) -> bool {
        (self.loops, self.hole_edges) != (other.loops, other.hole_edges)
            && self.loops <= other.loops
            && self.hole_edges <= other.hole_edges
    }

    /// Whether this has fewer boundary loops than `other`, or as many and fewer hole edges.
    fn closer_than(&self, other: &OpenBoundary) -> bool {
        (self.loops, self.hole_edges) < (other.loops, other.hole_edges)
    }
}

/// The stitching's triangles and vertices at one moment, to fall back on (see
/// [`Stitcher::restore`]).
struct Snapshot<T> {
    /// The triangles ([`DEAD`] where removed).
    tris: Vec<[u32; 3]>,
    pos: Vec<[f64; 3]>,
    nrm: Vec<[f64; 3]>,
    prov: Vec<Provenance>,
    work: Vec<Vec3<T>>,
    /// Which vertices are on the surface's rim (the front's new points at the box or the
    /// radius among them).
    rim: Vec<Rim>,
    /// Its [`Stitcher::open_boundary`].
    open: OpenBoundary,
    /// What the stitching had done until then.
    out: Stitched,
}

/// A candidate's remembered score (see [`Stitcher::refresh_score`]).
#[derive(Clone, Copy)]
struct RememberedScore {
    /// The epochs of `a`, `b`, `x` the score was computed for.
    epochs: [u32; 3],
    /// The bits of the reach the score and the shape were computed for.
    reach: u64,
    /// The bits of the angle floor the score was computed for (the shape does not depend
    /// on it).
    floor: u64,
    score: Option<f64>,
    /// The triangle's [`Stitcher::shape`].
    shape: Option<[f64; 3]>,
}

/// What [`Stitcher::refresh`] keeps of an edge from one call to the next.
#[derive(Default)]
struct EdgeMemo {
    /// How many times the edge was refreshed: a queued candidate is current only while it
    /// carries the latest count.
    version: u32,
    /// The candidates (vertices, or [`NEW`]) the edge's triangle failed with.
    rejected: Vec<u32>,
    /// The nearest points within reach of the edge (see [`Stitcher::update_nearest`]), and
    /// the number of points in the grid and the bits of the reach they were found for.
    nearest: Vec<(f64, u32)>,
    nearest_for: Option<(usize, u64)>,
    /// Scores by candidate, sorted (see [`Stitcher::refresh_score`]).
    scores: Vec<(u32, RememberedScore)>,
}

/// A new point proposed for an edge, before it is committed.
#[derive(Clone)]
struct Proposal<T> {
    point: Vec3<T>,
    pos: [f64; 3],
    normal: [f64; 3],
    s: f64,
    theta: f64,
}

struct Stitcher<'a, 'f, T, F> {
    pos: Vec<[f64; 3]>,
    nrm: Vec<[f64; 3]>,
    prov: Vec<Provenance>,
    work: &'a mut Vec<Vec3<T>>,
    /// Vertices on a boundary the surface does not close across.
    rim: Vec<Rim>,
    growth: &'a Growth<'f, T, F>,
    tris: Vec<[u32; 3]>,
    /// How many triangles the chart gave (the rest are the stitching's).
    initial: usize,
    /// The triangles' directed edges.
    edges: EdgeSet,
    /// The boundary edges and the local scales.
    boundary: Boundary,
    /// Boundary vertices, for candidate searches.
    points: PointGrid,
    /// Triangles near the boundary, for the intersection tests.
    faces: FaceGrid,
    /// Each edge's new point, once proposed (`None`: there is none).
    proposals: EdgeMap<Option<Proposal<T>>>,
    /// What [`Self::refresh`] keeps of each edge it looked at.
    memos: EdgeMap<EdgeMemo>,
    heap: BinaryHeap<Candidate>,
    /// Whether [`Self::open_wedge_leftovers`] remembers its angles in `wedge_angles` (only while no
    /// vertex is on trial: during a [`Self::refresh`], and in [`Self::acceptable`] for an
    /// existing vertex).
    wedge_memo: std::cell::Cell<bool>,
    /// The angle of vertex `w` about vertex `v` in `v`'s tangent frame, by `(v, w)`.
    wedge_angles: std::cell::RefCell<HashMap<(u32, u32), f64, FastHash>>,
    /// A count per vertex of the changes to the edges and boundary edges at it (see
    /// [`Self::touch`]).
    epoch: Vec<u32>,
    /// Which vertices are free samples (see [`Self::is_free`]).
    free: Vec<bool>,
    /// Triangles and points the proximity tests visited (see [`VISITS_PER_STEP`]).
    visits: std::cell::Cell<u64>,
    /// The smallest angle a stitched triangle may have now, degrees: [`GOOD_ANGLE_DEG`] in
    /// a round's first pass, [`MIN_ANGLE_DEG`] in its second.
    floor: f64,
}

impl<'a, 'f, T: Scalar, F: NormalField<T>> Stitcher<'a, 'f, T, F> {
    fn new(
        mesh: &mut Mesh,
        work: &'a mut Vec<Vec3<T>>,
        rim: &[Rim],
        free: &[(u32, f64)],
        growth: &'a Growth<'f, T, F>,
    ) -> Self {
        let tris = std::mem::take(&mut mesh.triangles);
        let pos = std::mem::take(&mut mesh.vertices);
        let nrm = std::mem::take(&mut mesh.normals);
        let prov = std::mem::take(&mut mesh.provenance);
        let n = pos.len();
        let edges = EdgeSet::new(n, &tris);
        let mut boundary = Boundary::new(n);
        // Which sides of each triangle are on the boundary (bit `k`: the side from corner `k`),
        // found side by side; the few boundary edges are then filed in triangle order.
        let open_sides = par::map(tris.len(), par::MIN_CHEAP, |i| {
            let t = tris[i];
            (0..3).fold(0u8, |m, k| {
                m | u8::from(!edges.contains(t[(k + 1) % 3], t[k])) << k
            })
        });
        for (t, &m) in tris.iter().zip(&open_sides).filter(|(_, &m)| m != 0) {
            for k in (0..3).filter(|k| m >> k & 1 == 1) {
                boundary.insert(t[k], t[(k + 1) % 3]);
            }
        }
        // Local scale: the mean length of the edges at each boundary vertex.
        boundary.set_mean_scales(&pos, &tris);
        let mut lengths: Vec<f64> = boundary
            .records
            .iter()
            .filter_map(|r| r.scale)
            .filter(|l| *l > 0.0)
            .collect();
        lengths.sort_by(f64::total_cmp);
        let cell = lengths
            .get(lengths.len() / 2)
            .copied()
            .unwrap_or(1.0)
            .max(1e-300)
            * REACH;
        let mut points = PointGrid::new(cell);
        for v in (0..n as u32).filter(|&v| boundary.scale(v).is_some()) {
            points.insert(v, pos[v as usize]);
        }
        let faces = FaceGrid::new(cell, &pos, &tris);
        // Samples on no triangle are candidates like boundary vertices, at their own spacing,
        // unless one lies right next to the mesh or to another one kept (a near-duplicate
        // would only make slivers): where fronts met and the chart's triangles were dropped,
        // the front then advances through the samples instead of placing points of its own.
        let mut is_free = vec![false; n];
        // (Taking free vertices in is optional: where the tests would visit more than the
        // budget allows, the rest are left out.)
        let mut visits = 0u64;
        let free_budget = VISITS_PER_TRIANGLE * tris.len() as u64 + VISITS_FLOOR;
        for &(v, h) in free {
            if visits > free_budget {
                break;
            }
            let p = pos[v as usize];
            let r = HOVER * h;
            let mut near = false;
            faces.near(&[p.map(|x| x - r), p.map(|x| x + r), p], |f| {
                visits += 1;
                near = near || point_triangle_distance(p, corners(&pos, tris[f as usize])) < r;
            });
            points.near(p, r, |w| {
                visits += 1;
                near = near || is_free[w as usize] && dist(pos[w as usize], p) < r;
            });
            if !near && h > 0.0 {
                boundary.set_scale(v, h);
                points.insert(v, p);
                is_free[v as usize] = true;
            }
        }
        let mut rim = rim.to_vec();
        rim.resize(pos.len(), Rim::Open);
        Stitcher {
            pos,
            nrm,
            prov,
            work,
            rim,
            growth,
            initial: tris.len(),
            tris,
            edges,
            boundary,
            points,
            faces,
            proposals: HashMap::default(),
            memos: HashMap::default(),
            heap: BinaryHeap::new(),
            wedge_memo: std::cell::Cell::new(false),
            visits: std::cell::Cell::new(0),
            floor: MIN_ANGLE_DEG,
            wedge_angles: std::cell::RefCell::new(HashMap::default()),
            epoch: Vec::new(),
            free: is_free,
        }
    }

    /// The boundary's components (edges linked by their vertices), and how many edges are
    /// on holes between fronts that met and were not stitched: components whose every vertex
    /// is [`Rim::Open`]. A hole opened until it reaches the surface's own boundary (a cone's
    /// apex) is part of that boundary, no longer a hole.
    fn open_boundary(&self) -> OpenBoundary {
        let edges: Vec<(u32, u32)> = self.boundary.edges().collect();
        let mut sets = UnionFind::new(self.pos.len());
        for &(a, b) in &edges {
            sets.union(a, b);
        }
        let mut components: HashSet<u32, FastHash> = HashSet::default();
        let mut rimmed: HashSet<u32, FastHash> = HashSet::default();
        for &(a, _) in &edges {
            let r = sets.find(a);
            components.insert(r);
            if self.rim[a as usize] != Rim::Open {
                rimmed.insert(r);
            }
        }
        OpenBoundary {
            loops: components.len(),
            hole_edges: edges
                .iter()
                .filter(|&&(a, _)| !rimmed.contains(&sets.find(a)))
                .count(),
        }
    }

    /// The state to fall back on, with `out` so far.
    fn snapshot(&self, out: &Stitched) -> Snapshot<T> {
        Snapshot {
            tris: self.tris.clone(),
            pos: self.pos.clone(),
            nrm: self.nrm.clone(),
            prov: self.prov.clone(),
            work: self.work.clone(),
            rim: self.rim.clone(),
            open: self.open_boundary(),
            out: *out,
        }
    }

    /// A stitcher started anew from `snapshot`, with `mesh` and `free` as given to
    /// [`stitch`]; and what the stitching had done until then.
    fn restore(
        self,
        snapshot: Snapshot<T>,
        mesh: &mut Mesh,
        free: &[(u32, f64)],
    ) -> (Self, Stitched) {
        let initial = snapshot.tris[..self.initial]
            .iter()
            .filter(|t| **t != DEAD)
            .count();
        let visits = self.visits.get();
        let Stitcher { work, growth, .. } = self;
        *work = snapshot.work;
        mesh.vertices = snapshot.pos;
        mesh.normals = snapshot.nrm;
        mesh.provenance = snapshot.prov;
        mesh.triangles = snapshot.tris.into_iter().filter(|t| *t != DEAD).collect();
        let mut s = Stitcher::new(mesh, work, &snapshot.rim, free, growth);
        // (The chart's triangles come first and keep their order.)
        s.initial = initial;
        s.visits.set(visits);
        (s, snapshot.out)
    }

    /// [`Self::fill_holes_by_chart`], or the state before it if it leaves a worse one (holes
    /// whose charts never fit stay opened).
    fn charts_or_keep(
        mut self,
        mut out: Stitched,
        mesh: &mut Mesh,
        free: &[(u32, f64)],
    ) -> (Self, Stitched) {
        let before = (self.growth.new_points && self.open_boundary().hole_edges > 0)
            .then(|| self.snapshot(&out));
        out.added += self.fill_holes_by_chart(&mut out);
        match before.filter(|b| b.open.better_than(&self.open_boundary())) {
            Some(before) => self.restore(before, mesh, free),
            None => (self, out),
        }
    }

    fn boundary_edges(&self) -> usize {
        self.boundary.edge_count()
    }

    /// The boundary edges in a deterministic order.
    fn boundary_edge_list(&self) -> Vec<(u32, u32)> {
        let mut list: Vec<(u32, u32)> = self.boundary.edges().collect();
        list.sort_unstable();
        list
    }

    fn is_boundary_edge(&self, a: u32, b: u32) -> bool {
        self.boundary.outs(a).contains(&b)
    }

    fn on_boundary(&self, v: u32) -> bool {
        !self.boundary.outs(v).is_empty()
    }

    /// Whether `v` is a free sample (one the chart left without a triangle) still on none.
    fn is_free(&self, v: u32) -> bool {
        self.free.get(v as usize).copied().unwrap_or(false) && !self.edges.any_from(v)
    }

    /// How many free vertices there are.
    fn free_left(&self) -> usize {
        self.boundary
            .records
            .iter()
            .filter(|r| self.is_free(r.vertex))
            .count()
    }

    /// Whether a triangle may be made on `v`: a boundary vertex, or a free one.
    fn is_candidate(&self, v: u32) -> bool {
        self.on_boundary(v) || self.is_free(v)
    }

    fn local(&self, v: u32) -> f64 {
        self.boundary.scale(v).unwrap_or(0.0)
    }

    /// The length scale of edge `a → b`: its own length, or its ends' mean edge length if
    /// that is longer.
    fn edge_scale(&self, a: u32, b: u32) -> f64 {
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        dist(pa, pb).max(0.5 * (self.local(a) + self.local(b)))
    }

    /// Adds the queued candidates, best first, each after its full test, refreshing the
    /// edges around every triangle added and an edge whose candidate failed; stops when the
    /// queue is empty or a budget (`steps` against `budget`, the visits against
    /// `visit_budget`) runs out, which `out` then records.
    fn advance_front(
        &mut self,
        out: &mut Stitched,
        steps: &mut usize,
        budget: usize,
        visit_budget: u64,
    ) {
        while let Some(c) = self.heap.pop() {
            if self.memos.get(&(c.a, c.b)).map(|m| m.version) != Some(c.version) {
                continue;
            }
            if *steps == budget || self.visits.get() > visit_budget {
                out.budget_hit = true;
                self.heap.clear();
                break;
            }
            *steps += 1;
            // A new point goes in on trial: the tests read it like any vertex.
            let x = if c.x == NEW {
                self.place_new_point(c.a, c.b)
            } else {
                Some(c.x)
            };
            match x {
                Some(x) if self.acceptable(c.a, c.b, x, c.x == NEW) => {
                    if c.x == NEW {
                        out.vertices += 1;
                        self.register(x, c.a, c.b);
                    }
                    self.add([c.b, c.a, x]);
                    out.added += 1;
                    self.refresh_near(c.a, c.b, x);
                }
                _ => {
                    if c.x == NEW && x.is_some() {
                        self.retract();
                    }
                    let rejected = &mut self.memos.entry((c.a, c.b)).or_default().rejected;
                    if !rejected.contains(&c.x) {
                        rejected.push(c.x);
                    }
                    self.refresh(c.a, c.b);
                }
            }
        }
    }

    /// Sets the smallest angle of the triangles stitched from now on (degrees). A change
    /// forgets the rejected candidates, which were decided with the old floor (remembered
    /// scores carry their floor); queued candidates are left to their full test.
    fn set_floor(&mut self, floor: f64) {
        if floor != self.floor {
            self.floor = floor;
            for memo in self.memos.values_mut() {
                memo.rejected.clear();
            }
        }
    }

    /// Finds the best candidate for the boundary edge `a → b` and queues it.
    fn refresh(&mut self, a: u32, b: u32) {
        // (Taken out of the table while the candidates are scored.)
        let mut memo = self.memos.remove(&(a, b)).unwrap_or_default();
        memo.version += 1;
        if self.is_boundary_edge(a, b) {
            if let Some((score, x)) = self.best_candidate(a, b, &mut memo) {
                self.heap.push(Candidate {
                    score,
                    a,
                    b,
                    x,
                    version: memo.version,
                });
            }
        }
        self.memos.insert((a, b), memo);
    }

    /// The best candidate for the boundary edge `a → b` and its score, if any.
    fn best_candidate(&self, a: u32, b: u32, memo: &mut EdgeMemo) -> Option<(f64, u32)> {
        let reach = REACH * self.edge_scale(a, b);
        self.update_nearest(a, b, reach, memo);
        let mut best: Option<(f64, u32)> = None;
        self.wedge_memo.set(true);
        for &(_, x) in &memo.nearest {
            if !self.is_candidate(x) || memo.rejected.contains(&x) {
                continue;
            }
            // A score is 4 per glued edge plus the smallest angle (below 3.5): a candidate
            // with less glue than the best so far cannot beat it (a tie keeps the best) and
            // is not scored.
            if best.is_some_and(|(s, _)| 4.0 * f64::from(self.glue(a, b, x)) + MAX_MIN_ANGLE <= s) {
                continue;
            }
            if let Some(score) = self.refresh_score(a, b, x, reach, &mut memo.scores) {
                // Equal scores go to the smaller vertex id, not to the nearer candidate: the
                // distances of symmetric candidates differ only by rounding.
                if best.is_none_or(|(s, bx)| score > s || (score == s && x < bx)) {
                    best = Some((score, x));
                }
            }
        }
        self.wedge_memo.set(false);
        // A new point in front of the edge, if no existing vertex makes a good enough
        // triangle there.
        if best.is_none_or(|(s, _)| s < NEW_POINT_SCORE)
            && self.may_grow(a, b)
            && !memo.rejected.contains(&NEW)
        {
            best = Some((NEW_POINT_SCORE - 1e-9, NEW));
        }
        best
    }

    /// Sets `memo.nearest` to the nearest points of the grid within `reach` of the middle of
    /// edge `a → b` other than `a` and `b`, a bounded number of them (the work per edge stays
    /// constant where boundary vertices crowd), as (distance, vertex), nearest first.
    fn update_nearest(&self, a: u32, b: u32, reach: f64, memo: &mut EdgeMemo) {
        let filed = self.points.len();
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let mid = [0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k]));
        // The grid only gains points, and points never move: the nearest of the points filed
        // before are among those found then, so only the points filed since are added to
        // them (while they are few).
        let before = memo
            .nearest_for
            .filter(|&(before, bits)| bits == reach.to_bits() && filed - before <= TOP_UP)
            .map(|(before, _)| before);
        if before == Some(filed) {
            return;
        }
        memo.nearest_for = Some((filed, reach.to_bits()));
        let found = &mut memo.nearest;
        if before.is_none() {
            found.clear();
        }
        let mut consider = |x: u32| {
            if x != a && x != b {
                let d = dist(self.pos[x as usize], mid);
                if d <= reach {
                    found.push((d, x));
                }
            }
        };
        match before {
            Some(before) => self
                .points
                .filed_since(before)
                .iter()
                .for_each(|&x| consider(x)),
            None => self.points.near(mid, reach, consider),
        }
        let order = |p: &(f64, u32), q: &(f64, u32)| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1));
        if found.len() > MAX_CANDIDATES {
            found.select_nth_unstable_by(MAX_CANDIDATES, order);
            found.truncate(MAX_CANDIDATES);
        }
        found.sort_unstable_by(order);
    }

    /// [`Self::score`] with the refresh's angle floor, remembered in `scores` (the edge's,
    /// by `x`): a score reads the positions, normals and provenance of `a`, `b`, `x` (which
    /// do not change once a vertex is registered), the reach, and the edges and boundary
    /// edges at `a`, `b` and `x` (each change to those bumps the vertex's epoch). So a
    /// remembered score with the same epochs and reach is the score computed anew, and a
    /// remembered shape with the same reach is the shape computed anew.
    fn refresh_score(
        &self,
        a: u32,
        b: u32,
        x: u32,
        reach: f64,
        scores: &mut Vec<(u32, RememberedScore)>,
    ) -> Option<f64> {
        let epochs = [a, b, x].map(|v| self.epoch.get(v as usize).copied().unwrap_or(0));
        let floor = self.floor.to_radians();
        let found = scores.binary_search_by_key(&x, |e| e.0);
        let shape = match found {
            Ok(i) if scores[i].1.reach == reach.to_bits() => {
                if scores[i].1.epochs == epochs && scores[i].1.floor == floor.to_bits() {
                    return scores[i].1.score;
                }
                scores[i].1.shape
            }
            _ => self.shape(a, b, x, reach, floor),
        };
        let score = shape.and_then(|angles| self.fits(a, b, x, angles, floor));
        let remembered = RememberedScore {
            epochs,
            reach: reach.to_bits(),
            floor: floor.to_bits(),
            score,
            shape,
        };
        match found {
            Ok(i) => scores[i].1 = remembered,
            Err(i) => scores.insert(i, (x, remembered)),
        }
        score
    }

    /// Notes a change at vertex `v` (its edges, its boundary edges, or the vertex itself):
    /// remembered scores that involve it are stale.
    fn touch(&mut self, v: u32) {
        let v = v as usize;
        if v >= self.epoch.len() {
            if v > self.pos.len() {
                return;
            }
            self.epoch.resize(v + 1, 0);
        }
        self.epoch[v] = self.epoch[v].wrapping_add(1);
    }

    /// Whether edge `a → b` may get a new point in front of it.
    fn may_grow(&self, a: u32, b: u32) -> bool {
        self.growth.new_points
            && self.rim[a as usize] != Rim::Barren
            && self.rim[b as usize] != Rim::Barren
            && self.pos.len() < self.growth.max_vertices
    }

    /// Appends the new point of edge `a → b` (proposed once per edge and remembered) as a
    /// vertex on trial: [`Self::register`] keeps it, [`Self::retract`] takes it back.
    fn place_new_point(&mut self, a: u32, b: u32) -> Option<u32> {
        if !self.proposals.contains_key(&(a, b)) {
            let p = self.propose(a, b);
            self.proposals.insert((a, b), p);
        }
        let p = self.proposals[&(a, b)].clone()?;
        let v = self.pos.len() as u32;
        self.touch(v);
        self.push_vertex(p.pos, p.normal, p.s, p.theta, p.point);
        Some(v)
    }

    /// Appends a new vertex on the surface (position and unit normal in `f64`, the point in
    /// the working precision) with closing provenance at arc length `s` and chart angle
    /// `theta`.
    fn push_vertex(&mut self, q: [f64; 3], normal: [f64; 3], s: f64, theta: f64, point: Vec3<T>) {
        self.pos.push(q);
        self.nrm.push(normal);
        self.prov.push(Provenance {
            curve: Provenance::CLOSING_CURVE,
            step: 0,
            s,
            theta,
        });
        self.work.push(point);
        self.rim.push(Rim::Open);
        self.boundary.push_vertex();
    }

    /// Takes back the vertex on trial.
    fn retract(&mut self) {
        self.touch(self.pos.len() as u32 - 1);
        self.pos.pop();
        self.nrm.pop();
        self.prov.pop();
        self.work.pop();
        self.rim.pop();
        self.boundary.pop_vertex();
    }

    /// Keeps the vertex on trial `v`, placed for edge `a → b`.
    fn register(&mut self, v: u32, a: u32, b: u32) {
        self.proposals.remove(&(a, b));
        let h = 0.5 * (self.local(a) + self.local(b));
        let h = h.max(dist(self.pos[a as usize], self.pos[b as usize]));
        self.boundary.set_scale(v, h);
        self.points.insert(v, self.pos[v as usize]);
        // Within an edge of the box or of the geodesic radius (the rule of
        // `triangulate::holes`), the front's new points along a band's end are its rim, not a
        // front left open (which would send the stitching round again for nothing).
        let g = self.growth;
        if super::near_terminal(
            self.pos[v as usize],
            self.prov[v as usize].s,
            h,
            g.bounding_box,
            g.max_radius,
        ) {
            self.rim[v as usize] = Rim::Terminal;
        }
    }

    /// Places a point on the surface in front of edge `a → b`, where the triangle on the
    /// edge would be equilateral: a chord from the nearer end, of the working precision.
    fn propose(&self, a: u32, b: u32) -> Option<Proposal<T>> {
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let e = sub(pb, pa);
        let len = dot(e, e).sqrt();
        let (na, nb) = (self.nrm[a as usize], self.nrm[b as usize]);
        let n = [0, 1, 2].map(|k| na[k] + nb[k]);
        let right = cross(e, n);
        let rl = dot(right, right).sqrt();
        if !(rl > 0.0 && len > 0.0) {
            return None;
        }
        let h = 0.5 * (len + self.edge_scale(a, b).min(1.5 * len));
        let height = 0.5 * 3f64.sqrt() * h;
        let ideal = [0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k]) + height * right[k] / rl);
        // Two half chords from `a`, each aimed at what is left of the way: where the potential
        // is not cubic a chord's truncation error is of the fifth order in its length
        // (Simpson's rule), and a proposal reaches up to 1.25 boundary edges; halving cuts it
        // 16-fold (a tilted fat torus's stitched point: relative drift 9.5e-4 in one chord,
        // 7.2e-5 in halves).
        // Where the potential is not known to be a cubic, a hop whose drift (estimated against
        // Boole's rule) exceeds [`HOP_DRIFT`] of its length is taken again as two hops: at a
        // fat torus's inner equator two halves still left a point 6.9e-4 off (relative). On
        // a cubic the estimate is rounding, so it is not computed.
        let mut point = self.work[a as usize].clone();
        let (mut left, mut taken) = (2u32, 0u32);
        while left > 0 {
            let d = sub(ideal, point.to_f64());
            let length = dot(d, d).sqrt() / f64::from(left);
            let next = trace::step_fixed(
                self.growth.field,
                &self.growth.cfg,
                &point,
                &Vec3::<T>::from_f64(d),
                &T::from_f64(length),
            )
            .ok()?;
            if taken + 2 * left <= MAX_HOPS
                && self.growth.cfg.mode() == Mode::Default
                && !self.growth.field.has_cubic_potential()
                && trace::chord_drift(
                    self.growth.field,
                    &point,
                    &next,
                    self.growth.cfg.integrating_factor(),
                ) > HOP_DRIFT * length
            {
                left *= 2;
                continue;
            }
            point = next;
            left -= 1;
            taken += 1;
        }
        let q = point.to_f64();
        if !q
            .iter()
            .all(|x| x.is_finite() && x.abs() <= self.growth.bounding_box)
        {
            return None;
        }
        let (_, normal, _) = trace::unit_normal(self.growth.field, &point).ok()?;
        let normal = normal.to_f64();
        let nl = dot(n, n).sqrt();
        if dot(normal, n) < NEW_POINT_TURN_COS * nl {
            return None;
        }
        let (sa, sb) = (self.prov[a as usize].s, self.prov[b as usize].s);
        let s = sa.min(sb) + height;
        if s > self.growth.max_radius {
            return None;
        }
        // Nothing already there: no boundary vertex nearer than half the new edges.
        let mut crowded = false;
        self.points.near(q, 0.5 * h, |w| {
            // Only candidates (boundary and free vertices): interior ones are guarded by the
            // triangles' clearance below.
            crowded = crowded
                || (w != a
                    && w != b
                    && dist(self.pos[w as usize], q) < 0.5 * h
                    && self.is_candidate(w));
        });
        if crowded {
            return None;
        }
        // Not over (or under) the surface already meshed: the point and the middle of the
        // triangle it would make stay clear of every triangle not at the edge's ends.
        let centre = [0, 1, 2].map(|k| (pa[k] + pb[k] + q[k]) / 3.0);
        for probe in [q, centre] {
            let reach = HOVER * h;
            let box_ = [probe.map(|x| x - reach), probe.map(|x| x + reach), probe];
            let mut near = false;
            let mut visits = 0;
            self.faces.near(&box_, |f| {
                visits += 1;
                let t = self.tris[f as usize];
                near = near
                    || (t != DEAD
                        && !t.contains(&a)
                        && !t.contains(&b)
                        && point_triangle_distance(probe, corners(&self.pos, t)) < reach);
            });
            self.visits.set(self.visits.get() + visits);
            if near {
                return None;
            }
        }
        let theta = 0.5 * (self.prov[a as usize].theta + self.prov[b as usize].theta);
        Some(Proposal {
            point,
            pos: q,
            normal,
            s,
            theta,
        })
    }

    /// Re-queues the boundary edges at a triangle just added: those at its corners, at their
    /// neighbours along the boundary and within the triangle's size. Edges farther away keep their candidates; one
    /// that the triangle spoiled fails its full test when it comes up and is looked at again.
    fn refresh_near(&mut self, a: u32, b: u32, x: u32) {
        let mut around = vec![a, b, x];
        for v in [a, b, x] {
            around.extend(self.boundary.outs(v));
            around.extend(self.boundary.ins(v));
        }
        // And the boundary vertices about as close to the triangle as its own size.
        let c = corners(&self.pos, [a, b, x]);
        let centre = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
        let size = (0..3)
            .map(|k| dist(c[k], c[(k + 1) % 3]))
            .fold(0.0, f64::max);
        self.points.near(centre, size, |w| {
            if dist(self.pos[w as usize], centre) <= size {
                around.push(w);
            }
        });
        around.sort_unstable();
        around.dedup();
        let mut list = Vec::new();
        for v in around {
            for &w in self.boundary.outs(v) {
                list.push((v, w));
            }
            for &u in self.boundary.ins(v) {
                list.push((u, v));
            }
        }
        list.sort_unstable();
        list.dedup();
        for (v, w) in list {
            self.refresh(v, w);
        }
    }

    /// The score of triangle `(b, a, x)`, or `None` when it may not be added (all tests
    /// but the exact intersection test, which [`Self::acceptable`] runs when it comes up).
    fn score(&self, a: u32, b: u32, x: u32, reach: f64, min_floor: f64) -> Option<f64> {
        let angles = self.shape(a, b, x, reach, min_floor)?;
        self.fits(a, b, x, angles, min_floor)
    }

    /// The tests of [`Self::score`] that read only the corners' positions and normals and
    /// the reach: the triangle's angles at `a`, `b`, `x` if it passes them.
    fn shape(&self, a: u32, b: u32, x: u32, reach: f64, min_floor: f64) -> Option<[f64; 3]> {
        let [pa, pb, px] = [a, b, x].map(|v| self.pos[v as usize]);
        let nx = self.nrm[x as usize];
        if dist(pa, px) > reach || dist(pb, px) > reach {
            return None;
        }
        let face = cross(sub(pa, pb), sub(px, pb));
        let mut field = [0.0; 3];
        for n in [self.nrm[a as usize], self.nrm[b as usize], nx] {
            for k in 0..3 {
                field[k] += n[k];
            }
        }
        let (ff, gg) = (dot(face, face), dot(field, field));
        // Against each corner's normal, not only their sum: corners on opposite sides of a
        // thin tube sum to almost nothing, and a triangle across the tube must not pass.
        let cos_tilt = self.tilt_limit([a, b, x]).to_radians().cos();
        let leans = [field, self.nrm[a as usize], self.nrm[b as usize], nx]
            .iter()
            .any(|&n| tilts_past(face, ff, n, cos_tilt));
        // With a floor on the angles no triangle is a sliver (below): the facing test comes
        // before the angles, which are dearer.
        if !(ff > 0.0 && gg > 0.0) || (min_floor != 0.0 && leans) {
            return None;
        }
        let angles = angles([pa, pb, px]);
        let min_angle = angles[0].min(angles[1]).min(angles[2]);
        // A hole's last sliver (a corner almost on the opposite edge) has no normal to speak
        // of: it goes in whichever way it faces, and the flips that follow remove it.
        let sliver = min_floor == 0.0 && min_angle < SLIVER_DEG.to_radians();
        if !sliver && leans {
            return None;
        }
        Some(angles)
    }

    /// The tests of [`Self::score`] that read the edges and boundary edges at the corners,
    /// for a triangle of the given `angles` that passed [`Self::shape`]: its score if it
    /// passes them.
    fn fits(&self, a: u32, b: u32, x: u32, angles: [f64; 3], min_floor: f64) -> Option<f64> {
        // Each edge at most twice, once each way.
        if self.edges.contains(a, x) || self.edges.contains(x, b) {
            return None;
        }
        let min_angle = angles[0].min(angles[1]).min(angles[2]);
        // Corners where both of the triangle's edges are boundary edges now: there it fills
        // the whole open wedge, so a sharp angle there is the boundary's, not the triangle's.
        let fills = |v: u32, before: u32, after: u32| {
            self.is_boundary_edge(before, v) && self.is_boundary_edge(v, after)
        };
        // (b, a, x): at a the edges are b–a and a–x, at b x–b and b–a, at x a–x and x–b.
        let filled = [fills(a, x, b), fills(b, a, x), fills(x, b, a)];
        if (0..3).any(|k| angles[k] < min_floor && !filled[k]) {
            return None;
        }
        // In the open wedge at each corner: triangle (b, a, x) spans, counter-clockwise,
        // from x to b at a, from a to x at b, and from b to a at x (a new point has no
        // wedge yet). A hole's last triangles are ears of its loop: the exact test alone
        // decides those.
        if min_floor > 0.0 {
            // With well-shaped seams, nor may it leave a sliver of a wedge beside it at a
            // corner: the triangle that fills that wedge later would have its angle there.
            let slivers = self.growth.well_shaped;
            let refused = |left: Option<[f64; 2]>| {
                left.is_none_or(|l| slivers && l.iter().any(|&w| w > 0.0 && w < min_floor))
            };
            let wedgeless = self.prov[x as usize].curve == Provenance::CLOSING_CURVE
                && !self.on_boundary(x)
                || self.is_free(x);
            if refused(self.open_wedge_leftovers(a, x, b))
                || refused(self.open_wedge_leftovers(b, a, x))
                || !wedgeless && refused(self.open_wedge_leftovers(x, b, a))
            {
                return None;
            }
        }
        Some(4.0 * f64::from(self.glue(a, b, x)) + quantized(min_angle))
    }

    /// How many of triangle `(b, a, x)`'s other edges close a boundary edge (its score's
    /// integer part, times 4).
    fn glue(&self, a: u32, b: u32, x: u32) -> u8 {
        u8::from(self.is_boundary_edge(x, a)) + u8::from(self.is_boundary_edge(b, x))
    }

    /// If the wedge at boundary vertex `v` from the direction of `from` counter-clockwise to
    /// that of `to` (about `v`'s field normal) lies in one of `v`'s open wedges (from a
    /// boundary in-edge's source counter-clockwise to a boundary out-edge's target, with no
    /// other boundary edge of `v` between), the angles that open wedge leaves before and
    /// after it (radians; 0 where a side is the open wedge's own boundary edge); `None` if
    /// it lies in none.
    ///
    /// While no vertex is on trial the angles about `v` are remembered (a refresh's candidates
    /// share their edge's ends and the ends' boundary neighbours, edges near each other share
    /// candidates, and a queued candidate was scored by a refresh): the same value as computed
    /// anew, since an angle reads only the positions and normals of its two vertices, which
    /// do not change once a vertex is registered (and a vertex on trial, whose id may come
    /// back with another position, is never remembered).
    fn open_wedge_leftovers(&self, v: u32, from: u32, to: u32) -> Option<[f64; 2]> {
        let (outs, ins) = (self.boundary.outs(v), self.boundary.ins(v));
        let p = self.pos[v as usize];
        let n = self.nrm[v as usize];
        // (Only needed for angles not remembered.)
        let frame = std::cell::OnceCell::new();
        let memo = self.wedge_memo.get();
        let angle = |w: u32| {
            if memo {
                if let Some(&t) = self.wedge_angles.borrow().get(&(v, w)) {
                    return t;
                }
            }
            let (e1, e2) = *frame.get_or_init(|| tangent_frame(n));
            let d = sub(self.pos[w as usize], p);
            let t = dot(d, e2).atan2(dot(d, e1));
            if memo {
                self.wedge_angles.borrow_mut().insert((v, w), t);
            }
            t
        };
        let ccw = |from: f64, to: f64| {
            use std::f64::consts::TAU;
            let d = to - from;
            // `d.rem_euclid(TAU)` without its `fmod` call for differences within a turn, as
            // of two angles from atan2 (there `d % TAU` is `d`, exactly).
            if d.abs() < TAU {
                if d < 0.0 {
                    d + TAU
                } else {
                    d
                }
            } else {
                d.rem_euclid(TAU)
            }
        };
        let (af, at) = (angle(from), angle(to));
        let span = ccw(af, at);
        for &z in ins {
            let az = angle(z);
            for &y in outs {
                let ay = angle(y);
                let wedge = ccw(az, ay);
                // The triangle's span must lie inside the wedge…
                if !(ccw(az, af) <= wedge && ccw(az, af) + span <= wedge + 1e-12) {
                    continue;
                }
                // …and no other boundary edge of v may cut the wedge.
                let cut = outs.iter().chain(ins.iter()).any(|&u| {
                    u != z && u != y && {
                        let au = ccw(az, angle(u));
                        au > 0.0 && au < wedge
                    }
                });
                if !cut {
                    let before = if z == from { 0.0 } else { ccw(az, af) };
                    let after = if y == to {
                        0.0
                    } else {
                        (wedge - ccw(az, af) - span).max(0.0)
                    };
                    return Some([before, after]);
                }
            }
        }
        None
    }

    /// The full test for triangle `(b, a, x)`, including the exact intersection test against
    /// the triangles near it; `x` may be the new point on trial.
    fn acceptable(&self, a: u32, b: u32, x: u32, on_trial: bool) -> bool {
        // (A vertex on trial is on no triangle yet.)
        if !self.is_boundary_edge(a, b) || !(on_trial || self.is_candidate(x)) {
            return false;
        }
        let reach = REACH * self.edge_scale(a, b);
        self.wedge_memo.set(!on_trial);
        let scored = self
            .score(a, b, x, reach, self.floor.to_radians())
            .is_some();
        self.wedge_memo.set(false);
        scored && self.clear(a, b, x) && self.meets_nothing(a, b, x)
    }

    /// Whether triangle `(b, a, x)` meets no triangle near it other than along the edges and
    /// corners it shares with them (exact).
    fn meets_nothing(&self, a: u32, b: u32, x: u32) -> bool {
        self.face_meets_nothing([b, a, x])
    }

    /// Whether triangle `t` meets no triangle near it other than along the edges and corners
    /// it shares with them (exact).
    fn face_meets_nothing(&self, t: [u32; 3]) -> bool {
        let c = corners(&self.pos, t);
        if self
            .growth
            .axis
            .is_some_and(|axis| triangle_meets_line(c, axis))
        {
            return false;
        }
        let (lo, hi) = bounds(&c);
        let mut hit = false;
        let mut visits = 0;
        self.faces.near(&c, |f| {
            visits += 1;
            let g = self.tris[f as usize];
            if hit || g == DEAD {
                return;
            }
            // Closed triangles whose boxes are apart have no common point: only faces whose
            // boxes meet this one's go to the exact test (a non-finite corner, which the
            // exact test answers `false` for, may be rejected here as well).
            let (glo, ghi) = bounds(&corners(&self.pos, g));
            if (0..3).any(|k| ghi[k] < lo[k] || glo[k] > hi[k]) {
                return;
            }
            hit = faces_intersect(&self.pos, t, g);
        });
        self.visits.set(self.visits.get() + visits);
        !hit
    }

    /// Whether no other boundary vertex lies on or right next to triangle `(b, a, x)`
    /// ([`CLEARANCE`]): the gap it would leave there would be a sliver, maybe one turned
    /// inside out.
    fn clear(&self, a: u32, b: u32, x: u32) -> bool {
        let t = [b, a, x];
        let corners_t = corners(&self.pos, t);
        let h = [a, b].iter().map(|&v| self.local(v)).fold(0.0, f64::max);
        let clearance = CLEARANCE * h;
        let centre = [0, 1, 2].map(|k| (corners_t[0][k] + corners_t[1][k] + corners_t[2][k]) / 3.0);
        let radius = (0..3)
            .map(|k| dist(centre, corners_t[k]))
            .fold(0.0, f64::max)
            + clearance;
        // Points outside the triangle's box grown by the clearance are farther than that
        // from it: most of the ball's points on a coarse front, rejected before the distance.
        let (lo, hi) = bounds(&corners_t);
        let (lo, hi) = (lo.map(|x| x - clearance), hi.map(|x| x + clearance));
        let mut crowded = false;
        let mut visits = 0;
        self.points.near(centre, radius, |w| {
            visits += 1;
            let p = self.pos[w as usize];
            crowded = crowded
                || ((0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k])
                    && !t.contains(&w)
                    && (self.on_boundary(w)
                        // A free vertex right next to a corner is a near-duplicate of it and
                        // stays unused; one farther in would be left under the triangle.
                        || self.is_free(w)
                            && corners_t.iter().all(|&c| dist(c, p) > 2.0 * clearance))
                    && point_triangle_distance(p, corners_t) < clearance);
        });
        self.visits.set(self.visits.get() + visits);
        !crowded
    }

    /// The triangle that closes the three-edge loop `ring`, if it faces the same side as the
    /// field normal at each of its corners (however far it tilts) and meets nothing.
    fn last_triangle(&self, ring: &[u32]) -> Option<[u32; 3]> {
        let t = [ring[2], ring[1], ring[0]];
        self.fits_across_bend(t).then_some(t)
    }

    /// Whether triangle `t` faces the same side as the field normal at each of its corners
    /// (however far it tilts) and meets nothing: the test of the triangles that close a hole
    /// across a bend sharper than they are.
    fn fits_across_bend(&self, t: [u32; 3]) -> bool {
        let [pa, pb, pc] = corners(&self.pos, t);
        let face = cross(sub(pb, pa), sub(pc, pa));
        t.iter().all(|&v| dot(face, self.nrm[v as usize]) > 0.0) && self.face_meets_nothing(t)
    }

    /// The triangulation of loop `ring` (of at most [`BENT_HOLE`] edges) whose smallest angle
    /// is largest among those whose every triangle faces the same side as the field normal
    /// at each of its corners (however far it tilts), covers no other vertex of the loop and
    /// meets nothing, nor the others; `None` if there is none. (Dynamic programming over the
    /// loop's sub-polygons: each triangle is tested once.)
    fn bent_triangulation(&self, ring: &[u32]) -> Option<Vec<[u32; 3]>> {
        let m = ring.len();
        if !(3..=BENT_HOLE).contains(&m) {
            return None;
        }
        // Triangle (i, j, k), i < j < k along the loop, oriented as an ear is.
        let tri = |i: usize, j: usize, k: usize| [ring[k], ring[j], ring[i]];
        let smallest = |t: [u32; 3]| -> Option<f64> {
            (self.covers_none(ring, t) && self.fits_across_bend(t)).then(|| {
                angles(corners(&self.pos, t))
                    .into_iter()
                    .fold(f64::INFINITY, f64::min)
            })
        };
        // best[i][k]: the best smallest angle of the sub-polygon i..=k, and its apex on i–k.
        let mut best = vec![vec![None::<(f64, usize)>; m]; m];
        for span in 2..m {
            for i in 0..m - span {
                let k = i + span;
                for j in i + 1..k {
                    let side = |a: usize, b: usize| {
                        if b == a + 1 {
                            Some(f64::INFINITY)
                        } else {
                            best[a][b].map(|(s, _)| s)
                        }
                    };
                    let (Some(left), Some(right)) = (side(i, j), side(j, k)) else {
                        continue;
                    };
                    let Some(here) = smallest(tri(i, j, k)) else {
                        continue;
                    };
                    let score = here.min(left).min(right);
                    if best[i][k].is_none_or(|(s, _)| score > s) {
                        best[i][k] = Some((score, j));
                    }
                }
            }
        }
        let mut out = Vec::with_capacity(m - 2);
        let mut stack = vec![(0, m - 1)];
        while let Some((i, k)) = stack.pop() {
            if k < i + 2 {
                continue;
            }
            let (_, j) = best[i][k]?;
            out.push(tri(i, j, k));
            stack.push((i, j));
            stack.push((j, k));
        }
        // The triangles were tested against the mesh, not against one another.
        let apart = out.iter().enumerate().all(|(a, &f)| {
            out[a + 1..]
                .iter()
                .all(|&g| !faces_intersect(&self.pos, f, g))
        });
        apart.then_some(out)
    }

    /// Whether the loop `ring` is known to bound a disc of the surface, so that the disc may
    /// be closed across a bend sharper than its triangles: on an ovaloid every loop does; round
    /// a hole the field knows (a band), every loop that does not go round its axis. (A loop
    /// that rings a missing handle of a surface the field knows nothing of, a tanglecube's,
    /// must stay open.)
    fn bounds_a_disc(&self, ring: &[u32]) -> bool {
        if self.growth.ovaloid {
            return true;
        }
        let Some(axis) = self.growth.axis else {
            return false;
        };
        let m = ring.len();
        let turn: f64 = (0..m)
            .map(|i| {
                let (p, q) = (ring[i], ring[(i + 1) % m]);
                turn_about(axis, self.pos[p as usize], self.pos[q as usize])
            })
            .sum();
        turn.abs() < std::f64::consts::PI
    }

    /// Closes the boundary loops that are left, ear by ear (the best-shaped ear first), as
    /// long as the ears face the way the field does, meet nothing and cover no other vertex of
    /// the loop: the last few triangles where fronts met may have to be thin. Loops of at most
    /// [`SMALL_HOLE`] edges are closed whatever they touch; loops of up to `open_limit` edges
    /// only if no vertex of theirs ended a curve on the surface's boundary. Returns how many
    /// triangles it added.
    fn fill_holes(&mut self, open_limit: usize) -> usize {
        let mut added = 0;
        let limit = open_limit.max(SMALL_HOLE);
        for start in self.boundary_edge_list() {
            let Some(mut ring) = self.loop_from(start, limit) else {
                continue;
            };
            if ring.len() > SMALL_HOLE && ring.iter().any(|&v| self.rim[v as usize] != Rim::Open) {
                continue;
            }
            while ring.len() >= 3 {
                let m = ring.len();
                let mut best: Option<(f64, usize)> = None;
                for i in 0..m {
                    let (u, v, w) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
                    // The ear at v is triangle (w, v, u): edge v → w with x = u.
                    let Some(score) = self.score(v, w, u, f64::INFINITY, 0.0) else {
                        continue;
                    };
                    if best.is_none_or(|(s, _)| score > s)
                        && self.covers_none(&ring, [w, v, u])
                        && self.meets_nothing(v, w, u)
                    {
                        best = Some((score, i));
                    }
                }
                let Some((_, i)) = best else {
                    // No ear fits: a small loop wide against the surface's curvature (its
                    // corners' normals far apart) takes a point on the surface in its middle.
                    if m <= FAN_HOLE && self.fill_by_fan(&ring) {
                        added += m;
                    } else if let Some(t) = (m == 3).then(|| self.last_triangle(&ring)).flatten() {
                        // A hole of one missing triangle across a bend sharper than the
                        // triangles (a flattened ellipsoid's rim): that triangle goes in if
                        // it faces the same side as each corner's normal and meets nothing,
                        // however far it tilts.
                        self.add(t);
                        added += 1;
                    } else if let Some(ts) = (m > 3 && self.bounds_a_disc(&ring))
                        .then(|| self.bent_triangulation(&ring))
                        .flatten()
                    {
                        // A few missing triangles across such a bend (the far tip of a
                        // 1:0.22:0.05 ellipsoid meshed from the other tip): the same test,
                        // for the best-shaped of the loop's triangulations that passes it.
                        added += ts.len();
                        for t in ts {
                            self.add(t);
                        }
                    }
                    break;
                };
                let (u, v, w) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
                self.add([w, v, u]);
                added += 1;
                ring.remove(i);
                if m == 3 {
                    break;
                }
            }
        }
        added
    }

    /// Fills loop `ring` with a fan around a new point on the surface near the loop's centre,
    /// when every triangle of the fan passes the tests an ear would. Whether it did.
    fn fill_by_fan(&mut self, ring: &[u32]) -> bool {
        let m = ring.len() as f64;
        let centre = [0, 1, 2].map(|k| ring.iter().map(|&v| self.pos[v as usize][k] / m).sum());
        // The chord starts at the corner nearest the centre: the shortest extrapolation.
        let Some(&from) = ring.iter().min_by(|&&u, &&v| {
            dist(self.pos[u as usize], centre).total_cmp(&dist(self.pos[v as usize], centre))
        }) else {
            return false;
        };
        let d = sub(centre, self.pos[from as usize]);
        let length = dot(d, d).sqrt();
        if length.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let start = &self.work[from as usize];
        let dir = Vec3::<T>::from_f64(d);
        let Ok(point) = trace::step_fixed(
            self.growth.field,
            &self.growth.cfg,
            start,
            &dir,
            &T::from_f64(length),
        ) else {
            return false;
        };
        let Ok((_, normal, _)) = trace::unit_normal(self.growth.field, &point) else {
            return false;
        };
        let (q, normal) = (point.to_f64(), normal.to_f64());
        if !q.iter().chain(&normal).all(|x| x.is_finite()) {
            return false;
        }
        let x = self.pos.len() as u32;
        let (s, theta) = ring.iter().fold((f64::INFINITY, 0.0), |(s, th), &v| {
            let p = &self.prov[v as usize];
            (s.min(p.s), th + p.theta / m)
        });
        self.push_vertex(q, normal, s + length, theta, point);
        let n = ring.len();
        let fits = (0..n).all(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            self.score(a, b, x, f64::INFINITY, 0.0).is_some() && self.meets_nothing(a, b, x)
        });
        if !fits {
            self.retract();
            return false;
        }
        self.register(x, ring[0], ring[1]);
        for i in 0..n {
            self.add([ring[(i + 1) % n], ring[i], x]);
        }
        true
    }

    /// The last resort for holes between fronts that met (every vertex of the loop
    /// [`Rim::Open`], at most [`CHART_HOLE`] edges, on an integrable field): each is filled
    /// through a chart of its own ([`Self::fill_by_chart`]); the holes whose charts fail are
    /// opened wider (one more ring of triangles each time) and tried again, up to
    /// [`CHART_ATTEMPTS`] times. A hole that never fits stays opened: where it reaches the
    /// surface's own boundary (such as the hole around a cone's apex) it merges into it rather
    /// than stay an extra hole. Returns how many triangles it added (and counts the removed
    /// ones and the new vertices in `out`).
    fn fill_holes_by_chart(&mut self, out: &mut Stitched) -> usize {
        if !self.growth.new_points {
            return 0;
        }
        let mut added = 0;
        let mut attempt = 0;
        // Each pass either fills a hole (a finite number of them), or opens the failed ones
        // (at most `CHART_ATTEMPTS` times): the bound is never reached, only a guard.
        for _ in 0..CHART_HOLE {
            let (mut failed, mut filled) = (Vec::new(), false);
            for ring in self.open_loops(CHART_HOLE) {
                match self.fill_by_chart(&ring, Patch::Refined, 0.0) {
                    Some((triangles, vertices)) => {
                        added += triangles;
                        out.vertices += vertices;
                        filled = true;
                    }
                    None => failed.push(ring),
                }
            }
            // A hole touching another at a vertex may not be walked round as a loop while
            // the other is open (the walk turns into the other there); once that one is
            // filled it is, so the loops are listed again.
            if failed.is_empty() {
                if filled {
                    continue;
                }
                break;
            }
            if attempt == CHART_ATTEMPTS {
                break;
            }
            attempt += 1;
            let (removed, _) = self.open_around(&failed, attempt);
            out.removed += removed.len();
        }
        added
    }

    /// The boundary loops of at most `limit` edges none of whose vertices ended a curve on a
    /// terminal condition: holes left where fronts met. Each loop once, in a deterministic
    /// order, with no vertex twice.
    ///
    /// Where the boundary touches itself at a vertex (two fans of triangles meeting there, as
    /// where a ragged far cap's rim pinches), the walk goes on along the next boundary edge
    /// counter-clockwise ([`Self::next_on_hole`]), so that the hole on either side of the
    /// pinch is a loop of its own.
    fn open_loops(&self, limit: usize) -> Vec<Vec<u32>> {
        let edges = self.boundary_edge_list();
        let index: HashMap<(u32, u32), usize, FastHash> =
            edges.iter().enumerate().map(|(i, &e)| (e, i)).collect();
        let next: Vec<Option<usize>> = edges
            .iter()
            .map(|&(a, b)| {
                self.next_on_hole(a, b)
                    .and_then(|c| index.get(&(b, c)).copied())
            })
            .collect();
        // Each edge is walked once: a walk that runs into an edge walked before is no loop.
        let mut walked = vec![false; edges.len()];
        let mut out = Vec::new();
        for start in 0..edges.len() {
            let mut ring = Vec::new();
            let mut e = Some(start);
            let mut closed = false;
            while let Some(i) = e {
                if walked[i] {
                    closed = i == start && !ring.is_empty();
                    break;
                }
                walked[i] = true;
                ring.push(edges[i].0);
                e = next[i];
            }
            if !closed {
                continue;
            }
            // A walk through a vertex twice is two holes touching there that the turn at the
            // vertex did not tell apart: each is a loop of its own.
            for ring in simple_loops(&ring) {
                if (3..=limit).contains(&ring.len())
                    && ring.iter().all(|&v| self.rim[v as usize] == Rim::Open)
                {
                    out.push(ring);
                }
            }
        }
        out
    }

    /// The end of the boundary edge that follows `from → v` round the hole on its right: the
    /// one edge out of `v`, or where the boundary touches itself at `v`, the first out-edge
    /// counter-clockwise about `v`'s normal from the edge back to `from` (the gap beside the
    /// fan that `from → v` ends).
    fn next_on_hole(&self, from: u32, v: u32) -> Option<u32> {
        match self.boundary.outs(v) {
            [] => None,
            [w] => Some(*w),
            outs => {
                let (e1, e2) = tangent_frame(self.nrm[v as usize]);
                let at = self.pos[v as usize];
                let angle = |w: u32| {
                    let d = sub(self.pos[w as usize], at);
                    dot(d, e2).atan2(dot(d, e1))
                };
                let back = angle(from);
                let turn = |w: u32| (angle(w) - back).rem_euclid(std::f64::consts::TAU);
                outs.iter()
                    .copied()
                    .min_by(|&x, &y| turn(x).total_cmp(&turn(y)).then(x.cmp(&y)))
            }
        }
    }

    /// Fills the hole bounded by `ring` (a boundary loop, the hole on the right of each edge)
    /// through a chart of its own: the loop is projected onto the plane across its corners'
    /// mean field normal, triangulated there by spade (the loop's edges as constraints, kept
    /// whole; with [`Patch::Refined`], refined to [`CHART_ANGLE_DEG`] with triangles about
    /// as large as those around the loop, or its edges if shorter: see
    /// [`Self::spacing_into`]), and each new point is put on the surface by a chord from the
    /// nearest corner. The patch goes in only if every corner and new point faces within
    /// [`CHART_TURN_DEG`] of the plane's normal, every triangle keeps its orientation once
    /// lifted, faces the field and meets no triangle already there (exact test), and, with a
    /// `floor` above zero (radians), every angle of its triangles is at least that, but where
    /// two of the loop's edges meet in one triangle (the loop's own angle there). Returns the
    /// triangles and vertices added.
    fn fill_by_chart(&mut self, ring: &[u32], patch: Patch, floor: f64) -> Option<(usize, usize)> {
        use spade::{AngleLimit, RefinementParameters};
        let m = ring.len();
        if m < 3 || self.pos.len() + 4 * m + 64 > self.growth.max_vertices {
            return None;
        }
        let turn_cos = CHART_TURN_DEG.to_radians().cos();
        let mut sum = [0.0; 3];
        let mut centre = [0.0; 3];
        for &v in ring {
            for k in 0..3 {
                sum[k] += self.nrm[v as usize][k];
                centre[k] += self.pos[v as usize][k] / m as f64;
            }
        }
        let length = dot(sum, sum).sqrt();
        if length.is_nan() || length <= 0.0 {
            return None;
        }
        let n = sum.map(|x| x / length);
        if ring.iter().any(|&v| {
            let c = dot(self.nrm[v as usize], n);
            c.is_nan() || c <= turn_cos
        }) {
            return None;
        }
        // Counter-clockwise in the chart is counter-clockwise about the normal, the mesh's
        // orientation.
        let (e1, e2) = tangent_frame(n);
        let ids: Vec<u32> = ring.iter().rev().copied().collect();
        let mean_edge = (0..m)
            .map(|i| {
                dist(
                    self.pos[ids[i] as usize],
                    self.pos[ids[(i + 1) % m] as usize],
                )
            })
            .sum::<f64>()
            / m as f64;
        // Chart positions are in mean edge lengths (spade refuses coordinates below 10⁻⁴³ or
        // so: a sphere of radius 10⁻⁵⁰ would lose its patches), snapped to multiples of 2⁻²⁴,
        // so that corners whose positions differ only by rounding (the same run in another
        // working precision) give spade the same input, and symmetric corners (a far cap
        // traced from a pole, nearly on one circle) the same triangulation.
        let snap = |x: f64| (x / CHART_SNAP).round() * CHART_SNAP;
        let chart = |q: [f64; 3]| {
            let d = sub(q, centre);
            [snap(dot(d, e1) / mean_edge), snap(dot(d, e2) / mean_edge)]
        };
        // The hole runs counter-clockwise once the loop is reversed.
        let corners2: Vec<[f64; 2]> = ids.iter().map(|&v| chart(self.pos[v as usize])).collect();
        let area: f64 = (0..m)
            .map(|i| {
                let (p, q) = (corners2[i], corners2[(i + 1) % m]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum::<f64>()
            * 0.5;
        if area.is_nan() || area <= 0.0 || !simple_polygon(&corners2) {
            return None;
        }
        // A frame of four far corners keeps the hole off the convex hull, whose edges the
        // refinement may split.
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for c in &corners2 {
            for k in 0..2 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        let pad = snap((hi[0] - lo[0]).max(hi[1] - lo[1]) + 1.0);
        let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = Default::default();
        for (x, y) in [
            (lo[0] - pad, lo[1] - pad),
            (hi[0] + pad, lo[1] - pad),
            (hi[0] + pad, hi[1] + pad),
            (lo[0] - pad, hi[1] + pad),
        ] {
            cdt.insert(Point2::new(x, y)).ok()?;
        }
        let mut handles = Vec::with_capacity(m);
        for c in &corners2 {
            let h = cdt.insert(Point2::new(c[0], c[1])).ok()?;
            if h.index() != 4 + handles.len() {
                // Two corners at one chart position.
                return None;
            }
            handles.push(h);
        }
        for i in 0..m {
            let (a, b) = (handles[i], handles[(i + 1) % m]);
            if !cdt.can_add_constraint(a, b) {
                return None;
            }
            cdt.add_constraint(a, b);
        }
        // Triangles about the size of the mesh's around the loop: the loop's edges between
        // curves that ended far apart can be twice as long as the edges into the mesh.
        let spacing = self
            .spacing_into(ring)
            .map_or(1.0, |h| (h / mean_edge).min(1.0));
        let equilateral = 0.25 * 3f64.sqrt() * spacing * spacing;
        let result = cdt.refine(
            RefinementParameters::new()
                .exclude_outer_faces(true)
                .keep_constraint_edges()
                .with_angle_limit(AngleLimit::from_deg(CHART_ANGLE_DEG))
                .with_max_allowed_area(1.5 * equilateral)
                .with_min_required_area(0.05 * equilateral)
                .with_max_additional_vertices(match patch {
                    Patch::Refined => 8 * m + 64,
                    Patch::Plain => 0,
                }),
        );
        // The loop's edges must have stayed whole: the patch is glued to them.
        if (0..m).any(|i| {
            cdt.get_edge_from_neighbors(handles[i], handles[(i + 1) % m])
                .is_none()
        }) {
            return None;
        }
        let outer: HashSet<usize, FastHash> =
            result.excluded_faces.iter().map(|f| f.index()).collect();
        let faces: Vec<[usize; 3]> = cdt
            .inner_faces()
            .filter(|f| !outer.contains(&f.fix().index()))
            .map(|f| f.vertices().map(|v| v.fix().index()))
            .collect();
        if faces.is_empty() || faces.iter().flatten().any(|&i| i < 4) {
            return None;
        }
        // Chart vertex → mesh vertex: the loop's corners, then new points on trial.
        let first_new = self.pos.len() as u32;
        let mut index: HashMap<usize, u32, FastHash> = HashMap::default();
        for (i, &v) in ids.iter().enumerate() {
            index.insert(4 + i, v);
        }
        let mut steiner: Vec<usize> = faces
            .iter()
            .flatten()
            .copied()
            .filter(|i| *i >= 4 + m)
            .collect();
        steiner.sort_unstable();
        steiner.dedup();
        let s0 = ring
            .iter()
            .map(|&v| self.prov[v as usize].s)
            .fold(f64::INFINITY, f64::min);
        let theta = ring
            .iter()
            .map(|&v| self.prov[v as usize].theta)
            .sum::<f64>()
            / m as f64;
        let mut lifted_ok = true;
        let mut near: Vec<u32> = Vec::new();
        for &i in &steiner {
            let vertex = cdt.vertex(spade::handles::FixedVertexHandle::from_index(i));
            let p2 = vertex.position();
            let target = [0, 1, 2].map(|k| centre[k] + mean_edge * (p2.x * e1[k] + p2.y * e2[k]));
            // Hops start from the nearest neighbour in the chart already on the surface (a
            // corner, or a point lifted before): about one hop away. Only a point whose
            // neighbours all come later starts from the nearest corner of the loop.
            near.clear();
            near.extend(
                vertex
                    .out_edges()
                    .filter_map(|e| index.get(&e.to().fix().index()).copied()),
            );
            let from = if near.is_empty() { &ids } else { &near };
            let Some(point) = self.lift(from, target, n, turn_cos, mean_edge) else {
                lifted_ok = false;
                break;
            };
            let (q, normal, _) = point;
            index.insert(i, self.pos.len() as u32);
            self.push_vertex(q, normal, s0 + dist(q, centre), theta, point.2);
        }
        let triangles: Vec<[u32; 3]> = faces
            .iter()
            .map(|f| f.map(|i| index.get(&i).copied().unwrap_or(u32::MAX)))
            .collect();
        // Whether chart vertices `p` and `q` are neighbours on the loop (its corners are the
        // chart vertices `4..4 + m`, in order).
        let loop_edge = |p: usize, q: usize| {
            let corner = |x: usize| (4..4 + m).contains(&x).then(|| x - 4);
            matches!((corner(p), corner(q)),
                (Some(i), Some(j)) if (i + 1) % m == j || (j + 1) % m == i)
        };
        let shapely = |f: [usize; 3], t: [u32; 3]| {
            let a = angles(corners(&self.pos, t));
            (0..3).all(|k| {
                a[k] >= floor || loop_edge(f[k], f[(k + 2) % 3]) && loop_edge(f[k], f[(k + 1) % 3])
            })
        };
        // A refined patch may keep a few triangles below the floor beside the loop (spade
        // cannot split the loop's edges, nor triangles below its smallest area, in a narrow
        // notch of a ragged far cap): those are left out, and the small holes they leave are
        // the front's.
        let thin_allowed = match patch {
            Patch::Refined => faces.len() / THIN_SHARE,
            Patch::Plain => 0,
        };
        let mut thin = vec![false; faces.len()];
        let mut thin_count = 0;
        let fits = lifted_ok
            && faces
                .iter()
                .zip(&triangles)
                .zip(&mut thin)
                .all(|((&f, &t), thin)| {
                    if t.contains(&u32::MAX) {
                        return false;
                    }
                    if floor > 0.0 && !shapely(f, t) {
                        *thin = true;
                        thin_count += 1;
                        return thin_count <= thin_allowed;
                    }
                    self.patch_triangle_fits(t, n, centre, e1, e2)
                });
        if !fits {
            while self.pos.len() > first_new as usize {
                self.retract();
            }
            return None;
        }
        for v in first_new..self.pos.len() as u32 {
            self.boundary.set_scale(v, mean_edge);
            self.points.insert(v, self.pos[v as usize]);
        }
        for (&t, _) in triangles.iter().zip(&thin).filter(|(_, &thin)| !thin) {
            self.add(t);
        }
        Some((
            faces.len() - thin_count,
            self.pos.len() - first_new as usize,
        ))
    }

    /// The median length of the edges from the corners of `ring` (a boundary loop) into the
    /// mesh, those that are not the loop's own; `None` if there are none.
    fn spacing_into(&self, ring: &[u32]) -> Option<f64> {
        let m = ring.len();
        let mut lengths: Vec<f64> = Vec::new();
        for (i, &v) in ring.iter().enumerate() {
            let (before, after) = (ring[(i + m - 1) % m], ring[(i + 1) % m]);
            lengths.extend(
                self.edges
                    .from(v)
                    .filter(|&w| w != before && w != after)
                    .map(|w| dist(self.pos[v as usize], self.pos[w as usize])),
            );
        }
        lengths.retain(|l| l.is_finite() && *l > 0.0);
        if lengths.is_empty() {
            return None;
        }
        let mid = lengths.len() / 2;
        Some(*lengths.select_nth_unstable_by(mid, f64::total_cmp).1)
    }

    /// The point of the surface over chart point `target` (on the chart's plane, normal `n`),
    /// reached by chords from the nearest of the vertices `starts` (in the working precision,
    /// in hops of at most `hop_length`), with its unit field normal, if that normal is within
    /// `turn_cos` of `n`.
    ///
    /// Distances are measured across the plane: the surface lies above or below it, by
    /// several hops on a wide far cap, and aiming at the target itself sent the hops round
    /// and round above it (points up to two edge lengths from where the chart put them).
    /// A hop along the surface covers less of the plane than its length where the surface
    /// is tilted, so the hops go on until the point is over the target to within
    /// [`LIFT_TOLERANCE`] hop lengths.
    fn lift(
        &self,
        starts: &[u32],
        target: [f64; 3],
        n: [f64; 3],
        turn_cos: f64,
        hop_length: f64,
    ) -> Option<([f64; 3], [f64; 3], Vec3<T>)> {
        let across = |q: [f64; 3]| {
            let d = sub(target, q);
            let h = dot(d, n);
            [d[0] - h * n[0], d[1] - h * n[1], d[2] - h * n[2]]
        };
        let reach = |q: [f64; 3]| {
            let d = across(q);
            dot(d, d)
        };
        let from = *starts.iter().min_by(|&&u, &&v| {
            reach(self.pos[u as usize])
                .total_cmp(&reach(self.pos[v as usize]))
                .then(u.cmp(&v))
        })?;
        // Hops of at most one local edge length: the chord's truncation error grows with the
        // fifth power of its length off cubic potentials.
        let mut point = self.work[from as usize].clone();
        let mut at = self.pos[from as usize];
        let mut over = false;
        for _ in 0..CHART_HOPS {
            let d = across(at);
            let length = dot(d, d).sqrt();
            if length.is_nan() {
                return None;
            }
            if length <= LIFT_TOLERANCE * hop_length {
                over = true;
                break;
            }
            point = trace::step_fixed(
                self.growth.field,
                &self.growth.cfg,
                &point,
                &Vec3::<T>::from_f64(d),
                &T::from_f64(length.min(hop_length)),
            )
            .ok()?;
            at = point.to_f64();
        }
        if !over {
            return None;
        }
        let (_, normal, _) = trace::unit_normal(self.growth.field, &point).ok()?;
        let (q, normal) = (point.to_f64(), normal.to_f64());
        let finite = q.iter().chain(&normal).all(|x| x.is_finite());
        (finite
            && q.iter().all(|x| x.abs() <= self.growth.bounding_box)
            && dot(normal, n) > turn_cos)
            .then_some((q, normal, point))
    }

    /// The largest tilt of a front triangle on corners `t` from their field normals,
    /// degrees: [`FRONT_TILT_DEG`] on a seam of an integrable surface other than an
    /// ellipsoid, away from curves stopped at a singular point; [`MAX_TILT_DEG`] elsewhere.
    fn tilt_limit(&self, t: [u32; 3]) -> f64 {
        let near_singular = t.iter().any(|&v| self.rim[v as usize] == Rim::Barren);
        if self.growth.new_points && !self.growth.ovaloid && !near_singular {
            FRONT_TILT_DEG
        } else {
            MAX_TILT_DEG
        }
    }

    /// Whether a triangle `t` of a hole's chart patch may go in: counter-clockwise in the
    /// chart (frame `e1`, `e2` at `centre`) also after lifting, facing the field at each
    /// corner within [`MAX_TILT_DEG`], and meeting no triangle already there (exact).
    fn patch_triangle_fits(
        &self,
        t: [u32; 3],
        n: [f64; 3],
        centre: [f64; 3],
        e1: [f64; 3],
        e2: [f64; 3],
    ) -> bool {
        let c = corners(&self.pos, t);
        let p2 = c.map(|q| {
            let d = sub(q, centre);
            [dot(d, e1), dot(d, e2)]
        });
        let turn = (p2[1][0] - p2[0][0]) * (p2[2][1] - p2[0][1])
            - (p2[1][1] - p2[0][1]) * (p2[2][0] - p2[0][0]);
        let face = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let ff = dot(face, face);
        if !(turn > 0.0 && ff > 0.0 && dot(face, n) > 0.0) {
            return false;
        }
        let cos_tilt = MAX_TILT_DEG.to_radians().cos();
        if t.iter()
            .any(|&v| tilts_past(face, ff, self.nrm[v as usize], cos_tilt))
        {
            return false;
        }
        self.face_meets_nothing(t)
    }

    /// Whether triangle `t` keeps clear of the other vertices of `ring` (a loop's ear must
    /// not cover part of the loop).
    fn covers_none(&self, ring: &[u32], t: [u32; 3]) -> bool {
        let c = corners(&self.pos, t);
        let size = (0..3)
            .map(|k| dist(c[k], c[(k + 1) % 3]))
            .fold(0.0, f64::max);
        ring.iter()
            .filter(|v| !t.contains(v))
            .all(|&v| point_triangle_distance(self.pos[v as usize], c) > EAR_CLEARANCE * size)
    }

    /// The boundary loop through edge `a → b`, if it is a simple loop (no pinched vertex on
    /// it) of at most `limit` edges.
    fn loop_from(&self, (a, b): (u32, u32), limit: usize) -> Option<Vec<u32>> {
        if !self.is_boundary_edge(a, b) {
            return None;
        }
        let mut ring = vec![a];
        let mut v = b;
        while v != a {
            if ring.len() > limit {
                return None;
            }
            ring.push(v);
            match self.boundary.outs(v) {
                [next] => v = *next,
                _ => return None,
            }
        }
        Some(ring)
    }

    /// The boundary loops that closing fronts left open: no vertex on a terminal boundary and
    /// at most [`REDO_HOLE`] edges. Each loop as its vertices.
    fn stuck_loops(&self) -> Vec<Vec<u32>> {
        let mut seen: HashSet<(u32, u32), FastHash> = HashSet::default();
        let mut out = Vec::new();
        for (a, b) in self.boundary_edge_list() {
            if seen.contains(&(a, b)) {
                continue;
            }
            // Walk the loop (at a pinched vertex, the first out-edge).
            let mut ring = Vec::new();
            let (mut u, mut v) = (a, b);
            let mut ok = true;
            while seen.insert((u, v)) {
                ring.push(u);
                if ring.len() > REDO_HOLE {
                    ok = false;
                }
                let Some(&w) = self.boundary.outs(v).first() else {
                    ok = false;
                    break;
                };
                (u, v) = (v, w);
            }
            // A loop on a terminal boundary is stuck only if it is short: a notch that the
            // rim pinched off, not the rim itself.
            let terminal = ring.iter().any(|&v| self.rim[v as usize] != Rim::Open);
            if ok && (!terminal || ring.len() <= SMALL_HOLE) {
                out.push(ring);
            }
        }
        out
    }

    /// Which vertices the stitching's triangles touch.
    fn touched(&self) -> Vec<bool> {
        let mut t = vec![false; self.pos.len()];
        for tri in &self.tris[self.initial..] {
            if *tri != DEAD {
                for &v in tri {
                    t[v as usize] = true;
                }
            }
        }
        t
    }

    /// Removes the triangles within `rings` rings of the vertices of `loops` (each round
    /// opens wider: a twist the last opening did not reach may be one ring farther); returns
    /// how many, and the vertices of the removed triangles.
    fn open_around(
        &mut self,
        loops: &[Vec<u32>],
        rings: usize,
    ) -> (Vec<[u32; 3]>, HashSet<u32, FastHash>) {
        let mut mark: HashSet<u32, FastHash> = loops.iter().flatten().copied().collect();
        let mut doomed: Vec<u32> = Vec::new();
        for ring in 0..rings {
            doomed = (0..self.tris.len() as u32)
                .filter(|&f| {
                    let t = self.tris[f as usize];
                    t != DEAD && t.iter().any(|v| mark.contains(v))
                })
                .collect();
            if ring + 1 < rings {
                // Not through the terminal boundary: the hole must stay a hole.
                for &f in &doomed {
                    let t = self.tris[f as usize];
                    mark.extend(t.iter().filter(|&&v| self.rim[v as usize] == Rim::Open));
                }
            }
        }
        let mut near = mark;
        let mut removed = Vec::with_capacity(doomed.len());
        for &f in &doomed {
            removed.push(self.tris[f as usize]);
            near.extend(self.tris[f as usize]);
            self.remove_triangle(f);
        }
        (removed, near)
    }

    /// Removes the islands: components of at most `limit` triangles (joined through shared
    /// edges) none of whose vertices ended a curve on a boundary, such as the chart's
    /// triangles left between dropped ones where many curves converge. Every triangle of such
    /// a component has a corner on the boundary, so only those are looked at. Returns how
    /// many triangles went.
    fn drop_islands(&mut self, limit: usize) -> usize {
        let near: Vec<u32> = (0..self.tris.len() as u32)
            .filter(|&f| {
                let t = self.tris[f as usize];
                t != DEAD && t.iter().any(|&v| self.on_boundary(v))
            })
            .collect();
        let mut by_edge: HashMap<(u32, u32), usize, FastHash> = HashMap::default();
        for (i, &f) in near.iter().enumerate() {
            let t = self.tris[f as usize];
            for k in 0..3 {
                by_edge.insert((t[k], t[(k + 1) % 3]), i);
            }
        }
        let mut sets = UnionFind::new(near.len());
        // Components joined to a triangle with no corner on the boundary are not islands.
        let mut anchored = vec![false; near.len()];
        for (i, &f) in near.iter().enumerate() {
            let t = self.tris[f as usize];
            for k in 0..3 {
                let twin = (t[(k + 1) % 3], t[k]);
                match by_edge.get(&twin) {
                    Some(&j) => {
                        sets.union(i as u32, j as u32);
                    }
                    None => anchored[i] |= self.edges.contains(twin.0, twin.1),
                }
            }
            anchored[i] |= t.iter().any(|&v| self.rim[v as usize] != Rim::Open);
        }
        let mut size = vec![0usize; near.len()];
        let mut root_anchored = vec![false; near.len()];
        for (i, &held) in anchored.iter().enumerate() {
            let r = sets.find(i as u32) as usize;
            size[r] += 1;
            root_anchored[r] |= held;
        }
        let doomed: Vec<u32> = near
            .iter()
            .enumerate()
            .filter(|&(i, _)| {
                let r = sets.find(i as u32) as usize;
                size[r] <= limit && !root_anchored[r]
            })
            .map(|(_, &f)| f)
            .collect();
        for &f in &doomed {
            self.remove_triangle(f);
        }
        doomed.len()
    }

    /// Removes triangle `f` (it stays as a tombstone until the end).
    fn remove_triangle(&mut self, f: u32) {
        let t = self.tris[f as usize];
        self.tris[f as usize] = DEAD;
        for v in t {
            self.touch(v);
        }
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            self.edges.remove(u, v);
            if self.edges.contains(v, u) {
                // Its twin is a boundary edge now.
                self.boundary.insert(v, u);
            } else {
                self.boundary.remove(u, v);
            }
        }
        for v in t {
            if self.boundary.scale(v).is_none() {
                self.points.insert(v, self.pos[v as usize]);
            }
            // The new boundary's scale: the longest of its boundary edges.
            let mut h = self.local(v);
            for &w in self.boundary.outs(v) {
                h = h.max(dist(self.pos[v as usize], self.pos[w as usize]));
            }
            self.boundary.set_scale(v, h);
        }
    }

    /// Adds triangle `t = (b, a, x)`.
    fn add(&mut self, t: [u32; 3]) {
        let f = self.tris.len() as u32;
        self.tris.push(t);
        self.faces.insert(f, corners(&self.pos, t));
        for v in t {
            self.touch(v);
        }
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            self.edges.insert(u, v);
            // If the twin `v → u` was a boundary edge, both are inside now.
            if !self.boundary.remove(v, u) {
                self.boundary.insert(u, v);
            }
        }
    }
}

/// Removes `v` from `list` (its first copy, swapping the last into its place); whether it
/// was there.
fn remove(list: &mut Vec<u32>, v: u32) -> bool {
    match list.iter().position(|&w| w == v) {
        Some(i) => {
            list.swap_remove(i);
            true
        }
        None => false,
    }
}

/// Two unit vectors across the unit normal `n`, the frame `(e1, e2, n)` right-handed.
fn tangent_frame(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = unit(cross(helper, n));
    (e1, cross(n, e1))
}

/// A closed walk split into loops that pass each vertex once: wherever the walk comes back
/// to a vertex, the part since its last visit is a loop of its own. The loops' edges are the
/// walk's, each once; loops of fewer than three vertices (an edge there and back) are left
/// out.
fn simple_loops(walk: &[u32]) -> Vec<Vec<u32>> {
    let mut loops = Vec::new();
    let mut path: Vec<u32> = Vec::with_capacity(walk.len());
    // Where each vertex on the path is (a far cap's loop has hundreds of vertices).
    let mut at: HashMap<u32, usize, FastHash> = HashMap::default();
    for &v in walk {
        if let Some(&k) = at.get(&v) {
            let tail = path.split_off(k);
            for u in &tail {
                at.remove(u);
            }
            if tail.len() >= 3 {
                loops.push(tail);
            }
        }
        at.insert(v, path.len());
        path.push(v);
    }
    if path.len() >= 3 {
        loops.push(path);
    }
    loops
}

/// Whether the closed polygon `p` is simple: no two edges meet but neighbours at their
/// shared corner (floating-point orientation tests with a margin, erring on "not simple").
fn simple_polygon(p: &[[f64; 2]]) -> bool {
    let m = p.len();
    let orient = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let size = p
        .iter()
        .flat_map(|q| q.iter())
        .fold(0.0f64, |s, x| s.max(x.abs()))
        .max(f64::MIN_POSITIVE);
    let eps = 1e-12 * size * size;
    for i in 0..m {
        let (a, b) = (p[i], p[(i + 1) % m]);
        for j in i + 1..m {
            if j == i + 1 || (i == 0 && j == m - 1) {
                continue;
            }
            let (c, d) = (p[j], p[(j + 1) % m]);
            let (o1, o2) = (orient(a, b, c), orient(a, b, d));
            let (o3, o4) = (orient(c, d, a), orient(c, d, b));
            let apart = (o1 > eps && o2 > eps)
                || (o1 < -eps && o2 < -eps)
                || (o3 > eps && o4 > eps)
                || (o3 < -eps && o4 < -eps);
            if !apart {
                return false;
            }
        }
    }
    true
}

/// Whether a face with normal `face` (of squared length `ff`) is further than the angle whose
/// cosine is `cos_limit` from the direction `n` (of any length): the front's and the patches'
/// tilt test, without normalising either.
#[inline]
fn tilts_past(face: [f64; 3], ff: f64, n: [f64; 3], cos_limit: f64) -> bool {
    dot(face, n) < cos_limit * (ff * dot(n, n)).sqrt()
}

/// The distance from `p` to the triangle `t` (closed).
fn point_triangle_distance(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let [a, b, c] = t;
    let n = cross(sub(b, a), sub(c, a));
    let nn = dot(n, n);
    if nn > 0.0 {
        // Inside the prism over the triangle: the distance to its plane.
        let inside = (0..3).all(|k| {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            dot(cross(sub(v, u), sub(p, u)), n) >= 0.0
        });
        if inside {
            return dot(sub(p, a), n).abs() / nn.sqrt();
        }
    }
    (0..3)
        .map(|k| segment_distance(p, t[k], t[(k + 1) % 3]))
        .fold(f64::INFINITY, f64::min)
}

fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let e = sub(b, a);
    let ee = dot(e, e);
    let u = if ee > 0.0 {
        (dot(sub(p, a), e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist(p, [a[0] + u * e[0], a[1] + u * e[1], a[2] + u * e[2]])
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    a.map(|x| x / l)
}

/// The corners' smallest and largest coordinates.
#[inline]
fn bounds(c: &[[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
    (
        [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k])),
        [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k])),
    )
}

fn corners(pos: &[[f64; 3]], t: [u32; 3]) -> [[f64; 3]; 3] {
    t.map(|v| pos[v as usize])
}

/// The angles of a triangle at its corners, radians.
fn angles([a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    let angle = |p: [f64; 3], q: [f64; 3], r: [f64; 3]| {
        let (u, v) = (sub(q, p), sub(r, p));
        let c = cross(u, v);
        dot(c, c).sqrt().atan2(dot(u, v))
    };
    [angle(a, b, c), angle(b, c, a), angle(c, a, b)]
}

/// Cuts pinched vertices apart: where the triangles around a vertex form more than one fan,
/// the triangles of all fans but the largest are removed, until no vertex is pinched.
/// Returns how many were removed.
pub(crate) fn unpinch(triangles: &mut Vec<[u32; 3]>) -> usize {
    let mut removed = 0;
    for _ in 0..64 {
        let drop = pinched_fans(triangles, |_| true).1;
        if drop.is_empty() {
            break;
        }
        let before = triangles.len();
        let mut f = 0u32;
        let mut next = drop.iter().peekable();
        triangles.retain(|_| {
            let gone = next.peek() == Some(&&f);
            if gone {
                next.next();
            }
            f += 1;
            !gone
        });
        removed += before - triangles.len();
    }
    removed
}

/// The pinched vertices among those `candidate` accepts (more than one fan of triangles
/// around them), and the triangles of all their fans but the largest (sorted). Skips
/// [`DEAD`] triangles.
fn pinched_fans(triangles: &[[u32; 3]], candidate: impl Fn(u32) -> bool) -> (Vec<u32>, Vec<u32>) {
    let n = triangles
        .iter()
        .filter(|t| **t != DEAD)
        .flat_map(|t| t.iter())
        .max()
        .map_or(0, |&m| m as usize + 1);
    // Vertex → triangles, in compressed rows, for the candidates.
    let candidate = &candidate;
    let corners = triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| **t != DEAD)
        .flat_map(|(f, t)| {
            t.iter()
                .filter(|&&v| candidate(v))
                .map(move |&v| (v as usize, f as u32))
        });
    let (start, star) = compressed_rows(n, corners).expect("n is above every live corner");
    let (mut pinched, mut drop) = (Vec::new(), Vec::new());
    let mut group = UnionFind::new(0);
    let (mut roots, mut sizes): (Vec<u32>, Vec<(u32, usize)>) = (Vec::new(), Vec::new());
    for v in 0..n {
        let faces = &star[start[v] as usize..start[v + 1] as usize];
        if faces.len() < 2 {
            continue;
        }
        // Union of the star's triangles that share an edge at v (a second common vertex).
        group.reset(faces.len());
        // Once every triangle is in one fan (the usual case) there is nothing to find.
        let mut fans = faces.len();
        'pairs: for i in 0..faces.len() {
            let ti = triangles[faces[i] as usize];
            for j in i + 1..faces.len() {
                let tj = triangles[faces[j] as usize];
                let shared = ti
                    .iter()
                    .filter(|&&w| w != v as u32 && tj.contains(&w))
                    .count();
                if shared > 0 && group.union(i as u32, j as u32) {
                    fans -= 1;
                    if fans == 1 {
                        break 'pairs;
                    }
                }
            }
        }
        if fans == 1 {
            continue;
        }
        roots.clear();
        roots.extend((0..faces.len() as u32).map(|i| group.find(i)));
        sizes.clear();
        for &r in &roots {
            match sizes.iter_mut().find(|(g, _)| *g == r) {
                Some(e) => e.1 += 1,
                None => sizes.push((r, 1)),
            }
        }
        if sizes.len() > 1 {
            pinched.push(v as u32);
            // The largest fan stays (the first of equals, by its lowest triangle).
            let keep = sizes
                .iter()
                .max_by_key(|(g, c)| (*c, std::cmp::Reverse(*g)))
                .map_or(0, |e| e.0);
            for (i, &r) in roots.iter().enumerate() {
                if r != keep {
                    drop.push(faces[i]);
                }
            }
        }
    }
    drop.sort_unstable();
    drop.dedup();
    (pinched, drop)
}

#[cfg(test)]
mod tests {
    use super::simple_loops;

    #[test]
    fn a_walk_through_a_vertex_twice_is_two_loops_each_edge_once() {
        // A 13-edge hole and a 3-edge one touching at vertex 5, walked as one.
        let walk = [1, 2, 3, 4, 5, 20, 21, 5, 6, 7, 8, 9];
        let loops = simple_loops(&walk);
        assert_eq!(
            loops,
            vec![vec![5, 20, 21], vec![1, 2, 3, 4, 5, 6, 7, 8, 9]]
        );
        let edges = |ring: &[u32]| {
            let m = ring.len();
            (0..m)
                .map(move |i| (ring[i], ring[(i + 1) % m]))
                .collect::<Vec<_>>()
        };
        let mut all: Vec<_> = loops.iter().flat_map(|l| edges(l)).collect();
        let mut want = edges(&walk);
        all.sort_unstable();
        want.sort_unstable();
        assert_eq!(all, want);
        // Nested returns, and an edge there and back (a two-vertex loop) left out.
        assert_eq!(
            simple_loops(&[1, 2, 3, 4, 2, 5, 6, 5, 7]),
            vec![vec![2, 3, 4], vec![1, 2, 5, 7]]
        );
        // A simple loop is itself.
        assert_eq!(simple_loops(&[3, 1, 2]), vec![vec![3, 1, 2]]);
    }
}
