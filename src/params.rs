//! Mesher parameters: one flat set, defined once, that the library, the invariant file's
//! `[mesh]` table, the command line's flags and the JSON report all read and write.
//!
//! Lengths that depend on the surface (the steps, the geodesic radius, the bounding box) and
//! the initial direction are automatic unless given: [`MeshParams::resolve`] works them out
//! from the surface's size and curvature at `p0` ([`Scales`]), so that the same surface
//! meshes the same way at any scale. Angles are [`Angle`]s, read and written in degrees.

use crate::error::MeshError;
use crate::geom::vec3::dot as dot3;
use crate::model::{least_aligned_tangent, Hole, LocalShape, NormalField};
use crate::scalar::Scalar;

/// An angle. Kept in radians; read and written in degrees wherever a person sees it (files,
/// the command line, reports).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct Angle(f64);

impl Angle {
    /// The angle of `degrees` degrees.
    pub fn from_degrees(degrees: f64) -> Angle {
        Angle(degrees.to_radians())
    }
    /// The angle of `radians` radians.
    pub const fn from_radians(radians: f64) -> Angle {
        Angle(radians)
    }
    /// In degrees.
    pub fn degrees(self) -> f64 {
        self.0.to_degrees()
    }
    /// In radians.
    pub const fn radians(self) -> f64 {
        self.0
    }
}

impl std::ops::Mul<f64> for Angle {
    type Output = Angle;
    fn mul(self, k: f64) -> Angle {
        Angle(self.0 * k)
    }
}

impl std::ops::Div<f64> for Angle {
    type Output = Angle;
    fn div(self, k: f64) -> Angle {
        Angle(self.0 / k)
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Angle {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.degrees())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Angle {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Angle, D::Error> {
        f64::deserialize(d).map(Angle::from_degrees)
    }
}

/// How curves are laid out (DESIGN.md §2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Method {
    /// The proposed method: the Step 2 fan (first points at least Δt apart) and Step 6
    /// insertion of new curves where neighbouring curves diverge.
    #[default]
    Proposed,
    /// The previous method (paper refs \[5\]\[6\]): [`MeshParams::curves`] curves at uniform
    /// angles, no insertion.
    Previous,
}

/// How one step is taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Mode {
    /// Exactly the paper: explicit Euler (eq. 6), first-order AD prediction (eq. 8–9) and the
    /// δ/δ' retry loop of Step 5.
    Paper,
    /// Δt in closed form from the predicted angle `α(Δt)` (aiming at the middle of the band),
    /// and a chord chosen so that Simpson's rule for `∫ v·dp` along it vanishes: on every
    /// integrable field of this model (potential of degree ≤ 3) the level set is kept to
    /// rounding error, i.e. no drift.
    #[default]
    Default,
}

/// Points and directions read as exactly three numbers: serde's arrays take the first three
/// of a longer list and leave the rest unread, so `p0 = [1, 0, 0, 7]` would run silently at
/// `(1, 0, 0)`.
#[cfg(feature = "serde")]
mod three {
    use serde::de::{Deserialize, Deserializer, Error};

    fn three<E: Error>(v: Vec<f64>) -> Result<[f64; 3], E> {
        <[f64; 3]>::try_from(v.as_slice())
            .map_err(|_| E::invalid_length(v.len(), &"an array of length 3 (x, y, z)"))
    }

    pub(super) fn exactly<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
        three(Vec::deserialize(d)?)
    }

    pub(super) fn optional<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 3]>, D::Error> {
        Option::<Vec<f64>>::deserialize(d)?.map(three).transpose()
    }
}

