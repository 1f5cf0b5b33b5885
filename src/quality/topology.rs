//! Topology of a triangle mesh: manifoldness, orientation, boundary, Euler characteristic.

use crate::geom::union_find::UnionFind;
use crate::triangulate::Mesh;
use std::collections::HashMap;

/// A fast hasher for edge keys (the counts do not depend on iteration order).
type EdgeHash = crate::geom::vec3::FastHash;

/// Topological facts about a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Topology {
    /// Vertices referenced by at least one triangle.
    pub vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Triangles.
    pub faces: usize,
    /// `V − E + F`.
    pub euler_characteristic: i64,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Closed loops formed by the boundary edges.
    pub boundary_loops: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Interior edges whose two triangles traverse them in the same direction.
    pub orientation_flips: usize,
    /// Triangles with a repeated vertex index.
    pub degenerate_triangles: usize,
    /// No boundary, manifold, consistently oriented.
    pub closed: bool,
}

impl Topology {
    /// Computes the topology of `mesh`.
    pub fn of(mesh: &Mesh) -> Topology {
        // (min, max) → (uses, uses in the min→max direction)
        let mut edges: HashMap<(u32, u32), (u32, u32), EdgeHash> =
            HashMap::with_capacity_and_hasher(3 * mesh.triangles.len() / 2, EdgeHash::default());
        let mut degenerate = 0;
        let mut used = vec![false; mesh.vertices.len()];
        for t in &mesh.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                degenerate += 1;
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                used[a as usize] = true;
                let e = edges.entry((a.min(b), a.max(b))).or_default();
                e.0 += 1;
                if a < b {
                    e.1 += 1;
                }
            }
        }
        let mut boundary = Vec::new();
        let (mut non_manifold, mut flips) = (0, 0);
        for (&(a, b), &(uses, forward)) in &edges {
            match uses {
                1 => boundary.push((a, b)),
                2 => {
                    if forward != 1 {
                        flips += 1
                    }
                }
                _ => non_manifold += 1,
            }
        }
        let boundary_loops = count_loops(&boundary, mesh.vertices.len());
        let vertices = used.iter().filter(|&&u| u).count();
        let faces = mesh.triangles.len() - degenerate;
        let euler = vertices as i64 - edges.len() as i64 + faces as i64;
        Topology {
            vertices,
            edges: edges.len(),
            faces,
            euler_characteristic: euler,
            boundary_edges: boundary.len(),
            boundary_loops,
            non_manifold_edges: non_manifold,
            orientation_flips: flips,
            degenerate_triangles: degenerate,
            closed: boundary.is_empty() && non_manifold == 0 && flips == 0 && faces > 0,
        }
    }
}

/// Connected components of the boundary-edge graph over vertices `0..n`.
fn count_loops(edges: &[(u32, u32)], n: usize) -> usize {
    let mut sets = UnionFind::new(n);
    for &(a, b) in edges {
        sets.union(a, b);
    }
    let mut roots: Vec<u32> = edges.iter().map(|&(a, _)| sets.find(a)).collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> Mesh {
        Mesh {
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            normals: vec![[0.0; 3]; 4],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
            provenance: vec![Default::default(); 4],
        }
    }

    #[test]
    fn a_tetrahedron_is_closed_with_euler_characteristic_two() {
        let t = Topology::of(&tetrahedron());
        assert!(t.closed);
        assert_eq!(t.euler_characteristic, 2);
        assert_eq!(t.boundary_loops, 0);
    }

    #[test]
    fn removing_a_face_leaves_one_boundary_loop() {
        let mut m = tetrahedron();
        m.triangles.pop();
        let t = Topology::of(&m);
        assert!(!t.closed);
        assert_eq!((t.boundary_edges, t.boundary_loops), (3, 1));
    }

    #[test]
    fn a_flipped_face_is_counted() {
        let mut m = tetrahedron();
        m.triangles[0] = [0, 1, 2];
        assert_eq!(Topology::of(&m).orientation_flips, 3);
    }
}
