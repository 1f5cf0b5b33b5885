//! Refinement to a bound on the face-normal error (optional: `MeshParams::max_normal_error`).
//!
//! A face's normal error is the angle between its plane and the field normal at its centroid,
//! the measure of [`crate::quality::face_normal_error`]. It grows with the face's size and with
//! how far its circumcentre lies from its centroid, so the worst faces are large obtuse ones:
//! the far pole's closing, or where curves diverge before a new one is inserted.
//!
//! Each round splits, for every face above the bound (worst first), the edge at the end of its
//! longest-edge propagation path (Rivara): the face's longest edge, unless the face across it
//! has a longer one, and so on. Splitting an edge that is the longest of both its faces keeps
//! the new faces' angles bounded. The new vertex is a chord step of [`trace::step_fixed`] from
//! one end of the edge towards the other, half the edge long, in the working precision: like
//! the relaxation's moves it lands on the level set of an integrable field. Edge flips then
//! restore the surface Delaunay property, and the new vertices and their neighbours take one
//! damped step towards the centroids of their neighbours, as in the relaxation: an edge split
//! leaves right angles beside it, and a right triangle's circumcentre is off its centroid by a
//! sixth of its longest edge, so without that step splits beget splits.

use super::flip::{against_field, agreement_at, HalfEdges};
use super::relax::{towards_centroid, DAMPING, MIN_AGREEMENT};
use super::{Mesh, Provenance};
use crate::geom::face_error_deg;
use crate::geom::vec3::{cross, dot, sub};
use crate::par;
use crate::params::Resolved;
use crate::scalar::{Scalar, Vec3};
use crate::trace::{self, StepConfig};
use crate::NormalField;

/// Most rounds of splits. Each round splits at most one edge per neighbourhood, and a bad
/// face's propagation path may take a few rounds to reach it.
pub const MAX_REFINE_ROUNDS: usize = 64;

/// Most faces on one longest-edge propagation path.
const MAX_PATH: usize = 64;

/// The refinement stops when the last this many rounds together at least doubled the faces
/// and left those over the bound no fewer and their area no smaller
/// ([`Refinement::stalled`]). Splits shrink the error of a face only where its corners lie
/// on one surface: the paper's mode leaves its vertices up to 4% off the unit sphere, and
/// there each split made steeper faces between a new vertex and a drifted one; asked for 5°,
/// the rounds went on to the point budget, 4 million triangles in 45 s, with more area over
/// the bound than at the start (it stops at 17,694 now). Likewise on a non-integrable field,
/// which has no surface for the corners to lie on: fig6 asked for 2° went to 2 million
/// vertices (now 6 rounds, 10,774 vertices). Where the refinement converges, the rounds that
/// double the faces are the first few, which take the count down; in its tail single rounds
/// raise the count or the area but add a few percent of faces (the unit sphere to 0.5° in
/// the default mode: 36 rounds).
const STALL_ROUNDS: usize = 4;

/// What a refinement to `MeshParams::max_normal_error` did ([`crate::MeshRun::refinement`]).
///
/// ```
/// use liemesh::{model::{Invariant, LieField}, preset::Preset, quality::face_normal_error};
///
/// let sphere = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0])?;
/// let field = LieField::<f64>::new(&sphere);
/// let mut params = Preset::Fig3.params();
/// params.max_normal_error = Some(liemesh::Angle::from_degrees(1.0));
/// let run = liemesh::run(&field, &params)?;
/// let refinement = run.refinement.expect("asked for");
/// assert!(refinement.added > 0 && refinement.over_limit == 0);
/// assert!(face_normal_error(&field, &run.mesh).0 <= 1.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Refinement {
    /// Rounds of splits made.
    pub rounds: usize,
    /// Vertices added.
    pub added: usize,
    /// Faces whose normal error is still above the bound: 0 unless the rounds, the point
    /// budget or the surface (a chord that finds no root, a split that would fold a face)
    /// stopped the refinement, or it stalled.
    pub over_limit: usize,
    /// Whether the refinement stopped because its last four rounds together at least doubled
    /// the faces and left those over the bound no fewer and their area no smaller: the mesh's
    /// vertices are not on one surface (the paper's mode, whose chords drift off their level
    /// set, or a non-integrable field, which has none), so that smaller faces only tilt more.
    #[cfg_attr(feature = "serde", serde(default))]
    pub stalled: bool,
}

