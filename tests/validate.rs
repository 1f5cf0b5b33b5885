//! `Mesh::validate` on the pipeline's meshes and on hand-made defects (DESIGN §4, "Validity of
//! every mesh"): what a valid mesh reports, and that every kind of defect is found and named.

use liemesh::mesh::{Validation, MAX_EXAMPLES};
use liemesh::model::{Invariant, LieField};
use liemesh::preset::{Preset, FIG46_RADIUS};
use liemesh::Mesh;

// The workloads of `liemesh bench` (from the binary's module that defines them).
#[allow(dead_code)]
#[path = "../src/cli/workloads.rs"]
mod workloads;

fn mesh(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Mesh {
    let n = vertices.len();
    Mesh {
        vertices,
        normals: vec![[0.0, 0.0, 1.0]; n],
        triangles,
        provenance: vec![Default::default(); n],
    }
}

fn sphere() -> Mesh {
    let invariant = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).unwrap();
    liemesh::generate(&LieField::<f64>::new(&invariant), &Preset::Fig3.params()).unwrap()
}

/// A tetrahedron with outward faces, translated by `o` and scaled by `s`.
fn tetrahedron(o: [f64; 3], s: f64, first: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let p = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        .map(|q| [o[0] + s * q[0], o[1] + s * q[1], o[2] + s * q[2]]);
    let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]].map(|f: [u32; 3]| f.map(|i| i + first));
    (p.to_vec(), t.to_vec())
}

/// Only the named kind of defect is present.
fn only(v: &Validation, kind: &str) {
    let counts = [
        ("self_intersections", v.self_intersections.count),
        ("non_manifold_edges", v.non_manifold_edges.count),
        ("non_manifold_vertices", v.non_manifold_vertices.count),
        ("orientation_flips", v.orientation_flips.count),
        ("degenerate_faces", v.degenerate_faces.count),
        ("out_of_range_faces", v.out_of_range_faces.count),
        ("non_finite_vertices", v.non_finite_vertices.count),
    ];
    for (name, count) in counts {
        assert_eq!(count > 0, name == kind, "{name} = {count}: {v}");
    }
}

#[test]
fn every_preset_mesh_is_valid_the_spheres_closed_and_the_patches_discs() {
    for preset in Preset::ALL {
        let field = LieField::<f64>::new(&preset.invariant());
        let params = preset.params();
        let m = liemesh::generate(&field, &params).unwrap();
        let v = m.validate();
        assert!(v.is_valid(), "{}: {v}", preset.name());
        assert_eq!(v.faces, m.triangles.len());
        assert_eq!(v.components, 1, "{}: {v}", preset.name());
        if params.max_radius == Some(FIG46_RADIUS) {
            // fig4–6 end at a geodesic radius: a disc.
            assert_eq!((v.boundary_loops, v.euler_characteristic), (1, 1), "{v}");
            assert!(!v.is_closed() && v.genus().is_none());
        } else {
            assert!(v.is_closed(), "{}: {v}", preset.name());
            assert_eq!((v.euler_characteristic, v.genus()), (2, Some(0)));
        }
        // The older topology summary agrees.
        let t = liemesh::quality::Topology::of(&m);
        assert_eq!(t.euler_characteristic, v.euler_characteristic);
        assert_eq!(t.closed, v.is_closed());
        assert_eq!(
            (t.edges, t.boundary_edges),
            (v.edges, v.boundary_edges.count)
        );
    }
}

#[test]
fn a_vertex_pushed_through_the_sphere_pierces_the_far_side() {
    let mut m = sphere();
    assert!(m.validate().is_closed());
    // The north pole goes to below the south pole: its fan becomes a spike through the
    // inside that pierces the faces around the south pole.
    let top = (0..m.vertices.len())
        .max_by(|&a, &b| m.vertices[a][2].total_cmp(&m.vertices[b][2]))
        .unwrap();
    m.vertices[top] = [0.0, 0.0, -1.5];
    let v = m.validate();
    only(&v, "self_intersections");
    assert!(v.self_intersections.count >= 3, "{v}");
    let has_top = |f: usize| m.triangles[f].contains(&(top as u32));
    let low = |f: usize| {
        m.triangles[f]
            .iter()
            .all(|&i| m.vertices[i as usize][2] < -0.8)
    };
    for &(f, g) in &v.self_intersections.examples {
        assert!(f < g);
        assert!(
            (has_top(f) && low(g)) || (has_top(g) && low(f)),
            "faces {f} and {g} are not a spike face and a south-cap face"
        );
    }
    let (f, g) = v.self_intersections.examples[0];
    assert!(
        v.to_string().starts_with(&format!(
            "invalid: {} self-intersecting face pairs (e.g. faces {f} and {g})",
            v.self_intersections.count
        )),
        "{v}"
    );
}

