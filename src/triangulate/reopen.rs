//! Re-closing a surface whose chart folds next to the hole.
//!
//! Geodesic polar coordinates stop being a chart where the curves from `p0` cross a caustic
//! (on an ellipsoid started away from its shortest axis, near the far end). There chart 1's
//! triangles fold over in space and the hole left between the curves is a thin twisted band
//! that no planar projection fills. The points themselves are fine, only their connectivity
//! is wrong: the folded triangles next to the hole, plus a ring or two of their neighbours,
//! are taken out, and the larger hole is filled with a constrained Delaunay triangulation of
//! its loop *and the points inside it*, projected across the region's mean normal.

use super::flip::agreement;
use super::{
    dot3, frame_around, point_in_polygon, rows_by_corner, signed_area, simple_polygon, ChartVertex,
    EdgeSet,
};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation as _};
use std::collections::{HashMap, HashSet};

/// Cosine between a chart-1 face and the field normal at its corners below which the face
/// counts as folded by the chart (30°: the default mode's faces stay within a few degrees).
const FOLDED: f64 = 0.866;

/// Rings of neighbours tried around the folded triangles before giving up.
const MAX_RINGS: usize = 16;

/// Fill attempts (each after growing the region by a ring or by the stars of pinch points).
const MAX_ATTEMPTS: usize = 128;

/// Region triangles all attempts together may handle beyond twice the mesh's triangles.
const WORK_FLOOR: usize = 200_000;

/// A successful reclosing.
pub(super) struct Reclosed {
    /// The chart-1 triangles kept.
    pub kept: Vec<[u32; 3]>,
    /// The triangles that fill the rest.
    pub closing: Vec<[u32; 3]>,
    /// What `accept` made of the two.
    pub finished: Vec<[u32; 3]>,
}

/// Chart-1 `triangles` minus a region around the hole bounded by `front` (the folded
/// triangles connected to it, or else the triangles along it, grown ring by ring), and the
/// triangles that fill the region and the hole together, as soon as `accept` takes them (given
/// the kept triangles, to finish in place, and the fill, it returns the finished mesh, or
/// `None` if the two do not stitch into a valid one); `None`
/// when no region within [`MAX_RINGS`] rings, [`MAX_ATTEMPTS`] attempts and the work budget
/// has a single simple loop whose flat image can be filled acceptably.
pub(super) fn reclose(
    front: &[u32],
    triangles: &[[u32; 3]],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
    accept: impl Fn(Vec<[u32; 3]>, &[[u32; 3]]) -> Option<Vec<[u32; 3]>>,
) -> Option<Reclosed> {
    let n = pos.len();
    let stars = Stars::new(triangles, n)?;
    let star = |v: u32| stars.at(v);
    // Chart 1's own boundary (the front, with any front edge split at a point on it), as
    // (edge, triangle) pairs: found once, kept apart from the region's edges below.
    let boundary: Vec<(u32, u32, u32)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(i, t)| (0..3).map(move |k| (t[k], t[(k + 1) % 3], i as u32)))
        .filter(|&(a, b, _)| stars.holding(triangles, b, a).is_none())
        .collect();
    let folded = |t: &[u32; 3]| agreement(pos, normals, *t) < FOLDED;

    // Folded triangles connected to the hole through folded triangles (sharing vertices).
    let mut in_region = vec![false; triangles.len()];
    let mut queue: Vec<u32> = Vec::new();
    for &v in front {
        for &t in star(v) {
            if !in_region[t as usize] && folded(&triangles[t as usize]) {
                in_region[t as usize] = true;
                queue.push(t);
            }
        }
    }
    if queue.is_empty() {
        // Nothing folded: a thin hole between curves that stopped short; give the fill the
        // triangles along the hole to work with.
        for &v in front {
            for &t in star(v) {
                if !in_region[t as usize] {
                    in_region[t as usize] = true;
                    queue.push(t);
                }
            }
        }
    }
    let mut region = Vec::new();
    while let Some(t) = queue.pop() {
        region.push(t);
        for &v in &triangles[t as usize] {
            for &u in star(v) {
                if !in_region[u as usize] && folded(&triangles[u as usize]) {
                    in_region[u as usize] = true;
                    queue.push(u);
                }
            }
        }
    }
    let absorb = |vertices: &[u32], region: &mut Vec<u32>, in_region: &mut [bool]| {
        for &v in vertices {
            for &u in star(v) {
                if !in_region[u as usize] {
                    in_region[u as usize] = true;
                    region.push(u);
                }
            }
        }
    };
    let mut rings = 0;
    // Each attempt costs about the region's size: the attempts together may cost twice the
    // mesh (plus a floor for small meshes), so that a hole that will not close does not make
    // a large mesh slower by more than a constant factor.
    let budget = 2 * triangles.len() + WORK_FLOOR;
    let mut work = 0;
    for _ in 0..MAX_ATTEMPTS {
        work += region.len();
        if work > budget {
            return None;
        }
        let grow = match fill_region(
            triangles, &stars, &boundary, &in_region, &region, pos, normals,
        ) {
            Ok(closing) => {
                let kept = || {
                    triangles
                        .iter()
                        .zip(&in_region)
                        .filter(|(_, &r)| !r)
                        .map(|(t, _)| *t)
                };
                // Judging the whole mesh costs about its size.
                work += triangles.len();
                if let Some(finished) = accept(kept().collect(), &closing) {
                    return Some(Reclosed {
                        kept: kept().collect(),
                        closing,
                        finished,
                    });
                }
                // The fill folds somewhere once stitched in: a larger region may not.
                true
            }
            // The kept triangles touch each other at these vertices across the region:
            // take their stars in too.
            Err(Retry::Pinched(vertices)) => {
                absorb(&vertices, &mut region, &mut in_region);
                false
            }
            Err(Retry::Grow) => true,
        };
        if grow {
            if rings == MAX_RINGS {
                return None;
            }
            rings += 1;
            let vertices: Vec<u32> = region.iter().flat_map(|&t| triangles[t as usize]).collect();
            absorb(&vertices, &mut region, &mut in_region);
        }
    }
    None
}

