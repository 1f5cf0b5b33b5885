//! End-to-end behaviour of the engine on the paper's presets.

use liemesh::model::{Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::quality::Topology;
use liemesh::scalar::{Dual, Scalar};
use liemesh::{run, MeshRun};

fn preset_run<T: Scalar>(p: Preset) -> MeshRun<T> {
    run(&LieField::<T>::new(&p.invariant()), &p.params()).expect("presets mesh")
}

#[test]
fn triangle_counts_order_as_in_the_paper() {
    let t: Vec<usize> = Preset::ALL
        .iter()
        .map(|&p| preset_run::<f64>(p).mesh.triangles.len())
        .collect();
    assert!(t[0] < t[2] && t[2] < t[1], "fig1 < fig3 < fig2: {t:?}");
    assert!(t[3] < t[5] && t[5] < t[4], "fig4 < fig6 < fig5: {t:?}");
}

#[test]
fn fig3_is_a_closed_oriented_sphere() {
    let r = preset_run::<f64>(Preset::Fig3);
    let topo = Topology::of(&r.mesh);
    assert!(topo.closed, "{topo:?}");
    assert_eq!(topo.euler_characteristic, 2);
    assert_eq!(topo.non_manifold_edges, 0);
    assert_eq!(topo.orientation_flips, 0);
    for v in &r.mesh.vertices {
        let radius = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!(
            (radius - 1.0).abs() < 1e-3,
            "vertex off the sphere: {radius}"
        );
    }
}

#[test]
fn every_sphere_preset_closes_in_both_modes() {
    for p in [Preset::Fig1, Preset::Fig2, Preset::Fig3] {
        for mode in [liemesh::Mode::Default, liemesh::Mode::Paper] {
            let mut params = p.params();
            params.mode = mode;
            let r = run(&LieField::<f64>::new(&p.invariant()), &params).unwrap();
            let topo = Topology::of(&r.mesh);
            assert!(
                topo.closed && topo.euler_characteristic == 2,
                "{p} {mode:?}: {topo:?}"
            );
        }
    }
}

#[test]
fn triangles_face_the_way_the_field_normal_points() {
    for p in Preset::ALL {
        let m = preset_run::<f64>(p).mesh;
        let mut against = 0;
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.vertices[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let fn_: [f64; 3] = (0..3)
                .map(|k| t.iter().map(|&i| m.normals[i as usize][k]).sum::<f64>())
                .collect::<Vec<_>>()
                .try_into()
                .unwrap();
            if n[0] * fn_[0] + n[1] * fn_[1] + n[2] * fn_[2] < 0.0 {
                against += 1;
            }
        }
        assert_eq!(
            against, 0,
            "{p}: {against} triangles face against the field normal"
        );
    }
}

#[test]
fn open_presets_are_discs() {
    for p in [Preset::Fig4, Preset::Fig5, Preset::Fig6] {
        let topo = Topology::of(&preset_run::<f64>(p).mesh);
        assert_eq!(
            (topo.euler_characteristic, topo.boundary_loops),
            (1, 1),
            "{p}: {topo:?}"
        );
        assert_eq!(
            (topo.non_manifold_edges, topo.orientation_flips),
            (0, 0),
            "{p}"
        );
    }
}

#[test]
fn relaxation_moves_interior_vertices_but_not_the_boundary_or_p0() {
    for p in [Preset::Fig4, Preset::Fig5, Preset::Fig6] {
        let r = preset_run::<f64>(p);
        let m = &r.mesh;
        // Directed edges without their reverse are the boundary.
        let mut directed = std::collections::HashSet::new();
        for t in &m.triangles {
            for k in 0..3 {
                directed.insert((t[k], t[(k + 1) % 3]));
            }
        }
        let mut on_boundary = vec![false; m.vertices.len()];
        for &(a, b) in &directed {
            if !directed.contains(&(b, a)) {
                on_boundary[a as usize] = true;
                on_boundary[b as usize] = true;
            }
        }
        let (mut moved, mut interior) = (0, 0);
        for (v, pr) in m.provenance.iter().enumerate() {
            let i = r.samples.curves[pr.curve as usize].points[pr.step as usize] as usize;
            let sampled = r.samples.points[i].to_f64();
            if on_boundary[v] || (pr.curve == 0 && pr.step == 0) {
                assert_eq!(m.vertices[v], sampled, "{p}: vertex {v} moved");
            } else {
                interior += 1;
                moved += usize::from(m.vertices[v] != sampled);
            }
        }
        assert!(
            on_boundary.iter().any(|&b| b) && moved * 10 > interior * 9,
            "{p}: {moved} of {interior} interior vertices moved"
        );
    }
}

#[test]
fn output_is_bit_identical_between_runs() {
    for p in Preset::ALL {
        assert_eq!(preset_run::<f64>(p).mesh, preset_run::<f64>(p).mesh, "{p}");
    }
}

#[test]
fn output_does_not_depend_on_the_number_of_threads() {
    // An ellipsoid large enough (about 21,000 vertices, 42,000 faces) that the relaxation
    // and the flips run all their parallel maps, in pools of one and of three threads.
    let invariant = Invariant::from_numbers(&[1.0, 4.0, 16.0, 0.0, 0.0, 0.0]).unwrap();
    let field = LieField::<f64>::new(&invariant);
    let mut params = Preset::Fig3.params();
    params.p0 = [0.0, 0.0, 0.25];
    params.beta_min = params.beta_min / 2.0;
    params.beta_max = params.beta_max / 2.0;
    params.dt = params.dt.map(|dt| dt / 2.0);
    let in_pool = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run(&field, &params).unwrap().mesh)
    };
    let (one, three) = (in_pool(1), in_pool(3));
    assert!(
        one.triangles.len() > 16_384,
        "{} faces",
        one.triangles.len()
    );
    assert_eq!(one.triangles, three.triangles);
    let bits =
        |v: &[[f64; 3]]| -> Vec<[u64; 3]> { v.iter().map(|p| p.map(f64::to_bits)).collect() };
    assert_eq!(bits(&one.vertices), bits(&three.vertices));
    assert_eq!(bits(&one.normals), bits(&three.normals));
}

