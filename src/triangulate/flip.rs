//! Edge flips on the surface: make the chart's triangulation Delaunay in space.
//!
//! The chart is conformal only near `p0`; farther out it stretches the surface, and a
//! triangulation that is Delaunay in the chart has needlessly thin triangles in space. Lawson
//! flips with the surface criterion — flip an edge when the two angles opposite to it add up
//! to more than π — restore the max-min-angle property on the surface. A flip is taken only
//! when it keeps the mesh a consistently oriented 2-manifold whose faces agree with the field
//! normal, and tilts no face further than [`FLIP_TILT_DEG`] from it unless the pair it
//! replaces tilted further; flips that undo a fold (a face against the field normal) come
//! first.

use crate::geom::intersect::triangle_meets_line;
use crate::geom::rows::rows_by_corner;
use crate::geom::vec3::{cross, dot, sub, FastHash};
use crate::par;
use std::collections::{HashMap, VecDeque};

/// The furthest a flip may tilt a triangle from its corners' field normals (their sum),
/// degrees, unless the pair it replaces tilted further.
const FLIP_TILT_DEG: f64 = 30.0;

/// Angle at `c` in triangle (a, b, c).
fn angle_at(c: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let (u, v) = (sub(a, c), sub(b, c));
    let cr = cross(u, v);
    dot(cr, cr).sqrt().atan2(dot(u, v))
}

/// Whether the angles at `c` in (a, b, c) and at `d` in (b, a, d) add up to more than π,
/// i.e. the edge `ab` is not Delaunay on the surface. Two acute angles cannot, which settles
/// most edges without an arctangent.
#[inline(always)]
fn delaunay_violation(pa: [f64; 3], pb: [f64; 3], pc: [f64; 3], pd: [f64; 3]) -> bool {
    if dot(sub(pa, pc), sub(pb, pc)) > 0.0 && dot(sub(pb, pd), sub(pa, pd)) > 0.0 {
        return false;
    }
    angle_at(pc, pa, pb) + angle_at(pd, pb, pa) > std::f64::consts::PI + 1e-12
}

/// Unnormalised face normal.
pub(super) fn face_normal(p: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|i| p[i as usize]);
    cross(sub(b, a), sub(c, a))
}

/// Sum of the field normals at a face's corners.
pub(super) fn field_normal(n: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let mut s = [0.0; 3];
    for i in t {
        for k in 0..3 {
            s[k] += n[i as usize][k];
        }
    }
    s
}

/// Cosine of the angle between a face and the field normal at its corners.
pub(super) fn agreement(p: &[[f64; 3]], n: &[[f64; 3]], t: [u32; 3]) -> f64 {
    agreement_at(t.map(|i| p[i as usize]), n, t)
}

/// [`agreement`] for a face whose corners `t` sit at `corners`.
pub(super) fn agreement_at(corners: [[f64; 3]; 3], n: &[[f64; 3]], t: [u32; 3]) -> f64 {
    let [a, b, c] = corners;
    cosine(cross(sub(b, a), sub(c, a)), field_normal(n, t))
}

/// [`agreement_at`] where it is below `floor` (a positive cosine), and `floor` itself where the
/// agreement is certainly at least `floor`: decided from `f·g` and `|f|²|g|²` without a square
/// root or a division where those are normal numbers, with a relative margin of 10⁻¹² that
/// covers their rounding. `min(floor, x)` and `x < min(floor, y)` come out as with the exact
/// agreements (the relaxation asks this of every face in every sweep).
pub(super) fn agreement_below(
    corners: [[f64; 3]; 3],
    n: &[[f64; 3]],
    t: [u32; 3],
    floor: f64,
) -> f64 {
    let [a, b, c] = corners;
    let (f, g) = (cross(sub(b, a), sub(c, a)), field_normal(n, t));
    let (fg, dd) = (dot(f, g), dot(f, f) * dot(g, g));
    if squares_comparable(fg, dd) && fg * fg >= floor * floor * (1.0 + 1e-12) * dd {
        return floor;
    }
    cosine(f, g)
}

/// Whether a positive `f·g` and `|f|²|g|²` are normal numbers far enough from underflow and
/// overflow that `(f·g)²` against a cosine's square times `|f|²|g|²` decides the cosine.
#[inline]
fn squares_comparable(fg: f64, dd: f64) -> bool {
    fg > 1e-140 && fg < 1e140 && (1e-280..=1e280).contains(&dd)
}

/// Cosine of the angle between face normal `f` and field normal `g`; −1 when either vanishes.
fn cosine(f: [f64; 3], g: [f64; 3]) -> f64 {
    let d = (dot(f, f) * dot(g, g)).sqrt();
    if d > 0.0 {
        dot(f, g) / d
    } else {
        -1.0
    }
}

/// `agreement(p, n, t) <= 0.0`, mostly from the sign of `f·g` alone: when it is finite and
/// not positive the agreement is not either, and when it is well above underflow while
/// `|f|²|g|²` is a normal number, the agreement is positive. Only the rest (vectors near
/// underflow or overflow, NaN) go through the square root and division.
pub(crate) fn against_field(p: &[[f64; 3]], n: &[[f64; 3]], t: [u32; 3]) -> bool {
    let (f, g) = (face_normal(p, t), field_normal(n, t));
    let fg = dot(f, g);
    // (−∞ is left to the full test: there `|f||g|` overflows too and −∞/∞ is NaN.)
    if fg <= 0.0 && fg.is_finite() {
        return true;
    }
    // `d = √(|f|²|g|²)` lies in [1e-150, 1e150], so `fg / d ≥ 1e-320 > 0`.
    let dd = dot(f, f) * dot(g, g);
    if fg > 1e-170 && (1e-300..=1e300).contains(&dd) {
        return false;
    }
    cosine(f, g) <= 0.0
}