/// All parameters of one meshing run.
///
/// `None` lengths and `w00` are automatic (see [`MeshParams::resolve`]). The defaults mesh
/// any surface of the model, closed or not, at any scale: the proposed method, the default
/// mode, β ∈ [4°, 8°], δ = 1.5, δ' = 0.6, insertion at 1.8 and merging at 0.7 steps.
///
/// ```
/// use liemesh::{Angle, MeshParams};
///
/// let mut params = MeshParams::at([0.0, 0.0, 2.0]);
/// params.beta_max = Angle::from_degrees(6.0);
/// params.max_normal_error = Some(Angle::from_degrees(1.0));
/// assert!(params.dt.is_none(), "Δt follows the surface unless given");
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
#[non_exhaustive]
pub struct MeshParams {
    /// Curve layout.
    pub method: Method,
    /// Number of curves of the previous method (at least 3).
    pub curves: usize,
    /// Step rule.
    pub mode: Mode,
    /// Initial point.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "three::exactly"))]
    pub p0: [f64; 3],
    /// Initial direction (projected onto the tangent plane at `p0`); automatic: the
    /// coordinate axis least aligned with the normal at `p0`.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "three::optional"))]
    pub w00: Option<[f64; 3]>,
    /// Initial step Δt; automatic: a tenth of the step scale, or twice `beta_max` (in radians)
    /// step scales when that is smaller.
    pub dt: Option<f64>,
    /// Smallest step (steps are clamped to `[dt_min, dt_max]`); automatic: 10⁻³ step scales,
    /// or a quarter of `beta_min` (in radians) step scales when that is smaller (but a
    /// five-hundredth of a given `dt_max` when that value is above it); where that would turn
    /// the normal at `p0` by more than a quarter of `beta_min` (a surface far from the
    /// origin, whose `|p0|` is not its size), the same of the radius of curvature at `p0`
    /// instead of the step scale; on an ellipsoid up to 20.5:1
    /// ([`NormalField::semi_axes_through`]) also at most a quarter of `beta_min` times its
    /// sharpest bend's radius, and from out on the flare of a band the field knows (farther
    /// from its axis than the waist's widest radius) likewise of its waist's sharpest bend,
    /// up to 6:1. On a non-integrable field, whose sheet may
    /// run into a singular point of the field, up to 10⁻² step scales but at most 4·10⁻³
    /// extent scales.
    pub dt_min: Option<f64>,
    /// Largest step; automatic: half the step scale, at most a twelfth of `max_radius`, and
    /// on an ellipsoid up to 20.5:1 at most its shortest semi-axis; round a hole the field
    /// knows ([`NormalField::hole_through`]) at least half the waist's narrowest radius, and
    /// each step at most a quarter of the band's radius about the axis where it starts (but
    /// not less than the waist's narrowest radius).
    pub dt_max: Option<f64>,
    /// β_min: smallest normal turn per step.
    #[cfg_attr(feature = "serde", serde(rename = "beta_min_deg"))]
    pub beta_min: Angle,
    /// β_max: largest normal turn per step.
    #[cfg_attr(feature = "serde", serde(rename = "beta_max_deg"))]
    pub beta_max: Angle,
    /// δ > 1: step growth when the normal turns less than β_min.
    pub grow: f64,
    /// δ' in (0, 1): step shrink when it turns more than β_max.
    pub shrink: f64,
    /// Insert a curve when neighbouring curves are more than `gap` × the local step apart, or
    /// their normals more than `gap` × β_max (proposed method); 1 to 100.
    pub gap: f64,
    /// End a curve when it comes closer than `merge` × the local step to a neighbour
    /// (proposed method; below `gap / 2` so that inserting and merging cannot chase each
    /// other).
    pub merge: f64,
    /// Largest arc length from `p0` along a curve; automatic: 4π extent scales (π on a
    /// non-integrable field); round a hole the field knows, the extent is at most `p0`'s
    /// radius about the axis or the band's largest semi-axis, whichever is larger.
    pub max_radius: Option<f64>,
    /// Half-size of the axis-aligned box around the origin that points stay in; automatic: 6
    /// extent scales.
    pub bounding_box: Option<f64>,
    /// End curves that run onto the surface other curves swept, and stitch the fronts where
    /// they meet (closing closed surfaces).
    pub close: bool,
    /// Most sample points (and mesh vertices) in total.
    pub max_points: usize,
    /// Most curves (initial and inserted).
    pub max_curves: usize,
    /// Most accepted steps on one curve.
    pub max_steps: usize,
    /// Most Δt retries within one step (paper mode), or Newton iterations for one chord
    /// (default mode, clamped to 4..=64; a chord that finds no root is retried at half the
    /// length, up to [`CHORD_HALVINGS`](crate::trace::CHORD_HALVINGS) times).
    pub max_retries: usize,
    /// Refinement: split faces whose normal error (the angle between the face and the field
    /// normal at its centroid) exceeds this, after the mesh is built. `None` leaves the mesh
    /// as built. Only faces whose corners lie on one surface can meet a bound below the
    /// field's own tilt across them: in the paper's mode (whose chords drift off the level
    /// set) and on a non-integrable field the refinement stops when it stalls
    /// ([`Refinement::stalled`](crate::triangulate::Refinement::stalled)).
    #[cfg_attr(
        feature = "serde",
        serde(
            rename = "max_normal_error_deg",
            skip_serializing_if = "Option::is_none"
        )
    )]
    pub max_normal_error: Option<Angle>,
}