#[test]
fn a_removed_face_leaves_a_boundary_loop() {
    let mut m = sphere();
    let removed = m.triangles.remove(100);
    let v = m.validate();
    assert!(v.is_valid() && !v.is_closed(), "{v}");
    assert_eq!((v.boundary_loops, v.boundary_edges.count), (1, 3));
    assert_eq!(v.euler_characteristic, 1);
    let mut edges: Vec<(u32, u32)> = (0..3)
        .map(|k| {
            let (a, b) = (removed[k], removed[(k + 1) % 3]);
            (a.min(b), a.max(b))
        })
        .collect();
    edges.sort_unstable();
    assert_eq!(v.boundary_edges.examples, edges);
    assert_eq!(
        v.to_string(),
        "valid: 1 boundary loop (3 edges), χ = 1, 1 component"
    );
}

#[test]
fn two_tetrahedra_sharing_a_vertex_make_a_bowtie() {
    // The second is the first reflected through their common vertex 0 (the reflection
    // reverses orientation, so its faces are reversed to face outwards).
    let (mut p, mut t) = tetrahedron([0.0; 3], 1.0, 0);
    p.extend([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]);
    let reflected: Vec<[u32; 3]> = t
        .iter()
        .map(|f| {
            let g = f.map(|i| if i == 0 { 0 } else { i + 3 });
            [g[0], g[2], g[1]]
        })
        .collect();
    t.extend(reflected);
    let v = mesh(p, t).validate();
    only(&v, "non_manifold_vertices");
    assert_eq!(v.non_manifold_vertices.examples, [0], "{v}");
    assert_eq!((v.vertices, v.edges, v.faces), (7, 12, 8));
    assert_eq!((v.components, v.euler_characteristic), (2, 3));
    assert_eq!(v.boundary_edges.count, 0);
    assert!(!v.is_valid() && v.genus().is_none());
    assert!(
        v.to_string()
            .contains("1 non-manifold vertex (e.g. vertex 0)"),
        "{v}"
    );
}

#[test]
fn a_bowtie_of_two_triangles_has_two_boundary_loops() {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let v = mesh(p, vec![[0, 1, 2], [0, 3, 4]]).validate();
    only(&v, "non_manifold_vertices");
    assert_eq!(v.non_manifold_vertices.examples, [0]);
    assert_eq!((v.boundary_loops, v.components), (2, 2));
}

#[test]
fn three_faces_on_one_edge_are_non_manifold() {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, 1.0],
    ];
    let v = mesh(p, vec![[0, 1, 2], [1, 0, 3], [1, 0, 4]]).validate();
    assert_eq!(v.non_manifold_edges.examples, [(0, 1)], "{v}");
    assert!(!v.is_valid());
}

#[test]
fn duplicate_faces_t_junctions_and_coincident_vertices_are_self_intersections() {
    let (p, mut t) = tetrahedron([0.0; 3], 1.0, 0);
    // A duplicate face, reversed (so that orientation stays consistent: it is an extra
    // sheet on the edges, non-manifold, and it intersects its twin).
    t.push([1, 2, 0]);
    let v = mesh(p.clone(), t).validate();
    assert_eq!(v.self_intersections.examples, [(0, 4)], "{v}");
    assert_eq!(v.non_manifold_edges.count, 3);

    // A T-junction: the top face's edge 0–1 is split at vertex 2 below it. Besides the
    // overlaps along the edge, vertices 0 and 1 each join two fans that share no edge.
    let p = vec![
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
    ];
    let v = mesh(p, vec![[0, 1, 3], [0, 4, 2], [2, 4, 1]]).validate();
    assert_eq!(v.self_intersections.examples, [(0, 1), (0, 2)], "{v}");
    assert_eq!(v.non_manifold_vertices.examples, [0, 1]);
    assert_eq!(v.orientation_flips.count + v.degenerate_faces.count, 0);

    // Two tetrahedra touching at a point through two distinct vertices at one position.
    let (mut p, mut t) = tetrahedron([0.0; 3], 1.0, 0);
    let (q, u) = tetrahedron([1.0, 0.0, 0.0], 1.0, 4);
    p.extend(q);
    t.extend(u);
    let v = mesh(p.clone(), t.clone()).validate();
    only(&v, "self_intersections");
    assert_eq!(v.components, 2);
    // Vertex 4 sits on vertex 1: the faces of the second at vertex 4 touch the first's.
    for &(f, g) in &v.self_intersections.examples {
        assert!(f < 4 && g >= 4, "{f} {g}");
    }
    // Moved an ulp apart, they no longer touch.
    p[4][0] = f64::from_bits(1f64.to_bits() + 1);
    assert!(mesh(p, t).validate().is_valid());
}