/// The triangles at each vertex (CSR).
struct Stars {
    start: Vec<u32>,
    list: Vec<u32>,
}

impl Stars {
    /// `None` if a triangle names a vertex not below `n`.
    fn new(triangles: &[[u32; 3]], n: usize) -> Option<Self> {
        let (start, list) = rows_by_corner(triangles, n, |t, _| t as u32)?;
        Some(Stars { start, list })
    }

    fn at(&self, v: u32) -> &[u32] {
        &self.list[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }

    /// The triangle with the directed edge `a → b`, if any.
    fn holding(&self, triangles: &[[u32; 3]], a: u32, b: u32) -> Option<u32> {
        self.at(a).iter().copied().find(|&t| {
            let t = triangles[t as usize];
            (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
        })
    }
}

/// Why a region could not be filled, and what to try next.
enum Retry {
    /// The kept triangles touch at these vertices (the loop would pass them twice), or these
    /// vertices bound islands of kept triangles inside the region: take their stars in.
    Pinched(Vec<u32>),
    /// The loop is not simple in projection, or the fill failed: a larger region may do.
    Grow,
}

/// Fills the hole plus the region's triangles, or `None` when their boundary is not one
/// simple loop or its projection cannot be filled.
fn fill_region(
    triangles: &[[u32; 3]],
    stars: &Stars,
    boundary: &[(u32, u32, u32)],
    in_region: &[bool],
    region: &[u32],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
) -> Result<Vec<[u32; 3]>, Retry> {
    // The boundary of the kept triangles, each edge directed with them on its left (as chart 1
    // lies to the left of the front): chart 1's boundary edges that are kept, and the region's
    // edges seen from a kept triangle.
    let kept = |t: u32| !in_region[t as usize];
    let mut next: HashMap<u32, u32> = HashMap::new();
    let mut pinched = Vec::new();
    let mut add = |a: u32, b: u32| {
        if next.insert(a, b).is_some() {
            pinched.push(a);
        }
    };
    for &(a, b, t) in boundary {
        if kept(t) {
            add(a, b);
        }
    }
    for &t in region {
        let t = triangles[t as usize];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if stars.holding(triangles, b, a).is_some_and(kept) {
                add(b, a);
            }
        }
    }
    if !pinched.is_empty() {
        pinched.sort_unstable();
        return Err(Retry::Pinched(pinched));
    }
    // Split the boundary into loops; all but the longest surround islands of kept triangles
    // inside the region (or the smaller side of a region that cuts the surface in two):
    // those are taken in too.
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut seen: HashMap<u32, usize> = HashMap::with_capacity(next.len());
    let mut loops: Vec<Vec<u32>> = Vec::new();
    for &s in &starts {
        if seen.contains_key(&s) {
            continue;
        }
        let mut lp = vec![s];
        seen.insert(s, loops.len());
        let mut v = *next.get(&s).ok_or(Retry::Grow)?;
        while v != s {
            if seen.insert(v, loops.len()).is_some() {
                return Err(Retry::Grow);
            }
            lp.push(v);
            v = *next.get(&v).ok_or(Retry::Grow)?;
        }
        loops.push(lp);
    }
    let longest = (0..loops.len())
        .max_by_key(|&i| (loops[i].len(), std::cmp::Reverse(i)))
        .ok_or(Retry::Grow)?;
    if loops.len() > 1 {
        let others = loops
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != longest)
            .flat_map(|(_, l)| l.iter().copied())
            .collect();
        return Err(Retry::Pinched(others));
    }
    let lp = loops.swap_remove(longest);
    if lp.len() < 3 {
        return Err(Retry::Grow);
    }
    let on_loop: HashSet<u32> = lp.iter().copied().collect();
    // Points inside: the region's vertices off the loop, used by no kept triangle.
    let mut inside: Vec<u32> = region
        .iter()
        .flat_map(|&t| triangles[t as usize])
        .filter(|v| !on_loop.contains(v))
        .collect();
    inside.sort_unstable();
    inside.dedup();
    if inside.iter().any(|&v| stars.at(v).iter().any(|&t| kept(t))) {
        return Err(Retry::Grow);
    }
    let Some(closing) = fill_polygon(&lp, &inside, pos, normals, Projection::Plane)
        .or_else(|| fill_polygon(&lp, &inside, pos, normals, Projection::Gauss))
    else {
        // Where the loop crosses itself (a neck of the region between two overlapping sheets
        // of chart 1), widen the region there; elsewhere grow it all round.
        let crossing = crossings(&lp, pos, normals);
        return Err(if crossing.is_empty() {
            Retry::Grow
        } else {
            Retry::Pinched(crossing)
        });
    };
    // No closing edge may repeat a kept one (that would make an edge non-manifold); the
    // closing's corners are all on the loop or inside, so only kept edges along the loop
    // can clash.
    let mut have: EdgeSet = lp
        .iter()
        .flat_map(|&v| stars.at(v))
        .filter(|&&t| kept(t))
        .flat_map(|&t| {
            let t = triangles[t as usize];
            (0..3).map(move |k| (t[k], t[(k + 1) % 3]))
        })
        .filter(|(a, b)| on_loop.contains(a) && on_loop.contains(b))
        .collect();
    for t in &closing {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if have.contains(&(a, b)) || !have.insert((a, b)) {
                return Err(Retry::Grow);
            }
        }
    }
    Ok(closing)
}

