//! The last step before a mesh leaves the pipeline: it must not pass through itself.
//!
//! The fence, the stitching's exact tests and the relaxation's orientation checks keep almost
//! every mesh embedded, but relaxation moves and surface-Delaunay flips are judged locally and
//! can still make two faces cross where the mesh is thin (a seam the stitching closed, a fold of
//! a non-integrable field's sweep). Here the crossings are found exactly, over the whole mesh,
//! and undone:
//!
//! 0. if relaxation made them ([`relax_pinned`]), the mesh goes back to where it was before
//!    relaxation and is relaxed again with the vertices around the crossing faces pinned (a
//!    ring wider each time, while that leaves fewer crossings): the surface keeps its faces;
//! 1. vertices of crossing faces that relaxation moved go back to where they were before it
//!    (a round of that which leaves no fewer crossings is taken back: the flips after
//!    relaxation may have joined those vertices differently);
//! 2. faces that still cross are removed — on a non-integrable field the swept surface ends
//!    where it would cross itself —, pinched vertices are cut apart, and only the component of
//!    `p0` (or the largest) is kept.
//!
//! What was removed is counted in [`Untangled`] and reported; a mesh that still crosses itself
//! after [`UNTANGLE_ROUNDS`] rounds is an error, never an output.

use super::relax::relax;
use super::stitch::unpinch;
use crate::geom::union_find::UnionFind;
use crate::mesh::Mesh;
use crate::params::Resolved;
use crate::scalar::{Scalar, Vec3};
use crate::NormalField;

/// Rounds of finding crossings and undoing them.
pub const UNTANGLE_ROUNDS: usize = 16;

/// Times relaxation is run again, with more vertices pinned, when it made faces cross.
const RELAX_AGAIN: usize = 3;

/// What untangling did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Untangled {
    /// Vertices put back where they were before relaxation.
    pub reverted: usize,
    /// Faces removed because they crossed others, or were cut off with them, or met the axis
    /// of the surface's hole ([`crate::model::Hole`]).
    pub removed: usize,
    /// Faces peeled off the boundary because they stood further than
    /// [`SINGULAR_FAN_DEG`](crate::triangulate::SINGULAR_FAN_DEG) off the surface with a corner
    /// on a curve that ended at a singular point (a fan or strip towards a cone's apex): the
    /// mesh stops short of the singular point there.
    #[cfg_attr(feature = "serde", serde(default))]
    pub off_surface: usize,
    /// Crossing face pairs left (0 unless the rounds ran out).
    pub left: usize,
    /// Vertices pinned where they were before relaxation when it was run again because it
    /// had made faces cross (0 if it did not).
    pub pinned: usize,
}

/// Relaxation made faces cross (`crossings` lists them): the mesh goes back to `before` and
/// is relaxed again with the crossing faces' vertices and their neighbours pinned, a ring
/// wider each time, up to [`RELAX_AGAIN`] times while that leaves fewer crossings. The state
/// with the fewest crossings is kept. Returns how many vertices were pinned in it.
pub(crate) fn relax_pinned<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    mesh: &mut Mesh,
    vertices: &mut Vec<Vec3<T>>,
    before: &Before<T>,
    crossings: impl Fn(&[[f64; 3]], &[[u32; 3]]) -> Vec<(usize, usize)>,
) -> usize {
    let n = before.positions.len();
    if mesh.vertices.len() != n {
        return 0;
    }
    let mut pairs = crossings(&mesh.vertices, &mesh.triangles);
    let mut pinned = vec![false; n];
    let mut kept_pins = 0;
    for _ in 0..RELAX_AGAIN {
        if pairs.is_empty() {
            break;
        }
        // The crossing faces' corners, then one ring more around everything pinned so far.
        for &(f, g) in &pairs {
            for v in mesh.triangles[f].into_iter().chain(mesh.triangles[g]) {
                pinned[v as usize] = true;
            }
        }
        let ring: Vec<u32> = before
            .triangles
            .iter()
            .filter(|t| t.iter().any(|&v| pinned[v as usize]))
            .flatten()
            .copied()
            .collect();
        for v in ring {
            pinned[v as usize] = true;
        }
        let last = (
            std::mem::replace(&mut mesh.vertices, before.positions.clone()),
            std::mem::replace(&mut mesh.normals, before.normals.clone()),
            std::mem::replace(&mut mesh.triangles, before.triangles.clone()),
            std::mem::replace(vertices, before.working.clone()),
        );
        relax(field, params, mesh, vertices, &pinned);
        let now = crossings(&mesh.vertices, &mesh.triangles);
        if now.len() >= pairs.len() {
            (mesh.vertices, mesh.normals, mesh.triangles, *vertices) = last;
            break;
        }
        pairs = now;
        kept_pins = pinned.iter().filter(|&&p| p).count();
    }
    kept_pins
}

