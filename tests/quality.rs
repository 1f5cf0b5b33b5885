//! The quality bar of the default mode, measured (issue: mesh quality you can measure).

// Needs invariant files (`examples/ellipsoid.toml`): feature `toml`.
#![cfg(feature = "toml")]

// The fuzz targets' checks (see `tests/suite.rs`).
use crate::fuzz_checks;

use liemesh::io::invariant_file::InvariantFile;
use liemesh::model::{Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::quality::{recover, QualityReport};
use liemesh::{MeshParams, Mode};
use std::path::Path;

fn measure(invariant: &Invariant, params: &MeshParams) -> (usize, QualityReport) {
    let run = liemesh::run(&LieField::<f64>::new(invariant), params).unwrap();
    let q = QualityReport::measure(invariant, params, &run.samples, &run.mesh);
    (run.mesh.triangles.len(), q)
}

fn ellipsoid() -> (Invariant, MeshParams) {
    let file = InvariantFile::read(Path::new("examples/ellipsoid.toml")).unwrap();
    (file.invariant, file.params)
}

#[test]
fn fig3_default_mode_is_closed_drift_free_and_well_shaped() {
    let params = Preset::Fig3.params();
    let (_, q) = measure(&Preset::Fig3.invariant(), &params);
    assert!(q.topology.closed && q.topology.euler_characteristic == 2);
    assert!(q.drift.unwrap().max <= 1e-9, "{:?}", q.drift);
    assert!(q.shape.min_angle >= 20.0, "{}", q.shape.min_angle);
    assert!(q.shape.min_angle_p1 >= 30.0, "{}", q.shape.min_angle_p1);
    assert!(q.face_normal_error_max <= params.beta_max.degrees());
}

/// A sphere's far cap traced from a pole is a hole between fronts that met, filled through a
/// chart of its own before the stitching's front advances: its face normals stay within 5° of
/// the field (fig2's reached 6.7° when the front closed the cap triangle by triangle).
#[test]
fn the_spheres_far_caps_close_through_their_own_chart_with_faces_along_the_field() {
    for preset in [Preset::Fig1, Preset::Fig2, Preset::Fig3] {
        let (_, q) = measure(&preset.invariant(), &preset.params());
        assert!(q.topology.closed && q.topology.euler_characteristic == 2);
        assert!(
            q.face_normal_error_max <= 5.0,
            "{preset}: {}",
            q.face_normal_error_max
        );
    }
}

/// fig2's 40 curves from the pole are congruent, so the quadrilaterals between neighbouring
/// curves are cocircular in the chart and either diagonal is Delaunay. Chart 1 decides them
/// alternately from one gap between curves to the next (`triangulate::chart_points`), which
/// the flips and the relaxation turn into wide triangles; deciding them all alike gave a
/// smallest angle of 9.0° (1 % quantile 9.0°), leaving them to rounding 14.6° (23.9°).
/// Since the fronts are stitched, the far cap is flipped before it is relaxed, as the chart
/// is: relaxed first, its ring of curve ends held the 1 % quantile at 24.1°.
#[test]
fn fig2s_ties_alternate_between_curves_and_relax_into_wide_triangles() {
    let (_, q) = measure(&Preset::Fig2.invariant(), &Preset::Fig2.params());
    assert!(q.topology.closed && q.topology.euler_characteristic == 2);
    assert!(q.shape.min_angle >= 17.0, "{}", q.shape.min_angle);
    assert!(q.shape.min_angle_p1 >= 33.0, "{}", q.shape.min_angle_p1);
}

/// fig3's far cap: the hole its fronts leave is refined at the mesh's spacing around it (not
/// its loop's, whose edges between curve ends are twice as long) and the stitched mesh is
/// flipped before it is relaxed. Before both, its smallest angle was 25.0° (1 %: 30.7°) and
/// its largest face-normal error 4.34°, where the chart-2 closing of the first round gave
/// 32.3° (37.6°) and 2.51°.
#[test]
fn fig3s_far_cap_is_as_fine_and_well_shaped_as_the_rest() {
    let (_, q) = measure(&Preset::Fig3.invariant(), &Preset::Fig3.params());
    assert!(q.topology.closed && q.topology.euler_characteristic == 2);
    assert!(q.shape.min_angle >= 30.0, "{}", q.shape.min_angle);
    assert!(q.shape.min_angle_p1 >= 35.0, "{}", q.shape.min_angle_p1);
    assert!(
        q.face_normal_error_max <= 3.0,
        "{}",
        q.face_normal_error_max
    );
}

#[test]
fn the_ellipsoid_at_ten_thousand_triangles_is_closed_drift_free_and_well_shaped() {
    let (inv, params) = ellipsoid();
    let (triangles, q) = measure(&inv, &params);
    assert!((8_000..=12_000).contains(&triangles), "{triangles}");
    assert!(
        q.topology.closed && q.topology.euler_characteristic == 2,
        "{:?}",
        q.topology
    );
    assert!(q.drift.unwrap().max <= 1e-9, "{:?}", q.drift);
    assert!(q.shape.min_angle >= 20.0, "{}", q.shape.min_angle);
    assert!(q.face_normal_error_max <= params.beta_max.degrees());
}

#[test]
fn paper_mode_drifts_off_the_sphere_and_the_default_mode_does_not() {
    let default = Preset::Fig3.params();
    let mut paper = default.clone();
    paper.mode = Mode::Paper;
    let inv = Preset::Fig3.invariant();
    let (_, qd) = measure(&inv, &default);
    let (_, qp) = measure(&inv, &paper);
    assert!(
        qp.drift.unwrap().max > 1e-3,
        "explicit Euler should drift: {:?}",
        qp.drift
    );
    assert!(qd.drift.unwrap().max < 1e-12);
}

/// Recovery errors at the given invariant's resolution and with every step halved (the β band
/// halved: in the default mode Δt is chosen so the normal turns by an angle in the band).
fn recovery_at_full_and_half_step(inv: &Invariant, params: &MeshParams) -> (f64, f64) {
    let error = |scale: f64| {
        let mut p = params.clone();
        p.beta_min = params.beta_min * scale;
        p.beta_max = params.beta_max * scale;
        let run = liemesh::run(&LieField::<f64>::new(inv), &p).unwrap();
        recover(&run.mesh, false, Some(inv)).relative_error.unwrap()
    };
    (error(1.0), error(0.5))
}

#[test]
fn the_sphere_is_recovered_from_fig3_and_halving_the_step_shrinks_the_error() {
    let (coarse, fine) =
        recovery_at_full_and_half_step(&Preset::Fig3.invariant(), &Preset::Fig3.params());
    assert!(coarse <= 1e-3, "coarse {coarse:e}");
    assert!(coarse / fine >= 3.0, "coarse {coarse:e}, fine {fine:e}");
}

#[test]
fn the_ellipsoid_is_recovered_and_halving_the_step_shrinks_the_error() {
    let (inv, params) = ellipsoid();
    let (coarse, fine) = recovery_at_full_and_half_step(&inv, &params);
    assert!(coarse <= 1e-3, "coarse {coarse:e}");
    assert!(coarse / fine >= 3.0, "coarse {coarse:e}, fine {fine:e}");
}

#[test]
fn fig6_reports_the_recovery_error_beside_the_integrability_defect() {
    let (_, q) = measure(&Preset::Fig6.invariant(), &Preset::Fig6.params());
    assert!(
        q.integrability_defect_max > 0.1,
        "fig6's field is not integrable"
    );
    assert!(q.recovery.relative_error.is_some());
    assert!(q.drift.is_none(), "no potential, no drift");
}

#[test]
fn paper_mode_curves_meet_on_the_far_side_of_the_ellipsoid_despite_their_drift() {
    // Explicit Euler carries curves off the ellipsoid by amounts that differ from curve to
    // curve; without allowing for that along the normal they pass over each other, never
    // collide, and keep spawning curves (4,596 of them before the drift-aware test).
    let (inv, params) = ellipsoid();
    let mut paper = params;
    paper.mode = Mode::Paper;
    let run = liemesh::run(&LieField::<f64>::new(&inv), &paper).unwrap();
    let collisions = run
        .samples
        .curves
        .iter()
        .filter(|c| c.end == liemesh::sample::CurveEnd::Collision)
        .count();
    assert!(
        run.samples.curves.len() < 3_000,
        "{}",
        run.samples.curves.len()
    );
    assert!(collisions > 10, "{collisions} collisions");
}

#[test]
fn fig6_face_normal_error_grows_with_distance_from_p0_as_the_field_twists_not_from_the_mesh() {
    // fig6's field is not integrable (|v·∇×v|/|v|² ≈ 3 near the rim): the surface swept by the
    // curves, tangent to v⊥ at p0, turns away from v⊥ by about ½·defect·s radians at geodesic
    // distance s. Its triangles are fine: near p0 the face normals agree with the field to
    // within β_max, and at the rim the field normals at the three corners of the worst faces
    // differ by less than 2β_max, so the large errors there are the field's twist, not coarse
    // or folded triangles.
    let params = Preset::Fig6.params();
    let inv = Preset::Fig6.invariant();
    let field = LieField::<f64>::new(&inv);
    let run = liemesh::run(&field, &params).unwrap();
    let mesh = &run.mesh;
    let beta_max = params.beta_max.degrees();
    let v3 = |i: u32| liemesh::scalar::Vec3::from_f64(mesh.vertices[i as usize]);
    let mut near_max = 0.0_f64;
    let mut rim = Vec::new();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(v3);
        let face = (&b - &a).cross(&(&c - &a));
        let centroid = (&(&a + &b) + &c).scale(&(1.0 / 3.0));
        let error = face
            .angle_to(&liemesh::model::NormalField::normal(&field, &centroid))
            .to_degrees();
        let s = t
            .iter()
            .map(|&i| mesh.provenance[i as usize].s)
            .sum::<f64>()
            / 3.0;
        let n = t.map(|i| liemesh::model::NormalField::normal(&field, &v3(i)));
        let spread = n[0]
            .angle_to(&n[1])
            .max(n[1].angle_to(&n[2]))
            .max(n[0].angle_to(&n[2]))
            .to_degrees();
        if s < 0.2 {
            near_max = near_max.max(error);
        } else if s > 0.8 {
            rim.push((error, spread));
        }
    }
    assert!(near_max <= beta_max, "near p0: {near_max}°");
    rim.sort_by(|x, y| y.0.total_cmp(&x.0));
    assert!(rim[0].0 > 45.0, "at the rim: {:?}", rim[0]);
    for &(error, spread) in &rim[..10] {
        assert!(spread < 2.0 * beta_max, "error {error}°, spread {spread}°");
    }
}

