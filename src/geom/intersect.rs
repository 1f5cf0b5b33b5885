//! Exact triangle–triangle intersection, on orientation predicates only.
//!
//! Every decision is the sign of an orientation determinant ([`Orient`]), so the answers are
//! exact for any finite coordinates: there is no tolerance and no constructed intersection
//! point. Triangles are closed (boundary included).
//!
//! * Two non-degenerate triangles: each is rejected if the other lies strictly on one side
//!   of its plane (three `orient3d` each, the usual exit); otherwise, if coplanar, the 2-D test
//!   in a projection along an axis the plane is not parallel to (chosen exactly: the axis
//!   whose projected area is non-zero); otherwise they meet iff an edge of one meets the other
//!   (the ends of the intersection segment on the planes' common line lie on edges), and an
//!   edge that crosses a plane meets the triangle iff the three orientations of the edge's
//!   line against the triangle's edges are not of mixed sign.
//! * Degenerate triangles (collinear or coincident corners, decided exactly) are the point set
//!   they cover: a segment between their two extreme corners, or a point.
//! * Faces of one mesh ([`faces_intersect`]) that share vertex indices may touch there; see
//!   that function for what counts as an intersection then.

use super::predicates::{Checked, Orient, P3};
use super::vec3::{cross, dot as dot3, sub};

/// A triangle by its three corners.
pub(crate) type Tri = [P3; 3];

/// Whether the closed triangles `a` and `b` have a common point, decided exactly.
///
/// Degenerate triangles are the segment or point they cover. Any non-finite coordinate
/// answers `false` (such a triangle is not a point set; mesh validation reports it apart).
#[cfg_attr(not(test), allow(dead_code))] // for the mesher's checks; tested here
pub(crate) fn triangles_intersect(a: Tri, b: Tri) -> bool {
    if !finite(&a) || !finite(&b) {
        return false;
    }
    let o = Checked;
    shapes_intersect(o, &shape(o, &a), &shape(o, &b))
}

/// Whether faces `f` and `g` of the mesh with vertex positions `p` intersect other than where
/// they are allowed to touch, decided exactly:
///
/// * sharing no index: iff the closed triangles have a common point
///   ([`triangles_intersect`]), so distinct vertices at the same position touch;
/// * sharing one index `v`: iff they have a common point other than `v`'s position (an edge of
///   one through the other, or an overlap next to `v`, flat or folded);
/// * sharing two indices (an edge): iff they have a common point off that edge, which for
///   non-degenerate faces means coplanar with the third corners on the same side;
/// * the same three indices (a duplicate face, in either orientation): always.
///
/// A degenerate face (collinear or coincident corners, or a repeated index) sharing an index
/// with the other face answers `false`: it has no interior to overlap with, and validation
/// reports it as degenerate. Sharing none, it is tested as the point set it covers.
/// An index out of range or a non-finite corner answers `false` (also reported apart).
#[cfg_attr(not(test), allow(dead_code))] // for the mesher's checks; tested here
pub(crate) fn faces_intersect(p: &[P3], f: [u32; 3], g: [u32; 3]) -> bool {
    let corners = |t: [u32; 3]| -> Option<Tri> {
        let c = [
            p.get(t[0] as usize)?,
            p.get(t[1] as usize)?,
            p.get(t[2] as usize)?,
        ];
        let c = [*c[0], *c[1], *c[2]];
        finite(&c).then_some(c)
    };
    let (Some(tf), Some(tg)) = (corners(f), corners(g)) else {
        return false;
    };
    if same_set(f, g) {
        return true;
    }
    let o = Checked;
    let (sf, sg) = (shape(o, &tf), shape(o, &tg));
    let repeated = |t: [u32; 3]| t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    match (&sf, &sg) {
        (Shape::Triangle(..), Shape::Triangle(..)) if !repeated(f) && !repeated(g) => {
            proper_faces_intersect(o, p, f, g)
        }
        _ if shared_count(f, g) > 0 => false,
        _ => shapes_intersect(o, &sf, &sg),
    }
}

/// [`faces_intersect`] for faces known to have three distinct in-range indices and
/// non-degenerate, finite corners (what validation tests after filtering), with the
/// predicates `o` (which must be exact on `p`).
#[cfg_attr(not(test), allow(dead_code))] // for the mesher's checks; tested here
pub(crate) fn proper_faces_intersect<O: Orient>(o: O, p: &[P3], f: [u32; 3], g: [u32; 3]) -> bool {
    let at =
        |t: [u32; 3]| PlanarFace::new(o, t, [p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]]);
    planar_faces_intersect(o, &at(f), &at(g))
}

/// A proper face (three distinct indices, finite non-degenerate corners) with its plane,
/// made once for the many tests of a face against its neighbours.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlanarFace<P> {
    /// Vertex indices.
    pub ids: [u32; 3],
    /// The plane through its corners, in the order of `ids` (so it holds the corners).
    pub plane: P,
}

impl<P> PlanarFace<P> {
    /// Face `ids` with corners `corners`.
    #[inline]
    pub fn new<O: Orient<Plane = P>>(o: O, ids: [u32; 3], corners: Tri) -> Self {
        PlanarFace {
            ids,
            plane: o.plane(corners[0], corners[1], corners[2]),
        }
    }
}

/// [`proper_faces_intersect`] for faces with their planes at hand (made with `o`).
///
/// A cyclic rotation of a plane's corners leaves every orientation against it unchanged, so
/// the tests of faces sharing corners read the face's own plane whichever corner they put
/// first.
#[inline]
pub(crate) fn planar_faces_intersect<O: Orient>(
    o: O,
    pf: &PlanarFace<O::Plane>,
    pg: &PlanarFace<O::Plane>,
) -> bool {
    let (f, g) = (pf.ids, pg.ids);
    let (tf, tg) = (o.plane_corners(&pf.plane), o.plane_corners(&pg.plane));
    let in_g = f.map(|x| (x == g[0]) | (x == g[1]) | (x == g[2]));
    match in_g[0] as u8 + in_g[1] as u8 + in_g[2] as u8 {
        0 => tri_tri(o, tf, &pf.plane, tg, &pg.plane),
        1 => {
            // Rotate both so that the shared vertex comes first.
            let i = if in_g[0] {
                0
            } else if in_g[1] {
                1
            } else {
                2
            };
            let j = if g[0] == f[i] {
                0
            } else if g[1] == f[i] {
                1
            } else {
                2
            };
            let (v, b, c) = (tf[i], tf[(i + 1) % 3], tf[(i + 2) % 3]);
            let sides = [o.side(&pg.plane, b), o.side(&pg.plane, c)];
            if sides[0] * sides[1] > 0 {
                return false;
            }
            wedges_meet(o, sides, v, b, c, tg[(j + 1) % 3], tg[(j + 2) % 3])
        }
        2 => {
            let i = if !in_g[0] {
                0
            } else if !in_g[1] {
                1
            } else {
                2
            };
            let j = if !f.contains(&g[0]) {
                0
            } else if !f.contains(&g[1]) {
                1
            } else {
                2
            };
            let (a, b, c) = (tf[(i + 1) % 3], tf[(i + 2) % 3], tf[i]);
            folded_onto(o, &pf.plane, a, b, c, tg[j])
        }
        _ => true,
    }
}

