//! Edge flips on the surface: make the chart's triangulation Delaunay in space.
//!
//! The chart is conformal only near `p0`; farther out it stretches the surface, and a
//! triangulation that is Delaunay in the chart has needlessly thin triangles in space. Lawson
//! flips with the surface criterion — flip an edge when the two angles opposite to it add up
//! to more than π — restore the max-min-angle property on the surface. A flip is taken only
//! when it keeps the mesh a consistently oriented 2-manifold whose faces agree with the field
//! normal; flips that undo a fold (a face against the field normal) come first.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A multiply-mix hasher for the packed directed-edge keys (SipHash dominated the profile).
#[derive(Default)]
pub(crate) struct EdgeHasher(u64);

impl Hasher for EdgeHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(self.0 ^ b as u64);
        }
    }
    #[inline]
    fn write_u32(&mut self, k: u32) {
        self.write_u64(k as u64);
    }
    #[inline]
    fn write_u64(&mut self, k: u64) {
        let h = (self.0 ^ k).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = h ^ (h >> 29);
    }
}

/// Directed edge `(a, b)` packed into one key.
#[inline]
fn key(a: u32, b: u32) -> u64 {
    ((a as u64) << 32) | b as u64
}

type EdgeMap = HashMap<u64, u32, BuildHasherDefault<EdgeHasher>>;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Angle at `c` in triangle (a, b, c).
fn angle_at(c: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let (u, v) = (sub(a, c), sub(b, c));
    let cr = cross(u, v);
    dot(cr, cr).sqrt().atan2(dot(u, v))
}

/// Unnormalised face normal.
fn face_normal(p: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|i| p[i as usize]);
    cross(sub(b, a), sub(c, a))
}

fn field_normal(n: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let mut s = [0.0; 3];
    for i in t {
        for k in 0..3 {
            s[k] += n[i as usize][k];
        }
    }
    s
}

/// Cosine of the angle between a face and the field normal at its corners.
fn agreement(p: &[[f64; 3]], n: &[[f64; 3]], t: [u32; 3]) -> f64 {
    let f = face_normal(p, t);
    let g = field_normal(n, t);
    let d = (dot(f, f) * dot(g, g)).sqrt();
    if d > 0.0 {
        dot(f, g) / d
    } else {
        -1.0
    }
}

/// Flips edges of `triangles` in place; returns the number of flips. At most
/// `budget` flips are made.
pub(crate) fn flip_to_surface_delaunay(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    triangles: &mut [[u32; 3]],
    budget: usize,
) -> usize {
    // Directed edge → triangle holding it.
    let mut owner: EdgeMap =
        HashMap::with_capacity_and_hasher(triangles.len() * 3, Default::default());
    for (ti, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            owner.insert(key(t[k], t[(k + 1) % 3]), ti as u32);
        }
    }
    let mut queue: std::collections::VecDeque<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter(|&(a, b)| a < b)
        .collect();
    let mut flips = 0;
    let mut visits = 0usize;
    let max_visits = 20 * triangles.len() + 1000;
    while let Some((a, b)) = queue.pop_front() {
        visits += 1;
        if flips >= budget || visits > max_visits {
            break;
        }
        let (Some(&t1), Some(&t2)) = (owner.get(&key(a, b)), owner.get(&key(b, a))) else {
            continue;
        };
        let c = third(triangles[t1 as usize], a, b);
        let d = third(triangles[t2 as usize], b, a);
        if c == d || owner.contains_key(&key(c, d)) || owner.contains_key(&key(d, c)) {
            continue;
        }
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
        let new_ok =
            agreement(points, normals, new1) > 0.0 && agreement(points, normals, new2) > 0.0;
        if !new_ok {
            continue;
        }
        // The flipped pair must not fold over the old one (the quad must be convex enough).
        let old_sum = {
            let (f1, f2) = (face_normal(points, old1), face_normal(points, old2));
            [f1[0] + f2[0], f1[1] + f2[1], f1[2] + f2[2]]
        };
        if dot(face_normal(points, new1), old_sum) <= 0.0
            || dot(face_normal(points, new2), old_sum) <= 0.0
        {
            let folded =
                agreement(points, normals, old1) <= 0.0 || agreement(points, normals, old2) <= 0.0;
            if !folded {
                continue;
            }
        }
        let folded =
            agreement(points, normals, old1) <= 0.0 || agreement(points, normals, old2) <= 0.0;
        let delaunay_violation =
            angle_at(pc, pa, pb) + angle_at(pd, pb, pa) > std::f64::consts::PI + 1e-12;
        if !(folded || delaunay_violation) {
            continue;
        }
        // Flip.
        for (x, y) in [(a, b), (b, c), (c, a), (b, a), (a, d), (d, b)] {
            owner.remove(&key(x, y));
        }
        triangles[t1 as usize] = new1;
        triangles[t2 as usize] = new2;
        for (t, tri) in [(t1, new1), (t2, new2)] {
            for k in 0..3 {
                owner.insert(key(tri[k], tri[(k + 1) % 3]), t);
            }
        }
        flips += 1;
        for (x, y) in [(a, d), (d, b), (b, c), (c, a)] {
            queue.push_back((x.min(y), x.max(y)));
        }
    }
    flips
}

fn third(t: [u32; 3], a: u32, b: u32) -> u32 {
    for k in 0..3 {
        if t[k] == a && t[(k + 1) % 3] == b {
            return t[(k + 2) % 3];
        }
    }
    unreachable!("edge ({a}, {b}) is in the triangle by construction")
}