#[test]
fn coplanar_overlaps_and_folds_are_found_exactly() {
    // A flat quad (two triangles) and a third triangle folded back onto the second.
    let apex = |z: f64| {
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.75, 0.5, z],
        ]
    };
    let faces = vec![[0, 1, 2], [0, 2, 3], [2, 1, 4]];
    // Exactly flat: face 2 lies on face 0 (same side of the shared edge 1–2).
    let v = mesh(apex(0.0), faces.clone()).validate();
    assert_eq!(v.self_intersections.examples, [(0, 2)], "{v}");
    // One ulp of the smallest normal number above or below: not coplanar, no overlap.
    for z in [
        f64::MIN_POSITIVE,
        -f64::MIN_POSITIVE,
        1e-300,
        2f64.powi(-60),
    ] {
        let v = mesh(apex(z), faces.clone()).validate();
        assert_eq!(v.self_intersections.count, 0, "z = {z}: {v}");
        assert_eq!(v.orientation_flips.count, 0);
    }
    // A triangle lying across the quad without sharing a vertex.
    let mut p = apex(0.0);
    p.extend([[0.2, 0.2, 0.0], [0.8, 0.2, 0.0], [0.5, 0.9, 0.0]]);
    let v = mesh(p, vec![[0, 1, 2], [0, 2, 3], [5, 6, 7]]).validate();
    assert_eq!(v.self_intersections.examples, [(0, 2), (1, 2)], "{v}");
}

#[test]
fn collinear_faces_and_repeated_indices_are_degenerate() {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [3.0, 3.0, 3.0],
        [0.0, 1.0, 0.0],
    ];
    let v = mesh(p, vec![[0, 1, 2], [0, 0, 3], [0, 1, 3]]).validate();
    assert_eq!(v.degenerate_faces.examples, [0, 1], "{v}");
    assert!(!v.is_valid());
    // Nearly collinear (an ulp off the line) is not degenerate.
    let q = vec![
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [3.0, 3.0, f64::from_bits(3f64.to_bits() + 1)],
    ];
    assert!(mesh(q, vec![[0, 1, 2]]).validate().is_valid());
}

#[test]
fn bad_input_is_reported_never_panicked_on() {
    let (mut p, mut t) = tetrahedron([0.0; 3], 1.0, 0);
    p.push([f64::NAN, 0.0, 0.0]);
    p.push([f64::INFINITY, f64::NEG_INFINITY, 1.0]);
    t.push([0, 4, 1]);
    t.push([0, 1, u32::MAX]);
    t.push([5, 5, 5]);
    let v = mesh(p, t).validate();
    assert_eq!(v.non_finite_vertices.examples, [4, 5]);
    assert_eq!(v.out_of_range_faces.examples, [5]);
    assert_eq!(v.degenerate_faces.examples, [6]);
    assert!(!v.is_valid());
    let text = v.to_string();
    assert!(
        text.contains("1 face with an index out of range (e.g. face 5)"),
        "{text}"
    );
    assert!(
        text.contains("2 non-finite vertices (e.g. vertex 4)"),
        "{text}"
    );
    // Huge, tiny and mixed scales.
    for s in [1e-300, 1e-150, 1e150, 1e300, f64::MAX / 4.0] {
        let (p, t) = tetrahedron([0.0; 3], s, 0);
        assert!(mesh(p, t).validate().is_closed(), "scale {s}");
    }
    let (mut p, t) = tetrahedron([0.0; 3], 1.0, 0);
    p[1][1] = 1e-310; // a subnormal coordinate: the integer fallback decides
    assert!(mesh(p, t).validate().is_closed());
}

#[test]
fn scaling_by_powers_of_two_changes_nothing() {
    let m = sphere();
    let v = m.validate();
    for k in [-900, -300, 300, 900] {
        let s = 2f64.powi(k / 2) * 2f64.powi(k - k / 2);
        let mut scaled = m.clone();
        for p in scaled.vertices.iter_mut() {
            *p = p.map(|x| x * s);
        }
        assert_eq!(scaled.validate(), v, "2^{k}");
    }
}

#[test]
fn many_offenders_keep_the_lowest_examples_and_the_full_count() {
    // Every face flipped in a closed mesh: every edge is a flip.
    let mut m = sphere();
    for t in m.triangles.iter_mut().step_by(2) {
        t.swap(1, 2);
    }
    let v = m.validate();
    assert!(v.orientation_flips.count > MAX_EXAMPLES);
    assert_eq!(v.orientation_flips.examples.len(), MAX_EXAMPLES);
    let mut sorted = v.orientation_flips.examples.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, v.orientation_flips.examples);
    // A report survives JSON.
    let json = serde_json::to_string(&v).unwrap();
    let back: Validation = serde_json::from_str(&json).unwrap();
    assert_eq!(back, v);
}

#[test]
fn the_answer_does_not_depend_on_the_thread_count() {
    // Large enough for the parallel paths.
    let (invariant, params) = workloads::workload_params(true, 20_000);
    let mut m = liemesh::generate(&LieField::<f64>::new(&invariant), &params).unwrap();
    assert!(m.triangles.len() > 16_384);
    // A vertex pushed through to the far side, so that the offender lists are not empty.
    let far = m.vertices.len() / 2;
    m.vertices[far] = m.vertices[far].map(|x| -1.2 * x);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let four = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .unwrap();
    let a = one.install(|| m.validate());
    let b = four.install(|| m.validate());
    assert!(a.self_intersections.count > 0, "{a}");
    assert_eq!(a, b);
}