/// The field's normal at an `f64` point, as the quality report measures faces: a field in a
/// wider type evaluates its own `f64` rounding where it has one
/// ([`NormalField::in_f64`]).
pub(crate) fn f64_normal<T: Scalar, F: NormalField<T>>(
    field: &F,
) -> impl Fn(&Vec3<f64>) -> Vec3<f64> + Copy + '_ {
    let fast = field.in_f64();
    move |c: &Vec3<f64>| match fast {
        Some(f) => f.normal(c),
        None => Vec3::from_f64(field.normal(&Vec3::<T>::from_f64(c.to_f64())).to_f64()),
    }
}

/// How many faces of `mesh` have a normal error above `limit_deg`, measured as [`refine`]
/// measures it (faces removed after refinement, when crossings are undone, no longer count).
pub(crate) fn faces_over<T: Scalar, F: NormalField<T>>(
    field: &F,
    mesh: &Mesh,
    limit_deg: f64,
) -> usize {
    let normal_at = f64_normal(field);
    par::map(mesh.triangles.len(), par::MIN_COSTLY, |t| {
        face_error_deg(
            mesh.triangles[t].map(|i| mesh.vertices[i as usize]),
            normal_at,
        )
    })
    .into_iter()
    .filter(|&e| e > limit_deg)
    .count()
}