impl Default for MeshParams {
    fn default() -> Self {
        MeshParams {
            method: Method::Proposed,
            curves: 15,
            mode: Mode::Default,
            p0: [0.0, 0.0, 1.0],
            w00: None,
            dt: None,
            dt_min: None,
            dt_max: None,
            beta_min: Angle::from_degrees(4.0),
            beta_max: Angle::from_degrees(8.0),
            grow: 1.5,
            shrink: 0.6,
            gap: 1.8,
            merge: 0.7,
            max_radius: None,
            bounding_box: None,
            close: true,
            max_points: 2_000_000,
            max_curves: 200_000,
            max_steps: 100_000,
            max_retries: 64,
            max_normal_error: None,
        }
    }
}

/// The two lengths the automatic parameters are measured in, from the surface at `p0`.
///
/// With `ρ` the radius of curvature in the most curved direction at `p0` (`1/|κ|max`):
/// - the **extent** scale `max(|p0|, ρ/4)` sizes the terminal conditions (a surface of the
///   model is centred at the origin, so `|p0|` is about its size; where `p0` is near the
///   origin, the curvature sizes it; a quarter of `ρ`, because the flat side of an elongated
///   quadric curves far less than its size suggests);
/// - the **step** scale `max(ρ, extent / 8)` sizes the steps (the curvature sets them; the
///   floor keeps a sharp tip, such as an elongated ellipsoid's, from shrinking the steps
///   everywhere else).
///
/// On a sphere of radius `r` both are `r`: the mesh is the same at every scale. A field that
/// knows how far its surface reaches ([`NormalField::size_through`]: a quadric's semi-axes,
/// or, for a field of one's own, its farthest centre of curvature at `p0`,
/// [`Scales::centres_reach`]) raises the extent to that ([`Scales::reaching`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Scales {
    /// Sizes the geodesic radius and the bounding box.
    pub extent: f64,
    /// Sizes Δt and its clamps.
    pub step: f64,
}

impl Scales {
    /// The scales of the surface whose local shape at `p0` is `shape`.
    pub fn of(p0: [f64; 3], shape: &LocalShape) -> Scales {
        let rho = shape.radius_of_curvature();
        let r0 = (p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]).sqrt();
        let extent = match (r0 > 0.0, rho.is_finite()) {
            (true, true) => r0.max(rho / 4.0),
            (true, false) => r0,
            (false, true) => rho,
            (false, false) => 1.0,
        };
        let step = if rho.is_finite() {
            rho.max(extent / 8.0)
        } else {
            extent
        };
        Scales { extent, step }
    }

    /// The distance from the origin of the farthest centre of curvature at `p0` (`p0 − n/κ`
    /// for each principal curvature `κ`) among those no farther than 16 extents, if it is
    /// farther than the extent (the default of [`NormalField::size_through`]): a surface
    /// reaches about that far round its centres of curvature. A torus meshed from its inner
    /// equator is near the origin, yet bends round its tube's centre, as far out as the ring
    /// (`R` against `R − a`): with the extent of `p0` alone, the bounding box cut a fat
    /// torus's outer half off. Farther centres (a nearly flat direction) tell nothing.
    pub fn centres_reach(&self, p0: [f64; 3], shape: &LocalShape) -> Option<f64> {
        let n = shape.normal;
        shape
            .curvatures
            .iter()
            .filter(|k| k.is_finite() && **k != 0.0)
            .map(|k| {
                let centre = [0, 1, 2].map(|i| p0[i] - n[i] / k);
                dot3(centre, centre).sqrt()
            })
            .filter(|d| d.is_finite() && *d <= CENTRE_REACH * self.extent)
            .max_by(f64::total_cmp)
            .filter(|&d| d > self.extent)
    }

    /// The scales with the extent raised to `size` when the field knows how far its surface
    /// reaches ([`NormalField::size_through`]); the step scale stays the local one.
    pub fn reaching(self, size: Option<f64>) -> Scales {
        match size {
            Some(s) if s > self.extent => Scales { extent: s, ..self },
            _ => self,
        }
    }
}