/// The ellipsoid meshed from `p0` with the β band scaled by `scale`.
fn ellipsoid_from(p0: [f64; 3], w00: [f64; 3], scale: f64) -> (usize, QualityReport) {
    let (inv, mut params) = ellipsoid();
    params.p0 = p0;
    params.w00 = Some(w00);
    params.beta_min = params.beta_min * scale;
    params.beta_max = params.beta_max * scale;
    measure(&inv, &params)
}

/// Closed with Euler characteristic 2, consistently oriented, smallest angle and largest
/// face-normal error (degrees) within the bounds.
fn assert_closed_and_fine(q: &QualityReport, min_angle: f64, max_face_error: f64) {
    assert!(
        q.topology.closed && q.topology.euler_characteristic == 2,
        "{:?}",
        q.topology
    );
    assert_eq!(q.topology.orientation_flips, 0);
    assert!(q.shape.min_angle >= min_angle, "{}", q.shape.min_angle);
    assert!(
        q.face_normal_error_max <= max_face_error,
        "{}",
        q.face_normal_error_max
    );
}

#[test]
fn the_ellipsoid_closes_watertight_from_the_tip_of_its_long_axis() {
    // The curves from (1, 0, 0) cross a caustic near (−1, 0, 0), where chart 1 folds and the
    // hole is a thin twisted band: the folded triangles are filled together with the hole.
    let (_, q) = ellipsoid_from([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0);
    assert!(q.drift.unwrap().max <= 1e-9, "{:?}", q.drift);
    assert_closed_and_fine(&q, 10.0, 15.0);
}

#[test]
fn the_ellipsoid_closes_watertight_from_its_middle_axis() {
    // From (0, 1/2, 0) the folded region on the far side spans more than a hemisphere of
    // normals: only the Gauss map lays it flat.
    let (_, q) = ellipsoid_from([0.0, 0.5, 0.0], [1.0, 0.0, 0.0], 1.0);
    assert_closed_and_fine(&q, 20.0, 20.0);
}

#[test]
fn the_ellipsoid_closes_watertight_at_a_quarter_of_the_beta_band() {
    // At 1°–2° the band's two sides overlap in a neck that uniform growth does not remove:
    // the region is widened where its loop crosses itself.
    let (triangles, q) = ellipsoid_from([0.0, 0.0, 0.25], [1.0, 0.0, 0.0], 0.25);
    assert!(triangles > 150_000, "{triangles}");
    assert_closed_and_fine(&q, 15.0, 2.0);
}

#[test]
fn the_ellipsoid_closes_watertight_with_the_beta_band_halved() {
    let (triangles, q) = ellipsoid_from([0.0, 0.0, 0.25], [1.0, 0.0, 0.0], 0.5);
    assert!(triangles > 30_000, "{triangles}");
    assert_closed_and_fine(&q, 20.0, 4.0);
}

#[test]
fn most_ellipsoids_close_from_any_starting_point() {
    // Axis-aligned ellipsoids with semi-axis ratios up to 4, each meshed from a random point
    // of it: from most starting points the curves cross a caustic on the far side, and the
    // closing has to fill the folded band. 16 of these 60 closed before folded triangles
    // were filled together with the hole (all 60 now, every one with angles of at least 17°
    // and face normals within 15° of the field); open meshes are reported, and valid. Since
    // the stitched mesh is flipped before it is relaxed, their smallest angles average 27.2°
    // and the lowest is 18.1° (21.5° and 15.7° before).
    let mut state = 12345_u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 1_000_000) as f64 / 1e6
    };
    let (mut closed, mut meshed) = (0, 0);
    for _ in 0..60 {
        let l: Vec<f64> = (0..3).map(|_| 1.0 + 15.0 * uniform()).collect();
        let inv = Invariant::from_numbers(&[l[0], l[1], l[2], 0.0, 0.0, 0.0]).unwrap();
        let d = [uniform() - 0.5, uniform() - 0.5, uniform() - 0.5];
        let scale = (l[0] * d[0] * d[0] + l[1] * d[1] * d[1] + l[2] * d[2] * d[2]).sqrt();
        let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let mut params = Preset::Fig3.params();
        params.p0 = d.map(|x| x / scale);
        params.w00 = Some(if d[0].abs() < 0.9 * length {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        });
        params.dt = Some(0.05);
        let Ok(run) = liemesh::run(&LieField::<f64>::new(&inv), &params) else {
            continue;
        };
        meshed += 1;
        fuzz_checks::check_mesh(&run.mesh).unwrap();
        if liemesh::quality::Topology::of(&run.mesh).closed {
            closed += 1;
            let q = QualityReport::measure(&inv, &params, &run.samples, &run.mesh);
            assert!(q.shape.min_angle >= 17.0, "{}", q.shape.min_angle);
            assert!(
                q.face_normal_error_max <= 15.0,
                "{}",
                q.face_normal_error_max
            );
        }
    }
    assert_eq!(meshed, 60);
    assert!(closed >= 57, "{closed} of 60 closed");
}