/// Splits the faces of `mesh` whose normal error exceeds `limit_deg` until none does, or the
/// rounds or `params.max_points` run out. `pos` holds the vertices in the working
/// precision and grows with the mesh. A mesh that is not a consistently oriented 2-manifold
/// is left as it is. `on_round(round, vertices, triangles)` is called as each round starts
/// (rounds counting from 1), for progress reports.
pub(crate) fn refine<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    limit_deg: f64,
    mesh: &mut Mesh,
    pos: &mut Vec<Vec3<T>>,
    on_round: &dyn Fn(usize, usize, usize),
) -> Refinement {
    let cfg = StepConfig::<T>::new(params);
    // The error is measured on the `f64` mesh, as the quality report measures it; a field in
    // a wider type evaluates its own `f64` rounding where it has one.
    let normal_at = f64_normal(field);
    let error = |vertices: &[[f64; 3]], tri: [u32; 3]| {
        face_error_deg(tri.map(|i| vertices[i as usize]), normal_at)
    };
    let mut errors = par::map(mesh.triangles.len(), par::MIN_COSTLY, |t| {
        error(&mesh.vertices, mesh.triangles[t])
    });
    let mut done = Refinement {
        over_limit: errors.iter().filter(|&&e| e > limit_deg).count(),
        ..Refinement::default()
    };
    // The count and area of the faces over the bound, and the faces, after each round, the
    // start first.
    let mut progress = vec![(
        done.over_limit,
        area_over(&mesh.vertices, &mesh.triangles, &errors, limit_deg),
        mesh.triangles.len(),
    )];
    let Mesh {
        vertices,
        normals,
        triangles,
        provenance,
    } = mesh;
    let mut he = match HalfEdges::new(std::mem::take(triangles), vertices.len()) {
        Ok(he) => he,
        Err(tri) => {
            *triangles = tri;
            return done;
        }
    };
    // Faces against the field, which only flips may let go of: splits and smoothing make
    // none (both are checked), so the flags only ever clear.
    let mut folded: Vec<bool> = (he.triangles().iter())
        .map(|&t| against_field(vertices, normals, t))
        .collect();
    let mut star = Vec::new();
    let mut marks = Marks::default();
    for round in 0..MAX_REFINE_ROUNDS {
        if done.over_limit == 0 || vertices.len() >= params.max_points {
            break;
        }
        on_round(round + 1, vertices.len(), he.triangles().len());
        let mut bad: Vec<u32> = (0..errors.len() as u32)
            .filter(|&t| errors[t as usize] > limit_deg)
            .collect();
        bad.sort_unstable_by(|&s, &t| {
            errors[t as usize]
                .total_cmp(&errors[s as usize])
                .then(s.cmp(&t))
        });
        // Triangles rewritten in this round: their errors are stale until the round ends,
        // so a bad one waits for the next round.
        let mut stale = vec![false; errors.len()];
        let mut changed: Vec<u32> = Vec::new();
        let mut added: Vec<u32> = Vec::new();
        for t in bad {
            if vertices.len() >= params.max_points {
                break;
            }
            if stale.get(t as usize) != Some(&false) {
                continue;
            }
            let Some(h) = propagation_end(&he, vertices, t) else {
                continue;
            };
            let a = he.triangles()[(h / 3) as usize][(h % 3) as usize];
            let Some((m, rewritten)) = split_edge(field, &cfg, &mut he, vertices, normals, pos, h)
            else {
                continue;
            };
            for t in rewritten {
                if t as usize >= folded.len() {
                    folded.resize(t as usize + 1, false);
                }
                folded[t as usize] = false;
                if t as usize >= stale.len() {
                    stale.resize(t as usize + 1, false);
                }
                stale[t as usize] = true;
                changed.push(t);
            }
            provenance.push(Provenance {
                curve: Provenance::REFINED_CURVE,
                step: round as u32 + 1,
                ..provenance[a as usize]
            });
            added.push(m);
        }
        if added.is_empty() {
            break;
        }
        done.rounds = round + 1;
        done.added += added.len();
        let budget = 8 * changed.len() + 64;
        let seeds = edges_of(&he, &mut marks, &changed);
        he.flip_from(vertices, normals, &seeds, &mut folded, budget, &mut changed);
        let moved = smooth_around(field, &cfg, &he, vertices, normals, provenance, pos, &added);
        // Faces whose corner moved are measured again, and flipped where no longer Delaunay.
        let mut around = Vec::new();
        for &v in &moved {
            he.star(v, &mut star);
            around.extend_from_slice(&star);
        }
        for &t in &around {
            folded[t as usize] = against_field(vertices, normals, he.triangles()[t as usize]);
        }
        let seeds = edges_of(&he, &mut marks, &around);
        changed.extend(around);
        let budget = 8 * changed.len() + 64;
        he.flip_from(vertices, normals, &seeds, &mut folded, budget, &mut changed);
        let changed = marks.unique(&changed);
        let tris = he.triangles();
        let fresh = par::map(changed.len(), par::MIN_COSTLY, |i| {
            error(vertices, tris[changed[i] as usize])
        });
        errors.resize(tris.len(), 0.0);
        for (&t, e) in changed.iter().zip(fresh) {
            errors[t as usize] = e;
        }
        done.over_limit = errors.iter().filter(|&&e| e > limit_deg).count();
        let now = (
            done.over_limit,
            area_over(vertices, he.triangles(), &errors, limit_deg),
            he.triangles().len(),
        );
        // The state STALL_ROUNDS rounds ago (the start, before that many rounds).
        let before = progress[progress.len().saturating_sub(STALL_ROUNDS)];
        progress.push(now);
        let (fewer, smaller, doubled) = (now.0 < before.0, now.1 < before.1, now.2 >= 2 * before.2);
        if progress.len() > STALL_ROUNDS && doubled && !fewer && !smaller {
            done.stalled = true;
            break;
        }
    }
    *triangles = he.into_triangles();
    done
}

