//! The error type of mesh generation.

use thiserror::Error;

/// Everything that can stop [`generate`](crate::generate) before it returns a mesh.
///
/// Each message says what was wrong and what to do about it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MeshError {
    /// A parameter is NaN or infinite.
    #[error("parameter `{name}` is {value}; it must be a finite number")]
    NonFinite {
        /// Parameter name.
        name: &'static str,
        /// The value found.
        value: f64,
    },
    /// The initial direction has no component in the tangent plane at `p0`.
    #[error(
        "the initial direction w00 = {w00:?} is parallel to the normal {normal:?} at p0; \
         choose a direction with a component in the tangent plane"
    )]
    DirectionParallelToNormal {
        /// The direction given.
        w00: [f64; 3],
        /// The field's normal at `p0`.
        normal: [f64; 3],
    },
    /// `v(p0)` is finite and not zero, but so long or so short that its squared length is not
    /// a normal `f64` number: its direction cannot be worked out in `f64` geometry.
    #[error(
        "the normal field at p0 = {p0:?} is {normal:?}, too long or too short for f64 geometry \
         (its squared length leaves the normal f64 range); only its direction matters: divide \
         the field by a constant that brings its length near 1"
    )]
    FieldMagnitude {
        /// The initial point.
        p0: [f64; 3],
        /// The field value there.
        normal: [f64; 3],
    },
    /// `v(p0)` is zero or not finite (or its derivative is not), so `p0` has no tangent
    /// plane or no curvature.
    #[error(
        "the normal field vanishes, or it or its derivative is not finite, at p0 = {p0:?} \
         (the field there: {normal:?}); p0 is a singular point, choose another initial point"
    )]
    SingularInitialPoint {
        /// The initial point.
        p0: [f64; 3],
        /// The field value there.
        normal: [f64; 3],
    },
    /// `v(p0)` gives a direction, but the surface's bend there (the field's derivative
    /// over its length) is not finite in `f64`.
    #[error(
        "the normal field at p0 = {p0:?} is {normal:?}, but how the surface bends there (the \
         field's derivative over its length) is not finite in f64: the surface bends too \
         sharply at p0 for f64 geometry, or the field is not differentiable there; scale the \
         field's coordinates or its numbers into a narrower range, or choose another initial \
         point"
    )]
    BendAtInitialPoint {
        /// The initial point.
        p0: [f64; 3],
        /// The field value there.
        normal: [f64; 3],
    },
    /// The surface at `p0` is too small or too large for `f64` geometry.
    #[error(
        "the surface at p0 has size {size:e} (its radius of curvature there, or p0's distance \
         from the origin); liemesh meshes surfaces of size {min:e} to {max:e}, where squared \
         lengths and areas stay normal f64 numbers: scale the field's coordinates into that range"
    )]
    SurfaceScale {
        /// The surface's size at `p0` ([`crate::Scales`]).
        size: f64,
        /// The smallest size meshed.
        min: f64,
        /// The largest size meshed.
        max: f64,
    },
    /// `β_min ≥ β_max`, or the band is not inside (0°, 90°).
    #[error(
        "the normal-angle band [β_min, β_max] = [{min_deg}°, {max_deg}°] is invalid; \
         it needs 0 < β_min < β_max < 90 degrees"
    )]
    AngleBand {
        /// β_min in degrees.
        min_deg: f64,
        /// β_max in degrees.
        max_deg: f64,
    },
    /// A step length or step bound is not positive, or the bounds are inverted.
    #[error("step size {name} = {value} is invalid: {why}")]
    StepSize {
        /// Which parameter.
        name: &'static str,
        /// The value found.
        value: f64,
        /// What is required.
        why: &'static str,
    },
    /// `δ ≤ 1`.
    #[error("the growth factor δ = {0} must be greater than 1 (the step grows when the normal turns too little)")]
    GrowthFactor(f64),
    /// `δ' ≥ 1` or `δ' ≤ 0`.
    #[error("the shrink factor δ' = {0} must lie strictly between 0 and 1 (the step shrinks when the normal turns too much)")]
    ShrinkFactor(f64),
    /// A budget is zero.
    #[error("the budget `{0}` is zero; every budget must allow at least one unit of work")]
    ZeroBudget(&'static str),
    /// A threshold factor is out of range.
    #[error("parameter `{name}` = {value} is out of range: {why}")]
    OutOfRange {
        /// Which parameter.
        name: &'static str,
        /// The value found.
        value: f64,
        /// What is allowed.
        why: &'static str,
    },
    /// The point budget ran out and the samples made no mesh: too few for a triangle, or
    /// none of their triangles survived validation.
    #[error(
        "the point budget max_points = {max_points} ran out after {points} sample point(s), \
         and they made no triangle that survived validation; allow more points (max_points)"
    )]
    PointBudgetTooSmall {
        /// The budget.
        max_points: usize,
        /// How many points the curves laid.
        points: usize,
    },
    /// `p0` lies outside the bounding box, where every curve ends at once.
    #[error(
        "p0 = {p0:?} lies outside the bounding box (every coordinate within ±{bounding_box:e}), \
         where every curve ends at once; give a larger bounding_box or a p0 inside it"
    )]
    OutsideBoundingBox {
        /// The initial point.
        p0: [f64; 3],
        /// The box's half side.
        bounding_box: f64,
    },
    /// The previous method needs at least three curves to span the tangent plane.
    #[error("the previous method needs at least 3 curves (got {0}); set `curves` of `Method::Previous` to 3 or more")]
    TooFewCurves(usize),
    /// The finished mesh failed validation (a bug: please report the input).
    #[error(
        "the mesh failed validation: {0}; this is a bug in liemesh, please report the input \
         (a mesh that fails validation is never returned)"
    )]
    Invalid(Box<crate::mesh::Validation>),
    /// The samples could not be triangulated (too few points, all points collinear in the chart…).
    #[error("could not triangulate the samples: {0}")]
    Triangulation(String),
    /// No triangle survived: every face the samples gave was removed as crossing another
    /// or as part of a component apart from `p0`'s.
    #[error(
        "no triangle of the {points} sample points survived validation ({}); try shorter \
         steps (dt_max below the {dt_max:.3e} used, dt, beta_max) or another p0",
        if *swept {
            "the swept surface folds onto itself right at p0"
        } else {
            "the curves crossed one another near p0: steps too long for how the surface \
             bends beyond them, as across the flat face of a flattened quadric"
        }
    )]
    Empty {
        /// How many points the curves laid.
        points: usize,
        /// Whether the field is not integrable at `p0` (the surface is swept, and may fold).
        swept: bool,
        /// The largest step the run used (given or automatic).
        dt_max: f64,
    },
}