/// The parameters of one run with every automatic value worked out: what the stages read.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Resolved {
    /// The parameters as given (not in the serialised form, which lists the worked-out
    /// values beside them).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub given: MeshParams,
    /// The surface's scales at `p0`.
    pub scales: Scales,
    /// Initial direction.
    pub w00: [f64; 3],
    /// Initial step.
    pub dt: f64,
    /// Smallest step.
    pub dt_min: f64,
    /// Largest step.
    pub dt_max: f64,
    /// Largest geodesic radius.
    pub max_radius: f64,
    /// Bounding box half-size.
    pub bounding_box: f64,
    /// Whether each chord is corrected back onto its level set: a field integrable at `p0`
    /// that is not known to be the gradient of a cubic
    /// ([`NormalField::has_cubic_potential`](crate::NormalField::has_cubic_potential)).
    pub level_correction: bool,
    /// Whether that correction weighs the field by an integrating factor: a field integrable
    /// at `p0` that is not a gradient (it has a curl near `p0`), such as unit normals of a
    /// surface. Only a gradient's rise along a chord is the potential's; on `v = g ∇F` it is
    /// weighed by `1/g`, whose change along the surface the field's curl gives
    /// ([`crate::trace`]). Not in the serialised form.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub integrating_factor: bool,
    /// The hole of the band through `p0`, if the field knows it
    /// ([`NormalField::hole_through`]): no triangle of the run meets its axis. Asked of the
    /// field once, here (not in the serialised form).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub hole: Option<Hole>,
}

impl Resolved {
    /// The parameters with every automatic value written out: meshing another field with
    /// them takes the same `w00`, steps and terminal conditions as this run (what a
    /// comparison of two nearby fields, e.g. a central difference, needs).
    pub fn explicit(&self) -> MeshParams {
        MeshParams {
            w00: Some(self.w00),
            dt: Some(self.dt),
            dt_min: Some(self.dt_min),
            dt_max: Some(self.dt_max),
            max_radius: Some(self.max_radius),
            bounding_box: Some(self.bounding_box),
            ..self.given.clone()
        }
    }
}

impl std::ops::Deref for Resolved {
    type Target = MeshParams;
    fn deref(&self) -> &MeshParams {
        &self.given
    }
}

/// The smallest surface meshed ([`MeshError::SurfaceScale`]).
pub(crate) const MIN_SURFACE_SIZE: f64 = 1e-60;
/// The largest surface meshed ([`MeshError::SurfaceScale`]).
pub(crate) const MAX_SURFACE_SIZE: f64 = 1e60;

/// Factors of the automatic lengths: Δt, dt_min, dt_max (of the step scale), max_radius and
/// bounding_box (of the extent scale).
const AUTO_DT: f64 = 0.1;
const AUTO_DT_MIN: f64 = 1e-3;
/// The automatic `dt_min` on a non-integrable field: a tenth of the automatic Δt (this, of
/// the step scale), but not above [`SWEPT_DT_MIN_OF_EXTENT`] extents, and not below the
/// integrable fields' clamp. The sweep's steps shrink in proportion to the distance to the
/// field's singular point, which for an invariant (the origin) lies within an extent of
/// `p0`; with the integrable fields' clamp, a hundredth of Δt, the curves crawled round it:
/// a random 18-number sweep from 0.04 off the origin laid 866,629 samples for 6,073
/// triangles in 35 s (2.5 s with this clamp). The cap by the extent keeps the old clamp where
/// the sheet is flat at `p0` and its step scale several extents long (a twisted linear
/// invariant 1.3 off the origin with a radius of curvature of 19.5 there kept 249
/// triangles; a tenth of Δt left 159).
const AUTO_DT_MIN_SWEPT: f64 = AUTO_DT / 10.0;
/// See [`AUTO_DT_MIN_SWEPT`].
const SWEPT_DT_MIN_OF_EXTENT: f64 = 4e-3;
const AUTO_DT_MAX: f64 = 0.5;
/// The flattest ellipsoid (longest over shortest semi-axis) whose automatic step clamps are
/// fitted to the whole surface (see [`MeshParams::resolve`]): measured, 1:1:0.05 (`λ`
/// 1:1:400) closes from its pole and from generic points (0.5 million triangles, 4–11 s);
/// 1:1:0.04 (`λ` 1:1:625) from its pole ran 54 s into the stitching budget and stayed open,
/// and 1:1:0.032 (`λ` 1:1:1000) 23–44 s. Flatter ones keep the clamps of `p0`: their curves
/// stop at the rim on the step floor, and the run says it was cut short.
const FITTED_FLATNESS: f64 = 20.5;
const AUTO_RADIUS: f64 = 4.0 * std::f64::consts::PI;
/// The automatic geodesic radius on a non-integrable field, of the extent scale: a
/// hemisphere's. No surface has such a normal field; the surface the curves sweep folds onto
/// itself within about this radius, and what lies beyond is laid only to be cut away.
const AUTO_RADIUS_SWEPT: f64 = std::f64::consts::PI;
const AUTO_BOX: f64 = 6.0;
/// The flattest band (widest over narrowest semi-axis of its waist) whose automatic step floor
/// lets curves follow its waist's sharpest bend (see [`MeshParams::resolve`]): elliptic
/// cylinders up to about 6:1 come out whole from their flat side, flatter ones with that
/// floor left holes in minutes of stitching (docs/status.md, forty-first session); they keep
/// the floor of `p0` and end cut short on it.
const BAND_FITTED_FLATNESS: f64 = 6.0;
/// The automatic `dt_max` is at most the geodesic radius over this: a curve crosses the
/// region it meshes in a dozen steps or more. Half the step scale alone can be as long as
/// the region is wide where the surface is flat at `p0`: a Hamiltonian sweep with a radius
/// of curvature of 14 at `p0`, 6.7 from the origin, took steps of 7 across a radius of 21
/// and came out as 168 triangles (739 with this bound).
const STEPS_ACROSS_RADIUS: f64 = 12.0;
/// Centres of curvature up to this many extents (of the shape at `p0`) from the origin raise
/// the extent ([`Scales::centres_reach`]).
const CENTRE_REACH: f64 = 16.0;

