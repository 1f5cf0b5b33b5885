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

mod chart_delaunay;
mod flip;
mod proximity;
mod refine;
mod relax;
mod stitch;
mod untangle;

pub(crate) use refine::{f64_normal, faces_over, refine};
pub use refine::{Refinement, MAX_REFINE_ROUNDS};
pub(crate) use relax::relax;
pub(crate) use stitch::unpinch;
pub use stitch::Stitched;
pub(crate) use untangle::{
    drop_unused, drop_unused_in, keep_main_component, relax_pinned, untangle, Before,
};
pub use untangle::{Untangled, UNTANGLE_ROUNDS};

#[cfg(test)]
pub(crate) use crate::mesh::octahedron;
pub use crate::mesh::{Mesh, Provenance};

use crate::error::MeshError;
use crate::geom::intersect::triangle_meets_line;
use crate::geom::union_find::UnionFind;
use crate::geom::vec3::{
    cross as cross3, dist as dist3, sub as sub3, turn_about, wider_than, FastHash,
};
use crate::model::LocalShape;
use crate::par;
use crate::params::Resolved;
use crate::sample::{CurveEnd, Samples};
use crate::scalar::{Scalar, Vec3};
use crate::trace::StepConfig;
use crate::NormalField;
use spade::{HasPosition, Point2, Triangulation as _};
use std::collections::HashMap;

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
/// module docs); without it the mesh is exactly the charts' triangulations (the paper). A run
/// that stitches its mesh flips once, after the stitching, instead ([`crate::run`]).
pub fn triangulate<T: Scalar>(
    samples: &Samples<T>,
    _close: bool,
    improve: bool,
) -> Result<(Mesh, ChartTriangulation), MeshError> {
    let chart = chart_triangulation(samples)?;
    let mesh = mesh_of_chart(samples, &chart, improve);
    Ok((mesh, chart))
}

/// The chart triangulation of `samples`: spade's constrained Delaunay triangulation of their
/// chart points inside the front, without the triangles that span a place where the chart is
/// not the surface. The costly half of [`triangulate`] (spade's bulk load), done once a run:
/// the stitching's retries and the state before relaxation rebuild the mesh from it with
/// [`mesh_of_chart`].
pub(crate) fn chart_triangulation<T: Scalar>(
    samples: &Samples<T>,
) -> Result<ChartTriangulation, MeshError> {
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
    // Chart triangles far larger in space than the sampling around them span a place where the
    // chart is not the surface: fronts that met, or ended far apart. The stitching below
    // closes what is left between real neighbours.
    let spacing = local_spacing(samples);
    let short = par::map(triangles.len(), par::MIN_CHEAP, |i| {
        let t = triangles[i];
        let h = t.iter().map(|&v| spacing[v as usize]).fold(0.0, f64::max);
        (0..3).all(|k| {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            dist3(pos[a], pos[b]) <= CHART_EDGE_FACTOR * h
        })
    });
    let mut short = short.into_iter();
    triangles.retain(|_| short.next() == Some(true));
    let normals: Vec<[f64; 3]> = samples.normals.iter().map(|v| v.to_f64()).collect();
    // Chart triangles that turn far from the field normal lie where the chart folds over
    // (inserted curves' chart positions are interpolated): they go, with the triangles
    // around them, and the stitching fills the hole in space.
    drop_folds(&pos, &normals, &mut triangles);
    Ok(ChartTriangulation {
        chart,
        triangles,
        front,
        closing: Vec::new(),
    })
}

/// The mesh of `samples` that `chart` (their [`chart_triangulation`]) gives, flipped to
/// surface Delaunay with `improve`.
pub(crate) fn mesh_of_chart<T: Scalar>(
    samples: &Samples<T>,
    chart: &ChartTriangulation,
    improve: bool,
) -> Mesh {
    let pos: Vec<[f64; 3]> = samples.points.iter().map(|p| p.to_f64()).collect();
    let normals: Vec<[f64; 3]> = samples.normals.iter().map(|v| v.to_f64()).collect();
    let mut all = chart.triangles.clone();
    if improve {
        let budget = 8 * all.len() + 64;
        flip::flip_to_surface_delaunay(&pos, &normals, &mut all, budget, &[], None);
    }
    // Three points on a line in space (curves that ran straight along a degenerate field)
    // make a triangle of no area and no normal, however good it looks in the chart.
    all.retain(|t| {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        cross3(sub3(b, a), sub3(c, a)) != [0.0; 3]
    });
    assemble(samples, &pos, &all)
}

/// Flips edges of `mesh` until it is Delaunay on the surface (at most 8 flips a triangle):
/// the stitched mesh's turn of the flips that [`triangulate`] gives a chart mesh that is not
/// stitched. The seams and patches the stitching adds are chosen one triangle at a time, and
/// relaxation moves each vertex towards its neighbours: on the far cap of a sphere traced from
/// its pole, relaxing them unflipped left its 1% smallest angle at 24° (fig2) where flipping
/// first gives 35.6°.
/// No flip makes a triangle that meets `axis` ([`NormalField::hole_through`]).
pub(crate) fn flip_to_surface_delaunay(mesh: &mut Mesh, axis: Option<[[f64; 3]; 2]>) {
    let budget = 8 * mesh.triangles.len() + 64;
    flip::flip_to_surface_delaunay(
        &mesh.vertices,
        &mesh.normals,
        &mut mesh.triangles,
        budget,
        &[],
        axis,
    );
}

/// The working-precision points of the vertices of `mesh`, every one a sample (a mesh as
/// [`triangulate`] makes it).
pub(crate) fn sample_vertices<T: Scalar>(samples: &Samples<T>, mesh: &Mesh) -> Vec<Vec3<T>> {
    mesh.provenance
        .iter()
        .map(|pr| {
            let i = samples.point_of(pr).expect("chart vertices are samples");
            samples.points[i as usize].clone()
        })
        .collect()
}