/// `agreement(p, n, t) >= cos_limit` for a positive `cos_limit`, without a square root or a
/// division where the products are normal numbers (the flips ask it of every flip they
/// consider).
fn within_tilt(p: &[[f64; 3]], n: &[[f64; 3]], t: [u32; 3], cos_limit: f64) -> bool {
    let (f, g) = (face_normal(p, t), field_normal(n, t));
    let (fg, dd) = (dot(f, g), dot(f, f) * dot(g, g));
    if squares_comparable(fg, dd) {
        return fg * fg >= cos_limit * cos_limit * dd;
    }
    agreement(p, n, t) >= cos_limit
}

/// No half-edge.
const NONE: u32 = u32::MAX;

/// One triangle of a vertex `o`'s star while the half-edges are built: its half-edges
/// `o → to` and `from → o`, the latter's index `into`.
#[derive(Clone, Copy, Default)]
struct StarEntry {
    to: u32,
    from: u32,
    into: u32,
}

/// No neighbouring entry in the star.
const UNLINKED: u32 = u32::MAX;

/// Triangles with the half-edge `h = 3 t + k` running from `tri[t][k]` to `tri[t][k + 1]`, its
/// opposite half-edge `twin[h]` (or [`NONE`] on the boundary), and one outgoing half-edge per
/// vertex. Flat arrays instead of a hash map of directed edges: a third of the memory and no
/// hashing in the flip loop.
pub(super) struct HalfEdges {
    tri: Vec<[u32; 3]>,
    twin: Vec<u32>,
    out: Vec<u32>,
    /// A line no flipped triangle may meet ([`crate::NormalField::hole_through`]).
    axis: Option<[[f64; 3]; 2]>,
}

#[inline]
fn next(h: u32) -> u32 {
    if h % 3 == 2 {
        h - 2
    } else {
        h + 1
    }
}

#[inline]
fn prev(h: u32) -> u32 {
    if h.is_multiple_of(3) {
        h + 2
    } else {
        h - 1
    }
}

impl HalfEdges {
    /// Builds the structure on the triangles `tri`, or gives them back unless they form a
    /// consistently oriented 2-manifold (each directed edge once, each vertex's triangles one
    /// fan): only there do the fan walks below see every triangle at a vertex.
    #[inline]
    pub(super) fn new(tri: Vec<[u32; 3]>, vertices: usize) -> Result<Self, Vec<[u32; 3]>> {
        match Self::links(&tri, vertices) {
            Some((twin, out)) => Ok(HalfEdges {
                tri,
                twin,
                out,
                axis: None,
            }),
            None => Err(tri),
        }
    }

    /// The triangles, given back.
    pub(super) fn into_triangles(self) -> Vec<[u32; 3]> {
        self.tri
    }

    /// `twin` and `out` of [`HalfEdges::new`], or `None`.
    #[inline(always)]
    fn links(tri: &[[u32; 3]], vertices: usize) -> Option<(Vec<u32>, Vec<u32>)> {
        let nh = 3 * tri.len();
        if nh >= NONE as usize {
            return None;
        }
        // Outgoing half-edges per vertex.
        let (start, outgoing) = rows_by_corner(tri, vertices, |t, k| (3 * t + k) as u32)?;
        // Around each vertex `o`, triangle `i` of its star has the half-edges `o → to`
        // and `from → o` (`into` is the latter's index); the twin of `o → d` is the star's
        // `d → o`. Matching within the star reads each triangle once, and walking it (`i` to
        // the triangle whose outgoing edge leads to `from[i]`) checks that the star is one
        // fan.
        let mut twin = vec![NONE; nh];
        let mut out = vec![NONE; vertices];
        let mut entries: Vec<StarEntry> = Vec::new();
        let mut links: Vec<[u32; 2]> = Vec::new();
        for o in 0..vertices {
            let star = &outgoing[start[o] as usize..start[o + 1] as usize];
            let Some(&first) = star.first() else {
                continue;
            };
            out[o] = first;
            entries.clear();
            entries.extend(star.iter().map(|&h| {
                let t = &tri[(h / 3) as usize];
                StarEntry {
                    to: t[((h + 1) % 3) as usize],
                    from: t[((h + 2) % 3) as usize],
                    into: prev(h),
                }
            }));
            links.clear();
            links.resize(star.len(), [UNLINKED; 2]);
            // `links[i] = [predecessor, successor]`: the entries `j` with `from[j] == to[i]`
            // and `to[j] == from[i]`; both are unique once `to` and `from` each are.
            for i in 0..entries.len() {
                let e = entries[i];
                if e.to as usize == o {
                    return None;
                }
                for j in 0..i {
                    let f = entries[j];
                    if f.to == e.to || f.from == e.from {
                        return None;
                    }
                    if f.from == e.to {
                        links[i][0] = j as u32;
                        links[j][1] = i as u32;
                    }
                    if f.to == e.from {
                        links[i][1] = j as u32;
                        links[j][0] = i as u32;
                    }
                }
            }
            let linked = |i: usize, side: usize| {
                let j = links[i][side];
                (j != UNLINKED).then_some(j as usize)
            };
            let (predecessor, successor) = (|i| linked(i, 0), |i| linked(i, 1));
            for (i, &h) in star.iter().enumerate() {
                if let Some(j) = predecessor(i) {
                    twin[h as usize] = entries[j].into;
                }
            }
            // One fan: walking forward from triangle 0 (and backward, if the fan is open)
            // visits every triangle of the star.
            let mut seen = 1;
            let mut i = 0;
            let mut closed = false;
            while let Some(j) = successor(i) {
                if j == 0 {
                    closed = true;
                    break;
                }
                seen += 1;
                if seen > star.len() {
                    return None;
                }
                i = j;
            }
            if !closed {
                let mut i = 0;
                while let Some(j) = predecessor(i) {
                    seen += 1;
                    if seen > star.len() {
                        return None;
                    }
                    i = j;
                }
            }
            if seen != star.len() {
                return None;
            }
        }
        Some((twin, out))
    }