/// A curl below this, relative to the Jacobian's size, is a gradient's rounding (in `f64`;
/// in a type of less precision, [`jacobian_rounding`](crate::model::jacobian_rounding)).
const CURL_FREE: f64 = 1e-10;

/// Whether the field has a curl at `p0` or half a step's scale from it along any axis (seven
/// Jacobians): a gradient has none anywhere, while unit normals of a surface `F = 0`, say,
/// may have none at a point of symmetry (an ellipsoid's vertex) but do beside it.
fn has_curl_near<T: Scalar, F: NormalField<T> + ?Sized>(
    field: &F,
    p0: [f64; 3],
    step: f64,
) -> bool {
    let mut probes = vec![p0];
    for k in 0..3 {
        for offset in [0.5 * step, -0.5 * step] {
            let mut x = p0;
            x[k] += offset;
            probes.push(x);
        }
    }
    probes.into_iter().any(|x| {
        let j = crate::model::jacobian(field, &crate::scalar::Vec3::<T>::from_f64(x))
            .map(|row| row.to_f64());
        let curl = [j[2][1] - j[1][2], j[0][2] - j[2][0], j[1][0] - j[0][1]];
        let size = j.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
        let curl = curl.iter().map(|x| x * x).sum::<f64>().sqrt();
        let rounding = CURL_FREE.max(crate::model::jacobian_rounding::<T>());
        curl.is_finite() && size.is_finite() && curl > rounding * size
    })
}

impl MeshParams {
    /// The defaults, from `p0`.
    pub fn at(p0: [f64; 3]) -> MeshParams {
        MeshParams {
            p0,
            ..MeshParams::default()
        }
    }