/// The area of the faces whose error (`errors`, by face) is above `limit_deg`.
fn area_over(vertices: &[[f64; 3]], triangles: &[[u32; 3]], errors: &[f64], limit_deg: f64) -> f64 {
    triangles
        .iter()
        .zip(errors)
        .filter(|(_, &e)| e > limit_deg)
        .map(|(t, _)| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let n = cross(sub(b, a), sub(c, a));
            0.5 * dot(n, n).sqrt()
        })
        .sum()
}

/// Splits the edge of half-edge `h = a → b` at a new vertex on the surface: a chord from `a`
/// towards `b`, half the edge long. Returns the new vertex and the triangles rewritten or
/// added, or `None` (and changes nothing) where the chord has no root or a new triangle would
/// face against the field.
fn split_edge<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    he: &mut HalfEdges,
    vertices: &mut Vec<[f64; 3]>,
    normals: &mut Vec<[f64; 3]>,
    pos: &mut Vec<Vec3<T>>,
    h: u32,
) -> Option<(u32, Vec<u32>)> {
    let tri = he.triangles()[(h / 3) as usize];
    let k = (h % 3) as usize;
    let [a, b, c] = [tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]];
    let d = (he.twin(h)).map(|g| he.triangles()[(g / 3) as usize][((g + 2) % 3) as usize]);
    let dir = &pos[b as usize] - &pos[a as usize];
    let length = dir.norm() * T::from_f64(0.5);
    let p = trace::step_fixed(field, cfg, &pos[a as usize], &dir, &length).ok()?;
    let (_, n, _) = trace::unit_normal(field, &p).ok()?;
    let m = vertices.len() as u32;
    vertices.push(p.to_f64());
    normals.push(n.to_f64());
    let mut faces = vec![[a, m, c], [m, b, c]];
    if let Some(d) = d {
        faces.extend([[b, m, d], [m, a, d]]);
    }
    if faces.iter().any(|&f| against_field(vertices, normals, f)) {
        vertices.pop();
        normals.pop();
        return None;
    }
    pos.push(p);
    Some((m, he.split(h, m)))
}

/// The edges of the triangles in `list`, each once, as half-edges.
fn edges_of(he: &HalfEdges, marks: &mut Marks, list: &[u32]) -> Vec<u32> {
    let tris = marks.unique(list);
    let mut edges = Vec::with_capacity(3 * tris.len());
    for t in tris {
        for h in 3 * t..3 * t + 3 {
            // An edge between two listed triangles is taken from its lower half-edge.
            if he.twin(h).is_none_or(|g| h < g || !marks.is_marked(g / 3)) {
                edges.push(h);
            }
        }
    }
    edges
}

/// Deduplicates lists of triangle indices in their order of first appearance, without sorting.
#[derive(Default)]
struct Marks {
    seen: Vec<u32>,
    epoch: u32,
}

impl Marks {
    /// `list` without repeats, in order.
    fn unique(&mut self, list: &[u32]) -> Vec<u32> {
        self.epoch += 1;
        let mut out = Vec::with_capacity(list.len());
        for &t in list {
            if t as usize >= self.seen.len() {
                self.seen.resize(t as usize + 1, 0);
            }
            if self.seen[t as usize] != self.epoch {
                self.seen[t as usize] = self.epoch;
                out.push(t);
            }
        }
        out
    }

    /// Whether `t` was in the list of the last [`Marks::unique`].
    fn is_marked(&self, t: u32) -> bool {
        self.seen.get(t as usize) == Some(&self.epoch)
    }
}

/// The half-edge to split for triangle `t`: the end of its longest-edge propagation path, an
/// edge that is the longest of both its triangles (or on the boundary); `None` if the path
/// is longer than [`MAX_PATH`].
fn propagation_end(he: &HalfEdges, vertices: &[[f64; 3]], t: u32) -> Option<u32> {
    let tris = he.triangles();
    let mut h = 3 * t + longest_edge(vertices, tris[t as usize]) as u32;
    for _ in 0..MAX_PATH {
        let Some(g) = he.twin(h) else {
            return Some(h);
        };
        let other = tris[(g / 3) as usize];
        let longest = longest_edge(vertices, other);
        if edge_len2(vertices, other, longest) <= edge_len2(vertices, other, (g % 3) as usize) {
            return Some(h);
        }
        h = 3 * (g / 3) + longest as u32;
    }
    None
}

