//! Triangulation of the samples (the paper's second "Step 7").
//!
//! 1. **Chart 1**: every sample at its geodesic polar position `(s cos θ, s sin θ)` (with
//!    ties between congruent curves broken, see [`chart_points`]), a constrained
//!    Delaunay triangulation (spade) whose constraint is the front polygon — the curves' last
//!    points in order of θ — and only the triangles inside it.
//! 2. **Chart 2** (closed surfaces): the front polygon bounds the hole the curves left on the
//!    far side. It is projected onto the plane across the mean normal of its vertices and
//!    triangulated there with the polygon as constraints, sharing the polygon's vertices, so
//!    the two charts are stitched edge to edge and the mesh is watertight.
//! 3. Triangles are counter-clockwise in both charts, whose frames are right-handed about the
//!    field normal: every triangle is oriented with the field normal.
//! 4. In the default mode, edge flips make the result Delaunay on the surface itself, and a
//!    tangential relaxation along the surface evens out the triangles.
//! 5. With `MeshParams::max_normal_error`, faces whose normal strays further than that from
//!    the field's are split (new vertices on the surface) until none does: see
//!    [`Refinement`].

mod flip;
mod refine;
mod relax;
mod reopen;

pub(crate) use refine::refine;
pub use refine::{Refinement, MAX_REFINE_ROUNDS};
pub(crate) use relax::relax;

#[cfg(test)]
pub(crate) use crate::mesh::octahedron;
pub use crate::mesh::{Mesh, Provenance};

use crate::error::MeshError;
use crate::geom::vec3::{
    cross as cross3, dot as dot3, normalize as normalize3, sub as sub3, FastHash,
};
use crate::sample::{CurveEnd, Samples};
use crate::scalar::Scalar;
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation as _};

/// The chart-1 triangulation, kept for audits (empty-circumcircle checks, snapshots).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChartTriangulation {
    /// Chart position of every sample point (by sample index), as [`chart_points`] gives it.
    pub chart: Vec<[f64; 2]>,
    /// Chart-1 triangles (sample indices, counter-clockwise in the chart).
    pub triangles: Vec<[u32; 3]>,
    /// The front polygon (sample indices, counter-clockwise in the chart); its edges are the
    /// constraints.
    pub front: Vec<u32>,
    /// Triangles of chart 2 that close the surface (sample indices).
    pub closing: Vec<[u32; 3]>,
}

#[derive(Clone, Copy, Debug)]
struct ChartVertex {
    position: Point2<f64>,
    index: u32,
}