/// Where the vertex with provenance `pr` stands: the end of a curve that ended on a terminal
/// condition, at a singular point or on a budget, or not.
fn rim_of<T>(samples: &Samples<T>, pr: &Provenance) -> stitch::Rim {
    let Some(curve) = samples.curves.get(pr.curve as usize) else {
        return stitch::Rim::Open;
    };
    if pr.step as usize + 1 != curve.points.len() {
        return stitch::Rim::Open;
    }
    match curve.end {
        CurveEnd::Radius | CurveEnd::BoundingBox => stitch::Rim::Terminal,
        CurveEnd::Singular | CurveEnd::Budget => stitch::Rim::Barren,
        CurveEnd::Collision | CurveEnd::Merge => stitch::Rim::Open,
    }
}

/// Whether a point `q` at geodesic distance `s` from `p0` lies within `reach` of the bounding
/// box or of the geodesic radius: the surface ends there as it does at the end of a curve
/// that reached them.
pub(crate) fn near_terminal(
    q: [f64; 3],
    s: f64,
    reach: f64,
    bounding_box: f64,
    max_radius: f64,
) -> bool {
    q.iter().any(|x| x.abs() >= bounding_box - reach) || s >= max_radius - reach
}

/// How many loops of `boundary`'s edges (vertex pairs of `mesh`; loops that touch at a vertex
/// count as one) have no vertex on the surface's own rim (see [`Stitched::holes`]).
///
/// A vertex is on the rim where a curve ended on a terminal condition, at a singular point or
/// on a budget, and also where it lies within its longest boundary edge of the bounding box or
/// of the geodesic radius (`params`), and within the longest step `dt_max`: the end of a curve
/// that reached them may have gone with the triangles the validation dropped, leaving a
/// band's end (a cylinder's, at the box) lined with vertices of curves that merged there. (A
/// hole of a few long edges beside the box is not on the rim: a thin cylinder's, four edges
/// of 100 mesh edges each, one corner 1.5 longest steps from the box.)
///
/// Round a hole the field knows (`axis`, [`NormalField::hole_through`]), a loop that does
/// not go round the axis and has a vertex off the rim is a hole as well, rim or not: a band
/// whose mesh stopped short of closing round its waist (the fronts round a 100:1
/// hyperboloid's flange met and left a wedge open out to the box) is a disc whose one loop
/// runs along the box and then back where the surface goes on.
pub(crate) fn holes<T>(
    samples: &Samples<T>,
    params: &Resolved,
    mesh: &Mesh,
    boundary: &[(u32, u32)],
    axis: Option<[[f64; 3]; 2]>,
) -> usize {
    if boundary.is_empty() {
        return 0;
    }
    // The boundary's vertices, numbered densely in ascending order.
    let mut ends: Vec<u32> = boundary.iter().flat_map(|&(a, b)| [a, b]).collect();
    ends.sort_unstable();
    ends.dedup();
    let index = |v: u32| ends.binary_search(&v).expect("a boundary vertex") as u32;
    let mut loops = UnionFind::new(ends.len());
    for &(a, b) in boundary {
        loops.union(index(a), index(b));
    }
    // Each boundary vertex's longest boundary edge, but at most the longest step: a curve
    // that reached the box or the radius ended within a step of it.
    let mut reach = vec![0.0f64; ends.len()];
    for &(a, b) in boundary {
        let length = match (mesh.vertices.get(a as usize), mesh.vertices.get(b as usize)) {
            (Some(&p), Some(&q)) => dist3(p, q),
            _ => 0.0,
        };
        for v in [a, b] {
            let k = index(v) as usize;
            reach[k] = reach[k].max(length.min(params.dt_max));
        }
    }
    // A loop is on the rim if any of its vertices is; round a hole, it must also go round
    // it unless all of its vertices are.
    let mut on_rim = vec![false; ends.len()];
    let mut off_rim = vec![false; ends.len()];
    let turn = axis.map(|axis| turns_about(mesh, boundary, axis));
    for (k, &v) in ends.iter().enumerate() {
        let rim = match (
            mesh.provenance.get(v as usize),
            mesh.vertices.get(v as usize),
        ) {
            (Some(pr), Some(&q)) => {
                rim_of(samples, pr) != stitch::Rim::Open
                    || near_terminal(q, pr.s, reach[k], params.bounding_box, params.max_radius)
            }
            _ => false,
        };
        let root = loops.find(k as u32) as usize;
        on_rim[root] |= rim;
        off_rim[root] |= !rim;
    }
    // Each loop's turn about the axis: its boundary edges' angles summed.
    let mut turns = vec![0.0f64; ends.len()];
    if let Some(turn) = &turn {
        for (&(a, _), &angle) in boundary.iter().zip(turn) {
            turns[loops.find(index(a)) as usize] += angle;
        }
    }
    let misses_hole =
        |k: usize| turn.is_some() && off_rim[k] && turns[k].abs() < std::f64::consts::PI;
    (0..ends.len() as u32)
        .filter(|&k| loops.find(k) == k && (!on_rim[k as usize] || misses_hole(k as usize)))
        .count()
}

/// The angle each edge of `boundary` turns about `axis`, in the direction of the triangle it
/// bounds (a boundary loop that goes once round the axis sums to ±2π, one that does not to
/// 0, for edges that each turn less than π, as edges of a mesh that keeps off the axis do).
fn turns_about(mesh: &Mesh, boundary: &[(u32, u32)], axis: [[f64; 3]; 2]) -> Vec<f64> {
    // Each boundary edge lies on one triangle, which says which way it runs.
    let index: HashMap<(u32, u32), usize, FastHash> =
        boundary.iter().enumerate().map(|(i, &e)| (e, i)).collect();
    let at = |v: u32| mesh.vertices[v as usize];
    let mut turns = vec![0.0; boundary.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if let Some(&i) = index.get(&(a.min(b), a.max(b))) {
                turns[i] = turn_about(axis, at(a), at(b));
            }
        }
    }
    turns
}

/// Stitches the chart mesh where its fronts meet (see the `stitch` module): triangles
/// between boundary parts that face each other and, on an integrable field, new vertices on
/// the surface where a gap has none. `vertices` holds the mesh's vertices in the working
/// precision and grows with it.
pub(crate) fn stitch<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    samples: &Samples<T>,
    chart: &ChartTriangulation,
    mesh: &mut Mesh,
    vertices: &mut Vec<Vec3<T>>,
) -> Stitched {
    // Chart triangles across the surface's hole (a band's waist seen from a flat flange, where
    // the chart is a disc) go first; the stitching then holds its own to the same line.
    let axis = params.hole.map(|h| h.axis());
    let across = drop_across(mesh, axis);
    let mut stitched = stitch_chart(field, params, samples, chart, mesh, vertices, axis);
    stitched.removed += across;
    stitched
}