/// Whether a vertex's fan is certified embedded: every face at the vertex meets every other
/// face at it only where they share corners, decided exactly without testing the pairs.
///
/// `rim` gives each face at the apex by its other two corners `(next, prev)`, in the face's
/// own order (the face is `apex → next → prev`); `closed` says that the rim edges form one
/// cycle (an interior vertex of a manifold, consistently oriented mesh), else one path (a
/// boundary vertex). Projected along the axis `k` of the largest component of the first
/// face's normal, the fan is certified when
///
/// * every face projects with the same non-zero orientation (exact `orient2d`): each face is
///   then the graph of an affine function over its projection, and its projection lies in
///   its sector, the wedge at the apex between its two edges (less than a half-turn);
/// * the sectors turn once round the apex (closed) or less than once (open), so that they
///   overlap only along the rays they share: the rim crosses the line through the apex
///   parallel to the second projected coordinate axis upwards `U` and downwards `D` times
///   (half-open comparisons, exact), a closed rim winds `U = D` times, and an open rim that
///   turns a full turn or more crosses both ways, so `U = 1` (closed) or `U + D ≤ 1` (open)
///   suffices.
///
/// Then two faces sharing only the apex project into sectors that meet only at the apex, so
/// they meet only on the line through the apex along `k`, where each holds the apex alone;
/// and two faces sharing an edge (orientations consistent: the caller's `closed` or path
/// guarantees it) project to opposite sides of its projection, so they meet only on it, where
/// each holds the edge alone. A `false` proves nothing: the caller tests those pairs.
/// Non-finite corners answer `false`.
pub(crate) fn fan_is_embedded<O: Orient>(
    o: O,
    apex: P3,
    mut rim: impl Iterator<Item = (P3, P3)>,
    closed: bool,
) -> bool {
    let finite = |p: &P3| p.iter().all(|x| x.is_finite());
    let Some((next, prev)) = rim.next() else {
        return false;
    };
    if !finite(&apex) {
        return false;
    }
    // The axis of the first face's normal: on a fan that is nearly flat every face projects
    // well along it, and on any other the orientations tell.
    let k = normal_axis(apex, next, prev);
    let a = proj(apex, k);
    let (mut sign, mut up, mut down) = (0, 0u32, 0u32);
    for (next, prev) in std::iter::once((next, prev)).chain(rim) {
        if !finite(&next) || !finite(&prev) {
            return false;
        }
        let (b, c) = (proj(next, k), proj(prev, k));
        let s = o.orient2d(a, b, c);
        if s == 0 || s == -sign {
            return false;
        }
        sign = s;
        up += (b[1] < a[1] && c[1] >= a[1]) as u32;
        down += (b[1] >= a[1] && c[1] < a[1]) as u32;
    }
    sign != 0 && if closed { up == 1 } else { up + down <= 1 }
}

/// Whether `a, b, c` are collinear or coincident (decided exactly; non-finite input counts as
/// degenerate). A triangle with this property has no plane and no interior.
#[cfg_attr(not(test), allow(dead_code))] // for the mesher's checks; tested here
pub(crate) fn triangle_is_degenerate(t: Tri) -> bool {
    !finite(&t) || drop_axis(Checked, t[0], t[1], t[2]).is_none()
}

/// [`triangle_is_degenerate`] for finite corners with the predicates `o`.
pub(crate) fn is_collinear<O: Orient>(o: O, a: P3, b: P3, c: P3) -> bool {
    drop_axis(o, a, b, c).is_none()
}

/// Whether the closed triangle `t` meets the infinite line through the two distinct points
/// `line`, decided exactly: the line passes each edge on one side (Plücker's test), and it
/// meets the triangle unless it passes two edges on opposite sides. A triangle in a plane
/// with the line (every sign zero) counts as meeting it, and so does a non-finite corner: a
/// line a mesh must keep off is better kept off such faces too.
pub(crate) fn triangle_meets_line(t: Tri, line: [P3; 2]) -> bool {
    if !finite(&t) {
        return true;
    }
    // Most triangles lie far from the line: every point of a triangle is within its longest
    // edge at the first corner of that corner, so a first corner farther from the line
    // misses it (in floating point, with a margin far above the rounding of the distance).
    let along = sub(line[1], line[0]);
    let from = sub(t[0], line[0]);
    let moment = cross(from, along);
    let (ll, ff) = (dot3(along, along), dot3(from, from));
    let distance2 = dot3(moment, moment) / ll;
    let reach2 = dot3(sub(t[1], t[0]), sub(t[1], t[0])).max(dot3(sub(t[2], t[0]), sub(t[2], t[0])));
    if distance2 > reach2 * (1.0 + 1e-6) + 1e-12 * ff && distance2.is_finite() {
        return false;
    }
    let o = Checked;
    let side = |k: usize| o.orient3d(line[0], line[1], t[k], t[(k + 1) % 3]);
    let s = [side(0), side(1), side(2)];
    !(s.contains(&1) && s.contains(&-1))
}

fn finite(t: &Tri) -> bool {
    t.iter().flatten().all(|x| x.is_finite())
}

fn same_set(f: [u32; 3], g: [u32; 3]) -> bool {
    f.iter().all(|v| g.contains(v)) && g.iter().all(|v| f.contains(v))
}

fn shared_count(f: [u32; 3], g: [u32; 3]) -> usize {
    f.iter().filter(|v| g.contains(v)).count()
}

/// `p` projected along axis `k` (the other two coordinates, in cyclic order, so that a
/// counter-clockwise turn about `+e_k` stays counter-clockwise).
#[inline]
fn proj(p: P3, k: usize) -> [f64; 2] {
    [p[(k + 1) % 3], p[(k + 2) % 3]]
}

/// The axis of the largest component of triangle `abc`'s float normal (ties to the lower
/// axis): the one along which it projects largest.
#[inline]
fn normal_axis(a: P3, b: P3, c: P3) -> usize {
    let n = cross(sub(b, a), sub(c, a));
    let (x, y, z) = (n[0].abs(), n[1].abs(), n[2].abs());
    if x >= y && x >= z {
        0
    } else if y >= z {
        1
    } else {
        2
    }
}

/// An axis along which triangle `abc` projects to a non-degenerate triangle, or `None` if the
/// corners are collinear (the three projected areas are the components of the normal, so
/// they all vanish exactly then). The float normal's largest component is tried first, so
/// one exact `orient2d` usually decides.
fn drop_axis<O: Orient>(o: O, a: P3, b: P3, c: P3) -> Option<usize> {
    let first = normal_axis(a, b, c);
    let area = |k: usize| o.orient2d(proj(a, k), proj(b, k), proj(c, k));
    if area(first) != 0 {
        return Some(first);
    }
    [(first + 1) % 3, (first + 2) % 3]
        .into_iter()
        .find(|&k| area(k) != 0)
}