impl HasPosition for ChartVertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// Triangulates `samples` into a mesh (and returns the chart triangulation beside it).
///
/// With `improve`, edges are then flipped until the mesh is Delaunay on the surface (see the
/// module docs); without it the mesh is exactly the charts' triangulations (the paper).
pub fn triangulate<T: Scalar>(
    samples: &Samples<T>,
    close: bool,
    improve: bool,
) -> Result<(Mesh, ChartTriangulation), MeshError> {
    check_samples(samples)?;
    let n = samples.points.len();
    if n < 3 {
        return Err(MeshError::Triangulation(format!(
            "only {n} sample point(s); the curves ended right away (check p0, Δt and the terminal conditions)"
        )));
    }
    let chart = chart_points(samples);
    let front = front_polygon(samples, &chart);
    let pos: Vec<[f64; 3]> = samples.points.iter().map(|p| p.to_f64()).collect();

    let mut triangles = chart_triangles(&chart, &front)?;
    let closable = close && samples.front_closed() && front.len() >= 3;
    let mut closing = Vec::new();
    if closable {
        let normals: Vec<[f64; 3]> = front
            .iter()
            .map(|&i| samples.normals[i as usize].to_f64())
            .collect();
        closing = close_hole(&front, &pos, &normals, &triangles);
        if !stitches_cleanly(&triangles, &closing, n) {
            // Better an honest hole than a non-manifold mesh.
            closing.clear();
        }
    }

    let normals: Vec<[f64; 3]> = samples.normals.iter().map(|v| v.to_f64()).collect();
    // Chart 1 (or what is kept of it) and a closing, flipped to surface Delaunay in place,
    // with what the flip pass knows about folds.
    let finish = |mut all: Vec<[u32; 3]>, closing: &[[u32; 3]]| {
        all.extend_from_slice(closing);
        let mut folded = None;
        if improve {
            let budget = 8 * all.len() + 64;
            folded = flip::flip_to_surface_delaunay(&pos, &normals, &mut all, budget).folded;
        }
        // Every mesh the test suite makes checks the flags against a rescan.
        debug_assert!(
            folded.is_none_or(|f| f == folds(&all, &pos, &normals)),
            "the flip pass's fold flags disagree with a rescan"
        );
        (all, folded)
    };
    // Whether finished triangles face against the field somewhere: the flip pass knows when
    // it ran; otherwise look.
    let still_folds = |all: &[[u32; 3]], folded: Option<bool>| {
        folded.unwrap_or_else(|| folds(all, &pos, &normals))
    };
    // The finished triangles, once some closing (or none) is settled on.
    let mut finished = None;
    if !closing.is_empty() {
        // Closing triangles across a thin, twisted hole can face against the field, and flips
        // cannot always turn them round: then the hole stays open rather than folded. When
        // flips around the hole already leave a fold there, the pass over the whole mesh
        // would end the same way and is spared.
        let local = improve && folds_near_the_hole(&triangles, &closing, &pos, &normals);
        debug_assert!(
            !local || {
                let (all, folded) = finish(triangles.clone(), &closing);
                still_folds(&all, folded)
            },
            "a closing that folds near the hole was unfolded by the whole mesh's flips"
        );
        if local {
            closing.clear();
        } else {
            let (all, folded) = finish(triangles.clone(), &closing);
            if still_folds(&all, folded) {
                closing.clear();
            } else {
                finished = Some(all);
            }
        }
    }
    // A hole that would not close because chart 1 folds next to it (curves crossing a
    // caustic) gets a second try: the folded triangles and their neighbours are filled
    // together with the hole.
    if closable && closing.is_empty() {
        let accept = |kept: Vec<[u32; 3]>, fill: &[[u32; 3]]| {
            if !stitches_cleanly(&kept, fill, n) {
                return None;
            }
            let (all, folded) = finish(kept, fill);
            (!still_folds(&all, folded)).then_some(all)
        };
        if let Some(r) = reopen::reclose(&front, &triangles, &pos, &normals, accept) {
            triangles = r.kept;
            closing = r.closing;
            finished = Some(r.finished);
        }
    }
    let mut all = finished.unwrap_or_else(|| finish(triangles.clone(), &closing).0);
    // Three points on a line in space (curves that ran straight along a degenerate field)
    // make a triangle of no area and no normal, however good it looks in the chart.
    all.retain(|t| {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        cross3(sub3(b, a), sub3(c, a)) != [0.0; 3]
    });
    let mesh = assemble(samples, &pos, &all);
    Ok((
        mesh,
        ChartTriangulation {
            chart,
            triangles,
            front,
            closing,
        },
    ))
}

/// Relative radial offset of alternate curves' points in chart 1 (2⁻³⁰, about 10⁻⁹).
const TIE_BREAK: f64 = 1.0 / (1u64 << 30) as f64;

/// The positions chart 1 is triangulated at: each sample's geodesic polar position
/// [`Samples::chart`], pushed out along its ray by a relative 2⁻³⁰ on every other curve in
/// order of θ and pulled in by as much on the rest (with an odd number of curves, the last
/// one stays in place, so that any two neighbouring curves differ).
///
/// Curves that symmetry makes congruent (a surface of revolution traced from a pole) lay
/// their points on exact circles about `p0`, so every quadrilateral between two neighbouring
/// curves and two rings is an isosceles trapezoid, hence cocircular: which diagonal it gets
/// was left to rounding, and spade's exact predicates took their slow path at every such tie
/// (fig2's points took four times as long to triangulate as fig3's, per point). The offsets
/// decide each tie deterministically, alternating from one gap between curves to the next,
/// the pattern that the relaxation evens out best (fig2 in the default mode: smallest angle
/// 14.6° → 18.0°, 1 % quantile 23.9° → 35.6°, against leaving the ties to rounding). Each
/// curve's points stay on their ray, and `p0` stays at the origin.
///
/// ```
/// use liemesh::{model::LieField, preset::Preset, sample::sample, triangulate::chart_points};
///
/// let preset = Preset::Fig2;
/// let samples = sample(&LieField::<f64>::new(&preset.invariant()), &preset.params())?;
/// let chart = chart_points(&samples);
/// for (i, c) in chart.iter().enumerate() {
///     let polar = samples.chart(i);
///     assert!((c[0] - polar[0]).hypot(c[1] - polar[1]) <= 1e-9 * polar[0].hypot(polar[1]));
/// }
/// # Ok::<(), liemesh::MeshError>(())
/// ```
pub fn chart_points<T: Scalar>(samples: &Samples<T>) -> Vec<[f64; 2]> {
    let order = curves_by_theta(samples);
    // Pushed out (+1), pulled in (−1), or, closing an odd number of curves, left in place:
    // any two neighbours differ.
    let mut push = vec![0.0; samples.curves.len()];
    let odd_last = (order.len() % 2 == 1).then(|| order.len() - 1);
    for (rank, &c) in order.iter().enumerate() {
        push[c] = match rank % 2 {
            _ if Some(rank) == odd_last => 0.0,
            0 => 1.0,
            _ => -1.0,
        };
    }
    (0..samples.provenance.len())
        .map(|i| {
            let [x, y] = samples.chart(i);
            // Hand-built samples may name curves that do not exist.
            let f = 1.0
                + TIE_BREAK
                    * push
                        .get(samples.provenance[i].curve as usize)
                        .unwrap_or(&0.0);
            [x * f, y * f]
        })
        .collect()
}