    #[inline]
    fn origin(&self, h: u32) -> u32 {
        self.tri[(h / 3) as usize][(h % 3) as usize]
    }

    #[inline]
    fn dest(&self, h: u32) -> u32 {
        self.origin(next(h))
    }

    /// Calls `visit` with every half-edge leaving `origin(start)`, one per triangle of its
    /// fan, until `visit` returns true; returns that half-edge, or else whether the fan
    /// closed around the vertex (it is interior).
    #[inline]
    fn walk_fan(&self, start: u32, mut visit: impl FnMut(u32) -> bool) -> Result<u32, bool> {
        let mut h = start;
        // A fan has at most 3T triangles; the budget guards against a broken structure.
        let mut budget = self.twin.len() + 1;
        loop {
            if visit(h) {
                return Ok(h);
            }
            let t = self.twin[prev(h) as usize];
            budget -= 1;
            if t == start {
                return Err(true);
            }
            if budget == 0 {
                return Err(false);
            }
            if t == NONE {
                break;
            }
            h = t;
        }
        // Open fan: walk the other way from `start`.
        let mut h = start;
        loop {
            let t = self.twin[h as usize];
            budget -= 1;
            if t == NONE || budget == 0 {
                return Err(false);
            }
            h = next(t);
            if visit(h) {
                return Ok(h);
            }
        }
    }

    /// [`HalfEdges::walk_fan`] for the half-edge it finds.
    #[inline]
    fn for_each_around(&self, start: u32, visit: impl FnMut(u32) -> bool) -> Option<u32> {
        self.walk_fan(start, visit).ok()
    }

    /// The half-edge `a → b`, if any.
    fn find(&self, a: u32, b: u32) -> Option<u32> {
        let start = self.out[a as usize];
        if start == NONE {
            return None;
        }
        self.for_each_around(start, |h| self.dest(h) == b)
    }

    /// Whether `a` and `b` share a triangle (an edge in either direction).
    fn adjacent(&self, a: u32, b: u32) -> bool {
        let start = self.out[a as usize];
        start != NONE
            && self
                .for_each_around(start, |h| self.dest(h) == b || self.origin(prev(h)) == b)
                .is_some()
    }

    /// Whether the edge `ab` between the triangles `(a, b, c)` and `(b, a, d)` should be
    /// flipped to `cd`: it is not Delaunay on the surface or one of its triangles faces against
    /// the field (`was_folded`), the edge `cd` is new, both new triangles agree with the field
    /// (within [`FLIP_TILT_DEG`], or at least as well as the old pair), and they do not fold
    /// over the old pair unless that undoes a fold.
    #[inline(always)]
    fn wants_flip(
        &self,
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        [a, b, c, d]: [u32; 4],
        was_folded: bool,
    ) -> bool {
        let (pa, pb, pc, pd) = (
            points[a as usize],
            points[b as usize],
            points[c as usize],
            points[d as usize],
        );
        let old1 = [a, b, c];
        let old2 = [b, a, d];
        let new1 = [a, d, c];
        let new2 = [d, b, c];
        // The tests, cheapest and most often decisive first (almost every edge is already
        // Delaunay and unfolded).
        if !was_folded && !delaunay_violation(pa, pb, pc, pd) {
            return false;
        }
        if c == d || self.adjacent(c, d) {
            return false;
        }
        let new_ok = !against_field(points, normals, new1) && !against_field(points, normals, new2);
        if !new_ok {
            return false;
        }
        // Nor may it tilt a triangle further from the field than [`FLIP_TILT_DEG`], unless the
        // old pair tilted further still: on a thin tube the wider of a long quad's diagonals
        // can be the Delaunay one and still cut across the surface.
        let limit = FLIP_TILT_DEG.to_radians().cos();
        if !(within_tilt(points, normals, new1, limit) && within_tilt(points, normals, new2, limit))
        {
            let cos_tilt = |t: [u32; 3]| agreement(points, normals, t);
            if cos_tilt(new1).min(cos_tilt(new2)) < cos_tilt(old1).min(cos_tilt(old2)) {
                return false;
            }
        }
        // Nor may it span the surface's hole: where a band's waist is seen from a flat
        // flange, every corner's normal points along the axis, and a triangle across the
        // waist agrees with them all.
        if let Some(axis) = self.axis {
            let meets = |t: [u32; 3]| triangle_meets_line(t.map(|v| points[v as usize]), axis);
            if meets(new1) || meets(new2) {
                return false;
            }
        }
        // The flipped pair must not fold over the old one (the quad must be convex enough)
        // unless it undoes a fold.
        let old_sum = {
            let (f1, f2) = (face_normal(points, old1), face_normal(points, old2));
            [f1[0] + f2[0], f1[1] + f2[1], f1[2] + f2[2]]
        };
        if (dot(face_normal(points, new1), old_sum) <= 0.0
            || dot(face_normal(points, new2), old_sum) <= 0.0)
            && !was_folded
        {
            return false;
        }
        true
    }

