//! Tangential relaxation on the surface (default mode).
//!
//! Each interior vertex moves towards the centroid of its neighbours, but along the surface:
//! the move is a drift-free chord step of [`trace::step_fixed`] in the working precision, so
//! the vertices stay exactly on the level set of an integrable field, dual numbers keep their
//! derivatives, and MPFR runs stay comparable with `f64` ones. `p0` and boundary vertices stay
//! where they are. Edge flips afterwards restore the surface Delaunay property.

use super::flip::{agreement_below, flip_to_surface_delaunay};
use super::Mesh;
use crate::geom::rows::rows_by_corner;
use crate::par;
use crate::params::Resolved;
use crate::scalar::{Scalar, Vec3};
use crate::trace::{self, StepConfig};
use crate::NormalField;

/// Relaxation sweeps; three take the worst angles from the sampler's ~19° to above 20°
/// on the presets and the ellipsoid while moving vertices by a fraction of a step.
const SWEEPS: usize = 3;
/// Fraction of the way to the neighbours' centroid moved per sweep.
pub(super) const DAMPING: f64 = 0.5;

/// Relaxes `mesh`, whose vertices in the working precision are `vertices` (moved in place).
/// Vertices marked in `pinned` (empty: none) stay where they are, and so do the edges of
/// the triangles around them.
pub(crate) fn relax<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    mesh: &mut Mesh,
    vertices: &mut Vec<Vec3<T>>,
    pinned: &[bool],
) {
    let n = mesh.vertices.len();
    let mut pos: Vec<Vec3<T>> = std::mem::take(vertices);
    // Out-neighbours in CSR form (`adj[start[v]..start[v] + len[v]]`): `b` once in `a`'s list
    // per triangle with the directed edge `a → b`, then sorted and deduplicated for a
    // deterministic sum; boundary vertices are fixed.
    let tris = &mesh.triangles;
    let (start, mut adj) = rows_by_corner(tris, n, |t, k| tris[t][(k + 1) % 3])
        .expect("the mesh's triangles name its vertices");
    for v in 0..n {
        adj[start[v] as usize..start[v + 1] as usize].sort_unstable();
    }
    // An edge used by other than exactly two triangles (`a → b` and `b → a` counted
    // together) is a boundary, or worse: both ends stay fixed.
    let uses = |a: u32, b: u32| {
        let list = &adj[start[a as usize] as usize..start[a as usize + 1] as usize];
        list.partition_point(|&x| x <= b) - list.partition_point(|&x| x < b)
    };
    let mut fixed = vec![false; n];
    for a in 0..n as u32 {
        let list = &adj[start[a as usize] as usize..start[a as usize + 1] as usize];
        // `a → b` is used as often as `b` repeats in `a`'s sorted list.
        for run in list.chunk_by(|x, y| x == y) {
            let b = run[0];
            if run.len() + uses(b, a) != 2 {
                fixed[a as usize] = true;
                fixed[b as usize] = true;
            }
        }
    }
    // p0 stays where it is (the vertex of curve 0's first point), and so do the pinned.
    for (v, pr) in mesh.provenance.iter().enumerate() {
        if pr.curve == 0 && pr.step == 0 {
            fixed[v] = true;
        }
    }
    for (f, &p) in fixed.iter_mut().zip(pinned) {
        *f |= p;
    }
    let mut len = vec![0u32; n];
    for v in 0..n {
        let list = &mut adj[start[v] as usize..start[v + 1] as usize];
        let mut m = 0;
        for k in 0..list.len() {
            if k == 0 || list[k] != list[m - 1] {
                list[m] = list[k];
                m += 1;
            }
        }
        len[v] = m as u32;
    }
    let neighbours = |v: usize| &adj[start[v] as usize..(start[v] + len[v]) as usize];
    let cfg = StepConfig::<T>::new(params);
    let damping = T::from_f64(DAMPING);
    // Each face's agreement with the field at the current positions, carried from one
    // sweep's check to the next sweep's starting point.
    let mut agreement: Option<Vec<f64>> = None;
    for _ in 0..SWEEPS {
        let moved: Vec<Vec3<T>> = par::map(n, par::MIN_COSTLY, |v| {
            if fixed[v] {
                return pos[v].clone();
            }
            towards_centroid(field, &cfg, &pos, v, neighbours(v), &damping)
        });
        let kept = keep_orientation(&mesh.triangles, &mesh.normals, pos, moved, agreement);
        (pos, agreement) = (kept.0, Some(kept.1));
    }
    drop((adj, start, len, fixed, agreement));
    // The neighbour lists are gone by now, and the vertices and normals are written in
    // place: the flip pass below is the peak of the pipeline's memory.
    for (v, p) in mesh.vertices.iter_mut().zip(&pos) {
        *v = p.to_f64();
    }
    par::for_each_mut(&mut mesh.normals, par::MIN_COSTLY, |i, nrm| {
        *nrm = trace::unit_normal(field, &pos[i])
            .map(|(_, n, _)| n.to_f64())
            .unwrap_or([0.0; 3]);
    });
    let budget = 8 * mesh.triangles.len() + 64;
    flip_to_surface_delaunay(
        &mesh.vertices,
        &mesh.normals,
        &mut mesh.triangles,
        budget,
        pinned,
        params.hole.map(|h| h.axis()),
    );
    *vertices = pos;
}