/// The curves' indices in order of their angle θ at `p0` (ties by index).
fn curves_by_theta<T>(samples: &Samples<T>) -> Vec<usize> {
    let mut order: Vec<usize> = (0..samples.curves.len()).collect();
    order.sort_by(|&a, &b| samples.curves[a].theta.total_cmp(&samples.curves[b].theta));
    order
}

/// Rejects samples that [`sample`](crate::sample::sample) cannot produce but a caller who
/// builds [`Samples`] by hand can: vectors of different lengths, curves without points or
/// naming points that do not exist, non-finite points or normals (which would end up as NaN
/// vertices) and non-finite arc lengths or angles (which leave a point without a chart
/// position).
fn check_samples<T: Scalar>(samples: &Samples<T>) -> Result<(), MeshError> {
    let n = samples.points.len();
    let bad = |what: String| Err(MeshError::Triangulation(what));
    if samples.normals.len() != n || samples.provenance.len() != n {
        return bad(format!(
            "inconsistent samples: {n} points, {} normals and {} provenance entries (all must be equal)",
            samples.normals.len(),
            samples.provenance.len()
        ));
    }
    for (c, curve) in samples.curves.iter().enumerate() {
        if curve.points.is_empty() {
            return bad(format!("inconsistent samples: curve {c} has no points"));
        }
        if let Some(&i) = curve.points.iter().find(|&&i| i as usize >= n) {
            return bad(format!(
                "inconsistent samples: curve {c} names point {i}, but there are {n} points"
            ));
        }
    }
    if let Some(i) =
        (0..n).find(|&i| !(samples.points[i].is_finite() && samples.normals[i].is_finite()))
    {
        return bad(format!(
            "sample point {i} or its normal is not finite: {:?}, {:?}",
            samples.points[i].to_f64(),
            samples.normals[i].to_f64()
        ));
    }
    if let Some((i, pr)) = (samples.provenance.iter().enumerate())
        .find(|(_, pr)| !(pr.s.is_finite() && pr.theta.is_finite()))
    {
        return bad(format!(
            "sample point {i} has no chart position: its provenance says s = {}, θ = {} (both must be finite)",
            pr.s, pr.theta
        ));
    }
    Ok(())
}

/// The front polygon: each curve's last point in order of θ, without the ends of merged
/// curves that lie inside the polygon of their neighbours (those curves stopped between two
/// that went on, and the region beyond their end belongs to the mesh).
fn front_polygon<T: Scalar>(samples: &Samples<T>, chart: &[[f64; 2]]) -> Vec<u32> {
    let order = curves_by_theta(samples);
    let mut poly: Vec<(u32, bool)> = order
        .iter()
        .map(|&c| {
            let curve = &samples.curves[c];
            (*curve.points.last().unwrap(), curve.end == CurveEnd::Merge)
        })
        .collect();
    // Remove merged ends inside the triangle (origin, previous, next), until none is left.
    for _ in 0..poly.len() {
        let m = poly.len();
        if m <= 3 {
            break;
        }
        let mut keep = Vec::with_capacity(m);
        let mut removed = false;
        for i in 0..m {
            let (v, merged) = poly[i];
            if merged && !removed {
                let prev = chart[poly[(i + m - 1) % m].0 as usize];
                let next = chart[poly[(i + 1) % m].0 as usize];
                let here = chart[v as usize];
                // Inside the wedge triangle ⇔ on the origin's side of prev→next.
                if cross2(sub2(next, prev), sub2(here, prev)) > 0.0
                    && wedge_span(prev, next) < std::f64::consts::PI
                {
                    removed = true;
                    continue;
                }
            }
            keep.push(poly[i]);
        }
        if !removed {
            break;
        }
        poly = keep;
    }
    let mut front: Vec<u32> = poly.into_iter().map(|(v, _)| v).collect();
    front.dedup();
    if front.len() > 1 && front.first() == front.last() {
        front.pop();
    }
    front
}