/// Removes the triangles of `mesh` that meet `axis` ([`NormalField::hole_through`]); returns
/// how many.
pub(crate) fn drop_across(mesh: &mut Mesh, axis: Option<[[f64; 3]; 2]>) -> usize {
    let Some(axis) = axis else {
        return 0;
    };
    let before = mesh.triangles.len();
    let p = &mesh.vertices;
    mesh.triangles
        .retain(|t| !triangle_meets_line(t.map(|v| p[v as usize]), axis));
    before - mesh.triangles.len()
}

/// Faces beside a singular point are peeled off the mesh's boundary while they stand further
/// than this off the surface (the field's normal at their centroid).
///
/// Curves end at different distances from a cone's apex (one step floor, a sharper bend on an
/// elliptic cone's narrow side), and a curve that went on past such an end, nearer the apex,
/// is joined to it by a fan of long faces across the sharply bending surface between them,
/// 60° to 116° off it on random elliptic cones; two curves that run into the apex side by side
/// can be joined by such a strip too. The mesh stops short of the apex there instead.
/// Elsewhere faces stand a few degrees off (a step turns the normal by at most `β_max`).
pub const SINGULAR_FAN_DEG: f64 = 40.0;

/// Removes the faces of `mesh` that stand further than [`SINGULAR_FAN_DEG`] off the surface,
/// have a corner on a curve of `samples` that ended at a singular point, and have a corner on
/// the boundary, again and again while the removals bring more of them to the boundary;
/// returns how many. Faces inside the mesh stay (taking them would open a hole). Nothing is
/// evaluated when no curve ended at a singular point.
pub(crate) fn peel_faces_beside_singular_points<T: Scalar, F: NormalField<T>>(
    field: &F,
    samples: &Samples<T>,
    mesh: &mut Mesh,
) -> usize {
    if !samples.curves.iter().any(|c| c.end == CurveEnd::Singular) {
        return 0;
    }
    let on_singular_curve: Vec<bool> = mesh
        .provenance
        .iter()
        .map(|pr| {
            samples
                .curves
                .get(pr.curve as usize)
                .is_some_and(|c| c.end == CurveEnd::Singular)
        })
        .collect();
    let normal_at = f64_normal(field);
    let p = &mesh.vertices;
    let off: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&f| {
            let t = mesh.triangles[f];
            t.iter().any(|&v| on_singular_curve[v as usize])
                && crate::geom::face_error_deg(t.map(|v| p[v as usize]), normal_at)
                    > SINGULAR_FAN_DEG
        })
        .collect();
    if off.is_empty() {
        return 0;
    }
    // Each vertex's faces; a vertex is on the boundary where one of its directed edges `v → u`
    // among its live faces has no `u → v` beside it.
    let tris = &mesh.triangles;
    let Some((start, faces)) = crate::geom::rows::rows_by_corner(tris, p.len(), |t, _| t as u32)
    else {
        return 0;
    };
    let mut gone = vec![false; tris.len()];
    let on_boundary = |v: u32, gone: &[bool]| {
        let star = || {
            faces[start[v as usize] as usize..start[v as usize + 1] as usize]
                .iter()
                .filter(|&&f| !gone[f as usize])
                .map(|&f| tris[f as usize])
        };
        let next = |t: [u32; 3]| t[(t.iter().position(|&x| x == v).unwrap_or(0) + 1) % 3];
        let prev = |t: [u32; 3]| t[(t.iter().position(|&x| x == v).unwrap_or(0) + 2) % 3];
        star().any(|t| !star().any(|o| prev(o) == next(t)))
            || star().any(|t| !star().any(|o| next(o) == prev(t)))
    };
    // A face is checked again only when a face at one of its corners goes (the only way its
    // corners can come to the boundary); what is peeled does not depend on the order.
    let mut is_off = vec![false; tris.len()];
    for &f in &off {
        is_off[f] = true;
    }
    let mut removed = 0;
    let mut stack = off;
    while let Some(f) = stack.pop() {
        if gone[f] || !tris[f].iter().any(|&v| on_boundary(v, &gone)) {
            continue;
        }
        gone[f] = true;
        removed += 1;
        for v in tris[f] {
            let star = &faces[start[v as usize] as usize..start[v as usize + 1] as usize];
            stack.extend(
                star.iter()
                    .map(|&g| g as usize)
                    .filter(|&g| is_off[g] && !gone[g]),
            );
        }
    }
    let mut gone = gone.into_iter();
    mesh.triangles.retain(|_| !gone.next().unwrap_or(false));
    removed
}