    /// Works out the automatic values for `field` (see [`Scales`]) and checks every parameter;
    /// the error says which one is wrong and what is allowed.
    pub fn resolve<T: Scalar, F: NormalField<T> + ?Sized>(
        &self,
        field: &F,
    ) -> Result<Resolved, MeshError> {
        self.check()?;
        let Some(shape) = LocalShape::at::<T, F>(field, self.p0) else {
            let v = field
                .normal(&crate::scalar::Vec3::from_f64(self.p0))
                .to_f64();
            return Err(MeshError::no_normal_at(self.p0, v));
        };
        let scales = Scales::of(self.p0, &shape).reaching(field.size_through(self.p0));
        // Beyond these sizes products of squared lengths leave f64's normal range (1e-80
        // and 1e80 were measured to fail in the chart and the validation).
        for size in [scales.extent, scales.step] {
            if !(MIN_SURFACE_SIZE..=MAX_SURFACE_SIZE).contains(&size) {
                return Err(MeshError::SurfaceScale {
                    size,
                    min: MIN_SURFACE_SIZE,
                    max: MAX_SURFACE_SIZE,
                });
            }
        }
        let w00 = match self.w00 {
            Some(w) => w,
            None => least_aligned_tangent(shape.normal),
        };
        // On an ellipsoid the field knows, the clamps also fit the whole surface: no step
        // longer than the ellipsoid is thick (a long step across a flattened ellipsoid's flat
        // face would jump its rim), and steps may shrink to resolve its sharpest bend, the
        // rim's radius `shortest² / longest` (the shape at `p0`, a flat pole, tells neither).
        // Only up to FITTED_FLATNESS: flatter ones, meshed with isotropic triangles small
        // enough for the rim, run for tens of seconds into the stitching budget; they keep
        // the clamps of `p0` and end in an error that names `dt_max`, or cut short.
        // Round a hole the field knows (a band's waist), no step longer than a quarter of the
        // band's radius about its axis where the step starts, and at least the waist's
        // narrowest radius (`trace::GIRTH_STEP`, with `dt_max` automatic): from a nearly flat
        // flange of a 100:1 hyperboloid, steps sized at `p0` went round the waist in a
        // hexagon, while a cap of the waist everywhere made a band started far out, where it
        // is a hundred times wider, three million triangles of the waist's size. (Letting the
        // steps shrink to the waist's bend as well took the curves through a 100:1 waist,
        // where the fronts then met and left the flange a disc with a wedge open, instead of
        // a band round the waist cut short there: docs/status.md.)
        let hole = field.hole_through(self.p0);
        let waist = hole.map(|h| h.waist());
        // p0's radius about the band's axis and the band's widest semi-axis.
        let band = hole.map(|h| (h.radius_about(self.p0), field.size_through(self.p0)));
        // From out on a band's flare (`p0` farther from the axis than the waist's widest
        // radius), steps may likewise shrink to the waist's sharpest bend (`narrowest² /
        // widest`), which the band meshes too and the bend at `p0` does not tell: from 100
        // up a hyperboloid 3.4:1 round its waist, 52 curves ended on a floor sized at `p0`.
        // Only up to BAND_FITTED_FLATNESS, as elliptic cylinders flatter than that, met from
        // their flat side, are not whole with any floor. (Within the waist's own girth the
        // floor of `p0` stays: a thin 3:1 cylinder left a hole with this one.)
        let band_bend = waist.zip(band).and_then(|(narrowest, (across, widest))| {
            let widest = widest?;
            (across > widest && widest <= BAND_FITTED_FLATNESS * narrowest)
                .then(|| narrowest * narrowest / widest)
        });
        let (thickness, sharpest) = field
            .semi_axes_through(self.p0)
            .filter(|[s0, _, s2]| *s2 <= FITTED_FLATNESS * *s0)
            .map(|[s0, _, s2]| (s0, s0 * s0 / s2))
            .unwrap_or((f64::INFINITY, band_bend.unwrap_or(f64::INFINITY)));
        let integrable = shape.is_integrable();
        // A band is meshed round its axis as far as it is wide: the extent is at most p0's
        // radius about the axis (or the band's largest semi-axis, if wider), not `|p0|`,
        // which grows along the axis although the band does not: a unit cylinder from
        // `(1, 0, 100)` was meshed out to a radius of 1,257 in 10⁶ triangles.
        let reach = match band {
            Some((across, widest)) if integrable => {
                scales.extent.min(across.max(widest.unwrap_or(0.0)))
            }
            _ => scales.extent,
        };
        let max_radius = self.max_radius.unwrap_or(
            if integrable {
                AUTO_RADIUS
            } else {
                AUTO_RADIUS_SWEPT
            } * reach,
        );
        // Round a hole, the girth sets the largest step as well as p0 does: at least what
        // a circular cylinder of the waist's radius would have. Near a sharp waist the step
        // scale at p0 follows the bend along the axis, a small fraction of the girth, and
        // steps that short round it left a hole where the fronts met across the bend.
        let girth = waist.map_or(0.0, |w| AUTO_DT_MAX * w);
        let dt_max = self.dt_max.unwrap_or(
            (AUTO_DT_MAX * scales.step)
                .max(girth)
                .min(thickness)
                .min(max_radius / STEPS_ACROSS_RADIUS),
        );
        let dt_min = self.dt_min.unwrap_or_else(|| {
            let quarter_band = 0.25 * self.beta_min.radians();
            let floor = AUTO_DT_MIN.min(quarter_band);
            // The step scale's floor, an eighth of `|p0|`, stands for the size of a surface
            // centred at the origin, which a field of one's own need not be: a unit sphere
            // centred at (10⁶, 0, 0) had a step floor of 125, longer than the sphere, and
            // every curve ended at its first step. Where the floor would turn the normal at
            // `p0` itself by more than a quarter of β_min, `|p0|` is not the surface's size,
            // and the floor is sized by the bend at `p0`, as it is for a surface round the
            // origin whose step scale is its radius of curvature.
            let rho = shape.radius_of_curvature();
            let floor_scale = if floor * scales.step > quarter_band * rho {
                rho
            } else {
                scales.step
            };
            let clamp = (floor * floor_scale).min(quarter_band * sharpest);
            let auto = if integrable {
                clamp
            } else {
                clamp.max(
                    (AUTO_DT_MIN_SWEPT.min(quarter_band) * scales.step)
                        .min(SWEPT_DT_MIN_OF_EXTENT * scales.extent),
                )
            };
            // (Only a surface hundreds of times flatter at `p0` than its extent has the
            // automatic dt_min above that bound.) A dt_max given below it, as the error of a
            // run whose steps were too long advises, takes dt_min down with it, in the
            // proportion of the automatic clamps.
            match self.dt_max {
                None => auto.min(dt_max),
                Some(given) if auto > given => given * (AUTO_DT_MIN / AUTO_DT_MAX),
                Some(_) => auto,
            }
        });
        let resolved = Resolved {
            given: self.clone(),
            scales,
            w00,
            // A β band far narrower than usual asks for steps below the usual clamps: the
            // automatic Δt and dt_min follow it there (a step of length h turns the normal by
            // about h / ρ radians), so that the band can be met and a budget, not the first
            // step, ends the run.
            dt: self
                .dt
                .unwrap_or(AUTO_DT.min(2.0 * self.beta_max.radians()) * scales.step),
            dt_min,
            dt_max,
            max_radius,
            bounding_box: self.bounding_box.unwrap_or(AUTO_BOX * scales.extent),
            level_correction: integrable && !field.has_cubic_potential(),
            integrating_factor: integrable
                && !field.has_cubic_potential()
                && has_curl_near(field, self.p0, scales.step),
            hole,
        };
        resolved.check_lengths()?;
        Ok(resolved)
    }