fn sub2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Counter-clockwise angle from the direction of `a` to that of `b`, in `[0, 2π)`.
fn wedge_span(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[1].atan2(b[0]) - a[1].atan2(a[0])).rem_euclid(std::f64::consts::TAU)
}

/// Constrained Delaunay triangulation of the chart points, keeping the triangles inside the
/// front polygon.
fn chart_triangles(chart: &[[f64; 2]], front: &[u32]) -> Result<Vec<[u32; 3]>, MeshError> {
    let vertices: Vec<ChartVertex> = chart
        .iter()
        .enumerate()
        .map(|(i, c)| ChartVertex {
            position: Point2::new(c[0], c[1]),
            index: i as u32,
        })
        .collect();
    let m = front.len();
    let use_front = m >= 3 && star_shaped(chart, front);
    let cdt = ConstrainedDelaunayTriangulation::<ChartVertex>::bulk_load(vertices)
        .map_err(|e| MeshError::Triangulation(format!("spade rejected a chart point: {e:?}")))?;
    let mut cdt = cdt;
    if use_front {
        // Handles by sample index (duplicates were merged by spade; map through the data).
        let mut handle = vec![None; chart.len()];
        for v in cdt.vertices() {
            handle[v.data().index as usize] = Some(v.fix());
        }
        for i in 0..m {
            let (a, b) = (front[i] as usize, front[(i + 1) % m] as usize);
            if let (Some(ha), Some(hb)) = (handle[a], handle[b]) {
                if ha != hb {
                    cdt.try_add_constraint(ha, hb);
                }
            }
        }
    }
    let (a0, rel) = if use_front {
        star_angles(chart, front)
    } else {
        (0.0, Vec::new())
    };
    // The origin lies on the inner side of every front edge's line, so a point nearer to it
    // than the nearest such line is inside whichever wedge the angle search picks: most
    // centroids are settled without an arctangent.
    let disk = if use_front {
        inner_disk(chart, front)
    } else {
        0.0
    };
    let inside = |c: [f64; 2]| {
        !use_front || c[0] * c[0] + c[1] * c[1] < disk || inside_star(chart, front, (a0, &rel), c)
    };
    // One pass in spade's order, straight into the result: beside the triangulation itself
    // (the peak of memory here), a list of face handles would cost as much as the result.
    let triangles = cdt
        .inner_faces()
        .filter_map(|face| {
            let [a, b, c] = face.vertices();
            let (pa, pb, pc) = (a.position(), b.position(), c.position());
            let centroid = [(pa.x + pb.x + pc.x) / 3.0, (pa.y + pb.y + pc.y) / 3.0];
            (inside(centroid) && !rounding_sliver(pa, pb, pc))
                .then(|| [a.data().index, b.data().index, c.data().index])
        })
        .collect();
    Ok(triangles)
}

/// Whether the chart triangle's area is at the level of rounding: three points on a line,
/// such as `p0` and the first points of the curves at θ = 0 and θ = π (whose `sin π` is not
/// exactly 0), which spade keeps as a hull triangle but which has no area in space.
fn rounding_sliver(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>) -> bool {
    let (u, v) = ([b.x - a.x, b.y - a.y], [c.x - a.x, c.y - a.y]);
    let area = cross2(u, v).abs();
    // |u|₁ ≥ |u|, so a triangle clear of this looser bound (1 % over it, far above the
    // rounding of either) is no sliver, and the two `hypot`s are spared.
    let loose = 1.01e-12 * (u[0].abs() + u[1].abs()) * (v[0].abs() + v[1].abs());
    area <= loose && area <= 1e-12 * u[0].hypot(u[1]) * v[0].hypot(v[1])
}

