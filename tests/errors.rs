//! Every bad input gets its typed error, never a panic.

use liemesh::model::{Invariant, InvariantError, LieField};
use liemesh::preset::Preset;
use liemesh::{generate, Angle, MeshError, MeshParams, Method};

fn mesh_sphere(params: &MeshParams) -> Result<liemesh::Mesh, MeshError> {
    generate(&LieField::<f64>::new(&Preset::Fig3.invariant()), params)
}

fn with(f: impl FnOnce(&mut MeshParams)) -> Result<liemesh::Mesh, MeshError> {
    let mut p = Preset::Fig3.params();
    f(&mut p);
    mesh_sphere(&p)
}

#[test]
fn non_finite_numbers_are_rejected() {
    assert!(matches!(
        with(|p| p.dt = Some(f64::NAN)),
        Err(MeshError::NonFinite { name: "dt", .. })
    ));
    assert!(matches!(
        with(|p| p.p0[1] = f64::INFINITY),
        Err(MeshError::NonFinite { name: "p0.y", .. })
    ));
    assert!(matches!(
        with(|p| p.beta_max = Angle::from_radians(f64::NEG_INFINITY)),
        Err(MeshError::NonFinite { .. })
    ));
    assert!(matches!(
        Invariant::from_numbers(&[1.0, f64::NAN, 1.0, 0.0, 0.0, 0.0]),
        Err(InvariantError::NonFinite { index: 2, .. })
    ));
}

#[test]
fn a_direction_parallel_to_the_normal_is_rejected() {
    let e = with(|p| p.w00 = Some([0.0, 0.0, 2.0])).unwrap_err();
    assert!(
        matches!(e, MeshError::DirectionParallelToNormal { .. }),
        "{e}"
    );
    assert!(e.to_string().contains("tangent plane"));
}

#[test]
fn a_vanishing_normal_at_p0_is_rejected() {
    let e = with(|p| p.p0 = [0.0, 0.0, 0.0]).unwrap_err();
    assert!(matches!(e, MeshError::SingularInitialPoint { .. }), "{e}");
}

#[test]
fn an_inverted_or_empty_angle_band_is_rejected() {
    let e = with(|p| {
        p.beta_min = Angle::from_degrees(8.0);
        p.beta_max = Angle::from_degrees(4.0);
    })
    .unwrap_err();
    assert!(matches!(e, MeshError::AngleBand { .. }), "{e}");
    let e = with(|p| p.beta_min = p.beta_max).unwrap_err();
    assert!(matches!(e, MeshError::AngleBand { .. }));
    // The degrees come back as typed, not through radians' rounding (-3.0000000000000004).
    let e = with(|p| p.beta_min = Angle::from_degrees(-3.0)).unwrap_err();
    assert!(e.to_string().contains("[-3°, 8°]"), "{e}");
}

#[test]
fn a_non_positive_step_is_rejected() {
    for dt in [0.0, -0.1] {
        let e = with(|p| p.dt = Some(dt)).unwrap_err();
        assert!(matches!(e, MeshError::StepSize { name: "dt", .. }), "{e}");
    }
}

#[test]
fn growth_and_shrink_factors_must_grow_and_shrink() {
    assert_eq!(
        with(|p| p.grow = 1.0).unwrap_err(),
        MeshError::GrowthFactor(1.0)
    );
    assert_eq!(
        with(|p| p.shrink = 1.0).unwrap_err(),
        MeshError::ShrinkFactor(1.0)
    );
    assert_eq!(
        with(|p| p.shrink = 0.0).unwrap_err(),
        MeshError::ShrinkFactor(0.0)
    );
}

#[test]
fn zero_budgets_are_rejected() {
    assert_eq!(
        with(|p| p.max_points = 0).unwrap_err(),
        MeshError::ZeroBudget("max_points")
    );
    assert_eq!(
        with(|p| p.max_curves = 0).unwrap_err(),
        MeshError::ZeroBudget("max_curves")
    );
    assert_eq!(
        with(|p| p.max_steps = 0).unwrap_err(),
        MeshError::ZeroBudget("max_steps")
    );
    assert_eq!(
        with(|p| p.max_retries = 0).unwrap_err(),
        MeshError::ZeroBudget("max_retries")
    );
}

#[test]
fn too_few_previous_method_curves_are_rejected() {
    let e = with(|p| {
        p.method = Method::Previous;
        p.curves = 2;
    })
    .unwrap_err();
    assert_eq!(e, MeshError::TooFewCurves(2));
}