/// The point set a triangle covers.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Point(P3),
    Segment(P3, P3),
    /// A non-degenerate triangle and an axis it can be projected along.
    Triangle(Tri, usize),
}

fn shape<O: Orient>(o: O, t: &Tri) -> Shape {
    if let Some(k) = drop_axis(o, t[0], t[1], t[2]) {
        return Shape::Triangle(*t, k);
    }
    // Collinear: along any axis on which the corners differ the order along the line is the
    // order of that coordinate, so its extremes are the segment's ends.
    match (0..3).find(|&k| t[0][k] != t[1][k] || t[1][k] != t[2][k]) {
        None => Shape::Point(t[0]),
        Some(k) => {
            let lo = (0..3)
                .min_by(|&i, &j| t[i][k].total_cmp(&t[j][k]))
                .unwrap_or(0);
            let hi = (0..3)
                .max_by(|&i, &j| t[i][k].total_cmp(&t[j][k]))
                .unwrap_or(1);
            Shape::Segment(t[lo], t[hi])
        }
    }
}

fn shapes_intersect<O: Orient>(o: O, s: &Shape, t: &Shape) -> bool {
    use Shape::*;
    match (*s, *t) {
        (Point(p), Point(q)) => p == q,
        (Point(p), Segment(a, b)) | (Segment(a, b), Point(p)) => point_on_segment(o, p, a, b),
        (Point(p), Triangle(t, k)) | (Triangle(t, k), Point(p)) => {
            o.orient3d(t[0], t[1], t[2], p) == 0 && point_in_triangle_2d(o, proj(p, k), t, k)
        }
        (Segment(p, q), Segment(r, s)) => segments_meet(o, p, q, r, s),
        (Segment(p, q), Triangle(t, k)) | (Triangle(t, k), Segment(p, q)) => {
            let sp = o.orient3d(t[0], t[1], t[2], p);
            let sq = o.orient3d(t[0], t[1], t[2], q);
            segment_meets_triangle(o, p, q, sp, sq, &t, k)
        }
        (Triangle(a, _), Triangle(b, _)) => {
            let plane = |t: Tri| o.plane(t[0], t[1], t[2]);
            tri_tri(o, &a, &plane(a), &b, &plane(b))
        }
    }
}

/// Every coordinate of `p` between those of `a` and `b` (for collinear points: `p` on the
/// segment).
fn between<const N: usize>(p: [f64; N], a: [f64; N], b: [f64; N]) -> bool {
    (0..N).all(|k| a[k].min(b[k]) <= p[k] && p[k] <= a[k].max(b[k]))
}

fn point_on_segment<O: Orient>(o: O, p: P3, a: P3, b: P3) -> bool {
    between(p, a, b) && (0..3).all(|k| o.orient2d(proj(a, k), proj(b, k), proj(p, k)) == 0)
}

fn point_in_triangle_2d<O: Orient>(o: O, p: [f64; 2], t: Tri, k: usize) -> bool {
    let [a, b, c] = t.map(|v| proj(v, k));
    !mixed([
        o.orient2d(a, b, p),
        o.orient2d(b, c, p),
        o.orient2d(c, a, p),
    ])
}

/// Some sign positive and some negative.
#[inline]
fn mixed(s: [i8; 3]) -> bool {
    s.iter().any(|&x| x > 0) && s.iter().any(|&x| x < 0)
}

/// All three strictly on the same side.
#[inline]
fn one_side(s: [i8; 3]) -> bool {
    (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0)
}