/// How the region is laid flat for its triangulation.
#[derive(Clone, Copy)]
enum Projection {
    /// Orthogonally onto the plane across the region's mean normal.
    Plane,
    /// Through the Gauss map: each point goes to its unit normal, projected stereographically
    /// from the pole opposite the mean normal. One-to-one and orientation-preserving wherever
    /// the surface is strictly convex, however far the normals turn (the pointed end of an
    /// ellipsoid), where the plane folds.
    Gauss,
}

/// The points `all` laid flat by `chart` around their mean normal, or `None` where the chart
/// does not hold (a normal facing away from the plane, or too near the Gauss map's pole).
fn flatten(
    all: &[u32],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
    chart: Projection,
) -> Option<Vec<[f64; 2]>> {
    let [f1, f2, nm] = frame_around(all.iter().map(|&v| normals[v as usize]))?;
    // For the plane every normal must face the plane's side, or the projection folds the
    // region over itself; the Gauss map only needs to stay off the opposite pole (near it the
    // image runs off to infinity).
    let limit = match chart {
        Projection::Plane => 0.0,
        Projection::Gauss => -0.99,
    };
    if all.iter().any(|&v| dot3(normals[v as usize], nm) <= limit) {
        return None;
    }
    Some(
        all.iter()
            .map(|&v| match chart {
                Projection::Plane => {
                    let p = pos[v as usize];
                    [dot3(p, f1), dot3(p, f2)]
                }
                Projection::Gauss => {
                    let u = normals[v as usize];
                    let k = 1.0 / (1.0 + dot3(u, nm));
                    [k * dot3(u, f1), k * dot3(u, f2)]
                }
            })
            .collect(),
    )
}