/// [`stitch`] once the chart's triangles across `axis` are gone.
fn stitch_chart<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    samples: &Samples<T>,
    chart: &ChartTriangulation,
    mesh: &mut Mesh,
    vertices: &mut Vec<Vec3<T>>,
    axis: Option<[[f64; 3]; 2]>,
) -> Stitched {
    // New points only on an integrable field: checked at p0 and at samples spread over the
    // run (a field may be integrable near p0 and not farther out).
    let probes = 16.min(samples.points.len()).max(1);
    let integrable = (0..probes).all(|k| {
        let i = k * samples.points.len() / probes;
        LocalShape::at::<T, F>(field, samples.points[i].to_f64()).is_none_or(|s| s.is_integrable())
    });
    let rim_of = |pr: &Provenance| rim_of(samples, pr);
    let rim: Vec<stitch::Rim> = mesh.provenance.iter().map(rim_of).collect();
    let growth = stitch::Growth {
        field,
        cfg: StepConfig::new(params),
        bounding_box: params.bounding_box,
        max_radius: params.max_radius,
        max_vertices: params.max_points,
        new_points: integrable,
        well_shaped: true,
        ovaloid: field.semi_axes_through(params.p0).is_some(),
        axis,
    };
    let (mut stitched, mut open) = stitch::stitch(mesh, vertices, &rim, &[], &growth);
    if open == 0 || !integrable {
        return stitched;
    }
    // The well-shaped seam can leave fronts that a seam of sharper triangles would have
    // joined (a thin tube's far side): the stitching is tried again from the chart's mesh
    // with every triangle down to the smallest angle competing from the start, and the result
    // with less open boundary is kept.
    let growth = stitch::Growth {
        well_shaped: false,
        ..growth
    };
    // The chart's mesh once more for both retries below (unflipped, as the first attempt's:
    // the stitched mesh is flipped afterwards).
    let mut chart_mesh = mesh_of_chart(samples, chart, false);
    drop_across(&mut chart_mesh, axis);
    let mut again = chart_mesh.clone();
    let mut again_vertices = sample_vertices(samples, &again);
    let (again_stitched, again_open) =
        stitch::stitch(&mut again, &mut again_vertices, &rim, &[], &growth);
    if again_open < open {
        (*mesh, *vertices, stitched, open) = (again, again_vertices, again_stitched, again_open);
    }
    if open == 0 {
        return stitched;
    }
    // Boundary left open between fronts that met: most often where the chart's triangles were
    // dropped over a long stretch (the far side of a torus's ring), and the front, placing
    // points of its own, could not grow across it. The stitching is tried again from the
    // chart's mesh with the samples the chart left without triangles offered as free
    // vertices, at their own spacing (see the `stitch` module); the result with less open
    // boundary is kept. (Offering them always would cost the sphere's far cap, where curves
    // crowd, most of the stitching's time again, and change its mesh.)
    let mut retry = chart_mesh;
    let mut retry_vertices = sample_vertices(samples, &retry);
    let first_free = retry.vertices.len();
    let mut used = vec![false; samples.points.len()];
    for i in retry
        .provenance
        .iter()
        .filter_map(|pr| samples.point_of(pr))
    {
        used[i as usize] = true;
    }
    let spacing = local_spacing(samples);
    let mut free = Vec::new();
    for (i, _) in used.iter().enumerate().filter(|(_, &u)| !u) {
        free.push((retry.vertices.len() as u32, spacing[i]));
        retry.vertices.push(samples.points[i].to_f64());
        retry.normals.push(samples.normals[i].to_f64());
        retry.provenance.push(samples.provenance[i]);
        retry_vertices.push(samples.points[i].clone());
    }
    if free.is_empty() {
        return stitched;
    }
    let retry_rim: Vec<stitch::Rim> = retry.provenance.iter().map(rim_of).collect();
    let (again, open_again) =
        stitch::stitch(&mut retry, &mut retry_vertices, &retry_rim, &free, &growth);
    if open_again < open {
        drop_unused_in(
            &mut retry,
            &mut retry_vertices,
            first_free..first_free + free.len(),
        );
        *mesh = retry;
        *vertices = retry_vertices;
        again
    } else {
        stitched
    }
}

/// Chart triangles whose normal is further than this from their corners' field normals are
/// folds.
const FOLD_DEG: f64 = 60.0;

/// Chart triangles whose corners' field normals are further apart than this bridge two
/// sheets of the surface: adjacent samples differ by a step's turn (a few degrees), so only a
/// triangle between samples that are not neighbours on the surface spans such a turn. The
/// face test alone lets one through where the two sheets' normals sum to its own, as across
/// the rim of a flattened ellipsoid (`[1, 2, 100]` from `(1, 0, 0)`: handles where the rim
/// should be).
const BRIDGE_DEG: f64 = 120.0;

/// Whether two corners of `t` have field normals further apart than the angle whose cosine
/// is `limit_cos` (a corner without a normal is not compared).
fn bridges(normals: &[[f64; 3]], t: [u32; 3], limit_cos: f64) -> bool {
    let n = t.map(|v| normals[v as usize]);
    (0..3).any(|k| wider_than(n[k], n[(k + 1) % 3], limit_cos))
}

/// Removes the chart triangles that fold ([`FOLD_DEG`]) or bridge two sheets
/// ([`BRIDGE_DEG`]), and every triangle that shares a corner with one.
fn drop_folds(pos: &[[f64; 3]], normals: &[[f64; 3]], triangles: &mut Vec<[u32; 3]>) {
    let limit = FOLD_DEG.to_radians().cos();
    let spread_limit = BRIDGE_DEG.to_radians().cos();
    let folds = par::map(triangles.len(), par::MIN_CHEAP, |i| {
        let t = triangles[i];
        flip::agreement(pos, normals, t) < limit || bridges(normals, t, spread_limit)
    });
    if !folds.contains(&true) {
        return;
    }
    let mut bad = vec![false; pos.len()];
    for (&t, _) in triangles.iter().zip(&folds).filter(|(_, &f)| f) {
        for v in t {
            bad[v as usize] = true;
        }
    }
    triangles.retain(|t| !t.iter().any(|&v| bad[v as usize]));
}

/// A chart triangle is kept only if no edge is longer in space than this many times the
/// largest [`local_spacing`] at its corners.
const CHART_EDGE_FACTOR: f64 = 4.0;