    /// The triangles, as flips and splits left them.
    pub(super) fn triangles(&self) -> &[[u32; 3]] {
        &self.tri
    }

    /// The half-edge running the other way along `h`'s edge, `None` on the boundary.
    pub(super) fn twin(&self, h: u32) -> Option<u32> {
        let g = self.twin[h as usize];
        (g != NONE).then_some(g)
    }

    /// The triangles around `v` into `faces`, and whether they close up around it (`v` is
    /// interior).
    pub(super) fn star(&self, v: u32, faces: &mut Vec<u32>) -> bool {
        faces.clear();
        let start = self.out[v as usize];
        start != NONE
            && self.walk_fan(start, |h| {
                faces.push(h / 3);
                false
            }) == Err(true)
    }

    /// The half-edge `a → b`: `hint` if it still is that (a flip since it was noted may have
    /// moved it), else found around `a`.
    #[inline(always)]
    fn locate(&self, a: u32, b: u32, hint: Option<u32>) -> Option<u32> {
        match hint {
            Some(h) if self.origin(h) == a && self.dest(h) == b => Some(h),
            _ => self.find(a, b),
        }
    }

    /// Splits the edge of half-edge `h = a → b` at the new vertex `m` (the next vertex
    /// index): its triangle `(a, b, c)` becomes `(a, m, c)` and `(m, b, c)`, and the triangle
    /// `(b, a, d)` across it, if any, `(b, m, d)` and `(m, a, d)`. The new triangles are
    /// appended. Returns the triangles rewritten or added.
    pub(super) fn split(&mut self, h: u32, m: u32) -> Vec<u32> {
        debug_assert_eq!(m as usize, self.out.len());
        let g = self.twin[h as usize];
        let t = h / 3;
        let (a, b, c) = (self.origin(h), self.dest(h), self.origin(prev(h)));
        let (bc, ca) = (self.twin[next(h) as usize], self.twin[prev(h) as usize]);
        let (u, d, ad, db) = if g == NONE {
            (NONE, NONE, NONE, NONE)
        } else {
            let d = self.origin(prev(g));
            (
                g / 3,
                d,
                self.twin[next(g) as usize],
                self.twin[prev(g) as usize],
            )
        };
        let t2 = self.tri.len() as u32;
        self.tri[t as usize] = [a, m, c];
        self.tri.push([m, b, c]);
        self.twin.extend([NONE; 3]);
        self.out.push(3 * t2);
        self.link(3 * t + 1, 3 * t2 + 2);
        self.link(3 * t + 2, ca);
        self.link(3 * t2 + 1, bc);
        self.out[a as usize] = 3 * t;
        self.out[b as usize] = 3 * t2 + 1;
        self.out[c as usize] = 3 * t + 2;
        let mut changed = vec![t, t2];
        if g == NONE {
            self.twin[3 * t as usize] = NONE;
            self.twin[3 * t2 as usize] = NONE;
            return changed;
        }
        let u2 = self.tri.len() as u32;
        self.tri[u as usize] = [b, m, d];
        self.tri.push([m, a, d]);
        self.twin.extend([NONE; 3]);
        self.link(3 * t, 3 * u2);
        self.link(3 * t2, 3 * u);
        self.link(3 * u + 1, 3 * u2 + 2);
        self.link(3 * u + 2, db);
        self.link(3 * u2 + 1, ad);
        self.out[d as usize] = 3 * u + 2;
        changed.extend([u, u2]);
        changed
    }