/// Whether the polygon is star-shaped about the origin with vertices in counter-clockwise
/// angular order (each wedge less than π): then "inside" is a per-wedge half-plane test.
fn star_shaped(chart: &[[f64; 2]], front: &[u32]) -> bool {
    let m = front.len();
    let mut total = 0.0;
    for i in 0..m {
        let a = chart[front[i] as usize];
        let b = chart[front[(i + 1) % m] as usize];
        let span = wedge_span(a, b);
        if span >= std::f64::consts::PI || span <= 0.0 {
            return false;
        }
        total += span;
    }
    (total - std::f64::consts::TAU).abs() < 1e-6
}

/// A squared radius about the origin within which every point is on the inner side of every
/// front edge's line, or 0; the polygon must be star-shaped about the origin (see
/// [`star_shaped`]).
///
/// A point at `|c| < r` from the origin, `r` the distance to the nearest edge line, is
/// inside edge `(a, b)` by `cross(b − a, c − a) ≥ (r − |c|) |b − a|`. The radius is kept
/// 10⁻⁶ (relative) inside `r`, and edges whose line passes within 10⁻⁶ |a| of the origin
/// turn the shortcut off, so that this margin dwarfs the rounding of the cross product.
fn inner_disk(chart: &[[f64; 2]], front: &[u32]) -> f64 {
    let m = front.len();
    let mut nearest = f64::INFINITY;
    for i in 0..m {
        let a = chart[front[i] as usize];
        let b = chart[front[(i + 1) % m] as usize];
        let e = sub2(b, a);
        // Distance² from the origin to the edge's line: cross(e, −a)² / |e|².
        let d = cross2(e, [-a[0], -a[1]]);
        let ee = e[0] * e[0] + e[1] * e[1];
        let line = d * d / ee;
        if !(d > 0.0 && ee > 0.0 && line >= 1e-12 * (a[0] * a[0] + a[1] * a[1])) {
            return 0.0;
        }
        nearest = nearest.min(line);
    }
    if nearest.is_finite() {
        nearest * (1.0 - 1e-6)
    } else {
        0.0
    }
}

/// Polar angle of `p` in `[0, 2π)`.
fn polar_angle(p: [f64; 2]) -> f64 {
    p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU)
}

/// Polar angle of `p` relative to `a0`, in `[0, 2π)`.
fn rel_angle(a0: f64, p: [f64; 2]) -> f64 {
    (polar_angle(p) - a0).rem_euclid(std::f64::consts::TAU)
}

/// `a0` (the first front vertex's polar angle) and every front vertex's angle relative to
/// it, computed once for all the `inside_star` tests.
fn star_angles(chart: &[[f64; 2]], front: &[u32]) -> (f64, Vec<f64>) {
    let a0 = polar_angle(chart[front[0] as usize]);
    let rel = front
        .iter()
        .map(|&v| rel_angle(a0, chart[v as usize]))
        .collect();
    (a0, rel)
}

fn inside_star(chart: &[[f64; 2]], front: &[u32], (a0, rel): (f64, &[f64]), c: [f64; 2]) -> bool {
    // Wedge containing the direction of c, by binary search on the vertex angles.
    let target = rel_angle(a0, c);
    let m = front.len();
    // Vertex angles relative to the first are increasing (star-shaped, counter-clockwise).
    let (mut lo, mut hi) = (0usize, m);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if rel[mid] <= target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a = chart[front[lo] as usize];
    let b = chart[front[(lo + 1) % m] as usize];
    cross2(sub2(b, a), sub2(c, a)) >= 0.0
}

/// Chart 2: triangulates the hole bounded by the front polygon in the plane across the mean
/// normal of its vertices. Returns no triangles when the projected polygon is not simple.
fn close_hole(
    front: &[u32],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
    existing: &[[u32; 3]],
) -> Vec<[u32; 3]> {
    let m = front.len();
    let Some([f1, f2, _]) = frame_around(normals.iter().copied()) else {
        return Vec::new();
    };
    let proj: Vec<[f64; 2]> = front
        .iter()
        .map(|&i| {
            let p = pos[i as usize];
            [dot3(p, f1), dot3(p, f2)]
        })
        .collect();
    // Chart 1 lies to the left of the front, so seen from outside the hole the front runs
    // clockwise; when its projection does not (a curve overshot the hole), triangles that are
    // counter-clockwise in the projection would disagree with chart 1's orientation, and
    // ears are cut instead.
    let Some(out) = reopen::fill_flat(front, m, &proj) else {
        return clip_ears(front, pos, normals, existing);
    };
    // A diagonal of the hole that chart 1 already has as an edge would make the mesh
    // non-manifold: cut ears instead, which never repeat an edge.
    let mut have: EdgeSet = edges_among(existing, front, pos.len())
        .into_iter()
        .collect();
    for t in &out {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            // The hole's triangles use each loop edge in the opposite direction to chart 1,
            // and any other edge must be new.
            if have.contains(&(a, b)) || !have.insert((a, b)) {
                return clip_ears(front, pos, normals, existing);
            }
        }
    }
    out
}