/// Finds the crossings of `mesh` with `crossings` and undoes them (see the module docs).
/// `before` holds each vertex's position before relaxation (in `f64` and the working
/// precision) and its unit normal then, for the vertices relaxation may have moved.
pub(crate) fn untangle<T: Scalar>(
    mesh: &mut Mesh,
    vertices: &mut [Vec3<T>],
    before: Option<&Before<T>>,
    crossings: impl Fn(&[[f64; 3]], &[[u32; 3]]) -> Vec<(usize, usize)>,
) -> Untangled {
    let mut done = Untangled::default();
    let mut reverting = before.is_some();
    // Reverts judged face by face can make things worse (the flips after relaxation changed
    // which vertices a face has): a round that leaves no fewer crossings is taken back and
    // the faces are removed instead.
    let mut last_round: Option<RevertRound<T>> = None;
    for _ in 0..UNTANGLE_ROUNDS {
        let mut pairs = crossings(&mesh.vertices, &mesh.triangles);
        if let Some(round) = last_round.take() {
            if pairs.len() >= round.crossings.len() {
                done.reverted -= round.moved.len();
                for m in round.moved {
                    mesh.vertices[m.vertex] = m.position;
                    mesh.normals[m.vertex] = m.normal;
                    vertices[m.vertex] = m.working;
                }
                pairs = round.crossings;
                reverting = false;
            }
        }
        done.left = pairs.len();
        if pairs.is_empty() {
            return done;
        }
        let mut faces: Vec<usize> = pairs.iter().flat_map(|&(f, g)| [f, g]).collect();
        faces.sort_unstable();
        faces.dedup();
        if let (true, Some(b)) = (reverting, before) {
            let mut moved = Vec::new();
            for &f in &faces {
                for v in mesh.triangles[f] {
                    let v = v as usize;
                    if v < b.positions.len() && mesh.vertices[v] != b.positions[v] {
                        moved.push(Moved {
                            vertex: v,
                            position: mesh.vertices[v],
                            normal: mesh.normals[v],
                            working: vertices[v].clone(),
                        });
                        mesh.vertices[v] = b.positions[v];
                        mesh.normals[v] = b.normals[v];
                        vertices[v] = b.working[v].clone();
                    }
                }
            }
            if !moved.is_empty() {
                done.reverted += moved.len();
                last_round = Some(RevertRound {
                    moved,
                    crossings: pairs,
                });
                continue;
            }
            reverting = false;
        }
        let drop: std::collections::HashSet<usize> = faces.into_iter().collect();
        let before_count = mesh.triangles.len();
        let mut f = 0;
        mesh.triangles.retain(|_| {
            let keep = !drop.contains(&f);
            f += 1;
            keep
        });
        unpinch(&mut mesh.triangles);
        keep_main_component(mesh);
        done.removed += before_count - mesh.triangles.len();
    }
    done.left = crossings(&mesh.vertices, &mesh.triangles).len();
    done
}

/// A round of reverts, kept to be taken back: each vertex it moved with its position, normal
/// and working-precision point until then, and the crossings before it.
struct RevertRound<T> {
    moved: Vec<Moved<T>>,
    crossings: Vec<(usize, usize)>,
}

/// A vertex a revert moved, and where it was.
struct Moved<T> {
    vertex: usize,
    position: [f64; 3],
    normal: [f64; 3],
    working: Vec3<T>,
}

/// Positions and normals before relaxation.
pub(crate) struct Before<T> {
    pub(crate) positions: Vec<[f64; 3]>,
    pub(crate) normals: Vec<[f64; 3]>,
    pub(crate) working: Vec<Vec3<T>>,
    pub(crate) triangles: Vec<[u32; 3]>,
}

/// Keeps only the faces of the component (faces connected through edges) that holds `p0`'s
/// vertex, or the largest component when `p0` is on none. Vertices are kept (unreferenced).
pub(crate) fn keep_main_component(mesh: &mut Mesh) {
    let tris = &mesh.triangles;
    if tris.is_empty() {
        return;
    }
    let n = mesh.vertices.len();
    // Union–find over vertices joined by edges: faces sharing an edge share two vertices,
    // and a pinch-free mesh's components through vertices and through edges agree.
    let mut parent = UnionFind::new(n);
    for t in tris {
        for k in 0..3 {
            parent.union(t[k], t[(k + 1) % 3]);
        }
    }
    let mut size = vec![0usize; n];
    for t in tris {
        size[parent.find(t[0]) as usize] += 1;
    }
    let p0 = mesh
        .provenance
        .iter()
        .position(|pr| pr.curve == 0 && pr.step == 0)
        .map(|v| parent.find(v as u32))
        .filter(|&r| size[r as usize] > 0);
    let keep = p0.unwrap_or_else(|| {
        (0..n as u32)
            .max_by_key(|&r| (size[r as usize], std::cmp::Reverse(r)))
            .unwrap_or(0)
    });
    mesh.triangles.retain(|t| parent.find(t[0]) == keep);
}

/// Drops the vertices no face uses (and their working-precision twins), renumbering the rest
/// in order.
pub(crate) fn drop_unused<T>(mesh: &mut Mesh, vertices: &mut Vec<Vec3<T>>) {
    drop_unused_in(mesh, vertices, 0..mesh.vertices.len());
}

/// [`drop_unused`] for the vertices in `range` only (the others stay, used or not).
pub(crate) fn drop_unused_in<T>(
    mesh: &mut Mesh,
    vertices: &mut Vec<Vec3<T>>,
    range: std::ops::Range<usize>,
) {
    let n = mesh.vertices.len();
    // (Vertices outside the range count as used.)
    let mut used: Vec<bool> = (0..n).map(|v| !range.contains(&v)).collect();
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut remap = vec![u32::MAX; n];
    let mut next = 0u32;
    for v in 0..n {
        if used[v] {
            remap[v] = next;
            next += 1;
        }
    }
    let keep = |v: &usize| used[*v];
    let mut k = 0;
    mesh.vertices.retain(|_| (keep(&k), k += 1).0);
    k = 0;
    mesh.normals.retain(|_| (keep(&k), k += 1).0);
    k = 0;
    mesh.provenance.retain(|_| (keep(&k), k += 1).0);
    k = 0;
    vertices.retain(|_| (keep(&k), k += 1).0);
    for t in &mut mesh.triangles {
        *t = t.map(|v| remap[v as usize]);
    }
}