    /// Lawson flips from the edges of half-edges `seeds` outwards, with the criteria of
    /// [`flip_to_surface_delaunay`], at most `budget` of them. `folded` flags the triangles
    /// that face against the field (flips clear flags); the triangles rewritten are appended
    /// to `changed`. Returns the number of flips.
    pub(super) fn flip_from(
        &mut self,
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        seeds: &[u32],
        folded: &mut [bool],
        budget: usize,
        changed: &mut Vec<u32>,
    ) -> usize {
        // The queue holds an edge as its two ends and the half-edge it had when queued,
        // which a flip elsewhere may have moved.
        let mut queue: VecDeque<(u32, u32, u32)> = (seeds.iter())
            .map(|&h| (self.origin(h), self.dest(h), h))
            .collect();
        let max_visits = 20 * queue.len() + 20 * budget + 64;
        let (mut flips, mut visits) = (0, 0);
        while let Some((a, b, h)) = queue.pop_front() {
            visits += 1;
            if flips >= budget || visits > max_visits {
                break;
            }
            let Some(h) = self.locate(a, b, Some(h)) else {
                continue;
            };
            let g = self.twin[h as usize];
            if g == NONE {
                continue;
            }
            let (t1, t2) = (h / 3, g / 3);
            let (c, d) = (self.origin(prev(h)), self.origin(prev(g)));
            let was_folded = folded[t1 as usize] || folded[t2 as usize];
            if !self.wants_flip(points, normals, [a, b, c, d], was_folded) {
                continue;
            }
            self.flip(t1, t2, [a, b, c, d]);
            folded[t1 as usize] = false;
            folded[t2 as usize] = false;
            changed.extend([t1, t2]);
            flips += 1;
            // `t1 = (a, d, c)` and `t2 = (d, b, c)`: the quad's sides.
            let (h1, h2) = (3 * t1, 3 * t2);
            queue.extend([(a, d, h1), (d, b, h2), (b, c, h2 + 1), (c, a, h1 + 2)]);
        }
        flips
    }

    /// The half-edge `x → y` of triangle `t` (which has it).
    fn slot(&self, t: u32, x: u32) -> u32 {
        let k = self.tri[t as usize]
            .iter()
            .position(|&v| v == x)
            .expect("the vertex is in the triangle by construction");
        3 * t + k as u32
    }

    fn link(&mut self, h: u32, g: u32) {
        self.twin[h as usize] = g;
        if g != NONE {
            self.twin[g as usize] = h;
        }
    }

    /// Replaces triangles `t1 = (a, b, c)` and `t2 = (b, a, d)` by `(a, d, c)` and `(d, b, c)`.
    fn flip(&mut self, t1: u32, t2: u32, [a, b, c, d]: [u32; 4]) {
        let bc = self.twin[self.slot(t1, b) as usize];
        let ca = self.twin[self.slot(t1, c) as usize];
        let ad = self.twin[self.slot(t2, a) as usize];
        let db = self.twin[self.slot(t2, d) as usize];
        self.tri[t1 as usize] = [a, d, c];
        self.tri[t2 as usize] = [d, b, c];
        let (h1, h2) = (3 * t1, 3 * t2);
        self.link(h1, ad);
        self.link(h1 + 1, h2 + 2);
        self.link(h1 + 2, ca);
        self.link(h2, db);
        self.link(h2 + 1, bc);
        self.out[a as usize] = h1;
        self.out[d as usize] = h2;
        self.out[b as usize] = h2 + 1;
        self.out[c as usize] = h1 + 2;
    }
}

/// One bit per triangle, bit `t % 64` of word `t / 64` (an eighth of the memory of
/// `Vec<bool>` at the pipeline's peak).
struct FlagSet(Vec<u64>);

impl FlagSet {
    #[inline]
    fn get(&self, i: usize) -> bool {
        self.0[i / 64] >> (i % 64) & 1 == 1
    }
    #[inline]
    fn clear(&mut self, i: usize) {
        self.0[i / 64] &= !(1u64 << (i % 64));
    }
}

/// What a flip pass did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FlipPass {
    /// How many edges were flipped.
    pub flips: usize,
    /// Whether some triangle still faces against the field ([`against_field`]) after the
    /// pass; `None` when the triangles were not a consistently oriented manifold, so the
    /// pass did not run and did not look.
    pub folded: Option<bool>,
}