#[test]
fn fig3_runs_in_f32_f64_and_dual() {
    let m64 = preset_run::<f64>(Preset::Fig3).mesh;
    let m32 = preset_run::<f32>(Preset::Fig3).mesh;
    let md = preset_run::<Dual<f64>>(Preset::Fig3).mesh;
    // Dual<f64>'s real part is computed exactly as f64 is.
    assert_eq!(md, m64);
    // f32 may take other discrete decisions (the audits report where); it must still mesh
    // the same sphere.
    let topo = liemesh::quality::Topology::of(&m32);
    assert!(topo.closed && topo.euler_characteristic == 2, "{topo:?}");
    for v in &m32.vertices {
        let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!(
            (r - 1.0).abs() < 1e-5,
            "f32 vertex off the sphere by {}",
            r - 1.0
        );
    }
}

#[test]
fn dual_numbers_carry_vertex_sensitivities() {
    // Sphere of radius 1/√λ scaled: d/dλ1 of every vertex is finite, and a finite
    // difference of the f64 meshes agrees with it.
    let inv = Invariant::from_numbers(&[1.0, 4.0, 16.0, 0.0, 0.0, 0.0]).unwrap();
    let mut params = Preset::Fig3.params();
    params.p0 = [0.0, 0.0, 0.25];
    params.dt = Some(0.05);
    let seeded = LieField::<f64>::seeded(&inv, 2);
    let r = run(&seeded, &params).unwrap();
    let h = 1e-6;
    let plus = Invariant::from_numbers(&[1.0, 4.0, 16.0 + h, 0.0, 0.0, 0.0]).unwrap();
    let rp = run(&LieField::<f64>::new(&plus), &params).unwrap();
    // Match points by (chart angle, step): the order in which curves advance (and so point
    // and curve numbers) may change when arc lengths tie to within the perturbation.
    let key = |pr: &liemesh::Provenance| (pr.theta.to_bits(), pr.step);
    // A chart angle can come back when a curve is inserted where an ended one was, so only
    // keys that occur once in each run identify a point.
    let unique = |prov: &[liemesh::Provenance]| {
        let mut count = std::collections::HashMap::new();
        for (i, pr) in prov.iter().enumerate() {
            count.entry(key(pr)).or_insert((0, i)).0 += 1;
        }
        count
            .into_iter()
            .filter(|(_, (n, _))| *n == 1)
            .map(|(k, (_, i))| (k, i))
            .collect::<std::collections::HashMap<_, _>>()
    };
    let index = unique(&rp.samples.provenance);
    let mine = unique(&r.samples.provenance);
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for (d, pr) in r.samples.points.iter().zip(&r.samples.provenance) {
        if !mine.contains_key(&key(pr)) {
            continue;
        }
        let Some(&j) = index.get(&key(pr)) else {
            continue;
        };
        let p = &rp.samples.points[j];
        compared += 1;
        for k in 0..3 {
            let fd = (p[k] - d[k].re) / h;
            worst = worst.max((fd - d[k].eps).abs());
        }
    }
    assert!(compared > 100, "only {compared} points in common");
    assert!(
        worst < 1e-4,
        "dual sensitivity vs finite difference: {worst}"
    );
}