impl MeshError {
    /// The error for a `p0` where the field, `normal`, gives no unit normal or no shape in
    /// `f64`: [`MeshError::SurfaceScale`] when `p0` itself lies beyond the sizes meshed (the
    /// field overflows there), [`MeshError::FieldMagnitude`] when the field is finite and not
    /// zero but its squared length is not a normal number, [`MeshError::BendAtInitialPoint`]
    /// when it gives a direction but no shape, [`MeshError::SingularInitialPoint`] otherwise.
    pub(crate) fn no_normal_at(p0: [f64; 3], normal: [f64; 3]) -> MeshError {
        // |p0|, without overflow in the squares.
        let size = p0[0].hypot(p0[1]).hypot(p0[2]);
        if size > crate::params::MAX_SURFACE_SIZE {
            return MeshError::SurfaceScale {
                size,
                min: crate::params::MIN_SURFACE_SIZE,
                max: crate::params::MAX_SURFACE_SIZE,
            };
        }
        let finite = normal.iter().all(|x| x.is_finite());
        let squared: f64 = normal.iter().map(|x| x * x).sum();
        if finite && normal.iter().any(|&x| x != 0.0) {
            if squared.is_normal() {
                MeshError::BendAtInitialPoint { p0, normal }
            } else {
                MeshError::FieldMagnitude { p0, normal }
            }
        } else {
            MeshError::SingularInitialPoint { p0, normal }
        }
    }
}