/// Rows by vertex, in triangle order: `value(t, k)` for every corner `k` of every triangle
/// `t`, filed under the corner's vertex (compressed rows: vertex `v`'s values are
/// `list[start[v]..start[v + 1]]`). Returns `(start, list)`, or `None` if a corner is not
/// below `vertices`.
fn rows_by_corner(
    triangles: &[[u32; 3]],
    vertices: usize,
    value: impl Fn(usize, usize) -> u32,
) -> Option<(Vec<u32>, Vec<u32>)> {
    let mut start = vec![0u32; vertices + 1];
    for t in triangles {
        for &v in t {
            *start.get_mut(v as usize + 1)? += 1;
        }
    }
    for v in 0..vertices {
        start[v + 1] += start[v];
    }
    let mut fill: Vec<u32> = start[..vertices].to_vec();
    let mut list = vec![0u32; start[vertices] as usize];
    for (t, tr) in triangles.iter().enumerate() {
        for (k, &v) in tr.iter().enumerate() {
            list[fill[v as usize] as usize] = value(t, k);
            fill[v as usize] += 1;
        }
    }
    Some((start, list))
}

/// A right-handed frame `(f1, f2, n)` whose `n` is the mean of `normals`, or `None` when they
/// cancel out (or are not finite).
fn frame_around(normals: impl Iterator<Item = [f64; 3]>) -> Option<[[f64; 3]; 3]> {
    let mut mean = [0.0; 3];
    for n in normals {
        for k in 0..3 {
            mean[k] += n[k];
        }
    }
    let len = dot3(mean, mean).sqrt();
    if len.is_nan() || len <= 0.0 {
        return None;
    }
    let nm = mean.map(|x| x / len);
    let helper = if nm[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let f1 = normalize3(cross3(helper, nm));
    Some([f1, cross3(nm, f1), nm])
}

/// Rings of chart-1 vertices around a closing that [`folds_near_the_hole`] flips with it.
const HOLE_RINGS: usize = 4;

/// Whether the closing still folds after surface-Delaunay flips among its own triangles and
/// the chart-1 triangles within [`HOLE_RINGS`] rings of its vertices (a small part of the
/// mesh). Flips elsewhere do not reach a fold there, so the flip pass over the whole mesh
/// would leave it too (debug builds check that); `false` also when the region is not a
/// manifold the pass can flip.
fn folds_near_the_hole(
    chart: &[[u32; 3]],
    closing: &[[u32; 3]],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
) -> bool {
    let mut near = vec![false; pos.len()];
    for &v in closing.iter().flatten() {
        near[v as usize] = true;
    }
    let touches = |t: &[u32; 3], near: &[bool]| t.iter().any(|&v| near[v as usize]);
    for _ in 0..HOLE_RINGS {
        let mut grown = near.clone();
        for t in chart.iter().filter(|t| touches(t, &near)) {
            for &v in t {
                grown[v as usize] = true;
            }
        }
        near = grown;
    }
    let mut region: Vec<[u32; 3]> = chart
        .iter()
        .filter(|t| touches(t, &near))
        .copied()
        .collect();
    region.extend_from_slice(closing);
    let budget = 8 * region.len() + 64;
    flip::flip_to_surface_delaunay(pos, normals, &mut region, budget).folded == Some(true)
}

/// Whether any of `triangles` faces against the field normal at its corners (a closing
/// triangle across a thin, twisted hole can): the flip pass's own test.
fn folds(triangles: &[[u32; 3]], pos: &[[f64; 3]], normals: &[[f64; 3]]) -> bool {
    triangles
        .iter()
        .any(|&t| flip::against_field(pos, normals, t))
}

/// Whether `closing` meets `chart` edge to edge: every directed edge is used once, and every
/// edge of the union by at most two triangles in opposite directions.
///
/// Chart 1 alone is the inner faces of one planar triangulation, so only its edges between
/// vertices of `closing` can clash: those and `closing`'s are checked.
fn stitches_cleanly(chart: &[[u32; 3]], closing: &[[u32; 3]], vertices: usize) -> bool {
    let used: Vec<u32> = closing.iter().flatten().copied().collect();
    let mut directed: EdgeSet = edges_among(chart, &used, vertices).into_iter().collect();
    closing
        .iter()
        .all(|t| (0..3).all(|k| t[k] != t[(k + 1) % 3] && directed.insert((t[k], t[(k + 1) % 3]))))
}

/// Directed-edge sets keyed by vertex pairs.
type EdgeSet = std::collections::HashSet<(u32, u32), FastHash>;

/// The directed edges of `triangles` whose ends are both among `among` (indices below
/// `vertices`; larger ones are ignored): what a hole's triangles, whose corners are all on
/// its loop, can clash with, found without hashing every edge of the mesh.
fn edges_among(triangles: &[[u32; 3]], among: &[u32], vertices: usize) -> Vec<(u32, u32)> {
    let mut mark = vec![false; vertices];
    for &v in among {
        if let Some(m) = mark.get_mut(v as usize) {
            *m = true;
        }
    }
    let on = |v: u32| mark.get(v as usize).copied().unwrap_or(false);
    triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter(|&(a, b)| on(a) && on(b))
        .collect()
}

/// Closes a hole whose projection is not a simple polygon (e.g. the thin band an ellipsoid's
/// curves leave along a caustic): repeatedly cuts off the ear with the smallest angle inside
/// the hole, measured in space about the field normal, never creating an edge twice.
fn clip_ears(
    front: &[u32],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
    existing: &[[u32; 3]],
) -> Vec<[u32; 3]> {
    // (sample index, normal) around the loop; the hole lies to the right of the loop.
    let mut ring: Vec<(u32, [f64; 3])> =
        front.iter().copied().zip(normals.iter().copied()).collect();
    // Every edge the mesh already has: an ear must not repeat one (that would make it
    // non-manifold).
    let mut edges: EdgeSet = edges_among(existing, front, pos.len())
        .into_iter()
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    let mut out = Vec::with_capacity(ring.len());
    while ring.len() > 3 {
        let m = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..m {
            let (a, b, c) = (ring[(i + m - 1) % m].0, ring[i].0, ring[(i + 1) % m].0);
            if edges.contains(&(a.min(c), a.max(c))) {
                continue;
            }
            let u = sub3(pos[a as usize], pos[b as usize]);
            let w = sub3(pos[c as usize], pos[b as usize]);
            let angle = dot3(ring[i].1, cross3(u, w))
                .atan2(dot3(u, w))
                .rem_euclid(std::f64::consts::TAU);
            if best.is_none_or(|(b, _)| angle < b) {
                best = Some((angle, i));
            }
        }
        let Some((_, i)) = best else {
            return Vec::new();
        };
        let (a, b, c) = (ring[(i + m - 1) % m].0, ring[i].0, ring[(i + 1) % m].0);
        out.push([c, b, a]);
        edges.insert((a.min(c), a.max(c)));
        ring.remove(i);
    }
    out.push([ring[2].0, ring[1].0, ring[0].0]);
    out
}

/// Twice the signed area of the closed polygon: positive when it runs counter-clockwise.
fn signed_area(p: &[[f64; 2]]) -> f64 {
    let m = p.len();
    (0..m).map(|i| cross2(p[i], p[(i + 1) % m])).sum()
}

/// No two non-adjacent edges of the closed polygon meet (O(m²): the hole is small).
fn simple_polygon(p: &[[f64; 2]]) -> bool {
    let m = p.len();
    if m > 4096 {
        return false;
    }
    let seg = |i: usize| (p[i], p[(i + 1) % m]);
    for i in 0..m {
        for j in i + 1..m {
            if j == i + 1 || (i == 0 && j == m - 1) {
                continue;
            }
            let (a, b) = seg(i);
            let (c, d) = seg(j);
            let o1 = cross2(sub2(b, a), sub2(c, a));
            let o2 = cross2(sub2(b, a), sub2(d, a));
            let o3 = cross2(sub2(d, c), sub2(a, c));
            let o4 = cross2(sub2(d, c), sub2(b, c));
            if o1 * o2 <= 0.0 && o3 * o4 <= 0.0 {
                return false;
            }
        }
    }
    true
}

fn point_in_polygon(p: &[[f64; 2]], c: [f64; 2]) -> bool {
    let m = p.len();
    let mut inside = false;
    for i in 0..m {
        let (a, b) = (p[i], p[(i + 1) % m]);
        if (a[1] > c[1]) != (b[1] > c[1]) {
            let x = a[0] + (c[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if c[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Builds the mesh from the used samples, renumbering vertices in sample order.
fn assemble<T: Scalar>(samples: &Samples<T>, pos: &[[f64; 3]], triangles: &[[u32; 3]]) -> Mesh {
    let n = pos.len();
    let mut used = vec![false; n];
    for t in triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut remap = vec![u32::MAX; n];
    let mut mesh = Mesh::default();
    for i in 0..n {
        if used[i] {
            remap[i] = mesh.vertices.len() as u32;
            mesh.vertices.push(pos[i]);
            mesh.normals.push(samples.normals[i].to_f64());
            mesh.provenance.push(samples.provenance[i]);
        }
    }
    mesh.triangles = triangles
        .iter()
        .map(|t| {
            [
                remap[t[0] as usize],
                remap[t[1] as usize],
                remap[t[2] as usize],
            ]
        })
        .collect();
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::audit::XorShift64;

    /// A polygon star-shaped about the origin: `m` vertices at increasing angles.
    fn star(rng: &mut XorShift64, m: usize, wobble: f64) -> Vec<[f64; 2]> {
        let mut angles: Vec<f64> = (0..m)
            .map(|i| (i as f64 + rng.uniform(0.0, 0.9)) * std::f64::consts::TAU / m as f64)
            .collect();
        angles.sort_by(f64::total_cmp);
        angles
            .iter()
            .map(|&a| {
                let r = 1.0 + rng.uniform(-wobble, wobble);
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    #[test]
    fn points_in_the_inner_disk_are_inside_the_star() {
        let mut rng = XorShift64::new(11);
        for trial in 0..200 {
            let m = 3 + trial % 40;
            let chart = star(&mut rng, m, [0.0, 0.3, 0.9][trial % 3]);
            let front: Vec<u32> = (0..m as u32).collect();
            if !star_shaped(&chart, &front) {
                continue;
            }
            let disk = inner_disk(&chart, &front);
            let angles = star_angles(&chart, &front);
            for _ in 0..200 {
                let r = disk.sqrt() * rng.uniform(0.0, 1.0);
                let a = rng.uniform(0.0, std::f64::consts::TAU);
                let c = [r * a.cos(), r * a.sin()];
                if c[0] * c[0] + c[1] * c[1] < disk {
                    assert!(inside_star(&chart, &front, (angles.0, &angles.1), c));
                }
            }
        }
    }

    #[test]
    fn an_edge_through_the_origin_turns_the_inner_disk_off() {
        // The edge from (1, 0) to (−1, 1e-9) passes 5e-10 from the origin.
        let chart = [[1.0, 0.0], [-1.0, 1e-9], [0.0, -1.0]];
        assert_eq!(inner_disk(&chart, &[0, 1, 2]), 0.0);
    }

    #[test]
    fn slivers_are_found_as_by_the_exact_bound() {
        let exact = |a: Point2<f64>, b: Point2<f64>, c: Point2<f64>| {
            let (u, v) = ([b.x - a.x, b.y - a.y], [c.x - a.x, c.y - a.y]);
            cross2(u, v).abs() <= 1e-12 * u[0].hypot(u[1]) * v[0].hypot(v[1])
        };
        let mut rng = XorShift64::new(5);
        let mut slivers = 0;
        for _ in 0..20_000 {
            let a = Point2::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
            let d = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
            // Off the line through a along d by a relative amount from 1e-16 to 1e-8.
            let off = 10f64.powf(rng.uniform(-16.0, -8.0));
            let t = rng.uniform(-2.0, 2.0);
            let b = Point2::new(a.x + d[0], a.y + d[1]);
            let c = Point2::new(a.x + t * d[0] - off * d[1], a.y + t * d[1] + off * d[0]);
            let want = exact(a, b, c);
            slivers += usize::from(want);
            assert_eq!(rounding_sliver(a, b, c), want, "{a:?} {b:?} {c:?}");
        }
        assert!(slivers > 1000, "{slivers}");
    }
}