/// Where vertex `v` moves: `damping` of the way to the centroid of its `neighbours`, along
/// the surface (a chord of [`trace::step_fixed`]); where it is unless that chord exists.
#[inline]
pub(super) fn towards_centroid<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    pos: &[Vec3<T>],
    v: usize,
    neighbours: &[u32],
    damping: &T,
) -> Vec3<T> {
    if neighbours.is_empty() {
        return pos[v].clone();
    }
    let mut c = Vec3::<T>::zero();
    for &u in neighbours {
        c = &c + &pos[u as usize];
    }
    let c = c.scale(&(T::one() / T::from_f64(neighbours.len() as f64)));
    let d = &c - &pos[v];
    let len = d.norm() * damping.clone();
    if len.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
        return pos[v].clone();
    }
    trace::step_fixed(field, cfg, &pos[v], &d, &len).unwrap_or_else(|_| pos[v].clone())
}

/// Cosine between a face and the field normal below which a move counts as folding it.
pub(super) const MIN_AGREEMENT: f64 = 0.5;

/// Accepts the sweep's moves except where a triangle would fold: the vertices of every
/// triangle whose face normal turns away from the field normal (and did not before) go back
/// to where they were, until no such triangle is left. `before` holds each face's agreement
/// at `old` if known; returns the positions and each face's agreement at them (agreements
/// above [`MIN_AGREEMENT`] given as that).
fn keep_orientation<T: Scalar>(
    triangles: &[[u32; 3]],
    normals: &[[f64; 3]],
    old: Vec<Vec3<T>>,
    mut new: Vec<Vec3<T>>,
    before: Option<Vec<f64>>,
) -> (Vec<Vec3<T>>, Vec<f64>) {
    // Only agreements below `MIN_AGREEMENT` matter (each face is held to the lower of that
    // and where it was), so those above are not computed exactly.
    let agreement = |pos: &[Vec3<T>], t: &[u32; 3]| {
        agreement_below(
            t.map(|i| pos[i as usize].to_f64()),
            normals,
            *t,
            MIN_AGREEMENT,
        )
    };
    // Positions are read through `to_f64` rather than copied: free for `f64`, and no second
    // copy of the mesh at the pipeline's peak memory.
    let before: Vec<f64> = before.unwrap_or_else(|| {
        par::map(triangles.len(), par::MIN_CHEAP, |t| {
            agreement(&old, &triangles[t])
        })
    });
    // Every face is checked in the first round, and again whenever a corner went back, so
    // the last value computed for a face is its agreement at the final positions. The first
    // round's values are computed up front, in parallel; the round itself recomputes a
    // face's value only if a corner went back earlier in the round.
    let mut now = par::map(triangles.len(), par::MIN_CHEAP, |t| {
        agreement(&new, &triangles[t])
    });
    // The round in which each vertex went back (a vertex goes back at most once). After the
    // first round only triangles with a vertex that went back in this round or the last can
    // have changed since they were checked; the others would pass again.
    const NEVER: u32 = u32::MAX;
    let mut reverted_in = vec![NEVER; new.len()];
    // Each round reverts at least one moved vertex, so this ends within `new.len()` rounds.
    for round in 0..=new.len() as u32 {
        let mut reverted = false;
        for ((t, &b), a) in triangles.iter().zip(&before).zip(&mut now) {
            let changed = |&i: &u32| {
                let r = reverted_in[i as usize];
                r != NEVER && r + 1 >= round
            };
            if t.iter().any(changed) {
                *a = agreement(&new, t);
            } else if round > 0 {
                continue;
            }
            let limit = MIN_AGREEMENT.min(b);
            if *a < limit {
                for &i in t {
                    let i = i as usize;
                    if new[i].to_f64() != old[i].to_f64() {
                        new[i] = old[i].clone();
                        reverted_in[i] = round;
                        reverted = true;
                    }
                }
            }
        }
        if !reverted {
            break;
        }
    }
    (new, now)
}