/// How far apart the samples are around each sample point: the longer of the steps into and
/// out of it on its curve, and, when no curve was inserted (the previous method, whose
/// curves spread apart with the radius), the arc between neighbouring curves at its radius.
fn local_spacing<T>(samples: &Samples<T>) -> Vec<f64> {
    let mut h = vec![0.0f64; samples.points.len()];
    for curve in &samples.curves {
        for (k, &i) in curve.points.iter().enumerate() {
            let before = samples.steps[i as usize].dt;
            let after = curve
                .points
                .get(k + 1)
                .map_or(0.0, |&j| samples.steps[j as usize].dt);
            let i = i as usize;
            h[i] = h[i].max(before).max(after);
        }
    }
    if samples.curves.iter().all(|c| c.parent.is_none()) && !samples.curves.is_empty() {
        let arc = std::f64::consts::TAU / samples.curves.len() as f64;
        for (i, pr) in samples.provenance.iter().enumerate() {
            h[i] = h[i].max(pr.s * arc);
        }
    }
    h
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
    let poly: Vec<(u32, bool)> = order
        .iter()
        .map(|&c| {
            let curve = &samples.curves[c];
            (*curve.points.last().unwrap(), curve.end == CurveEnd::Merge)
        })
        .collect();
    // Remove merged ends inside the triangle (origin, previous, next), the first in θ order
    // each time, until none is left (or three ends are). A removal changes the test only for
    // its two neighbours, so the ends that pass it are kept in an ordered set and the two
    // are tested again: linear-logarithmic, where scanning the whole polygon per removal was
    // quadratic (a flattened ellipsoid's 27,847 merged curves: 0.6 s of its run).
    let m = poly.len();
    let mut prev: Vec<usize> = (0..m).map(|i| (i + m - 1) % m).collect();
    let mut next: Vec<usize> = (0..m).map(|i| (i + 1) % m).collect();
    let inside = |i: usize, prev: &[usize], next: &[usize]| {
        let (v, merged) = poly[i];
        merged && {
            let before = chart[poly[prev[i]].0 as usize];
            let after = chart[poly[next[i]].0 as usize];
            let here = chart[v as usize];
            // Inside the wedge triangle ⇔ on the origin's side of before→after.
            cross2(sub2(after, before), sub2(here, before)) > 0.0
                && wedge_span(before, after) < std::f64::consts::PI
        }
    };
    let mut alive = vec![true; m];
    let mut left = m;
    let mut ready: std::collections::BTreeSet<usize> =
        (0..m).filter(|&i| inside(i, &prev, &next)).collect();
    while left > 3 {
        let Some(i) = ready.pop_first() else {
            break;
        };
        let (p, n) = (prev[i], next[i]);
        next[p] = n;
        prev[n] = p;
        alive[i] = false;
        left -= 1;
        for j in [p, n] {
            if inside(j, &prev, &next) {
                ready.insert(j);
            } else {
                ready.remove(&j);
            }
        }
    }
    let mut front: Vec<u32> = (0..m).filter(|&i| alive[i]).map(|i| poly[i].0).collect();
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
    // spade takes coordinates between about 1e-43 and 1e60 in magnitude: a chart far outside
    // (a surface of size 1e-50 or 1e100) is scaled by a power of two, which changes no
    // predicate's sign; charts of ordinary size are handed over as they are. A small chart is
    // scaled up too, to coordinates of 16–32 at most (as on a surface of unit size): spade's
    // bulk load walks its hull with a test that allows `f64::EPSILON` on squared lengths,
    // which on a chart 10⁻⁵ across breaks ties of cocircular points another way (a posed
    // cone from `p0` scaled by 2⁻²⁰ kept a hole at its apex that it closes at unit size).
    let largest = chart.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    let unit = if largest > 0.0 && largest < 2f64.powi(-8) {
        2f64.powi(4 - largest.log2().floor() as i32)
    } else if largest > 2f64.powi(60) {
        2f64.powi(-largest.log2().round() as i32)
    } else {
        1.0
    };
    let vertices: Vec<ChartVertex> = chart
        .iter()
        .enumerate()
        .map(|(i, c)| ChartVertex {
            position: Point2::new(c[0] * unit, c[1] * unit),
            index: i as u32,
        })
        .collect();
    let m = front.len();
    let use_front = m >= 3 && star_shaped(chart, front);
    let cdt = chart_delaunay::triangulate(vertices)
        .map_err(|e| MeshError::Triangulation(format!("spade rejected a chart point: {e:?}")))?;
    let mut cdt = cdt;
    if m >= 3 {
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
    // A front that is not star-shaped about p0 (curves that ended at very different radii)
    // bounds the mesh all the same: inside by the even-odd rule.
    let polygon = EvenOdd::new(if !use_front && m >= 3 {
        front.iter().map(|&v| chart[v as usize]).collect()
    } else {
        Vec::new()
    });
    let inside = |c: [f64; 2]| {
        if use_front {
            c[0] * c[0] + c[1] * c[1] < disk || inside_star(chart, front, (a0, &rel), c)
        } else {
            polygon.is_empty() || polygon.contains(c)
        }
    };
    let kept = |face: spade::handles::FaceHandle<'_, _, ChartVertex, _, _, _>| {
        let [a, b, c] = face.vertices();
        let (pa, pb, pc) = (a.position(), b.position(), c.position());
        let centroid = [
            (pa.x + pb.x + pc.x) / 3.0 / unit,
            (pa.y + pb.y + pc.y) / 3.0 / unit,
        ];
        (inside(centroid) && !rounding_sliver(pa, pb, pc))
            .then(|| [a.data().index, b.data().index, c.data().index])
    };
    // Reading the faces out of spade's DCEL is a walk through memory in no spatial order
    // (a tenth of a 10⁵-triangle run's chart triangulation), so large charts are read in
    // chunks side by side, in spade's order all the same.
    let faces = cdt.num_inner_faces();
    if faces < par::MIN_CHEAP {
        return Ok(cdt.inner_faces().filter_map(kept).collect());
    }
    const CHUNKS: usize = 16;
    let handles: Vec<_> = cdt.fixed_inner_faces().collect();
    let parts = par::map(CHUNKS, 2, |c| {
        handles[c * faces / CHUNKS..(c + 1) * faces / CHUNKS]
            .iter()
            .filter_map(|&h| kept(cdt.face(h)))
            .collect::<Vec<_>>()
    });
    drop(handles);
    Ok(parts.concat())
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

/// A polygon for even-odd tests of many points, its edges filed so that a point is tested
/// against a few of them instead of all.
///
/// First by the rows of `y` the edges span: only edges whose `y` range holds the point's `y`
/// can change the answer, and each of those is in the point's row (the row of a `y` never
/// decreases with it), so the answer is [`point_in_polygon`]'s, bit for bit. Where that
/// files too many (long edges across many rows: a front whose curves ended at very different
/// radii, as fronts about `p0` do), by the sectors of direction about the origin the edges
/// span, and the test counts crossings of the ray from the point away from the origin
/// ([`crosses_outward`]) instead of a ray along `x`: the same parity for every point off the
/// edges. A front whose curves are in order of θ spans each sector a few times (a horizontal
/// line crosses it at every spike); one with θ ties, which [`star_shaped`] refuses (curves
/// inserted into the same gap from both sides), took the edge-by-edge test's O(edges) per
/// triangle: 28 s of a 31 s run with 10⁴ front vertices.
struct EvenOdd {
    p: Vec<[f64; 2]>,
    filing: Filing,
}

/// How an [`EvenOdd`] polygon's edges are filed. Edge `i` runs from `p[i]` to `p[i + 1]`;
/// bin `r`'s edges are `edges[start[r]..start[r + 1]]`.
enum Filing {
    /// None: every edge is tested.
    All,
    /// By the rows of `y` they span, from `y0` at `inv` rows per unit.
    Rows {
        y0: f64,
        inv: f64,
        start: Vec<u32>,
        edges: Vec<u32>,
    },
    /// By the sectors of [`pseudo_angle`] they span about the origin.
    Sectors { start: Vec<u32>, edges: Vec<u32> },
}

/// Edges filed per edge, on average, above which a filing is not used.
const MAX_FILED_PER_EDGE: usize = 16;

impl EvenOdd {
    fn new(p: Vec<[f64; 2]>) -> EvenOdd {
        let m = p.len();
        // Small polygons, and any with a non-finite coordinate, are tested edge by edge.
        let filing = if m < 16 || !p.iter().flatten().all(|x| x.is_finite()) {
            Filing::All
        } else {
            by_rows(&p)
                .or_else(|| by_sectors(&p))
                .unwrap_or(Filing::All)
        };
        EvenOdd { p, filing }
    }

    fn is_empty(&self) -> bool {
        self.p.is_empty()
    }

    /// Whether `c` is inside by the even-odd rule.
    fn contains(&self, c: [f64; 2]) -> bool {
        let m = self.p.len();
        let edge = |i: u32| (self.p[i as usize], self.p[(i as usize + 1) % m]);
        match &self.filing {
            Filing::All => point_in_polygon(&self.p, c),
            Filing::Rows {
                y0,
                inv,
                start,
                edges,
            } => {
                let r = row(*y0, *inv, m, c[1]);
                edges[start[r] as usize..start[r + 1] as usize]
                    .iter()
                    .fold(false, |inside, &i| {
                        let (a, b) = edge(i);
                        inside ^ crosses_along_x(a, b, c)
                    })
            }
            Filing::Sectors { start, edges } => {
                // (The origin has no outward ray.)
                let Some(r) = sector(m, c) else {
                    return point_in_polygon(&self.p, c);
                };
                edges[start[r] as usize..start[r + 1] as usize]
                    .iter()
                    .fold(false, |inside, &i| {
                        let (a, b) = edge(i);
                        inside ^ crosses_outward(a, b, c)
                    })
            }
        }
    }
}

/// Files every edge of `p` in the bins `bins(i)` gives it (inclusive ranges of bin indices,
/// at most two, of `count` bins), unless that files more than [`MAX_FILED_PER_EDGE`] per edge.
fn file_edges(
    m: usize,
    count: usize,
    bins: impl Fn(usize) -> [Option<(usize, usize)>; 2],
) -> Option<(Vec<u32>, Vec<u32>)> {
    let mut start = vec![0u32; count + 1];
    let mut total = 0usize;
    for i in 0..m {
        for (r0, r1) in bins(i).into_iter().flatten() {
            total += r1 - r0 + 1;
            if total > MAX_FILED_PER_EDGE * m {
                return None;
            }
            for c in &mut start[r0 + 1..=r1 + 1] {
                *c += 1;
            }
        }
    }
    for r in 0..count {
        start[r + 1] += start[r];
    }
    let mut fill = start.clone();
    let mut edges = vec![0u32; total];
    for i in 0..m {
        for (r0, r1) in bins(i).into_iter().flatten() {
            for f in &mut fill[r0..=r1] {
                edges[*f as usize] = i as u32;
                *f += 1;
            }
        }
    }
    Some((start, edges))
}

/// The row of `y` among `rows` rows from `y0` at `inv` per unit (clamped; NaN in the first).
#[inline]
fn row(y0: f64, inv: f64, rows: usize, y: f64) -> usize {
    (((y - y0) * inv).floor().max(0.0) as usize).min(rows - 1)
}

/// `p`'s edges filed by the rows of `y` they span, one row per edge.
fn by_rows(p: &[[f64; 2]]) -> Option<Filing> {
    let m = p.len();
    let lo = p.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min);
    let hi = p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max);
    let inv = m as f64 / (hi - lo);
    if !(inv.is_finite() && inv > 0.0) {
        return None;
    }
    let (start, edges) = file_edges(m, m, |i| {
        let (a, b) = (p[i][1], p[(i + 1) % m][1]);
        [
            Some((row(lo, inv, m, a.min(b)), row(lo, inv, m, a.max(b)))),
            None,
        ]
    })?;
    Some(Filing::Rows {
        y0: lo,
        inv,
        start,
        edges,
    })
}