/// Flips edges of `triangles` in place. At most `budget` flips are made. Triangles that do
/// not form a consistently oriented 2-manifold are left as they are (a flip there could make
/// an edge non-manifold). Edges whose quad has a vertex marked in `pinned` (empty: none)
/// are not flipped.
pub(crate) fn flip_to_surface_delaunay(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    triangles: &mut Vec<[u32; 3]>,
    budget: usize,
    pinned: &[bool],
    axis: Option<[[f64; 3]; 2]>,
) -> FlipPass {
    let max_visits = 20 * triangles.len() + 1000;
    let mut he = match HalfEdges::new(std::mem::take(triangles), points.len()) {
        Ok(he) => HalfEdges { axis, ..he },
        Err(tri) => {
            *triangles = tri;
            return FlipPass {
                flips: 0,
                folded: None,
            };
        }
    };
    // The queue: every edge once, in triangle order, then the edges around each flip in
    // the order of the flips. The first part is not stored but read from the triangles'
    // slots at `cursor` (with the half-edge's index for free); the few triangles that a flip
    // rewrites before the cursor has read them are kept as they were in `unread`.
    let slots = 3 * he.tri.len();
    let mut cursor = 0usize;
    let mut unread: HashMap<u32, [u32; 3], FastHash> = HashMap::default();
    let mut queue: VecDeque<(u32, u32)> = VecDeque::new();
    // Which triangles face against the field, computed once: a flip only ever creates
    // triangles that agree with it, so the flags change only by being cleared.
    let tri = &he.tri;
    let mut folded = FlagSet(par::map(tri.len().div_ceil(64), par::MIN_CHEAP / 64, |w| {
        let chunk = &tri[64 * w..(64 * w + 64).min(tri.len())];
        chunk.iter().enumerate().fold(0u64, |bits, (k, t)| {
            bits | u64::from(against_field(points, normals, *t)) << k
        })
    }));
    let mut flips = 0;
    let mut visits = 0usize;
    loop {
        let (a, b, slot) = if cursor < slots {
            let (h, t, k) = (cursor as u32, cursor / 3, cursor % 3);
            cursor += 1;
            // The last slot of a triangle is the last read of its saved copy (and there is
            // rarely any copy to look for).
            let saved = if unread.is_empty() {
                None
            } else if k == 2 {
                unread.remove(&(t as u32))
            } else {
                unread.get(&(t as u32)).copied()
            };
            let tri = saved.unwrap_or(he.tri[t]);
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a >= b {
                continue;
            }
            (a, b, Some(h))
        } else if let Some((a, b)) = queue.pop_front() {
            (a, b, None)
        } else {
            break;
        };
        visits += 1;
        if flips >= budget || visits > max_visits {
            break;
        }
        let Some(h) = he.locate(a, b, slot) else {
            continue;
        };
        let g = he.twin[h as usize];
        if g == NONE {
            continue;
        }
        let (t1, t2) = (h / 3, g / 3);
        let (c, d) = (he.origin(prev(h)), he.origin(prev(g)));
        if !pinned.is_empty() && [a, b, c, d].iter().any(|&v| pinned[v as usize]) {
            continue;
        }
        let was_folded = folded.get(t1 as usize) || folded.get(t2 as usize);
        if !he.wants_flip(points, normals, [a, b, c, d], was_folded) {
            continue;
        }
        for t in [t1, t2] {
            if 3 * t as usize + 2 >= cursor {
                unread.entry(t).or_insert(he.tri[t as usize]);
            }
        }
        he.flip(t1, t2, [a, b, c, d]);
        folded.clear(t1 as usize);
        folded.clear(t2 as usize);
        flips += 1;
        for (x, y) in [(a, d), (d, b), (b, c), (c, a)] {
            queue.push_back((x.min(y), x.max(y)));
        }
    }
    *triangles = he.into_triangles();
    // Flips only clear flags (both new triangles must agree with the field), so the flags
    // left are exactly the triangles that still face against it.
    FlipPass {
        flips,
        folded: Some(folded.0.iter().any(|&bits| bits != 0)),
    }
}

#[cfg(test)]
mod tests {
    use super::super::octahedron;
    use super::*;

    #[test]
    fn half_edges_of_a_closed_surface_pair_every_edge_with_its_reverse() {
        let (p, t) = octahedron();
        let he = HalfEdges::new(t, p.len()).expect("a closed 2-manifold");
        for h in 0..he.twin.len() as u32 {
            let g = he.twin[h as usize];
            assert_ne!(g, NONE);
            assert_eq!(he.twin[g as usize], h);
            assert_eq!((he.origin(g), he.dest(g)), (he.dest(h), he.origin(h)));
        }
        for v in 0..p.len() as u32 {
            assert_eq!(he.origin(he.out[v as usize]), v);
        }
        assert_eq!(he.find(4, 0), Some(2));
        assert!(he.adjacent(0, 2) && !he.adjacent(0, 1));
    }

    #[test]
    fn splitting_an_edge_keeps_every_half_edge_paired_with_its_reverse() {
        let (p, t) = octahedron();
        let mut he = HalfEdges::new(t, p.len()).expect("a closed 2-manifold");
        let h = he.find(0, 2).unwrap();
        let changed = he.split(h, 6);
        assert_eq!(changed.len(), 4);
        assert_eq!(he.triangles().len(), 10);
        for h in 0..he.twin.len() as u32 {
            let g = he.twin(h).expect("closed");
            assert_eq!(he.twin[g as usize], h);
            assert_eq!((he.origin(g), he.dest(g)), (he.dest(h), he.origin(h)));
        }
        for v in 0..7u32 {
            assert_eq!(he.origin(he.out[v as usize]), v);
        }
        let mut star = Vec::new();
        assert!(he.star(6, &mut star));
        assert_eq!(star.len(), 4);
        assert!(he.find(0, 2).is_none() && he.adjacent(0, 6) && he.adjacent(6, 2));
        // The new vertex's neighbours are the edge's ends and the two opposite corners.
        let mut ring: Vec<u32> = star
            .iter()
            .flat_map(|&f| he.triangles()[f as usize])
            .filter(|&v| v != 6)
            .collect();
        ring.sort_unstable();
        ring.dedup();
        assert_eq!(ring, [0, 2, 4, 5]);
        // An open fan: the split edge 1–2 is on the boundary.
        let open = vec![[0u32, 1, 2], [0, 2, 3]];
        let mut he = HalfEdges::new(open, 4).unwrap();
        assert!(!he.star(0, &mut star) && star.len() == 2);
        let h = he.find(1, 2).unwrap();
        assert_eq!(he.split(h, 4).len(), 2);
        assert!(he.twin(0).is_none() && !he.star(4, &mut star) && star.len() == 2);
    }

