//! Validation of any mesh (DESIGN §4, "Validity of every mesh"): topology, orientation,
//! degeneracy and self-intersection, the geometric questions decided with exact predicates.
//!
//! The topology is read from the faces around each vertex (a vertex → faces table built by
//! counting sort, then each vertex's edges sorted by their far end): no hash table, and the
//! same walk gives the edges, their use counts and directions, and the fans at each vertex.
//! Self-intersections are found by a grid broad phase over the faces' boxes
//! ([`PairGrid`]) and decided exactly by
//! [`proper_faces_intersect`](crate::geom::intersect::proper_faces_intersect)'s rules.
//! Nearly every pair the broad phase finds shares a vertex, and the topology walk certifies
//! most vertices' fans embedded at the cost of one `orient2d` per face and corner
//! ([`fan_is_embedded`]): pairs sharing a vertex or an edge there are proved apart and
//! not tested (on the 10⁵-face sphere, 1,600 pairs are tested of 630,000 found).
//!
//! Both walks are bound by memory access, so they read the mesh renumbered in space-filling
//! order (see [`validate`]). On large meshes the topology and the geometry's set-up run side
//! by side, then the pair tests by chunks of cells on rayon's pool; every result is either a
//! count or the lowest offenders, so the report is the same for any number of threads.

use super::Mesh;
use crate::geom::grid::{cell_size, radix_sort, spatial_order, Aabb, Box32, PairGrid};
use crate::geom::intersect::{fan_is_embedded, is_collinear, planar_faces_intersect, PlanarFace};
use crate::geom::predicates::{scale, Checked, Exponents, InRange, Orient, P3};
use crate::geom::rows::rows_by_corner;
use crate::geom::union_find::UnionFind;
use crate::par;
use std::fmt;

/// How many offenders of each kind a [`Validation`] names.
pub const MAX_EXAMPLES: usize = 16;

/// How many offenders of one kind a mesh has, and the first [`MAX_EXAMPLES`] of them
/// (the lowest, in ascending order, so the report does not depend on the order of the work).
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Offenders<T> {
    /// How many there are.
    pub count: usize,
    /// The lowest of them, ascending; at most [`MAX_EXAMPLES`].
    pub examples: Vec<T>,
}

impl<T> Default for Offenders<T> {
    fn default() -> Self {
        Offenders {
            count: 0,
            examples: Vec::new(),
        }
    }
}

impl<T: Ord + Copy> Offenders<T> {
    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The first example, if any.
    pub fn first(&self) -> Option<T> {
        self.examples.first().copied()
    }

    /// Counts `x` and keeps it if it is among the lowest [`MAX_EXAMPLES`].
    fn push(&mut self, x: T) {
        self.count += 1;
        if self.examples.len() == MAX_EXAMPLES && self.examples.last().is_some_and(|&l| x >= l) {
            return;
        }
        let at = self.examples.partition_point(|&e| e < x);
        self.examples.insert(at, x);
        self.examples.truncate(MAX_EXAMPLES);
    }
}

/// What [`Mesh::validate`] found: counts, topology, and every kind of defect with its count
/// and first offenders.
///
/// Faces with an index out of range or a repeated index take no part in the topology (they
/// are reported and left out), so `vertices`, `edges`, `faces` and the Euler characteristic
/// describe the remaining faces. Geometric checks (degeneracy, self-intersection) skip faces
/// with a non-finite corner; self-intersection is tested among the non-degenerate faces.
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Validation {
    /// Vertices referenced by a face (unreferenced vertices are allowed and not counted).
    pub vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Faces with three distinct in-range indices.
    pub faces: usize,
    /// `vertices − edges + faces`.
    pub euler_characteristic: i64,
    /// Connected components, faces being connected through shared edges (two fans touching
    /// at a vertex only are two components).
    pub components: usize,
    /// Edges used by one face, as `(low, high)` vertex pairs. Allowed: a valid mesh may have
    /// a boundary.
    pub boundary_edges: Offenders<(u32, u32)>,
    /// Closed loops of boundary edges. Each vertex is split into its fans first, so loops
    /// that touch at a non-manifold vertex count separately (a bowtie of two triangles has
    /// two loops); at non-manifold edges, loops are the connected pieces of boundary.
    pub boundary_loops: usize,
    /// Edges used by more than two faces, as `(low, high)` vertex pairs.
    pub non_manifold_edges: Offenders<(u32, u32)>,
    /// Vertices whose faces form more than one fan (faces around a vertex joined through the
    /// edges at that vertex): "bowties".
    pub non_manifold_vertices: Offenders<u32>,
    /// Edges with two faces that traverse them in the same direction, as `(low, high)`.
    pub orientation_flips: Offenders<(u32, u32)>,
    /// Faces with a repeated index or with collinear or coincident corners (decided exactly).
    pub degenerate_faces: Offenders<usize>,
    /// Faces with an index not below the number of vertices.
    pub out_of_range_faces: Offenders<usize>,
    /// Vertices with a NaN or infinite coordinate.
    pub non_finite_vertices: Offenders<u32>,
    /// Pairs of faces `(low, high)` that intersect other than where they share vertices or an
    /// edge (decided exactly; see the module documentation of the intersection test):
    /// crossings, overlaps, folds, duplicate faces, and faces touching at distinct vertices
    /// with equal coordinates.
    pub self_intersections: Offenders<(usize, usize)>,
}