    /// Checks every parameter that does not depend on the surface: numbers finite, the β band
    /// inside (0°, 90°), lengths and factors in range, budgets non-zero. [`Self::resolve`]
    /// (and so every run) does this first; call it to catch bad input before a field exists.
    ///
    /// ```
    /// use liemesh::MeshParams;
    /// let mut params = MeshParams::default();
    /// params.p0 = [f64::NAN, 0.0, 0.0];
    /// assert!(params.check().unwrap_err().to_string().contains("p0.x"));
    /// ```
    pub fn check(&self) -> Result<(), MeshError> {
        let finite = |name: &'static str, value: f64| {
            if value.is_finite() {
                Ok(())
            } else {
                Err(MeshError::NonFinite { name, value })
            }
        };
        for (i, &x) in self.p0.iter().enumerate() {
            finite(["p0.x", "p0.y", "p0.z"][i], x)?;
        }
        if let Some(w) = self.w00 {
            for (i, &x) in w.iter().enumerate() {
                finite(["w00.x", "w00.y", "w00.z"][i], x)?;
            }
        }
        for (name, v) in [
            ("dt", self.dt),
            ("dt_min", self.dt_min),
            ("dt_max", self.dt_max),
            ("max_radius", self.max_radius),
            ("bounding_box", self.bounding_box),
        ] {
            if let Some(v) = v {
                finite(name, v)?;
            }
        }
        for (name, v) in [
            ("beta_min_deg", self.beta_min.degrees()),
            ("beta_max_deg", self.beta_max.degrees()),
            ("grow", self.grow),
            ("shrink", self.shrink),
            ("gap", self.gap),
            ("merge", self.merge),
        ] {
            finite(name, v)?;
        }
        let (bmin, bmax) = (self.beta_min.radians(), self.beta_max.radians());
        if !(bmin > 0.0 && bmin < bmax && bmax < std::f64::consts::FRAC_PI_2) {
            // Degrees as typed: the round trip through radians leaves `-3` as
            // `-3.0000000000000004`; thirteen significant digits drop that.
            let as_typed = |a: Angle| {
                let d = a.degrees();
                format!("{d:.12e}").parse().unwrap_or(d)
            };
            return Err(MeshError::AngleBand {
                min_deg: as_typed(self.beta_min),
                max_deg: as_typed(self.beta_max),
            });
        }
        if self.grow <= 1.0 {
            return Err(MeshError::GrowthFactor(self.grow));
        }
        if !(self.shrink > 0.0 && self.shrink < 1.0) {
            return Err(MeshError::ShrinkFactor(self.shrink));
        }
        // Below a step, inserted curves start nearer their neighbours than they step and go
        // on inserting: fig3 at `gap` 0.6 (`merge` 0) laid 49,370 curves for 5,186 triangles
        // within 10⁵ points, and ran for minutes into the default budget.
        if !(self.gap >= 1.0 && self.gap <= 100.0) {
            return Err(MeshError::OutOfRange {
                name: "gap",
                value: self.gap,
                why: "the insertion threshold must lie in [1, 100] step lengths (closer curves \
                      go on inserting more)",
            });
        }
        if !(self.merge >= 0.0 && self.merge < self.gap / 2.0) {
            return Err(MeshError::OutOfRange {
                name: "merge",
                value: self.merge,
                why: "the merge threshold must lie in [0, gap/2) step lengths",
            });
        }
        if let Some(e) = self.max_normal_error {
            finite("max_normal_error_deg", e.degrees())?;
            if !(e.radians() > 0.0 && e.radians() < std::f64::consts::FRAC_PI_2) {
                return Err(MeshError::OutOfRange {
                    name: "max_normal_error_deg",
                    value: e.degrees(),
                    why: "the bound on the face-normal error must lie strictly between 0° and 90°",
                });
            }
        }
        for (name, v) in [
            ("max_points", self.max_points),
            ("max_curves", self.max_curves),
            ("max_steps", self.max_steps),
            ("max_retries", self.max_retries),
        ] {
            if v == 0 {
                return Err(MeshError::ZeroBudget(name));
            }
        }
        let fan = match self.method {
            Method::Previous if self.curves < 3 => {
                return Err(MeshError::TooFewCurves(self.curves))
            }
            Method::Previous => self.curves,
            Method::Proposed => 6,
        };
        if self.max_curves < fan {
            return Err(MeshError::OutOfRange {
                name: "max_curves",
                value: self.max_curves as f64,
                why: "the curve budget must allow the initial fan (6 curves for the proposed \
                      method, `curves` for the previous one)",
            });
        }
        Ok(())
    }
}