/// Closed segments `pq` and `rs` in a plane (non-degenerate after projection).
fn segments_meet_2d<O: Orient>(o: O, p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> bool {
    let (d1, d2) = (o.orient2d(r, s, p), o.orient2d(r, s, q));
    let (d3, d4) = (o.orient2d(p, q, r), o.orient2d(p, q, s));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    (d1 == 0 && between(p, r, s))
        || (d2 == 0 && between(q, r, s))
        || (d3 == 0 && between(r, p, q))
        || (d4 == 0 && between(s, p, q))
}

/// Closed segments `pq` and `rs` in space (`p ≠ q`, `r ≠ s`).
fn segments_meet<O: Orient>(o: O, p: P3, q: P3, r: P3, s: P3) -> bool {
    if o.orient3d(p, q, r, s) != 0 {
        return false;
    }
    // Coplanar: project along an axis the common plane is not parallel to.
    if let Some(k) = drop_axis(o, p, q, r).or_else(|| drop_axis(o, p, q, s)) {
        return segments_meet_2d(o, proj(p, k), proj(q, k), proj(r, k), proj(s, k));
    }
    // All four on the line pq: compare intervals along an axis on which p and q differ.
    let k = (0..3).find(|&k| p[k] != q[k]).unwrap_or(0);
    p[k].min(q[k]) <= r[k].max(s[k]) && r[k].min(s[k]) <= p[k].max(q[k])
}

/// Segment `pq` against the non-degenerate triangle `t` (projectable along `k`), given the
/// sides `sp`, `sq` of `p` and `q` with respect to `t`'s plane.
fn segment_meets_triangle<O: Orient>(
    o: O,
    p: P3,
    q: P3,
    sp: i8,
    sq: i8,
    t: &Tri,
    k: usize,
) -> bool {
    if sp * sq > 0 {
        return false;
    }
    if sp == 0 && sq == 0 {
        let (p2, q2) = (proj(p, k), proj(q, k));
        let [a, b, c] = t.map(|v| proj(v, k));
        return point_in_triangle_2d(o, p2, *t, k)
            || point_in_triangle_2d(o, q2, *t, k)
            || segments_meet_2d(o, p2, q2, a, b)
            || segments_meet_2d(o, p2, q2, b, c)
            || segments_meet_2d(o, p2, q2, c, a);
    }
    // The segment crosses (or ends on) the plane, at the point where its line does; the line
    // passes through the closed triangle iff it does not pass two edges on opposite sides.
    let s = [
        o.orient3d(p, q, t[0], t[1]),
        o.orient3d(p, q, t[1], t[2]),
        o.orient3d(p, q, t[2], t[0]),
    ];
    !mixed(s)
}

/// Two non-degenerate closed triangles `a` and `b`, with their planes `pa` and `pb`.
fn tri_tri<O: Orient>(o: O, a: &Tri, pa: &O::Plane, b: &Tri, pb: &O::Plane) -> bool {
    let sa = [o.side(pb, a[0]), o.side(pb, a[1]), o.side(pb, a[2])];
    if one_side(sa) {
        return false;
    }
    let sb = [o.side(pa, b[0]), o.side(pa, b[1]), o.side(pa, b[2])];
    if one_side(sb) {
        return false;
    }
    let (ka, kb) = (
        || drop_axis(o, a[0], a[1], a[2]).unwrap_or(2),
        || drop_axis(o, b[0], b[1], b[2]).unwrap_or(2),
    );
    if sa == [0, 0, 0] {
        // Coplanar: two convex polygons meet iff edges cross or one holds a corner of the
        // other.
        let k = ka();
        let (pa, pb) = (a.map(|p| proj(p, k)), b.map(|p| proj(p, k)));
        return (0..3).any(|i| {
            (0..3).any(|j| segments_meet_2d(o, pa[i], pa[(i + 1) % 3], pb[j], pb[(j + 1) % 3]))
        }) || point_in_triangle_2d(o, pa[0], *b, k)
            || point_in_triangle_2d(o, pb[0], *a, k);
    }
    // Not coplanar: the intersection is a segment on the planes' common line whose ends lie
    // on edges, so it is non-empty iff an edge of one meets the other. Each edge needs the
    // projection axis only if it lies in the other's plane, so it is found lazily.
    let edge_hits = |x: &Tri, sx: [i8; 3], y: &Tri, ky: &dyn Fn() -> usize| {
        (0..3).any(|i| {
            let j = (i + 1) % 3;
            if sx[i] * sx[j] > 0 {
                return false;
            }
            let k = if sx[i] == 0 && sx[j] == 0 { ky() } else { 0 };
            segment_meets_triangle(o, x[i], x[j], sx[i], sx[j], y, k)
        })
    };
    edge_hits(a, sa, b, &kb) || edge_hits(b, sb, a, &ka)
}

/// Non-degenerate faces `(v, b, c)` and `(v, d, e)` sharing only the corner `v`: do they have
/// a common point other than `v`?
///
/// Both are convex and contain `v`, so they do iff their corner wedges at `v`,
/// `W_f = cone(b − v, c − v)` and `W_g = cone(d − v, e − v)`, share a direction. Not coplanar,
/// `W_f` meets `g`'s plane in at most one ray `u`; writing `[x, y, z]` for
/// `orient3d(v, x, y, z)` and taking `p` one of `b, c` off `g`'s plane (`q` the other),
/// `u = sign[d,e,p] ([d,e,p] (q − v) − [d,e,q] (p − v))`, which lies in `W_g` iff
/// `[d,e,p]·[d,q,p] ≥ 0` and `[d,e,p]·[q,e,p] ≥ 0`: two more orientations, no constructed
/// point. Coplanar, two wedges of angle < π share a direction iff one holds a boundary ray
/// of the other. `sides` are those of `b` and `c` against the plane of `(v, d, e)`; the
/// caller has already answered `false` when they are strictly on one side (the usual case,
/// and all it needs is the two signs).
fn wedges_meet<O: Orient>(o: O, sides: [i8; 2], v: P3, b: P3, c: P3, d: P3, e: P3) -> bool {
    let [sb, sc] = sides;
    if sb == 0 && sc == 0 {
        let k = drop_axis(o, v, d, e).unwrap_or(2);
        let [v, b, c, d, e] = [v, b, c, d, e].map(|p| proj(p, k));
        let ccw = |x: [f64; 2], y: [f64; 2]| {
            if o.orient2d(v, x, y) < 0 {
                (y, x)
            } else {
                (x, y)
            }
        };
        let ((b, c), (d, e)) = (ccw(b, c), ccw(d, e));
        let inside = |x: [f64; 2], l: [f64; 2], r: [f64; 2]| {
            o.orient2d(v, l, x) >= 0 && o.orient2d(v, x, r) >= 0
        };
        return inside(d, b, c) || inside(e, b, c) || inside(b, d, e) || inside(c, d, e);
    }
    let (p, q, sp) = if sb != 0 { (b, c, sb) } else { (c, b, sc) };
    sp * o.orient3d(v, d, q, p) >= 0 && sp * o.orient3d(v, q, e, p) >= 0
}

/// Non-degenerate faces `(a, b, c)` and one with corners `a, b, d` (sharing the edge `ab`):
/// a common point off the edge exists iff they are coplanar with `c` and `d` on the same
/// side of `ab` (otherwise the planes meet only in the line `ab`, which each face meets in
/// the edge alone). `f` is the plane of `(a, b, c)` (or of a cyclic rotation of it).
fn folded_onto<O: Orient>(o: O, f: &O::Plane, a: P3, b: P3, c: P3, d: P3) -> bool {
    if o.side(f, d) != 0 {
        return false;
    }
    let k = drop_axis(o, a, b, c).unwrap_or(2);
    let (a, b) = (proj(a, k), proj(b, k));
    o.orient2d(a, b, proj(c, k)) * o.orient2d(a, b, proj(d, k)) > 0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::predicates::InRange;
    use crate::geom::rng::XorShift64;

    #[test]
    fn a_line_meets_the_triangles_it_passes_through_and_no_other() {
        let axis = [[0.0, 0.0, -1.0], [0.0, 0.0, 2.0]];
        let cases: [(&str, Tri, bool); 9] = [
            (
                "across it",
                [[1.0, 0.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.5]],
                true,
            ),
            (
                "through a corner",
                [[0.0, 0.0, 3.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                true,
            ),
            (
                "along an edge",
                [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                true,
            ),
            (
                "beside it",
                [[1.0, 0.0, 0.0], [2.0, 1.0, 0.0], [1.0, 1.0, 1.0]],
                false,
            ),
            (
                "standing beside it",
                [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0]],
                false,
            ),
            // Decided before the exact test, and by it from a far corner.
            (
                "far from it",
                [[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 9.0]],
                false,
            ),
            (
                "reaching across it",
                [[5.0, 0.0, 0.0], [-5.0, 1.0, 0.0], [-5.0, -1.0, 0.0]],
                true,
            ),
            // Counted as meeting it, wherever they lie.
            (
                "in a plane with it",
                [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 1.0]],
                true,
            ),
            (
                "not finite",
                [[f64::NAN, 0.0, 0.0], [2.0, 1.0, 0.0], [1.0, 1.0, 1.0]],
                true,
            ),
        ];
        for (what, t, meets) in cases {
            assert_eq!(triangle_meets_line(t, axis), meets, "{what}");
        }
    }

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Tri {
        [a, b, c]
    }

    /// Both argument orders and every rotation of each triangle give the same answer.
    fn check(a: Tri, b: Tri, expected: bool) {
        for r in 0..3 {
            for s in 0..3 {
                let ra = [a[r], a[(r + 1) % 3], a[(r + 2) % 3]];
                let rb = [b[s], b[(s + 1) % 3], b[(s + 2) % 3]];
                assert_eq!(triangles_intersect(ra, rb), expected, "{ra:?} {rb:?}");
                assert_eq!(triangles_intersect(rb, ra), expected, "{rb:?} {ra:?}");
                let flipped = [ra[0], ra[2], ra[1]];
                assert_eq!(triangles_intersect(flipped, rb), expected);
            }
        }
    }

    const Z: f64 = 0.0;

    #[test]
    fn crossing_piercing_and_separate_triangles() {
        let base = tri([Z, Z, Z], [4.0, Z, Z], [Z, 4.0, Z]);
        // A vertical triangle through the interior.
        check(
            base,
            tri([1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [2.0, 1.0, 1.0]),
            true,
        );
        // Above the plane.
        check(
            base,
            tri([1.0, 1.0, 0.5], [1.0, 1.0, 1.0], [2.0, 1.0, 1.0]),
            false,
        );
        // Straddling the plane but outside the triangle.
        check(
            base,
            tri([5.0, 5.0, -1.0], [5.0, 5.0, 1.0], [6.0, 5.0, 1.0]),
            false,
        );
        // Touching the plane at one corner, inside the triangle.
        check(
            base,
            tri([1.0, 1.0, Z], [1.0, 1.0, 1.0], [2.0, 1.0, 1.0]),
            true,
        );
        // Touching at a corner, outside.
        check(
            base,
            tri([3.0, 3.0, Z], [3.0, 3.0, 1.0], [4.0, 3.0, 1.0]),
            false,
        );
        // Touching the hypotenuse at its midpoint (2, 2, 0) with one corner.
        check(
            base,
            tri([2.0, 2.0, Z], [3.0, 3.0, 1.0], [3.0, 2.0, 1.0]),
            true,
        );
        // Corner to corner.
        check(base, tri([4.0, Z, Z], [5.0, Z, 1.0], [5.0, 1.0, Z]), true);
        // Edge through an edge (crossing edges, perpendicular planes).
        check(
            base,
            tri([2.0, -1.0, -1.0], [2.0, 1.0, 1.0], [2.0, -1.0, 1.0]),
            true,
        );
        // Through the interior and out the other side with no corner inside: a big triangle.
        check(
            base,
            tri([-10.0, 1.0, -1.0], [10.0, 1.0, -1.0], [0.0, 1.0, 10.0]),
            true,
        );
    }

    #[test]
    fn coplanar_configurations() {
        let base = tri([Z, Z, Z], [4.0, Z, Z], [Z, 4.0, Z]);
        check(base, tri([1.0, 1.0, Z], [2.0, 1.0, Z], [1.0, 2.0, Z]), true); // inside
        check(
            base,
            tri([-1.0, -1.0, Z], [9.0, -1.0, Z], [-1.0, 9.0, Z]),
            true,
        ); // around
        check(
            base,
            tri([3.0, 3.0, Z], [5.0, 3.0, Z], [3.0, 5.0, Z]),
            false,
        ); // beyond
        check(base, tri([2.0, 2.0, Z], [5.0, 3.0, Z], [3.0, 5.0, Z]), true); // corner on edge
        check(base, tri([4.0, Z, Z], [5.0, Z, Z], [5.0, 1.0, Z]), true); // corner to corner
        check(
            base,
            tri([1.0, -1.0, Z], [3.0, -1.0, Z], [2.0, 1.0, Z]),
            true,
        ); // edges cross
        check(
            base,
            tri([1.0, -1.0, Z], [3.0, -1.0, Z], [2.0, -0.5, Z]),
            false,
        ); // below
           // Star of David: no corner inside the other, six crossings.
        let up = tri([Z, Z, Z], [6.0, Z, Z], [3.0, 6.0, Z]);
        let down = tri([Z, 4.0, Z], [3.0, -2.0, Z], [6.0, 4.0, Z]);
        check(up, down, true);
        // A tilted plane (the projection is chosen exactly).
        let t = |x: f64, y: f64| [x, y, 1.0 + 2.0 * x - 3.0 * y];
        check(
            tri(t(Z, Z), t(4.0, Z), t(Z, 4.0)),
            tri(t(1.0, 1.0), t(2.0, 1.0), t(1.0, 2.0)),
            true,
        );
        check(
            tri(t(Z, Z), t(4.0, Z), t(Z, 4.0)),
            tri(t(3.0, 3.0), t(5.0, 3.0), t(3.0, 5.0)),
            false,
        );
    }

    #[test]
    fn degenerate_triangles_are_segments_or_points() {
        let base = tri([Z, Z, Z], [4.0, Z, Z], [Z, 4.0, Z]);
        let seg = |a: P3, b: P3| {
            tri(
                a,
                b,
                [
                    (a[0] + b[0]) / 2.0,
                    (a[1] + b[1]) / 2.0,
                    (a[2] + b[2]) / 2.0,
                ],
            )
        };
        check(base, seg([1.0, 1.0, -1.0], [1.0, 1.0, 1.0]), true); // pierces
        check(base, seg([1.0, 1.0, 0.5], [1.0, 1.0, 1.0]), false);
        check(base, seg([-1.0, 1.0, Z], [1.0, 1.0, Z]), true); // in the plane, entering
        check(base, seg([-2.0, 1.0, Z], [-1.0, 1.0, Z]), false);
        check(base, tri([1.0, 1.0, Z], [1.0, 1.0, Z], [1.0, 1.0, Z]), true); // a point inside
        check(
            base,
            tri([1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 1.0]),
            false,
        );
        // Segment against segment.
        check(
            seg([Z, Z, Z], [2.0, 2.0, Z]),
            seg([Z, 2.0, Z], [2.0, Z, Z]),
            true,
        );
        check(
            seg([Z, Z, Z], [2.0, 2.0, Z]),
            seg([Z, 2.0, 1.0], [2.0, Z, 1.0]),
            false,
        );
        check(
            seg([Z, Z, Z], [2.0, Z, Z]),
            seg([1.0, Z, Z], [3.0, Z, Z]),
            true,
        ); // overlap
        check(
            seg([Z, Z, Z], [2.0, Z, Z]),
            seg([3.0, Z, Z], [4.0, Z, Z]),
            false,
        );
        check(
            seg([Z, Z, Z], [2.0, Z, Z]),
            tri([2.0, Z, Z], [2.0, Z, Z], [2.0, Z, Z]),
            true,
        );
        // Non-finite input.
        assert!(!triangles_intersect(
            base,
            tri([f64::NAN, Z, Z], [1.0, Z, Z], [Z, 1.0, Z])
        ));
    }

    /// Points one ulp off a plane are decided exactly: above, on and below.
    #[test]
    fn one_ulp_off_the_plane() {
        // The plane through (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1) and triangles touching it
        // with one corner: nudge that corner by an ulp in z.
        let base = tri([0.1, Z, Z], [Z, 0.1, Z], [Z, Z, 0.1]);
        let c: P3 = [0.025, 0.025, 0.05];
        let mut hits = Vec::new();
        for dz in [-1i64, 0, 1] {
            let z = f64::from_bits(c[2].to_bits().wrapping_add(dz as u64));
            let probe = tri([c[0], c[1], z], [1.0, 1.0, 1.0], [1.0, 2.0, 1.0]);
            let side = Checked.orient3d(base[0], base[1], base[2], probe[0]);
            hits.push((side, triangles_intersect(base, probe)));
        }
        // Whether c is exactly on the plane depends on rounding; the answers must follow the
        // exact side: a triangle reaching the plane intersects, one stopping short does not.
        for (side, hit) in hits {
            let above = Checked.orient3d(base[0], base[1], base[2], [1.0, 1.0, 1.0]);
            assert_eq!(hit, side != above, "side {side}");
        }
        // An exactly representable plane: z = 0.5 and points 1 ulp above and below it.
        let plane = tri([Z, Z, 0.5], [1.0, Z, 0.5], [Z, 1.0, 0.5]);
        let up = f64::from_bits(0.5f64.to_bits() + 1);
        let down = f64::from_bits(0.5f64.to_bits() - 1);
        let probe = |z: f64| tri([0.25, 0.25, z], [0.25, 0.25, 2.0], [0.5, 0.25, 2.0]);
        assert!(!triangles_intersect(plane, probe(up)));
        assert!(triangles_intersect(plane, probe(0.5)));
        assert!(triangles_intersect(plane, probe(down)));
        // A corner an ulp outside an edge, in the plane.
        let edge = f64::from_bits(0.5f64.to_bits() + 1);
        let flat = tri([Z, Z, Z], [1.0, Z, Z], [Z, 1.0, Z]);
        let outside = tri([0.5, edge, Z], [2.0, 2.0, Z], [3.0, 2.0, Z]);
        let on = tri([0.5, 0.5, Z], [2.0, 2.0, Z], [3.0, 2.0, Z]);
        assert!(!triangles_intersect(flat, outside));
        assert!(triangles_intersect(flat, on));
    }

    #[test]
    fn huge_and_tiny_coordinates_are_exact() {
        for s in [1e-300, 1e-150, 1e150, 1e300] {
            let base = tri([Z, Z, Z], [4.0 * s, Z, Z], [Z, 4.0 * s, Z]);
            let probe = tri([s, s, -s], [s, s, s], [2.0 * s, s, s]);
            assert!(triangles_intersect(base, probe), "{s}");
            let above = tri([s, s, 1e-300], [s, s, s], [2.0 * s, s, s]);
            assert!(!triangles_intersect(base, above), "{s}");
        }
    }

    fn faces(p: &[P3], f: [u32; 3], g: [u32; 3]) -> bool {
        let a = faces_intersect(p, f, g);
        assert_eq!(a, faces_intersect(p, g, f), "{f:?} {g:?} not symmetric");
        let rot = [f[1], f[2], f[0]];
        assert_eq!(
            a,
            faces_intersect(p, rot, g),
            "{f:?} {g:?} not rotation-invariant"
        );
        a
    }

    #[test]
    fn faces_sharing_an_edge() {
        let p = [
            [Z, Z, Z],
            [1.0, Z, Z],
            [Z, 1.0, Z],
            [Z, -1.0, Z],   // 3: the other side, flat
            [0.5, 0.5, Z],  // 4: same side, flat: folded over
            [Z, -1.0, 1.0], // 5: bent
            [Z, 1.0, Z],    // 6: at the position of 2
        ];
        assert!(!faces(&p, [0, 1, 2], [1, 0, 3]));
        assert!(faces(&p, [0, 1, 2], [1, 0, 4]));
        assert!(!faces(&p, [0, 1, 2], [1, 0, 5]));
        assert!(faces(&p, [0, 1, 2], [1, 0, 6]));
        assert!(faces(&p, [0, 1, 2], [0, 1, 4])); // flipped orientation makes no difference
        assert!(faces(&p, [0, 1, 2], [2, 1, 0])); // duplicate, reversed
        assert!(faces(&p, [0, 1, 2], [0, 1, 2]));
        // A flat neighbour an ulp inside the fold line is still on the other side.
        let q = [
            [Z, Z, Z],
            [1.0, Z, Z],
            [Z, 1.0, Z],
            [0.5, -f64::MIN_POSITIVE, Z],
        ];
        assert!(!faces(&q, [0, 1, 2], [1, 0, 3]));
        let q = [
            [Z, Z, Z],
            [1.0, Z, Z],
            [Z, 1.0, Z],
            [0.5, f64::MIN_POSITIVE, Z],
        ];
        assert!(faces(&q, [0, 1, 2], [1, 0, 3]));
    }

    #[test]
    fn faces_sharing_a_vertex() {
        let p = [
            [Z, Z, Z],         // 0: shared
            [1.0, Z, Z],       // 1
            [Z, 1.0, Z],       // 2
            [-1.0, Z, Z],      // 3
            [Z, -1.0, Z],      // 4
            [0.2, 0.2, -1.0],  // 5
            [0.2, 0.2, 1.0],   // 6
            [1.0, 1.0, Z],     // 7
            [0.5, 2.0, Z],     // 8
            [-1.0, -1.0, 1.0], // 9
            [0.3, 0.3, Z],     // 10: inside face (0, 1, 2)
            [Z, Z, 1.0],       // 11
            [1.0, Z, Z],       // 12: at the position of 1
        ];
        assert!(!faces(&p, [0, 1, 2], [0, 3, 4])); // opposite flat wedges: vertex only
        assert!(faces(&p, [0, 1, 2], [0, 5, 6])); // edge 5–6 pierces (0, 1, 2)
        assert!(faces(&p, [0, 1, 2], [0, 7, 8])); // flat overlap near the vertex
        assert!(!faces(&p, [0, 1, 2], [0, 9, 11])); // folded but apart
        assert!(faces(&p, [0, 1, 2], [0, 10, 11])); // folded onto: edge 0–10 lies in it
        assert!(faces(&p, [0, 1, 2], [0, 12, 11])); // distinct vertex at a shared position
        assert!(faces(&p, [0, 1, 2], [0, 11, 5])); // edge 11–5 crosses it at (0.1, 0.1, 0)
        assert!(!faces(&p, [0, 1, 2], [0, 11, 9]));
        // Degenerate faces sharing a vertex answer false; sharing none, they are point sets.
        assert!(!faces(&p, [0, 1, 2], [0, 10, 7])); // collinear corners 0, 10, 7
        assert!(faces(&p, [0, 1, 2], [10, 7, 10]));
        assert!(!faces(&p, [0, 1, 2], [0, 99, 3])); // out of range
    }

    /// Reference for random soups: the closed-set test is symmetric and agrees with a
    /// floating-point computation of the intersection on inputs far from degenerate.
    #[test]
    fn agrees_with_a_float_reference_on_random_triangles() {
        let mut rng = XorShift64::new(11);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let a: Tri = [rng.in_cube(1.0), rng.in_cube(1.0), rng.in_cube(1.0)];
            let off = rng.in_cube(0.8);
            let b: Tri = [0, 1, 2].map(|_| {
                let p = rng.in_cube(0.7);
                [p[0] + off[0], p[1] + off[1], p[2] + off[2]]
            });
            let Some(reference) = float_reference(&a, &b) else {
                continue;
            };
            let got = triangles_intersect(a, b);
            assert_eq!(got, reference, "{a:?} {b:?}");
            assert_eq!(got, triangles_intersect(b, a));
            if got {
                hits += 1
            } else {
                misses += 1
            }
        }
        assert!(hits > 1000 && misses > 1000, "{hits} {misses}");
    }

    /// Exact reference on small integer coordinates: the closed triangles (any shape) share a
    /// point iff `Σλᵢaᵢ = Σμⱼbⱼ` has a solution with λ, μ ≥ 0, Σλ = Σμ = 1. If that linear
    /// program is feasible it has a basic solution, so trying every set of linearly
    /// independent columns (solved in exact rationals) decides it.
    fn lp_reference(a: &Tri, b: &Tri) -> bool {
        let col = |v: usize| -> [i128; 5] {
            let (p, s) = if v < 3 { (a[v], 1) } else { (b[v - 3], -1) };
            let c = p.map(|x| x as i128 * s);
            [c[0], c[1], c[2], (v < 3) as i128, (v >= 3) as i128]
        };
        let rhs = [0i128, 0, 0, 1, 1];
        (1u32..64).any(|set| {
            let cols: Vec<usize> = (0..6).filter(|v| set >> v & 1 == 1).collect();
            solve_nonnegative(&cols.iter().map(|&v| col(v)).collect::<Vec<_>>(), rhs)
        })
    }

    /// Whether `Σ xⱼ colⱼ = rhs` has a unique solution with `x ≥ 0` (columns independent).
    fn solve_nonnegative(cols: &[[i128; 5]], rhs: [i128; 5]) -> bool {
        let n = cols.len();
        // Augmented 5 × (n + 1) matrix of fractions (num, den), den > 0.
        let mut m: Vec<Vec<(i128, i128)>> = (0..5)
            .map(|r| {
                let mut row: Vec<(i128, i128)> = cols.iter().map(|c| (c[r], 1)).collect();
                row.push((rhs[r], 1));
                row
            })
            .collect();
        fn gcd(a: i128, b: i128) -> i128 {
            if b == 0 {
                a.abs().max(1)
            } else {
                gcd(b, a % b)
            }
        }
        let norm = |(n, d): (i128, i128)| {
            let g = gcd(n, d) * d.signum();
            (n / g, d / g)
        };
        let sub_mul = |x: (i128, i128), f: (i128, i128), y: (i128, i128)| {
            norm((x.0 * f.1 * y.1 - f.0 * y.0 * x.1, x.1 * f.1 * y.1))
        };
        let mut pivots = Vec::new();
        let mut row = 0;
        for c in 0..n {
            let Some(p) = (row..5).find(|&r| m[r][c].0 != 0) else {
                return false; // dependent columns: not a basic solution
            };
            m.swap(row, p);
            for r in 0..5 {
                if r != row && m[r][c].0 != 0 {
                    let f = norm((m[r][c].0 * m[row][c].1, m[r][c].1 * m[row][c].0));
                    let pivot_row = m[row].clone();
                    for k in 0..=n {
                        m[r][k] = sub_mul(m[r][k], f, pivot_row[k]);
                    }
                }
            }
            pivots.push(row);
            row += 1;
        }
        // Consistent iff the remaining rows have a zero right-hand side.
        if (row..5).any(|r| m[r][n].0 != 0) {
            return false;
        }
        (0..n).all(|c| {
            let (num, den) = m[pivots[c]][n];
            let (pn, pd) = m[pivots[c]][c];
            // x = (num/den) / (pn/pd) ≥ 0
            (num * pd).signum() * (den * pn).signum() >= 0
        })
    }

    /// Small integer coordinates make coincident, collinear and coplanar corners common: the
    /// closed-set test must agree with the exact reference on all of them.
    #[test]
    fn agrees_with_an_exact_reference_on_integer_triangles() {
        let mut rng = XorShift64::new(21);
        let mut int = |r: u64| (rng.next_u64() % (2 * r + 1)) as f64 - r as f64;
        let (mut hits, mut total) = (0, 0);
        for i in 0..8000 {
            let r = if i % 2 == 0 { 1 } else { 3 };
            let mut pt = || [int(r), int(r), int(r)];
            let a: Tri = [pt(), pt(), pt()];
            let mut b: Tri = [pt(), pt(), pt()];
            if i % 4 == 1 {
                b = b.map(|p| [p[0], p[1], a[0][2]]); // often coplanar with a flat a
            }
            let expected = lp_reference(&a, &b);
            assert_eq!(triangles_intersect(a, b), expected, "{a:?} {b:?}");
            // Validation's path: robust directly, with the filtered plane sides.
            if !triangle_is_degenerate(a) && !triangle_is_degenerate(b) {
                let plane = |t: Tri| InRange.plane(t[0], t[1], t[2]);
                let got = tri_tri(InRange, &a, &plane(a), &b, &plane(b));
                assert_eq!(got, expected, "{a:?} {b:?}");
            }
            hits += expected as usize;
            total += 1;
        }
        assert!(hits > total / 10 && hits < total * 9 / 10, "{hits}/{total}");
    }

    /// Faces sharing indices, against the closed-set reference: sharing a vertex `v`, a
    /// common point other than `v` exists iff the edge opposite `v` in either face meets
    /// the other face; sharing the edge `ab`, a common point off it exists iff a third
    /// corner lies in the other face or the edges `ac`, `bd` or `bc`, `ad` cross.
    #[test]
    fn shared_index_rules_agree_with_the_reference() {
        let mut rng = XorShift64::new(8);
        let (mut checked, mut hits) = (0, 0);
        for i in 0..12_000 {
            let r = 1 + (i % 3) as u64;
            let mut p: Vec<P3> = Vec::new();
            for _ in 0..5 {
                let mut c = || (rng.next_u64() % (2 * r + 1)) as f64 - r as f64;
                p.push([c(), c(), c()]);
            }
            if i % 5 == 0 {
                for q in p.iter_mut() {
                    q[2] = 0.0; // all coplanar
                }
            }
            let (f, g) = if i % 2 == 0 {
                ([0u32, 1, 2], [0u32, 3, 4])
            } else {
                ([0u32, 1, 2], [1u32, 0, 3])
            };
            let t = |x: [u32; 3]| x.map(|i| p[i as usize]);
            if triangle_is_degenerate(t(f)) || triangle_is_degenerate(t(g)) {
                assert!(!faces_intersect(&p, f, g));
                continue;
            }
            let seg = |a: usize, b: usize| -> Tri { [p[a], p[b], p[b]] };
            let pt = |a: usize| -> Tri { [p[a]; 3] };
            let expected = if g[0] == 0 {
                lp_reference(&seg(1, 2), &t(g)) || lp_reference(&seg(3, 4), &t(f))
            } else {
                lp_reference(&pt(2), &t(g))
                    || lp_reference(&pt(3), &t(f))
                    || lp_reference(&seg(0, 2), &seg(1, 3))
                    || lp_reference(&seg(1, 2), &seg(0, 3))
            };
            let got = faces_intersect(&p, f, g);
            assert_eq!(got, expected, "{f:?} {g:?} {p:?}");
            assert_eq!(proper_faces_intersect(InRange, &p, f, g), expected);
            checked += 1;
            hits += got as usize;
        }
        assert!(checked > 4000 && hits > checked / 20, "{hits}/{checked}");
    }

    /// Intersection by clipping each triangle's edges against the other's plane in floating
    /// point, `None` when some quantity is too close to zero to trust.
    fn float_reference(a: &Tri, b: &Tri) -> Option<bool> {
        use crate::geom::vec3::{dot, normalize};
        let hit = |x: &Tri, y: &Tri| -> Option<bool> {
            let n = normalize(cross(sub(y[1], y[0]), sub(y[2], y[0])));
            let d: Vec<f64> = x.iter().map(|p| dot(n, sub(*p, y[0]))).collect();
            let mut any = false;
            for i in 0..3 {
                let j = (i + 1) % 3;
                if d[i].abs() < 1e-9 || d[j].abs() < 1e-9 {
                    return None;
                }
                if d[i] * d[j] > 0.0 {
                    continue;
                }
                let t = d[i] / (d[i] - d[j]);
                let q: P3 = [0, 1, 2].map(|k| x[i][k] + t * (x[j][k] - x[i][k]));
                // Barycentric side tests of q in y.
                let mut sides = [0.0; 3];
                for e in 0..3 {
                    let f = (e + 1) % 3;
                    sides[e] = dot(n, cross(sub(y[f], y[e]), sub(q, y[e])));
                    if sides[e].abs() < 1e-9 {
                        return None;
                    }
                }
                any |= sides.iter().all(|&s| s > 0.0);
            }
            Some(any)
        };
        Some(hit(a, b)? || hit(b, a)?)
    }

    /// The rim of a fan round the origin: points at the given angles (degrees), radius 1,
    /// heights `z`; faces `origin → rim[i] → rim[i + 1]` (closing the cycle if `closed`).
    fn fan(angles: &[f64], z: &[f64], closed: bool) -> Vec<(P3, P3)> {
        let at = |i: usize| {
            let a = angles[i].to_radians();
            [a.cos(), a.sin(), z[i % z.len()]]
        };
        let faces = if closed {
            angles.len()
        } else {
            angles.len() - 1
        };
        (0..faces)
            .map(|i| (at(i), at((i + 1) % angles.len())))
            .collect()
    }

    fn embedded(rim: &[(P3, P3)], closed: bool) -> bool {
        fan_is_embedded(InRange, [0.0; 3], rim.iter().copied(), closed)
    }

    #[test]
    fn fans_that_turn_once_are_certified_and_others_are_not() {
        let hexagon = [0.0, 60.0, 120.0, 180.0, 240.0, 300.0];
        let flat = [0.0];
        let wavy = [0.3, -0.2, 0.4, -0.1, 0.2, -0.3];
        assert!(embedded(&fan(&hexagon, &flat, true), true));
        assert!(embedded(&fan(&hexagon, &wavy, true), true));
        // Turning twice round the apex: every other face overlaps another.
        let twice: Vec<f64> = (0..9).map(|i| 80.0 * i as f64).collect();
        assert!(!embedded(&fan(&twice, &flat, true), true));
        // A face turned over.
        let mut flipped = fan(&hexagon, &wavy, true);
        flipped[2] = (flipped[2].1, flipped[2].0);
        assert!(!embedded(&flipped, true));
        // Open fans: a half-turn is certified, and 300° from 10°; one that turns more than
        // once is not, and nor is 300° from 170°, which crosses the line both ways (the test
        // is sufficient only).
        assert!(embedded(
            &fan(&[10.0, 70.0, 130.0, 190.0], &wavy, false),
            false
        ));
        let over: Vec<f64> = (0..8).map(|i| 60.0 * i as f64).collect();
        assert!(!embedded(&fan(&over, &flat, false), false));
        let wide = |from: f64| -> Vec<f64> { (0..6).map(|i| from + 60.0 * i as f64).collect() };
        assert!(embedded(&fan(&wide(10.0), &flat, false), false));
        assert!(!embedded(&fan(&wide(170.0), &flat, false), false));
        // A flat (collinear) face, a non-finite corner, no face at all.
        let mut flat_face = fan(&hexagon, &flat, true);
        flat_face[0].1 = [2.0, 0.0, 0.0];
        assert!(!embedded(&flat_face, true));
        let mut nan = fan(&hexagon, &flat, true);
        nan[3].0[2] = f64::NAN;
        assert!(!embedded(&nan, true));
        assert!(!embedded(&[], true));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig {
            cases: 512, ..proptest::prelude::ProptestConfig::default()
        })]

        /// A certified fan has no intersecting pair of faces (checked pair by pair with
        /// `faces_intersect`): random rims, in order or not, flat or folded, closed or open.
        #[test]
        fn a_certified_fan_has_no_intersecting_faces(seed in proptest::prelude::any::<u64>()) {
            let mut rng = XorShift64::new(seed);
            let k = 3 + (rng.next_u64() % 8) as usize;
            let closed = rng.next_u64().is_multiple_of(2);
            let sorted = !rng.next_u64().is_multiple_of(3);
            let steep = rng.uniform(0.0, 3.0);
            let mut p: Vec<P3> = vec![[0.0; 3]];
            let mut angle = rng.uniform(0.0, 360.0);
            for _ in 0..k {
                angle = if sorted {
                    angle + rng.uniform(5.0, 720.0 / k as f64)
                } else {
                    rng.uniform(0.0, 360.0)
                };
                let (r, a) = (rng.uniform(0.2, 2.0), angle.to_radians());
                // On a lattice of 1/8 now and then, so that exact ties occur.
                let q = [r * a.cos(), r * a.sin(), rng.uniform(-steep, steep)];
                let on_lattice = rng.next_u64().is_multiple_of(4);
                p.push(if on_lattice { q.map(|x| (x * 8.0).round() / 8.0) } else { q });
            }
            let faces: Vec<[u32; 3]> = (1..=k as u32)
                .filter(|&i| closed || i < k as u32)
                .map(|i| [0, i, i % k as u32 + 1])
                .collect();
            let rim: Vec<(P3, P3)> =
                faces.iter().map(|f| (p[f[1] as usize], p[f[2] as usize])).collect();
            if embedded(&rim, closed) {
                for (i, &f) in faces.iter().enumerate() {
                    for &g in &faces[i + 1..] {
                        proptest::prop_assert!(!faces_intersect(&p, f, g), "{p:?} {f:?} {g:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn random_fans_are_certified_and_refused_both() {
        // The property above is not vacuous: of the fans it draws, some are certified and
        // some are not.
        let mut rng = XorShift64::new(7);
        let (mut yes, mut no) = (0, 0);
        for _ in 0..200 {
            let k = 3 + (rng.next_u64() % 8) as usize;
            let angles: Vec<f64> = (0..k).map(|_| rng.uniform(0.0, 360.0)).collect();
            let mut sorted = angles.clone();
            sorted.sort_by(f64::total_cmp);
            let z = [rng.uniform(-0.5, 0.5)];
            for a in [angles, sorted] {
                if embedded(&fan(&a, &z, true), true) {
                    yes += 1;
                } else {
                    no += 1;
                }
            }
        }
        assert!(yes > 50 && no > 50, "{yes} certified, {no} not");
    }
}