impl Mesh {
    /// Checks that the mesh is an embedded, consistently oriented 2-manifold, possibly with
    /// boundary: manifold edges and vertices, consistent orientation, no degenerate faces,
    /// no bad indices or coordinates, and no self-intersections, the geometric questions
    /// decided with exact predicates. Never panics; the answer is deterministic.
    ///
    /// ```
    /// use liemesh::{generate, model::{Invariant, LieField}, preset::Preset};
    /// let invariant = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0])?;
    /// let mesh = generate(&LieField::<f64>::new(&invariant), &Preset::Fig3.params())?;
    /// let v = mesh.validate();
    /// assert!(v.is_closed(), "{v}");
    /// assert_eq!(v.genus(), Some(0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn validate(&self) -> Validation {
        validate(&self.vertices, &self.triangles)
    }
}

impl Validation {
    /// An embedded oriented 2-manifold, possibly with boundary: no non-manifold edges or
    /// vertices, no orientation flips, no degenerate faces, no bad indices or coordinates,
    /// no self-intersections. (A mesh without faces is valid.)
    pub fn is_valid(&self) -> bool {
        self.non_manifold_edges.is_empty()
            && self.non_manifold_vertices.is_empty()
            && self.orientation_flips.is_empty()
            && self.degenerate_faces.is_empty()
            && self.out_of_range_faces.is_empty()
            && self.non_finite_vertices.is_empty()
            && self.self_intersections.is_empty()
    }

    /// Valid, with at least one face and no boundary.
    pub fn is_closed(&self) -> bool {
        self.is_valid() && self.boundary_edges.is_empty() && self.faces > 0
    }

    /// The genus (summed over the components) of a closed mesh, which is then orientable:
    /// `components − χ/2`. `None` unless [`Validation::is_closed`].
    pub fn genus(&self) -> Option<u64> {
        if !self.is_closed() {
            return None;
        }
        let twice = 2 * self.components as i64 - self.euler_characteristic;
        (twice >= 0 && twice % 2 == 0).then_some(twice as u64 / 2)
    }
}

fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

impl fmt::Display for Validation {
    /// One paragraph: the verdict, then each defect with its count and first offender, then
    /// the topology.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let shape = format!(
            "χ = {}, {}",
            self.euler_characteristic,
            plural(self.components, "component", "components")
        );
        let boundary = format!(
            "{} ({})",
            plural(self.boundary_loops, "boundary loop", "boundary loops"),
            plural(self.boundary_edges.count, "edge", "edges")
        );
        if self.is_valid() {
            return if self.faces == 0 {
                write!(f, "valid: no faces")
            } else if self.is_closed() {
                let genus = self
                    .genus()
                    .map_or(String::new(), |g| format!(", genus {g}"));
                write!(f, "valid: closed, {shape}{genus}")
            } else {
                write!(f, "valid: {boundary}, {shape}")
            };
        }
        let mut parts = Vec::new();
        let faces = |o: &Offenders<usize>, what: &str, whats: &str| {
            o.first()
                .map(|x| format!("{} (e.g. face {x})", plural(o.count, what, whats)))
        };
        let edges = |o: &Offenders<(u32, u32)>, what: &str, whats: &str| {
            o.first()
                .map(|(a, b)| format!("{} (e.g. {a}–{b})", plural(o.count, what, whats)))
        };
        let vertices = |o: &Offenders<u32>, what: &str, whats: &str| {
            o.first()
                .map(|v| format!("{} (e.g. vertex {v})", plural(o.count, what, whats)))
        };
        parts.extend(self.self_intersections.first().map(|(a, b)| {
            format!(
                "{} (e.g. faces {a} and {b})",
                plural(
                    self.self_intersections.count,
                    "self-intersecting face pair",
                    "self-intersecting face pairs"
                )
            )
        }));
        parts.extend(edges(
            &self.non_manifold_edges,
            "non-manifold edge",
            "non-manifold edges",
        ));
        parts.extend(vertices(
            &self.non_manifold_vertices,
            "non-manifold vertex",
            "non-manifold vertices",
        ));
        parts.extend(edges(
            &self.orientation_flips,
            "orientation flip",
            "orientation flips",
        ));
        parts.extend(faces(
            &self.degenerate_faces,
            "degenerate face",
            "degenerate faces",
        ));
        parts.extend(faces(
            &self.out_of_range_faces,
            "face with an index out of range",
            "faces with an index out of range",
        ));
        parts.extend(vertices(
            &self.non_finite_vertices,
            "non-finite vertex",
            "non-finite vertices",
        ));
        write!(
            f,
            "invalid: {}; {}, {}, {}, {shape}, {boundary}",
            parts.join(", "),
            plural(self.vertices, "vertex", "vertices"),
            plural(self.edges, "edge", "edges"),
            plural(self.faces, "face", "faces"),
        )
    }
}