impl Resolved {
    /// Checks the lengths (given or automatic).
    // `!(x > 0.0)` on purpose: NaN fails the test too.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn check_lengths(&self) -> Result<(), MeshError> {
        let auto = |given: Option<f64>| given.is_none();
        let bad = |name: &'static str, value: f64, why: &'static str| {
            Err(MeshError::StepSize { name, value, why })
        };
        if !(self.dt > 0.0) {
            return bad("dt", self.dt, "Δt must be greater than 0");
        }
        if !(self.dt_min > 0.0) {
            return bad(
                "dt_min",
                self.dt_min,
                "the smallest step must be greater than 0",
            );
        }
        if !(self.dt_max >= self.dt_min) {
            let why = if auto(self.given.dt_max) {
                "the automatic largest step is below the dt_min given; give dt_max too"
            } else {
                "the largest step must not be below dt_min"
            };
            return bad("dt_max", self.dt_max, why);
        }
        if !(self.max_radius > 0.0) {
            return Err(MeshError::OutOfRange {
                name: "max_radius",
                value: self.max_radius,
                why: "the largest geodesic radius must be greater than 0",
            });
        }
        if !(self.bounding_box > 0.0) {
            return Err(MeshError::OutOfRange {
                name: "bounding_box",
                value: self.bounding_box,
                why: "the bounding box half-size must be greater than 0",
            });
        }
        // (The automatic box is six extents, and the extent is at least p0's distance from
        // the origin: only a box given can leave p0 out.)
        if self.given.p0.iter().any(|x| x.abs() > self.bounding_box) {
            return Err(MeshError::OutsideBoundingBox {
                p0: self.given.p0,
                bounding_box: self.bounding_box,
            });
        }
        Ok(())
    }
}