/// `p`'s edges filed by the sectors of direction about the origin they span, one sector per
/// edge. Each edge goes in the sectors of the shorter arc between its ends' directions (the
/// directions of its points) and one more on each side, so that rounding in
/// [`pseudo_angle`] near a sector's border cannot leave it out of the sector of a point whose
/// outward ray crosses it; an edge through the origin goes everywhere.
fn by_sectors(p: &[[f64; 2]]) -> Option<Filing> {
    let m = p.len();
    let (start, edges) = file_edges(m, m, |i| {
        let (a, b) = (p[i], p[(i + 1) % m]);
        let (ka, kb) = match (sector(m, a), sector(m, b)) {
            (Some(ka), Some(kb)) => (ka, kb),
            // An end at the origin: the edge lies along the other end's direction.
            (Some(k), None) | (None, Some(k)) => return wrapped(m, k, k),
            (None, None) => return [None, None],
        };
        let (turn, along) = (cross2(a, b), a[0] * b[0] + a[1] * b[1]);
        if turn == 0.0 && along < 0.0 {
            return [Some((0, m - 1)), None];
        }
        // Counter-clockwise from the first to the second. Ends less than a quarter turn
        // apart span at most two quarters of the pseudo-angle, half the sectors: more is
        // rounding that put two nearly equal directions in reverse order.
        let (from, to) = if turn >= 0.0 { (ka, kb) } else { (kb, ka) };
        if along > 0.0 && 2 * ((to + m - from) % m) > m {
            wrapped(m, to, from)
        } else {
            wrapped(m, from, to)
        }
    })?;
    Some(Filing::Sectors { start, edges })
}