/// Sorts a short slice in place (a vertex's edges: about a dozen), falling back to the
/// library sort for long ones.
fn insertion_sort(v: &mut [u64]) {
    if v.len() > 32 {
        v.sort_unstable();
        return;
    }
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && v[j - 1] > x {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// Faces from which the topology and the geometry's set-up run side by side, and the pair tests by
/// chunks of cells, on rayon's pool (it was 16,384). Validation costs 340–420 ns a face on
/// one thread. Measured on two cores: in a loop of `Mesh::validate` (a warm pool) fig3's
/// 1,980 faces went 338 → 250 ns a face and the 10⁴ sphere's 373 → 278; inside whole runs
/// (`MeshRun::timings`, best of 5, two runs of each build alternated) the 10⁴ sphere's
/// validation stage went 441–446 → 366–392 ns a triangle and the 10⁴ ellipsoid's 497–508 →
/// 311–336, while the presets gained nothing (waking the pool costs what it saves), and at
/// 512 faces fig5 and fig6 (under 900 faces) lost 20%.
const PARALLEL_FACES: usize = 1024;

/// The validation of the mesh with vertex positions `p` and faces `tris`.
///
/// The checks read the mesh in a local layout: vertices renumbered in the Morton order of
/// their positions, proper faces renumbered accordingly and sorted by their lowest vertex.
/// Neighbours in the mesh are then neighbours in memory, which is what makes the walk over
/// vertex fans and the broad phase fast (both are bound by memory access, not arithmetic);
/// offenders are translated back to the caller's numbers.
pub(crate) fn validate(p: &[P3], tris: &[[u32; 3]]) -> Validation {
    validate_listing(p, tris).validation
}

/// [`validate`], and every self-intersecting pair of faces (lower index first, in order).
pub(crate) fn validate_listing_crossings(
    p: &[P3],
    tris: &[[u32; 3]],
) -> (Validation, Vec<(usize, usize)>) {
    let listed = validate_listing(p, tris);
    (listed.validation, listed.crossings)
}

/// A validation with the lists behind two of its counts.
pub(crate) struct Listed {
    /// The validation.
    pub validation: Validation,
    /// Every self-intersecting pair of faces, lower index first, in order.
    pub crossings: Vec<(usize, usize)>,
    /// Every boundary edge, as `(low, high)` vertex pairs, in order.
    pub boundary: Vec<(u32, u32)>,
}

/// [`validate`], listing every self-intersecting pair and every boundary edge.
pub(crate) fn validate_listing(p: &[P3], tris: &[[u32; 3]]) -> Listed {
    let n = p.len();
    let mut v = Validation {
        vertices: 0,
        edges: 0,
        faces: 0,
        euler_characteristic: 0,
        components: 0,
        boundary_edges: Offenders::default(),
        boundary_loops: 0,
        non_manifold_edges: Offenders::default(),
        non_manifold_vertices: Offenders::default(),
        orientation_flips: Offenders::default(),
        degenerate_faces: Offenders::default(),
        out_of_range_faces: Offenders::default(),
        non_finite_vertices: Offenders::default(),
        self_intersections: Offenders::default(),
    };
    let finite = |q: &P3| q.iter().all(|x| x.is_finite());
    for (i, _) in p.iter().enumerate().filter(|(_, q)| !finite(q)) {
        v.non_finite_vertices.push(i as u32);
    }
    // Vertices in Morton order: `old_vertex[new]`, `rank[old]`, positions `q[new]`.
    let old_vertex = spatial_order(n, |i| p[i]);
    let mut rank = vec![0u32; n];
    for (new, &old) in old_vertex.iter().enumerate() {
        rank[old as usize] = new as u32;
    }
    let q: Vec<P3> = par::map(n, par::MIN_CHEAP, |k| p[old_vertex[k] as usize]);
    // Faces with three distinct in-range indices take part in the topology; renumbered, and
    // sorted by lowest vertex (`old_face[new]`).
    let id_bits = 64 - (tris.len() as u64).leading_zeros();
    let mut keyed: Vec<u64> = Vec::with_capacity(tris.len());
    for (f, t) in tris.iter().enumerate() {
        if t.iter().any(|&i| i as usize >= n) {
            v.out_of_range_faces.push(f);
        } else if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            v.degenerate_faces.push(f);
        } else {
            let low = rank[t[0] as usize]
                .min(rank[t[1] as usize])
                .min(rank[t[2] as usize]);
            keyed.push((low as u64) << id_bits | f as u64);
        }
    }
    let vertex_bits = 64 - (n as u64).leading_zeros();
    radix_sort(&mut keyed, id_bits, id_bits + vertex_bits);
    let ids = (1u64 << id_bits) - 1;
    let old_face: Vec<u32> = keyed.iter().map(|&e| (e & ids) as u32).collect();
    drop(keyed);
    let faces: Vec<[u32; 3]> = par::map(old_face.len(), par::MIN_CHEAP, |k| {
        tris[old_face[k] as usize].map(|i| rank[i as usize])
    });
    drop(rank);
    // Geometry on the faces whose corners are finite. The predicates must be exact on every
    // coordinate they see: directly if all lie in robust's window, else on a copy scaled by a
    // power of two, else through the checked (per-call) predicates.
    let geo: Vec<u32> = (0..faces.len() as u32)
        .filter(|&k| faces[k as usize].iter().all(|&i| finite(&q[i as usize])))
        .collect();
    let mut used = vec![false; n];
    for &k in &geo {
        for &i in &faces[k as usize] {
            used[i as usize] = true;
        }
    }
    let spread = Exponents::of(
        q.iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .flat_map(|(c, _)| c.iter().copied()),
    );
    drop(used);
    let mesh = Local {
        p: &q,
        faces: &faces,
        old_vertex: &old_vertex,
        geo: &geo,
    };
    let Found {
        mut boundary,
        degenerate,
        crossings,
    } = if spread.in_window() {
        checks(InRange, mesh, &mut v)
    } else if let Some(k) = spread.window_scale() {
        let scaled: Vec<P3> = q.iter().map(|c| c.map(|x| scale(x, k))).collect();
        checks(InRange, Local { p: &scaled, ..mesh }, &mut v)
    } else {
        checks(Checked, mesh, &mut v)
    };
    for k in degenerate {
        v.degenerate_faces.push(old_face[k as usize] as usize);
    }
    let mut all: Vec<(usize, usize)> = crossings
        .into_iter()
        .map(|(a, b)| {
            let (f, g) = (old_face[a as usize] as usize, old_face[b as usize] as usize);
            (f.min(g), f.max(g))
        })
        .collect();
    for &pair in &all {
        v.self_intersections.push(pair);
    }
    all.sort_unstable();
    boundary.sort_unstable();
    Listed {
        validation: v,
        crossings: all,
        boundary,
    }
}

/// The corners of face `t` after its corner `v`, in the face's order: `v → next → prev`.
#[inline]
fn others(t: [u32; 3], v: u32) -> (u32, u32) {
    if t[0] == v {
        (t[1], t[2])
    } else if t[1] == v {
        (t[2], t[0])
    } else {
        (t[0], t[1])
    }
}

/// The mesh in validation's layout (see [`validate`]), with points on which the predicates
/// are exact.
#[derive(Clone, Copy)]
struct Local<'a> {
    /// Vertex positions, in Morton order.
    p: &'a [P3],
    /// Proper faces, renumbered.
    faces: &'a [[u32; 3]],
    /// The caller's number of each vertex.
    old_vertex: &'a [u32],
    /// The faces whose corners are finite.
    geo: &'a [u32],
}