#[cfg(feature = "mpfr")]
#[test]
fn presets_in_f64_agree_with_mpfr256_within_1e_minus_9() {
    use liemesh::scalar::Mpfr;
    for p in Preset::ALL {
        let r64 = preset_run::<f64>(p);
        let rmp = preset_run::<Mpfr<256>>(p);
        // Same discrete decisions: the same curves and points (arc lengths differ in the last
        // bits), and the same triangles up to where each triangle's listing starts, the
        // stitched ones included (fig2's and fig3's far caps tie on symmetric triangles).
        let ids =
            |r: &[liemesh::Provenance]| r.iter().map(|p| (p.curve, p.step)).collect::<Vec<_>>();
        assert_eq!(
            ids(&r64.samples.provenance),
            ids(&rmp.samples.provenance),
            "{p}"
        );
        assert_eq!(
            r64.mesh.canonical_triangles(),
            rmp.mesh.canonical_triangles(),
            "{p}"
        );
        let max_diff = |a: &[liemesh::scalar::Vec3<f64>],
                        b: &[liemesh::scalar::Vec3<Mpfr<256>>]| {
            a.iter()
                .zip(b)
                .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k].to_f64()).abs()))
                .fold(0.0_f64, f64::max)
        };
        let samples = max_diff(&r64.samples.points, &rmp.samples.points);
        let vertices = max_diff(&r64.vertices, &rmp.vertices);
        assert!(
            samples <= 1e-9,
            "{p}: samples, f64 vs Mpfr<256>: {samples:e}"
        );
        assert!(
            vertices <= 1e-9,
            "{p}: mesh vertices, f64 vs Mpfr<256>: {vertices:e}"
        );
    }
}

#[test]
fn meshes_have_no_unreferenced_or_duplicate_vertices_nor_degenerate_faces() {
    for p in Preset::ALL {
        let m = preset_run::<f64>(p).mesh;
        let mut used = vec![false; m.vertices.len()];
        for t in &m.triangles {
            for &i in t {
                used[i as usize] = true;
            }
            let [a, b, c] = t.map(|i| m.vertices[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            assert!(
                n.iter().map(|x| x * x).sum::<f64>() > 1e-24,
                "{p}: degenerate {t:?}"
            );
        }
        assert!(used.iter().all(|&u| u), "{p}: unreferenced vertex");
        let mut keys: Vec<[u64; 3]> = m.vertices.iter().map(|v| v.map(f64::to_bits)).collect();
        keys.sort_unstable();
        let n = keys.len();
        keys.dedup();
        assert_eq!(keys.len(), n, "{p}: duplicate vertices");
    }
}