/// The sectors from `from` counter-clockwise to `to` (of `m`), widened by one on each side,
/// as at most two inclusive ranges.
fn wrapped(m: usize, from: usize, to: usize) -> [Option<(usize, usize)>; 2] {
    let steps = (to + m - from) % m;
    if steps + 3 > m {
        return [Some((0, m - 1)), None];
    }
    let first = (from + m - 1) % m;
    let last = first + steps + 2;
    if last < m {
        [Some((first, last)), None]
    } else {
        [Some((first, m - 1)), Some((0, last - m))]
    }
}

/// The sector of `c`'s direction among `m` equal sectors of [`pseudo_angle`]; `None` at the
/// origin (or for a non-finite `c`).
fn sector(m: usize, c: [f64; 2]) -> Option<usize> {
    let t = pseudo_angle(c)?;
    Some(((t * (m as f64 / 4.0)) as usize).min(m - 1))
}

/// A direction's angle about the origin as a number in `[0, 4)` that grows with it
/// counter-clockwise from `+x` (not in proportion: a quarter turn per unit, with no
/// arctangent); `None` at the origin.
fn pseudo_angle(c: [f64; 2]) -> Option<f64> {
    let [x, y] = c;
    let r = x.abs() + y.abs();
    if !(r > 0.0 && r.is_finite()) {
        return None;
    }
    let t = if y >= 0.0 {
        if x >= 0.0 {
            y / r
        } else {
            1.0 - x / r
        }
    } else if x < 0.0 {
        2.0 - y / r
    } else {
        3.0 + x / r
    };
    Some(t.min(4.0 - f64::EPSILON * 4.0))
}