/// What [`checks`] found beyond the counts it writes into the validation; faces are indices
/// into the local faces.
struct Found {
    /// Boundary edges, as the caller's `(low, high)` vertex pairs.
    boundary: Vec<(u32, u32)>,
    /// Faces with collinear or coincident corners.
    degenerate: Vec<u32>,
    /// Self-intersecting pairs of faces.
    crossings: Vec<(u32, u32)>,
}

/// Topology, degenerate faces and self-intersecting pairs of `m` with the predicates `o`.
///
/// Topology and the geometry's set-up read the same arrays and write apart, so on large
/// meshes they run side by side; the pair tests follow, as they skip the pairs at the
/// vertices whose fans topology certified embedded.
fn checks<O: Orient + Sync>(o: O, m: Local<'_>, v: &mut Validation) -> Found {
    let mut topology_part = || topology(o, m, v);
    let geometry_part = || prepare(o, m);
    let ((boundary, embedded), prepared) = if m.faces.len() >= PARALLEL_FACES {
        par::join(topology_part, geometry_part)
    } else {
        (topology_part(), geometry_part())
    };
    Found {
        crossings: crossings(o, m, &prepared, &embedded),
        boundary,
        degenerate: prepared.degenerate,
    }
}

/// Counts, edges, fans, components and boundary loops of `m.faces` (all proper), offenders
/// named by `m.old_vertex`; returns the boundary edges, named so, as `(low, high)` pairs,
/// and for each vertex whether its fan is certified embedded ([`fan_is_embedded`]): one fan,
/// every edge at it used once or twice and then in opposite directions.
fn topology<O: Orient>(o: O, m: Local<'_>, v: &mut Validation) -> (Vec<(u32, u32)>, Vec<bool>) {
    let (faces, n, old_vertex) = (m.faces, m.p.len(), m.old_vertex);
    // Vertex → faces, by counting sort: faces ascending around each vertex.
    let (start, slots) =
        rows_by_corner(faces, n, |f, _| f as u32).expect("proper faces name vertices below n");
    let old = |i: u32| old_vertex[i as usize];
    let edge = |a: u32, b: u32| {
        let (a, b) = (old(a), old(b));
        (a.min(b), a.max(b))
    };
    let mut components = UnionFind::new(faces.len());
    // The (vertex, fan) nodes: each vertex's first, and for the rare vertex with more than
    // one fan the slots (ascending) whose face is in another, with that fan's node. (A node
    // per slot was 12 MB at 10⁶ faces.)
    let mut first_node = vec![0u32; n];
    let mut other_fans: Vec<(u32, u32)> = Vec::new();
    let mut nodes = 0u32;
    // Boundary edges as (v, w, face) with v < w.
    let mut boundary: Vec<(u32, u32, u32)> = Vec::new();
    // Scratch: the edges at a vertex, packed as far end w (high 32 bits), local slot, and
    // whether the face runs v → w (lowest bit), so that sorting groups them by edge.
    let mut ends: Vec<u64> = Vec::new();
    let mut local = UnionFind::new(0);
    let mut root_fan: Vec<u32> = Vec::new();
    let mut embedded = vec![false; n];
    for vtx in 0..n {
        let (s, e) = (start[vtx] as usize, start[vtx + 1] as usize);
        if s == e {
            continue;
        }
        let vtx32 = vtx as u32;
        v.vertices += 1;
        ends.clear();
        for (ls, &f) in slots[s..e].iter().enumerate() {
            let (next, prev) = others(faces[f as usize], vtx32);
            let slot = (ls as u64) << 1;
            ends.push((next as u64) << 32 | slot | 1);
            ends.push((prev as u64) << 32 | slot);
        }
        insertion_sort(&mut ends);
        local.reset(e - s);
        let slot_of = |x: u64| (x as u32) >> 1;
        // Whether every edge at this vertex is used once, or twice in opposite directions,
        // and how many are used once.
        let (mut manifold, mut open_edges) = (true, 0);
        let mut i = 0;
        while i < ends.len() {
            let w = (ends[i] >> 32) as u32;
            let mut j = i + 1;
            while j < ends.len() && (ends[j] >> 32) as u32 == w {
                local.union(slot_of(ends[i]), slot_of(ends[j]));
                j += 1;
            }
            match j - i {
                1 => open_edges += 1,
                2 => manifold &= ends[i] & 1 != ends[i + 1] & 1,
                _ => manifold = false,
            }
            if w > vtx32 {
                v.edges += 1;
                let face = |x: u64| slots[s + slot_of(x) as usize];
                for &x in &ends[i + 1..j] {
                    components.union(face(ends[i]), face(x));
                }
                match j - i {
                    1 => {
                        v.boundary_edges.push(edge(vtx32, w));
                        boundary.push((vtx32, w, face(ends[i])));
                    }
                    2 if ends[i] & 1 == ends[i + 1] & 1 => v.orientation_flips.push(edge(vtx32, w)),
                    2 => {}
                    _ => v.non_manifold_edges.push(edge(vtx32, w)),
                }
            }
            i = j;
        }
        // Number the fans at this vertex.
        root_fan.clear();
        root_fan.resize(e - s, u32::MAX);
        let first = nodes;
        first_node[vtx] = first;
        for ls in 0..(e - s) as u32 {
            let r = local.find(ls) as usize;
            if root_fan[r] == u32::MAX {
                root_fan[r] = nodes;
                nodes += 1;
            }
            if root_fan[r] != first {
                other_fans.push(((s + ls as usize) as u32, root_fan[r]));
            }
        }
        if nodes - first > 1 {
            v.non_manifold_vertices.push(old(vtx32));
        } else if manifold && (open_edges == 0 || open_edges == 2) {
            let rim = slots[s..e].iter().map(|&f| {
                let (next, prev) = others(faces[f as usize], vtx32);
                (m.p[next as usize], m.p[prev as usize])
            });
            embedded[vtx] = fan_is_embedded(o, m.p[vtx], rim, open_edges == 0);
        }
    }
    v.faces = faces.len();
    v.euler_characteristic = v.vertices as i64 - v.edges as i64 + faces.len() as i64;
    let mut roots: Vec<u32> = (0..faces.len() as u32)
        .map(|f| components.find(f))
        .collect();
    roots.sort_unstable();
    roots.dedup();
    v.components = roots.len();
    // Boundary loops: components of the boundary edges between (vertex, fan) nodes.
    let node_of = |vtx: u32, f: u32| {
        let (s, e) = (
            start[vtx as usize] as usize,
            start[vtx as usize + 1] as usize,
        );
        let slot = (s + slots[s..e].iter().position(|&g| g == f).unwrap_or(0)) as u32;
        match other_fans.binary_search_by_key(&slot, |&(x, _)| x) {
            Ok(k) => other_fans[k].1,
            Err(_) => first_node[vtx as usize],
        }
    };
    let mut loops = UnionFind::new(nodes as usize);
    let mut ends_of_loops = Vec::with_capacity(boundary.len());
    for &(a, b, f) in &boundary {
        let (na, nb) = (node_of(a, f), node_of(b, f));
        loops.union(na, nb);
        ends_of_loops.push(na);
    }
    let mut roots: Vec<u32> = ends_of_loops.iter().map(|&x| loops.find(x)).collect();
    roots.sort_unstable();
    roots.dedup();
    v.boundary_loops = roots.len();
    let boundary = boundary.iter().map(|&(a, b, _)| edge(a, b)).collect();
    (boundary, embedded)
}