/// One damped step of the relaxation for the vertices `added` and their neighbours (but not
/// `p0` nor boundary vertices); moves that would fold a face are taken back. Returns the
/// vertices that moved.
#[allow(clippy::too_many_arguments)]
fn smooth_around<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    he: &HalfEdges,
    vertices: &mut [[f64; 3]],
    normals: &mut [[f64; 3]],
    provenance: &[Provenance],
    pos: &mut [Vec3<T>],
    added: &[u32],
) -> Vec<u32> {
    let tris = he.triangles();
    let mut star = Vec::new();
    let mut around: Vec<u32> = added.to_vec();
    for &m in added {
        he.star(m, &mut star);
        around.extend(star.iter().flat_map(|&f| tris[f as usize]));
    }
    around.sort_unstable();
    around.dedup();
    around.retain(|&v| {
        let pr = provenance[v as usize];
        !(pr.curve == 0 && pr.step == 0)
    });
    // Each interior vertex's neighbours: the corner after it in each triangle of its star.
    let rings: Vec<Option<Vec<u32>>> = (around.iter())
        .map(|&v| {
            he.star(v, &mut star).then(|| {
                (star.iter())
                    .map(|&f| {
                        let t = tris[f as usize];
                        let k = t
                            .iter()
                            .position(|&x| x == v)
                            .expect("a corner of its star");
                        t[(k + 1) % 3]
                    })
                    .collect()
            })
        })
        .collect();
    let damping = T::from_f64(DAMPING);
    // (vertex, new position, its field normal) for the vertices that move.
    let moves: Vec<(u32, Vec3<T>, [f64; 3])> = par::map(around.len(), par::MIN_COSTLY, |i| {
        let v = around[i];
        let ring = rings[i].as_deref()?;
        let p = towards_centroid(field, cfg, pos, v as usize, ring, &damping);
        let (_, n, _) = trace::unit_normal(field, &p).ok()?;
        (p.to_f64() != vertices[v as usize]).then(|| (v, p, n.to_f64()))
    })
    .into_iter()
    .flatten()
    .collect();
    // Faces around the moved vertices, with their agreement before the moves.
    let mut near: Vec<u32> = Vec::new();
    for (v, _, _) in &moves {
        he.star(*v, &mut star);
        near.extend_from_slice(&star);
    }
    near.sort_unstable();
    near.dedup();
    let agreement = |p: &[[f64; 3]], t: u32| {
        let tri = tris[t as usize];
        agreement_at(tri.map(|i| p[i as usize]), normals, tri)
    };
    let old: Vec<f64> = near.iter().map(|&t| agreement(vertices, t)).collect();
    let mut at = vertices.to_vec();
    for (v, p, _) in &moves {
        at[*v as usize] = p.to_f64();
    }
    // Take back every corner of a face that would fold, until none would; each pass takes
    // back at least one move, so this ends.
    let mut kept = vec![true; moves.len()];
    let index_of = |v: u32| moves.binary_search_by_key(&v, |(u, _, _)| *u).ok();
    loop {
        let mut reverted = false;
        for (&t, &b) in near.iter().zip(&old) {
            if agreement(&at, t) >= MIN_AGREEMENT.min(b) {
                continue;
            }
            for v in tris[t as usize] {
                if let Some(i) = index_of(v).filter(|&i| kept[i]) {
                    kept[i] = false;
                    at[v as usize] = vertices[v as usize];
                    reverted = true;
                }
            }
        }
        if !reverted {
            break;
        }
    }
    let mut moved = Vec::new();
    for ((v, p, n), keep) in moves.into_iter().zip(kept) {
        if keep {
            vertices[v as usize] = p.to_f64();
            normals[v as usize] = n;
            pos[v as usize] = p;
            moved.push(v);
        }
    }
    moved
}