#[test]
fn an_unsupported_output_extension_is_rejected() {
    let e = liemesh::io::MeshFormat::from_path(std::path::Path::new("mesh.xyz")).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains(".ply") && msg.contains(".obj") && msg.contains(".stl"),
        "{msg}"
    );
}

#[test]
fn small_budgets_end_the_run_without_error() {
    let m = with(|p| p.max_points = 50).unwrap();
    assert!(m.vertices.len() <= 50);
    for v in &m.vertices {
        assert!(v.iter().all(|x| x.is_finite()));
    }
}

/// A field finite and not zero at `p0` but too long or too short for `f64` geometry (found by
/// trying user fields scaled by 1e300 and 1e-300: the error said the field vanished, or was not
/// finite, and to choose another `p0`). The error now names the remedy; a field scaled within
/// range meshes as the unscaled one (only its direction matters).
#[test]
fn a_field_too_long_or_too_short_for_f64_says_to_rescale_it() {
    let sphere = |k: f64| {
        let inv = Invariant::from_numbers(&[k, k, k, 0.0, 0.0, 0.0]).unwrap();
        generate(&LieField::<f64>::new(&inv), &Preset::Fig3.params())
    };
    for k in [1e300, 1e-300] {
        let e = sphere(k).unwrap_err();
        assert!(matches!(e, MeshError::FieldMagnitude { .. }), "{k}: {e}");
        assert!(e.to_string().contains("divide the field"), "{e}");
    }
    let unit = sphere(1.0).unwrap().triangles.len();
    for k in [1e100, 1e-100] {
        assert_eq!(sphere(k).unwrap().triangles.len(), unit, "scaled by {k}");
    }
}

/// Where the field overflows because `p0` is far out, or gives a direction but no finite
/// bend, the error says so and what to do, rather than calling `p0` a singular point (found
/// by a new user's sweep: `p0 = (1e200, 1e200, 0)` and `λ = (1e-200, 1, 1e200)` from
/// `(1, 1e-100, 0)` were both "the normal field vanishes ... choose another initial point").
#[test]
fn overflow_at_p0_is_told_apart_from_a_singular_point() {
    let mesh = |numbers: [f64; 6], p0: [f64; 3]| {
        let inv = Invariant::from_numbers(&numbers).unwrap();
        generate(&LieField::<f64>::new(&inv), &MeshParams::at(p0))
    };
    let e = mesh([1.0, 1.0, 1.0, 0.0, 0.0, 0.0], [1e200, 1e200, 0.0]).unwrap_err();
    match &e {
        MeshError::SurfaceScale { size, .. } => {
            assert!((size / 1e200 - 2f64.sqrt()).abs() < 1e-12, "{e}")
        }
        _ => panic!("{e}"),
    }
    let e = mesh([1e-200, 1.0, 1e200, 0.0, 0.0, 0.0], [1.0, 1e-100, 0.0]).unwrap_err();
    assert!(matches!(e, MeshError::BendAtInitialPoint { .. }), "{e}");
    assert!(e.to_string().contains("bends too sharply"), "{e}");
    // A zero of the field is still a singular point.
    let e = mesh([1.0, 1.0, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0]).unwrap_err();
    assert!(matches!(e, MeshError::SingularInitialPoint { .. }), "{e}");
}

/// A budget too small for any mesh, or a `p0` outside the box given, is named as such (a new
/// user's sweep: `max_points = 3` was blamed on curves crossing near `p0`, a box that leaves
/// `p0` out on "only 1 sample point").
#[test]
fn a_budget_too_small_or_a_p0_outside_the_box_is_named() {
    let ellipsoid = Invariant::from_numbers(&[1.0, 4.0, 9.0, 0.0, 0.0, 0.0]).unwrap();
    let mesh = |f: &dyn Fn(&mut MeshParams)| {
        let mut p = MeshParams::at([1.0, 0.0, 0.0]);
        f(&mut p);
        generate(&LieField::<f64>::new(&ellipsoid), &p)
    };
    for budget in [1, 2, 3] {
        let e = mesh(&|p| p.max_points = budget).unwrap_err();
        assert!(
            matches!(e, MeshError::PointBudgetTooSmall { max_points, .. } if max_points == budget),
            "{budget}: {e}"
        );
        assert!(e.to_string().contains("allow more points"), "{e}");
    }
    let e = mesh(&|p| p.bounding_box = Some(0.5)).unwrap_err();
    assert!(matches!(e, MeshError::OutsideBoundingBox { .. }), "{e}");
    assert!(e.to_string().contains("larger bounding_box"), "{e}");
    // A box that holds p0 meshes.
    assert!(mesh(&|p| p.bounding_box = Some(1.5)).is_ok());
}