/// The loop's vertices at the ends of edges that cross another edge of the loop in the Gauss
/// map's image (empty if none do, or the loop is too long to check).
fn crossings(lp: &[u32], pos: &[[f64; 3]], normals: &[[f64; 3]]) -> Vec<u32> {
    let m = lp.len();
    let Some(p) = flatten(lp, pos, normals, Projection::Gauss) else {
        return Vec::new();
    };
    if m > 4096 {
        return Vec::new();
    }
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let mut out = Vec::new();
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue;
            }
            let (a, b) = (p[i], p[(i + 1) % m]);
            let (c, d) = (p[j], p[(j + 1) % m]);
            if cross(a, b, c) * cross(a, b, d) <= 0.0 && cross(c, d, a) * cross(c, d, b) <= 0.0 {
                out.extend([lp[i], lp[(i + 1) % m], lp[j], lp[(j + 1) % m]]);
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Constrained Delaunay triangulation of the loop `lp` (kept triangles to its left) and the
/// points `inside` that fall inside it, laid flat by `chart` around their mean normal; `None`
/// unless the flat loop is simple and runs clockwise seen from outside, and every point keeps
/// its own vertex.
fn fill_polygon(
    lp: &[u32],
    inside: &[u32],
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
    chart: Projection,
) -> Option<Vec<[u32; 3]>> {
    let all: Vec<u32> = lp.iter().chain(inside).copied().collect();
    let proj = flatten(&all, pos, normals, chart)?;
    fill_flat(&all, lp.len(), &proj)
}

/// [`fill_polygon`] once laid flat: `all` starts with the loop's `m` vertices, and `proj`
/// holds the flat position of each of `all`.
pub(super) fn fill_flat(all: &[u32], m: usize, proj: &[[f64; 2]]) -> Option<Vec<[u32; 3]>> {
    let polygon = &proj[..m];
    if !simple_polygon(polygon) || signed_area(polygon) >= 0.0 {
        return None;
    }
    // Points of the region that fall outside the loop (where chart 1 had laid the region
    // over its neighbours) are left out: the fill covers the loop either way, and the mesh
    // simply does not use them.
    let vertices: Vec<ChartVertex> = proj
        .iter()
        .enumerate()
        .filter(|&(i, &c)| i < m || point_in_polygon(polygon, c))
        .map(|(i, c)| ChartVertex {
            position: Point2::new(c[0], c[1]),
            index: i as u32,
        })
        .collect();
    let expected = vertices.len();
    let edges: Vec<[usize; 2]> = (0..m).map(|i| [i, (i + 1) % m]).collect();
    let mut conflict = false;
    let cdt =
        ConstrainedDelaunayTriangulation::<ChartVertex>::try_bulk_load_cdt(vertices, edges, |_| {
            conflict = true
        })
        .ok()?;
    if conflict || cdt.num_vertices() != expected {
        return None;
    }
    let mut out = Vec::new();
    for face in cdt.inner_faces() {
        let [a, b, c] = face.vertices();
        let (pa, pb, pc) = (a.position(), b.position(), c.position());
        let centroid = [(pa.x + pb.x + pc.x) / 3.0, (pa.y + pb.y + pc.y) / 3.0];
        if point_in_polygon(polygon, centroid) {
            out.push([a, b, c].map(|h| all[h.data().index as usize]));
        }
    }
    Some(out)
}