/// Whether edge `a → b` crosses the ray from `c` along `+x` (half-open in `y`, the rule of
/// [`point_in_polygon`]).
#[inline]
fn crosses_along_x(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    if (a[1] > c[1]) != (b[1] > c[1]) {
        let x = a[0] + (c[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
        c[0] < x
    } else {
        false
    }
}

/// Whether edge `a → b` crosses the ray from `c` away from the origin: the line through
/// the origin and `c` separates `a` and `b` (half-open, like [`crosses_along_x`]), and meets
/// the edge at `t c` with `t > 1`, where `t (c × (b − a)) = a × b`.
#[inline]
fn crosses_outward(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    let (sa, sb) = (cross2(c, a), cross2(c, b));
    if (sa > 0.0) != (sb > 0.0) {
        let (num, den) = (cross2(a, b), sb - sa);
        // t > 1 with the sign of the denominator taken into account.
        if den > 0.0 {
            num > den
        } else {
            num < den
        }
    } else {
        false
    }
}

/// Whether `c` is inside polygon `p` by the even-odd rule, every edge tested.
fn point_in_polygon(p: &[[f64; 2]], c: [f64; 2]) -> bool {
    let m = p.len();
    (0..m).fold(false, |inside, i| {
        inside ^ crosses_along_x(p[i], p[(i + 1) % m], c)
    })
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
    use crate::geom::rng::XorShift64;

    /// A hole cut into a closed sphere is a loop where the surface goes on; the rim of a disc
    /// that curves ended at the geodesic radius is not, however many edges it has.
    #[test]
    fn holes_are_boundary_loops_away_from_the_surfaces_own_rim() {
        use crate::preset::Preset;
        for (preset, closed) in [(Preset::Fig3, true), (Preset::Fig6, false)] {
            let field = crate::model::LieField::<f64>::new(&preset.invariant());
            let run = crate::run(&field, &preset.params()).expect("the preset meshes");
            let mut mesh = run.mesh.clone();
            let (v, boundary) = crate::mesh::validate_with_boundary(&mesh);
            assert_eq!(v.is_closed(), closed, "{preset:?}: {v}");
            assert_eq!(
                holes(&run.samples, &run.params, &mesh, &boundary, None),
                0,
                "{preset:?}"
            );
            assert_eq!(run.stitched.holes, 0, "{preset:?}");
            // Two triangles away from the rim (well inside the radius and the box) and from
            // each other: two holes.
            let (radius, box_size) = (run.params.max_radius, run.params.bounding_box);
            let inner: Vec<usize> = (0..mesh.triangles.len())
                .filter(|&f| {
                    mesh.triangles[f].iter().all(|&i| {
                        let pr = &mesh.provenance[i as usize];
                        rim_of(&run.samples, pr) == stitch::Rim::Open
                            && !boundary.iter().any(|&(a, b)| a == i || b == i)
                            && pr.s < 0.5 * radius
                            && mesh.vertices[i as usize]
                                .iter()
                                .all(|x| x.abs() < 0.5 * box_size)
                    })
                })
                .collect();
            let first = inner[0];
            let apart = |f: usize| {
                mesh.triangles[f]
                    .iter()
                    .all(|i| !mesh.triangles[first].contains(i))
            };
            let second = *inner.iter().rev().find(|&&f| apart(f)).expect("two apart");
            mesh.triangles.remove(first.max(second));
            mesh.triangles.remove(first.min(second));
            let (_, boundary) = crate::mesh::validate_with_boundary(&mesh);
            assert_eq!(
                holes(&run.samples, &run.params, &mesh, &boundary, None),
                2,
                "{preset:?}"
            );
        }
    }

    /// The rim rule shared by the holes count and the stitcher's new points: within `reach`
    /// of any face of the box (either sign, any axis) or of the geodesic radius, and nowhere
    /// else.
    #[test]
    fn near_terminal_is_within_reach_of_the_box_or_the_radius() {
        let (reach, bounding_box, max_radius) = (0.5, 10.0, 20.0);
        let near = |q: [f64; 3], s: f64| near_terminal(q, s, reach, bounding_box, max_radius);
        assert!(!near([0.0, 0.0, 0.0], 0.0));
        assert!(!near([9.49, -9.49, 9.49], 19.49));
        for k in 0..3 {
            for sign in [1.0, -1.0] {
                let mut q = [1.0, 2.0, 3.0];
                q[k] = sign * 9.5;
                assert!(near(q, 5.0), "{q:?}");
                q[k] = sign * 9.49;
                assert!(!near(q, 5.0), "{q:?}");
            }
        }
        assert!(near([0.0; 3], 19.5));
        assert!(near([0.0; 3], 25.0));
        // No reach: only what reached the box or the radius.
        assert!(!near_terminal([9.99, 0.0, 0.0], 19.99, 0.0, 10.0, 20.0));
        assert!(near_terminal([-10.0, 0.0, 0.0], 0.0, 0.0, 10.0, 20.0));
    }

    /// Filed by rows, the even-odd test answers as the edge-by-edge one bit for bit, on
    /// random polygons (also self-intersecting ones, with repeated and horizontal edges) and
    /// on points at their vertices' coordinates (on horizontal edges, even).
    #[test]
    fn filed_even_odd_test_agrees_with_every_edge() {
        let mut rng = XorShift64::new(5);
        for m in [3, 16, 17, 40, 200] {
            for _ in 0..20 {
                let mut p: Vec<[f64; 2]> = (0..m)
                    .map(|_| [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)])
                    .collect();
                if m > 3 {
                    p[1] = p[0];
                    p[3][1] = p[2][1];
                }
                let filing = if m < 16 {
                    Filing::All
                } else {
                    by_rows(&p).unwrap_or(Filing::All)
                };
                let e = EvenOdd {
                    p: p.clone(),
                    filing,
                };
                let mut probes: Vec<[f64; 2]> = (0..400)
                    .map(|_| [rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2)])
                    .collect();
                probes.extend(p.iter().map(|q| [q[0] - 1e-3, q[1]]));
                probes.extend([[0.0, f64::NAN], [0.0, f64::INFINITY], [0.0, -5.0]]);
                for c in probes {
                    assert_eq!(e.contains(c), point_in_polygon(&p, c), "{c:?}");
                }
            }
        }
    }

    /// Filed by sectors, the even-odd test answers as the edge-by-edge one: on fronts about
    /// the origin whose radii jump (too many rows for the row filing), with θ ties and
    /// steps back by rounding, and on random polygons filed so.
    #[test]
    fn sector_filed_even_odd_test_agrees_with_every_edge() {
        let mut rng = XorShift64::new(8);
        for trial in 0..60 {
            let m = [16, 50, 300, 2000][trial % 4];
            let p: Vec<[f64; 2]> = if trial % 3 == 2 {
                (0..m)
                    .map(|_| [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)])
                    .collect()
            } else {
                let mut angles: Vec<f64> = (0..m)
                    .map(|_| rng.uniform(0.0, std::f64::consts::TAU))
                    .collect();
                angles.sort_by(f64::total_cmp);
                // Ties, and a tie one rounding step back.
                for k in (2..m).step_by(7) {
                    angles[k] = angles[k - 1];
                }
                (0..m)
                    .map(|k| {
                        let r = 10f64.powf(rng.uniform(-2.0, 0.0));
                        let mut q = [r * angles[k].cos(), r * angles[k].sin()];
                        if k % 11 == 5 {
                            q[0] = q[0].next_up();
                        }
                        q
                    })
                    .collect()
            };
            // (Random polygons' long edges overfill the sectors from a few dozen edges on.)
            let Some(filing) = by_sectors(&p) else {
                assert!(
                    trial % 3 == 2 && m > 16,
                    "trial {trial}: sectors overfilled"
                );
                continue;
            };
            let e = EvenOdd {
                filing,
                p: p.clone(),
            };
            let probes = (0..500).map(|_| [rng.uniform(-1.1, 1.1), rng.uniform(-1.1, 1.1)]);
            for c in probes.chain([[0.0, 0.0], [0.0, f64::NAN]]) {
                assert_eq!(
                    e.contains(c),
                    point_in_polygon(&p, c),
                    "trial {trial}: {c:?}"
                );
            }
            if trial % 3 != 2 && m >= 300 {
                let Filing::Sectors { edges, .. } = EvenOdd::new(p.clone()).filing else {
                    panic!("trial {trial}: a front with jumping radii is filed by sectors");
                };
                // Each edge in its own sector or two and the one on each side: ties and
                // steps back by rounding file no edge all round.
                assert!(edges.len() <= 5 * m, "trial {trial}: {} filed", edges.len());
            }
        }
    }

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

    /// A triangle across the two sheets of a thin disc (top and bottom normals 147° apart)
    /// goes with the folds, and so do its corner-sharing neighbours, although its face agrees
    /// with the sum of its corners' normals; a triangle whose corners' normals differ by a
    /// step's turn stays.
    #[test]
    fn a_chart_triangle_across_two_sheets_is_dropped_as_a_fold() {
        let (s, c) = (147.0f64.to_radians() / 2.0).sin_cos();
        let (up, down) = ([c, 0.0, s], [c, 0.0, -s]);
        // Corners 0 and 1 on the top sheet near the rim, 2 on the bottom one; 3 beside them
        // on top; 4, 5, 6 on top farther in.
        let pos = [
            [0.95, -0.05, 0.03],
            [0.95, 0.05, 0.03],
            [0.95, 0.0, -0.03],
            [0.85, 0.0, 0.035],
            [0.5, 0.0, 0.05],
            [0.6, 0.0, 0.05],
            [0.5, 0.1, 0.05],
        ];
        let normals = [up, up, down, up, up, up, up];
        // The bridge faces +x (outward), within 60° of its corners' summed normal.
        let bridge = [0, 2, 1];
        assert!(flip::agreement(&pos, &normals, bridge) > FOLD_DEG.to_radians().cos());
        let beside = [3, 0, 1];
        let apart = [4, 5, 6];
        assert!(flip::agreement(&pos, &normals, apart) > FOLD_DEG.to_radians().cos());
        let mut triangles = vec![bridge, beside, apart];
        drop_folds(&pos, &normals, &mut triangles);
        // The bridge and the triangle sharing its corners go; the one apart from it stays.
        assert_eq!(triangles, vec![apart]);
        let turned = [0.6, 0.0, 0.8];
        assert!(!bridges(
            &[up, up, turned],
            [0, 1, 2],
            BRIDGE_DEG.to_radians().cos()
        ));
        assert!(bridges(&normals, bridge, BRIDGE_DEG.to_radians().cos()));
    }
}