/// Squared length of the edge `tri[k] → tri[k + 1]`.
fn edge_len2(vertices: &[[f64; 3]], tri: [u32; 3], k: usize) -> f64 {
    let (p, q) = (
        vertices[tri[k] as usize],
        vertices[tri[(k + 1) % 3] as usize],
    );
    (0..3).map(|i| (p[i] - q[i]) * (p[i] - q[i])).sum()
}

/// The corner `k` whose edge `tri[k] → tri[k + 1]` is the longest (the first of equals).
fn longest_edge(vertices: &[[f64; 3]], tri: [u32; 3]) -> usize {
    let mut best = 0;
    for k in 1..3 {
        if edge_len2(vertices, tri, k) > edge_len2(vertices, tri, best) {
            best = k;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Invariant, LieField};
    use crate::preset::Preset;
    use crate::quality::{face_normal_error, Topology};
    use crate::scalar::Dual;
    use crate::{Angle, MeshParams};

    fn sphere() -> Invariant {
        Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).unwrap()
    }

    /// fig3 (2,006 faces, the largest normal error 2.5°) with refinement to `limit_deg`.
    fn coarse_sphere(limit_deg: f64) -> MeshParams {
        let mut params = Preset::Fig3.params();
        params.max_normal_error = Some(Angle::from_degrees(limit_deg));
        params
    }

    /// The sphere meshed with `params` but without refinement.
    fn without_refinement(field: &LieField<f64>, params: &MeshParams) -> crate::MeshRun<f64> {
        let mut params = params.clone();
        params.max_normal_error = None;
        crate::run(field, &params).unwrap()
    }

    #[test]
    fn refinement_brings_every_face_within_the_bound_and_keeps_the_sphere_closed() {
        let field = LieField::<f64>::new(&sphere());
        let params = coarse_sphere(1.0);
        let before = without_refinement(&field, &params).mesh;
        assert!(face_normal_error(&field, &before).0 > 2.0);
        let run = crate::run(&field, &params).unwrap();
        let done = run.refinement.unwrap();
        assert!(done.added > 100 && done.over_limit == 0, "{done:?}");
        assert!(face_normal_error(&field, &run.mesh).0 <= 1.0);
        // The new vertices are on the sphere (drift-free chords), and the mesh is still a
        // closed, consistently oriented sphere.
        for v in &run.mesh.vertices {
            let r = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((r - 1.0).abs() < 1e-14, "{r}");
        }
        crate::fuzz_checks::check_mesh(&run.mesh).unwrap();
        let topo = Topology::of(&run.mesh);
        assert!(topo.closed && topo.euler_characteristic == 2, "{topo:?}");
        assert_eq!(
            run.mesh.triangles.len(),
            before.triangles.len() + 2 * done.added
        );
        let refined = (run.mesh.provenance.iter())
            .filter(|p| p.curve == Provenance::REFINED_CURVE)
            .count();
        assert_eq!(refined, done.added);
    }

    #[test]
    fn an_open_cap_is_refined_up_to_its_rim_which_stays_in_place() {
        let field = LieField::<f64>::new(&sphere());
        let mut params = coarse_sphere(1.0);
        params.close = false;
        params.max_radius = Some(1.2);
        let unrefined = without_refinement(&field, &params);
        let run = crate::run(&field, &params).unwrap();
        let done = run.refinement.unwrap();
        assert!(done.added > 10 && done.over_limit == 0, "{done:?}");
        crate::fuzz_checks::check_mesh(&run.mesh).unwrap();
        let (before, after) = (Topology::of(&unrefined.mesh), Topology::of(&run.mesh));
        assert!(
            before.boundary_loops == 1 && after.boundary_loops == 1,
            "{after:?}"
        );
        // Rim vertices are not smoothed (the rim may gain vertices, on the sphere).
        let rim = |m: &Mesh| {
            let mut uses = std::collections::HashMap::new();
            for t in &m.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
            let mut v: Vec<u32> = (uses.into_iter())
                .filter(|&(_, n)| n == 1)
                .flat_map(|((a, b), _)| [a, b])
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        let old_rim = rim(&unrefined.mesh);
        for &v in &old_rim {
            assert_eq!(
                run.mesh.vertices[v as usize],
                unrefined.mesh.vertices[v as usize]
            );
        }
        assert!(rim(&run.mesh).len() >= old_rim.len());
    }

    #[test]
    fn refinement_stops_at_the_point_budget() {
        let field = LieField::<f64>::new(&sphere());
        let mut params = coarse_sphere(0.3);
        let unrefined = without_refinement(&field, &params);
        // The budget counts mesh vertices, which stitching and validation make differ from
        // the sample points: 400 more than the mesh refinement starts from (room enough for
        // the stitching's far-cap patch, which a tighter budget leaves without new points).
        params.max_points = unrefined.mesh.vertices.len() + 400;
        let run = crate::run(&field, &params).unwrap();
        let done = run.refinement.unwrap();
        assert_eq!(run.mesh.vertices.len(), params.max_points);
        assert!(done.added == 400 && done.over_limit > 0, "{done:?}");
    }

    #[test]
    fn dual_numbers_refine_exactly_as_f64_does() {
        let params = coarse_sphere(1.0);
        let a = crate::run(&LieField::<f64>::new(&sphere()), &params).unwrap();
        let b = crate::run(&LieField::<Dual<f64>>::new(&sphere()), &params).unwrap();
        assert_eq!(a.refinement, b.refinement);
        assert!(crate::fuzz_checks::same_bits(&a.mesh, &b.mesh));
    }

    #[test]
    fn f32_refines_to_the_bound_up_to_its_rounding() {
        let params = coarse_sphere(1.0);
        let run = crate::run(&LieField::<f32>::new(&sphere()), &params).unwrap();
        let done = run.refinement.unwrap();
        assert!(done.added > 100 && done.over_limit == 0, "{done:?}");
        let (max, _) = face_normal_error(&LieField::<f64>::new(&sphere()), &run.mesh);
        assert!(max <= 1.0 + 1e-3, "{max}");
    }

    #[cfg(feature = "mpfr")]
    #[test]
    fn mpfr_refines_like_f64_with_vertices_on_the_sphere_to_its_precision() {
        use crate::scalar::Mpfr;
        let params = coarse_sphere(1.0);
        let run = crate::run(&LieField::<Mpfr<256>>::new(&sphere()), &params).unwrap();
        let done = run.refinement.unwrap();
        assert!(done.added > 100 && done.over_limit == 0, "{done:?}");
        let worst = (run.vertices.iter())
            .map(|v| (v.norm() - Mpfr::<256>::from_f64(1.0)).to_f64().abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-60, "{worst:e}");
    }

    #[test]
    fn propagation_ends_at_an_edge_longest_in_both_triangles() {
        // A flat triangle (0, 1, 2) whose longest edge 0–1 borders a triangle with a longer
        // edge, 1–3, which borders one with a longer edge still, 3–4, on the boundary: the
        // path ends there.
        let vertices = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.2, 0.0],
            [0.2, -3.0, 0.0],
            [3.0, -1.0, 0.0],
        ];
        let tris = vec![[0, 1, 2], [1, 0, 3], [1, 3, 4]];
        let he = HalfEdges::new(tris, vertices.len()).unwrap();
        let h = propagation_end(&he, &vertices, 0).unwrap();
        let t = he.triangles()[(h / 3) as usize];
        let k = (h % 3) as usize;
        let mut edge = [t[k], t[(k + 1) % 3]];
        edge.sort_unstable();
        assert_eq!(edge, [3, 4]);
    }
}