/// The geometry's set-up: degenerate faces, and the others filed for the pair tests.
struct Prepared {
    /// Faces (indices into the local faces) with collinear or coincident corners.
    degenerate: Vec<u32>,
    /// The other faces with finite corners; the grid's face `i` is `solid[i]`.
    solid: Vec<u32>,
    /// Their overlapping boxes.
    grid: PairGrid,
}

/// Sorts the faces `m.geo` (finite corners) into degenerate ones and the others, and files
/// the others' boxes for the broad phase.
fn prepare<O: Orient + Sync>(o: O, m: Local<'_>) -> Prepared {
    let corners = |t: [u32; 3]| [m.p[t[0] as usize], m.p[t[1] as usize], m.p[t[2] as usize]];
    let collinear = par::map(m.geo.len(), PARALLEL_FACES, |i| {
        let c = corners(m.faces[m.geo[i] as usize]);
        is_collinear(o, c[0], c[1], c[2])
    });
    let mut degenerate = Vec::new();
    let mut solid: Vec<u32> = Vec::with_capacity(m.geo.len());
    let mut boxes: Vec<Box32> = Vec::with_capacity(m.geo.len());
    for (&k, &flat) in m.geo.iter().zip(&collinear) {
        if flat {
            degenerate.push(k);
        } else {
            solid.push(k);
            boxes.push(Box32::enclosing(&Aabb::of_triangle(&corners(
                m.faces[k as usize],
            ))));
        }
    }
    // Cells of 1.5 median boxes: fewer entries per face than 1, fewer faces per cell than 2
    // (the fastest of the three on the benchmark meshes).
    let cell = 1.5 * cell_size(boxes.iter().map(Box32::extent));
    Prepared {
        degenerate,
        solid,
        grid: PairGrid::new(boxes, cell),
    }
}