    #[test]
    fn flips_from_a_seed_undo_a_long_diagonal_and_only_there() {
        // A flat rhombus split along its long diagonal 0–2 (angles of 147° at 1 and 3),
        // beside a triangle on 2–3 that is fine as it is.
        let p = vec![
            [-1.0, 0.0, 0.0],
            [0.0, -0.3, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.3, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let n = vec![[0.0, 0.0, 1.0]; 5];
        let t = vec![[0, 1, 2], [0, 2, 3], [3, 2, 4]];
        let mut he = HalfEdges::new(t, 5).unwrap();
        let mut folded = vec![false; 3];
        let mut changed = Vec::new();
        let fine = he.find(2, 3).unwrap();
        assert_eq!(
            he.flip_from(&p, &n, &[fine], &mut folded, 8, &mut changed),
            0
        );
        assert!(changed.is_empty());
        let long = he.find(0, 2).unwrap();
        assert_eq!(
            he.flip_from(&p, &n, &[long], &mut folded, 8, &mut changed),
            1
        );
        changed.sort_unstable();
        assert_eq!(changed, [0, 1]);
        assert!(he.adjacent(1, 3) && he.find(0, 2).is_none() && he.find(2, 0).is_none());
    }

    #[test]
    fn half_edges_leave_the_boundary_of_an_open_fan_unpaired() {
        let t = vec![[0, 1, 2], [0, 2, 3]];
        let he = HalfEdges::new(t, 4).expect("an open fan");
        let unpaired = he.twin.iter().filter(|&&g| g == NONE).count();
        assert_eq!(unpaired, 4);
        assert_eq!(he.twin[2], 3);
        // The walk around 0 sees both triangles, whichever it starts from.
        assert_eq!((he.find(0, 1), he.find(0, 2)), (Some(0), Some(3)));
        assert_eq!(he.find(0, 3), None);
        assert!(he.adjacent(0, 3) && he.adjacent(3, 0) && !he.adjacent(1, 3));
    }

    #[test]
    fn half_edges_refuse_a_vertex_whose_triangles_form_two_fans() {
        // Two triangles touching only at vertex 0 (a bow tie).
        let t = vec![[0, 1, 2], [0, 3, 4]];
        assert!(HalfEdges::new(t, 5).is_err());
    }

    #[test]
    fn half_edges_refuse_a_directed_edge_used_twice() {
        // Both triangles run 0 → 1: one of them is upside down.
        let t = vec![[0, 1, 2], [0, 1, 3]];
        assert!(HalfEdges::new(t, 4).is_err());
    }

    #[test]
    fn half_edges_refuse_a_triangle_with_a_repeated_corner() {
        let t = vec![[0, 1, 1], [0, 1, 2]];
        assert!(HalfEdges::new(t, 3).is_err());
    }

    #[test]
    fn against_field_is_the_sign_of_the_agreement() {
        let mut rng = crate::geom::rng::XorShift64::new(17);
        let mut against = 0;
        for k in 0..30_000 {
            // Ordinary scales for half the faces, from underflow to overflow for the rest, and
            // some exactly degenerate faces.
            let range = if k % 2 == 0 { 3.0 } else { 200.0 };
            let scale = 10f64.powf(rng.uniform(-range, range));
            let mut p: Vec<[f64; 3]> = (0..3).map(|_| rng.in_cube(scale)).collect();
            if k % 10 == 0 {
                p[2] = p[1];
            }
            let normal_scale = 10f64.powf(rng.uniform(-range, range));
            let mut n: Vec<[f64; 3]> = (0..3).map(|_| rng.in_cube(normal_scale)).collect();
            if k % 97 == 0 {
                n[0][0] = f64::NAN;
            }
            let t = [0, 1, 2];
            let want = agreement(&p, &n, t) <= 0.0;
            against += usize::from(want);
            assert_eq!(against_field(&p, &n, t), want, "{p:?} {n:?}");
        }
        // Both answers occur often (extreme scales make many faces degenerate).
        assert!((5_000..25_000).contains(&against), "{against}");
    }

    #[test]
    fn within_tilt_is_the_agreement_against_the_limit() {
        let mut rng = crate::geom::rng::XorShift64::new(29);
        let limit = FLIP_TILT_DEG.to_radians().cos();
        let mut within = 0;
        for k in 0..30_000 {
            let range = if k % 2 == 0 { 3.0 } else { 200.0 };
            let scale = 10f64.powf(rng.uniform(-range, range));
            let p: Vec<[f64; 3]> = (0..3).map(|_| rng.in_cube(scale)).collect();
            // Normals near the face's for a third of the faces, so that both answers occur.
            let f = face_normal(&p, [0, 1, 2]);
            let n: Vec<[f64; 3]> = (0..3)
                .map(|_| {
                    let r = rng.in_cube(1.0);
                    let u = if k % 3 == 0 {
                        [f[0] + r[0] * dot(f, f).sqrt(), f[1], f[2]]
                    } else {
                        r
                    };
                    u.map(|x| x * 10f64.powf(rng.uniform(-range, range)))
                })
                .collect();
            let cos = agreement(&p, &n, [0, 1, 2]);
            if (cos - limit).abs() < 1e-12 {
                continue;
            }
            within += usize::from(cos >= limit);
            assert_eq!(
                within_tilt(&p, &n, [0, 1, 2], limit),
                cos >= limit,
                "{p:?} {n:?}"
            );
        }
        assert!((1_000..29_000).contains(&within), "{within}");
    }

    #[test]
    fn agreement_below_a_floor_is_exact_there_and_the_floor_above() {
        let mut rng = crate::geom::rng::XorShift64::new(31);
        let floor = 0.5;
        let (mut above, mut exact) = (0, 0);
        for k in 0..30_000 {
            let range = if k % 2 == 0 { 3.0 } else { 200.0 };
            let scale = 10f64.powf(rng.uniform(-range, range));
            let p: Vec<[f64; 3]> = (0..3).map(|_| rng.in_cube(scale)).collect();
            let f = face_normal(&p, [0, 1, 2]);
            // Every corner's normal at 60° from the face for a quarter of the faces (the
            // agreement then lies at the floor to rounding), near it for another quarter.
            let unit = |v: [f64; 3]| v.map(|x| x / dot(v, v).sqrt());
            let (fu, side) = (unit(f), unit(cross(f, rng.in_cube(1.0))));
            let n: Vec<[f64; 3]> = (0..3)
                .map(|_| {
                    let u = match k % 4 {
                        0 => {
                            let s = 0.75f64.sqrt();
                            [0, 1, 2].map(|i| 0.5 * fu[i] + s * side[i])
                        }
                        1 => {
                            let r = rng.in_cube(1.0);
                            [0, 1, 2].map(|i| fu[i] + r[i])
                        }
                        _ => rng.in_cube(1.0),
                    };
                    u.map(|x| x * 10f64.powf(rng.uniform(-range, range)))
                })
                .collect();
            let t = [0, 1, 2];
            let cos = agreement(&p, &n, t);
            let got = agreement_below([p[0], p[1], p[2]], &n, t, floor);
            if cos < floor {
                exact += 1;
                assert_eq!(got.to_bits(), cos.to_bits(), "{p:?} {n:?}");
            } else {
                above += 1;
                assert!(
                    got == floor || got.to_bits() == cos.to_bits(),
                    "{p:?} {n:?}"
                );
            }
            // What the relaxation asks of it, against any earlier agreement.
            let b = rng.uniform(-1.0, 1.0);
            assert_eq!(got < floor.min(b), cos < floor.min(b));
            assert_eq!(floor.min(got), floor.min(cos));
        }
        assert!(exact > 5_000 && above > 5_000, "{exact} {above}");
    }

    /// A flat rhombus in the plane z = 0 whose diagonal 0–2 is the long one.
    fn rhombus() -> Vec<[f64; 3]> {
        vec![
            [-2.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ]
    }

    #[test]
    fn a_long_diagonal_is_flipped_and_a_short_one_kept() {
        // Normal +z: the long diagonal 0–2 faces two obtuse angles.
        let p = rhombus();
        let n = vec![[0.0, 0.0, 1.0]; 4];
        let mut t = vec![[0, 1, 2], [0, 2, 3]];
        let pass = flip_to_surface_delaunay(&p, &n, &mut t, 10, &[], None);
        assert_eq!((pass.flips, pass.folded), (1, Some(false)));
        let mut edges: Vec<_> = t
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .collect();
        edges.sort_unstable();
        assert!(edges.contains(&(1, 3)) || edges.contains(&(3, 1)));
        // Now Delaunay: a second pass changes nothing.
        assert_eq!(
            flip_to_surface_delaunay(&p, &n, &mut t, 10, &[], None).flips,
            0
        );
    }

    #[test]
    fn a_flip_across_a_tube_that_would_tilt_its_faces_is_not_taken() {
        // 0–2 runs along the top of a narrow tube, 1 and 3 lie down its sides, whose normals
        // point sideways. 0–2 is not Delaunay (its opposite angles are 96° each), but the
        // diagonal 1–3 cuts across the tube: its faces would tilt 36.9° from their corners'
        // normals, against 29.7° now.
        let p = vec![
            [-2.0, 0.0, 0.0],
            [0.0, -1.0, -1.5],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, -1.5],
        ];
        let n = vec![
            [0.0, 0.0, 1.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
        ];
        let mut t = vec![[0, 1, 2], [0, 2, 3]];
        let tilt = |t: [u32; 3]| agreement(&p, &n, t).acos().to_degrees();
        assert!((tilt([0, 1, 2]) - 29.7).abs() < 0.1 && (tilt([0, 1, 3]) - 36.9).abs() < 0.1);
        let pass = flip_to_surface_delaunay(&p, &n, &mut t, 10, &[], None);
        assert_eq!(pass.flips, 0);
        assert_eq!(t, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn a_pass_reports_the_folds_it_leaves() {
        // The field points down, so both triangles face against it, and so would the flipped
        // pair: nothing is flipped, and the pass says the mesh still folds.
        let p = rhombus();
        let n = vec![[0.0, 0.0, -1.0]; 4];
        let mut t = vec![[0, 1, 2], [0, 2, 3]];
        let pass = flip_to_surface_delaunay(&p, &n, &mut t, 10, &[], None);
        assert_eq!((pass.flips, pass.folded), (0, Some(true)));
        assert!(t.iter().all(|&t| against_field(&p, &n, t)));
    }

    #[test]
    fn flips_leave_a_non_manifold_mesh_alone() {
        let mut p = rhombus();
        p.push([0.0, 0.0, 1.0]);
        let n = vec![[0.0, 0.0, 1.0]; 5];
        let mut t = vec![[0, 1, 2], [0, 2, 3], [0, 2, 4]];
        let before = t.clone();
        let pass = flip_to_surface_delaunay(&p, &n, &mut t, 10, &[], None);
        assert_eq!((pass.flips, pass.folded), (0, None));
        assert_eq!(t, before);
    }
}