/// The posed-quadric example (DESIGN.md §1, three non-zero angles): closed, on the turned
/// quadric to rounding, and `recover` gives λ and the angles back to 1e-3.
#[test]
fn a_posed_ellipsoid_closes_stays_on_its_quadric_and_recovers_its_angles() {
    let file = InvariantFile::read(Path::new("examples/surfaces/posed-ellipsoid.toml")).unwrap();
    let inv = &file.invariant;
    assert_eq!(inv.reading(), liemesh::model::AngleReading::Quadric);
    assert!(inv.numbers()[3..6].iter().all(|&a| a != 0.0));
    let run = liemesh::run(&LieField::<f64>::new(inv), &file.params).unwrap();
    let q = QualityReport::measure(inv, &file.params, &run.samples, &run.mesh);
    assert!(
        q.topology.closed && q.topology.euler_characteristic == 2,
        "{:?}",
        q.topology
    );
    // The potential ½ pᵀ A p is 0.5 at p0 (pᵀ A p = 1): drift at rounding level.
    assert!(
        q.drift.expect("a posed quadric is integrable").max < 1e-14,
        "{:?}",
        q.drift
    );
    let r = recover(&run.mesh, false, Some(inv));
    for (got, want) in r.a_invariant.iter().zip(inv.numbers()) {
        assert!((got - want).abs() < 1e-3, "recovered {:?}", r.a_invariant);
    }
}