/// The self-intersecting pairs among the prepared faces, as indices into `m.faces`.
///
/// Nearly every pair the broad phase reports shares a vertex (on the benchmark meshes, 99.7%
/// of them). Two faces sharing one vertex, or an edge, at a vertex whose fan is certified
/// embedded ([`fan_is_embedded`]) meet only there, so only the other pairs are tested.
fn crossings<O: Orient + Sync>(
    o: O,
    m: Local<'_>,
    prepared: &Prepared,
    embedded: &[bool],
) -> Vec<(u32, u32)> {
    let Prepared { solid, grid, .. } = prepared;
    let corners = |t: [u32; 3]| [m.p[t[0] as usize], m.p[t[1] as usize], m.p[t[2] as usize]];
    let test = |i: u32, j: u32, out: &mut Vec<(u32, u32)>| {
        let (a, b) = (solid[i as usize], solid[j as usize]);
        let (f, g) = (m.faces[a as usize], m.faces[b as usize]);
        let (mut shared, mut certified) = (0, false);
        for x in f {
            if g.contains(&x) {
                shared += 1;
                certified |= embedded[x as usize];
            }
        }
        if certified && shared < 3 {
            return;
        }
        let (pf, pg) = (
            PlanarFace::new(o, f, corners(f)),
            PlanarFace::new(o, g, corners(g)),
        );
        if planar_faces_intersect(o, &pf, &pg) {
            out.push((a, b));
        }
    };
    // The pairs by chunks of cells, in parallel on large meshes; chunks come back in order.
    let cells = grid.cells();
    let chunks = if solid.len() >= PARALLEL_FACES { 64 } else { 1 };
    let mut found: Vec<(u32, u32)> = par::map(chunks, 2, |c| {
        let mut out = Vec::new();
        grid.pairs_in_cells(c * cells / chunks..(c + 1) * cells / chunks, |i, j| {
            test(i, j, &mut out)
        });
        out
    })
    .concat();
    grid.pairs_with_outliers(|i, j| test(i, j, &mut found));
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::intersect::{faces_intersect, triangle_is_degenerate};
    use crate::geom::rng::XorShift64;
    use crate::mesh::octahedron;
    use proptest::prelude::*;

    fn mesh(vertices: Vec<P3>, triangles: Vec<[u32; 3]>) -> Mesh {
        let n = vertices.len();
        Mesh {
            vertices,
            normals: vec![[0.0; 3]; n],
            triangles,
            provenance: vec![Default::default(); n],
        }
    }

    #[test]
    fn offenders_keep_the_lowest_examples_in_order() {
        let mut o = Offenders::default();
        for x in (0..100u32).rev().chain(0..3) {
            o.push(x);
        }
        assert_eq!(o.count, 103);
        assert_eq!(o.examples.len(), MAX_EXAMPLES);
        assert_eq!(o.examples[..5], [0, 0, 1, 1, 2]);
    }

    #[test]
    fn loops_through_a_pinched_vertex_count_per_fan() {
        // Two triangles, and two quads of two triangles each, meeting only at vertex 0 in
        // turns: each fan is its own boundary loop, whichever face the vertex lists first.
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
            [0.0, 1.0, 1.0],
            [0.0, 1.0, 2.0],
            [0.0, 0.0, 2.0],
        ];
        for t in [
            vec![[0, 1, 2], [0, 3, 4]],
            vec![[0, 3, 4], [0, 5, 6], [0, 6, 7], [0, 1, 2]],
            vec![[0, 5, 6], [0, 1, 2], [0, 6, 7], [0, 3, 4]],
        ] {
            let fans = if t.len() == 2 { 2 } else { 3 };
            let v = mesh(p.clone(), t.clone()).validate();
            assert_eq!(v.boundary_loops, fans, "{t:?}");
            assert_eq!(v.non_manifold_vertices.count, 1, "{t:?}");
            assert_eq!(v.components, fans, "{t:?}");
        }
    }

    #[test]
    fn the_octahedron_is_a_closed_sphere() {
        let (p, t) = octahedron();
        let v = mesh(p, t).validate();
        assert!(v.is_closed(), "{v}");
        assert_eq!((v.vertices, v.edges, v.faces), (6, 12, 8));
        assert_eq!(
            (v.euler_characteristic, v.components, v.genus()),
            (2, 1, Some(0))
        );
        assert_eq!(v.to_string(), "valid: closed, χ = 2, 1 component, genus 0");
    }

    #[test]
    fn an_empty_mesh_is_valid_but_not_closed() {
        let v = Mesh::default().validate();
        assert!(v.is_valid() && !v.is_closed());
        assert_eq!(v.to_string(), "valid: no faces");
    }

    #[test]
    fn a_missing_face_leaves_one_boundary_loop() {
        let (p, mut t) = octahedron();
        t.remove(3);
        let v = mesh(p, t).validate();
        assert!(v.is_valid() && !v.is_closed(), "{v}");
        assert_eq!((v.boundary_edges.count, v.boundary_loops), (3, 1));
        assert_eq!(v.boundary_edges.examples, [(0, 3), (0, 4), (3, 4)]);
        assert_eq!(v.euler_characteristic, 1);
        assert_eq!(v.genus(), None);
    }

    #[test]
    fn a_flipped_face_is_named_by_its_edges() {
        let (p, mut t) = octahedron();
        t[0] = [0, 4, 2];
        let v = mesh(p, t).validate();
        assert!(!v.is_valid());
        assert_eq!(v.orientation_flips.examples, [(0, 2), (0, 4), (2, 4)]);
        assert!(
            v.to_string()
                .starts_with("invalid: 3 orientation flips (e.g. 0–2)"),
            "{v}"
        );
    }

    #[test]
    fn bad_indices_and_coordinates_are_reported_not_panicked_on() {
        let (mut p, mut t) = octahedron();
        t.push([0, 1, 99]);
        t.push([2, 2, 3]);
        p[5] = [f64::NAN, 0.0, f64::INFINITY];
        let v = mesh(p, t).validate();
        assert_eq!(v.out_of_range_faces.examples, [8]);
        assert_eq!(v.degenerate_faces.examples, [9]);
        assert_eq!(v.non_finite_vertices.examples, [5]);
        assert_eq!(v.faces, 8);
        assert!(!v.is_valid());
    }

    /// Self-intersections by testing every pair of faces that validation tests (proper,
    /// finite, non-degenerate), without a broad phase.
    fn brute_force(p: &[P3], t: &[[u32; 3]]) -> Vec<(usize, usize)> {
        let ok = |f: &[u32; 3]| {
            f.iter().all(|&i| (i as usize) < p.len())
                && f[0] != f[1]
                && f[1] != f[2]
                && f[0] != f[2]
                && !triangle_is_degenerate(f.map(|i| p[i as usize]))
        };
        let mut pairs = Vec::new();
        for i in 0..t.len() {
            for j in i + 1..t.len() {
                if ok(&t[i]) && ok(&t[j]) && faces_intersect(p, t[i], t[j]) {
                    pairs.push((i, j));
                }
            }
        }
        pairs
    }

    /// `p` with every point moved by up to `amount` along each axis.
    fn perturbed(p: &[P3], rng: &mut XorShift64, amount: f64) -> Vec<P3> {
        p.iter()
            .map(|x| {
                let d = rng.in_cube(amount);
                [x[0] + d[0], x[1] + d[1], x[2] + d[2]]
            })
            .collect()
    }

    fn check_against_brute_force(p: Vec<P3>, t: Vec<[u32; 3]>) -> Validation {
        let expected = brute_force(&p, &t);
        let v = mesh(p, t).validate();
        assert_eq!(v.self_intersections.count, expected.len(), "{v}");
        let first: Vec<_> = expected.into_iter().take(MAX_EXAMPLES).collect();
        assert_eq!(v.self_intersections.examples, first);
        v
    }

    /// A random triangle soup: clusters of five corners with sizes over two and a half
    /// orders of magnitude (so that the grid needs several levels), nine faces in ten within
    /// a cluster (sharing corners), one in ten across the whole soup; on a lattice of 1/64
    /// if asked (so that coincident, collinear and coplanar corners occur).
    fn soup(seed: u64, faces: usize, lattice: bool) -> (Vec<P3>, Vec<[u32; 3]>) {
        let mut rng = XorShift64::new(seed);
        let clusters = faces / 3 + 1;
        let mut p = Vec::with_capacity(5 * clusters);
        for _ in 0..clusters {
            let c = rng.in_cube(1.0);
            let s = 10f64.powf(rng.uniform(-2.5, 0.0));
            for _ in 0..5 {
                let d = rng.in_cube(s);
                let mut q = [c[0] + d[0], c[1] + d[1], c[2] + d[2]];
                if lattice {
                    q = q.map(|x| (x * 64.0).round() / 64.0);
                }
                p.push(q);
            }
        }
        let mut pick = |n: u64| (rng.next_u64() % n) as u32;
        let t = (0..faces)
            .map(|_| {
                if pick(10) == 0 {
                    [0, 1, 2].map(|_| pick(p.len() as u64))
                } else {
                    let c = 5 * pick(clusters as u64);
                    let a = pick(5);
                    let b = (a + 1 + pick(4)) % 5;
                    let mut d = pick(5);
                    while d == a || d == b {
                        d = (d + 1) % 5;
                    }
                    [c + a, c + b, c + d]
                }
            })
            .collect();
        (p, t)
    }

    /// The octahedron subdivided `levels` times onto the unit sphere (a closed mesh).
    fn geosphere(levels: usize) -> (Vec<P3>, Vec<[u32; 3]>) {
        let (mut p, mut t) = octahedron();
        for _ in 0..levels {
            let mut mid = std::collections::HashMap::new();
            let mut next = Vec::new();
            for f in &t {
                let mut m = [0u32; 3];
                for k in 0..3 {
                    let (a, b) = (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]));
                    m[k] = *mid.entry((a, b)).or_insert_with(|| {
                        let (x, y) = (p[a as usize], p[b as usize]);
                        let c = [0, 1, 2].map(|i| (x[i] + y[i]) / 2.0);
                        let r = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                        p.push(c.map(|x| x / r));
                        p.len() as u32 - 1
                    });
                }
                next.push([f[0], m[0], m[2]]);
                next.push([f[1], m[1], m[0]]);
                next.push([f[2], m[2], m[1]]);
                next.push(m);
            }
            t = next;
        }
        (p, t)
    }

    #[test]
    fn a_subdivided_sphere_is_closed_and_perturbing_it_agrees_with_brute_force() {
        let (p, t) = geosphere(3);
        let v = check_against_brute_force(p.clone(), t.clone());
        assert!(v.is_closed(), "{v}");
        assert_eq!(
            (v.faces, v.euler_characteristic, v.genus()),
            (512, 2, Some(0))
        );
        let mut rng = XorShift64::new(4);
        let mut found = 0;
        for amount in [0.02, 0.05, 0.1, 0.3] {
            found += check_against_brute_force(perturbed(&p, &mut rng, amount), t.clone())
                .self_intersections
                .count;
        }
        assert!(found > 0);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// The broad phase loses no intersecting pair and invents none.
        #[test]
        fn self_intersections_agree_with_brute_force(
            seed in any::<u64>(),
            faces in 2usize..120,
            lattice in any::<bool>(),
        ) {
            let (p, t) = soup(seed, faces, lattice);
            check_against_brute_force(p, t);
        }

        /// Closed and open manifolds perturbed from smooth to tangled: the pairs at fans
        /// certified embedded go untested, and the answer still agrees with brute force.
        #[test]
        fn perturbed_manifolds_agree_with_brute_force(
            seed in any::<u64>(),
            amount in 0.0f64..0.3,
            holes in 0usize..6,
        ) {
            let (p, mut t) = geosphere(2);
            let mut rng = XorShift64::new(seed);
            for _ in 0..holes {
                let k = (rng.next_u64() % t.len() as u64) as usize;
                t.swap_remove(k);
            }
            check_against_brute_force(perturbed(&p, &mut rng, amount), t);
        }

        /// Renumbering vertices and reordering faces renames the offenders, nothing else.
        #[test]
        fn renumbering_changes_only_the_names(seed in any::<u64>(), faces in 2usize..80) {
            let (p, t) = soup(seed, faces, true);
            let v = mesh(p.clone(), t.clone()).validate();
            let mut rng = XorShift64::new(seed ^ 1);
            let mut perm: Vec<u32> = (0..p.len() as u32).collect();
            for i in (1..perm.len()).rev() {
                perm.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            let mut q = vec![[0.0; 3]; p.len()];
            for (old, &new) in perm.iter().enumerate() {
                q[new as usize] = p[old];
            }
            let u: Vec<[u32; 3]> = t.iter().rev().map(|f| f.map(|i| perm[i as usize])).collect();
            let w = mesh(q, u).validate();
            prop_assert_eq!(
                (v.vertices, v.edges, v.faces, v.euler_characteristic, v.components),
                (w.vertices, w.edges, w.faces, w.euler_characteristic, w.components)
            );
            prop_assert_eq!(v.boundary_loops, w.boundary_loops);
            prop_assert_eq!(v.self_intersections.count, w.self_intersections.count);
            prop_assert_eq!(v.degenerate_faces.count, w.degenerate_faces.count);
            prop_assert_eq!(v.non_manifold_edges.count, w.non_manifold_edges.count);
            prop_assert_eq!(v.non_manifold_vertices.count, w.non_manifold_vertices.count);
            prop_assert_eq!(v.orientation_flips.count, w.orientation_flips.count);
        }

        /// Arbitrary indices and coordinates (NaN, infinities, extremes) never panic and
        /// are reported.
        #[test]
        fn arbitrary_input_never_panics(
            coords in proptest::collection::vec(
                prop_oneof![
                    any::<f64>(),
                    -2.0f64..2.0,
                    Just(0.0),
                    Just(f64::NAN),
                    Just(f64::MAX),
                    Just(f64::MIN_POSITIVE),
                ],
                0..60,
            ),
            tris in proptest::collection::vec(any::<[u8; 3]>(), 0..40),
        ) {
            let p: Vec<P3> = coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            let t: Vec<[u32; 3]> = tris.iter().map(|f| f.map(|i| i as u32 % 24)).collect();
            let v = mesh(p.clone(), t.clone()).validate();
            let bad = t.iter().filter(|f| f.iter().any(|&i| i as usize >= p.len())).count();
            prop_assert_eq!(v.out_of_range_faces.count, bad);
            let _ = v.to_string();
        }
    }
}
