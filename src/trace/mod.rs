//! Tracing one integral curve: one adaptive step at a time (paper Steps 3–5).
//!
//! A step at `p_i` with incoming direction `w_{i-1}`:
//! 1. `v_i = v(p_i)`, `n_i = v_i/|v_i|`;
//! 2. `w_i = normalize(w_{i-1} − (n_i·w_{i-1}) n_i)` (eq. 7);
//! 3. one forward-mode JVP `J_v(p_i) w_i`, reused for every trial Δt;
//! 4. the predicted normal `v_i + Δt J_v w_i` (eq. 8–9) and its angle α to `v_i` choose Δt;
//! 5. the new point: `p_i + Δt w_i` in [`Mode::Paper`] (eq. 6), or a drift-free chord of
//!    length Δt in [`Mode::Default`]. A default-mode step whose normal, measured at the
//!    chord's end, turned by more than [`OVERSHOOT`] times `β_max` is cut and taken again.

use crate::geom::vec3::wider_than;
use crate::params::{Mode, Resolved};
use crate::scalar::{self, Scalar, Vec3};
use crate::NormalField;

/// Step control converted once to the working scalar type.
#[derive(Clone, Debug)]
pub struct StepConfig<T> {
    mode: Mode,
    beta_min: T,
    beta_max: T,
    tan_target: T,
    grow: T,
    shrink: T,
    dt_min: T,
    dt_max: T,
    max_retries: usize,
    /// `cos(OVERSHOOT · β_max)`; −∞ when that angle is a half turn or more (no step
    /// overshoots it).
    overshoot_cos: f64,
    /// Whether chords are corrected back onto their level set ([`Resolved::level_correction`]).
    level_correction: bool,
    /// Whether that correction weighs the field by an integrating factor
    /// ([`Resolved::integrating_factor`]).
    integrating_factor: bool,
    /// Gauss–Legendre's rule for the rise of a potential along a chord ([`on_level`]).
    rise_rule: [(T, T); 5],
    /// The hole of a band whose steps fit its girth ([`GIRTH_STEP`]): the field's, when
    /// `dt_max` is automatic (a given one is every step's bound).
    girth: Option<crate::model::Hole>,
}

/// Gauss–Legendre's five nodes on `[0, 1]` with their weights, in `T`'s own precision: the
/// rule is exact for polynomials of degree 9, and nodes rounded to `f64` would spoil that in
/// MPFR.
fn gauss_legendre_5<T: Scalar>() -> [(T, T); 5] {
    let n = T::from_f64;
    let half = n(0.5);
    let s = (n(10.0) / n(7.0)).sqrt();
    // Half the distances of the nodes from the middle of [−1, 1]: ⅓√(5 ∓ 2√(10/7)) / 2.
    let inner = (n(5.0) - n(2.0) * s.clone()).sqrt() / n(6.0);
    let outer = (n(5.0) + n(2.0) * s).sqrt() / n(6.0);
    let r70 = n(70.0).sqrt();
    let w_inner = (n(322.0) + n(13.0) * r70.clone()) / n(1800.0);
    let w_outer = (n(322.0) - n(13.0) * r70) / n(1800.0);
    [
        (half.clone() - outer.clone(), w_outer.clone()),
        (half.clone() - inner.clone(), w_inner.clone()),
        (half.clone(), n(64.0) / n(225.0)),
        (half.clone() + inner, w_inner),
        (half + outer, w_outer),
    ]
}

impl<T: Scalar> StepConfig<T> {
    /// Reads the step parameters (assumed validated).
    pub fn new(params: &Resolved) -> Self {
        StepConfig {
            mode: params.mode,
            beta_min: T::from_f64(params.beta_min.radians()),
            beta_max: T::from_f64(params.beta_max.radians()),
            tan_target: T::from_f64(0.5 * (params.beta_min.radians() + params.beta_max.radians()))
                .tan(),
            grow: T::from_f64(params.grow),
            shrink: T::from_f64(params.shrink),
            dt_min: T::from_f64(params.dt_min),
            dt_max: T::from_f64(params.dt_max),
            max_retries: params.max_retries,
            // Only the default mode's chords read it.
            level_correction: params.level_correction,
            integrating_factor: params.integrating_factor,
            rise_rule: gauss_legendre_5(),
            girth: params.hole.filter(|_| params.given.dt_max.is_none()),
            overshoot_cos: {
                let angle = OVERSHOOT * params.beta_max.radians();
                if angle < std::f64::consts::PI {
                    angle.cos()
                } else {
                    f64::NEG_INFINITY
                }
            },
        }
    }

    /// The longest step from `p`: `dt_max`, and round a band's hole no longer than
    /// [`GIRTH_STEP`] times the band's radius about its axis at `p` (at least the waist's
    /// narrowest radius), so that no step jumps across the waist, while far out on a flaring
    /// band steps may grow with it.
    fn dt_max_at(&self, p: &Vec3<T>) -> T {
        let Some(hole) = self.girth else {
            return self.dt_max.clone();
        };
        let girth = GIRTH_STEP * hole.radius_about(p.to_f64());
        let cap = T::from_f64(girth.max(hole.waist()));
        scalar::min(cap, self.dt_max.clone())
    }

    /// The step mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Whether the level correction weighs the field by an integrating factor
    /// ([`Resolved::integrating_factor`]).
    pub(crate) fn integrating_factor(&self) -> bool {
        self.integrating_factor
    }
}

/// Why a step could not be taken: the curve ends there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepStop {
    /// `v(p)` is zero or not finite: a singular point.
    SingularNormal,
    /// The carried direction is parallel to the normal, so it has no tangent part.
    NoTangent,
    /// The new point is not finite.
    NonFinite,
    /// Default mode: the drift-free chord's Newton solve found no root within its budget,
    /// at the step's length nor at up to [`CHORD_HALVINGS`] halvings of it above `dt_min`
    /// (the field turns too fast there for a chord to balance it, as on fields far from
    /// integrable).
    NoChord,
}

/// Round a band's hole, no automatic step is longer than this fraction of the band's radius
/// about its axis where it starts (nor shorter than the waist's narrowest radius): a band is
/// then gone round in two dozen steps at least. Far out on an elliptic hyperboloid (3:1),
/// steps of the whole radius crossed its flat side in a few and left a hole where the
/// fronts met (three of the class test's far bands at 256 cases); half the radius still one.
pub const GIRTH_STEP: f64 = 0.25;

/// How many times a default-mode step halves its length when the chord's Newton solve finds
/// no root, before the curve ends with [`StepStop::NoChord`].
pub const CHORD_HALVINGS: u32 = 3;

/// A default-mode step whose normal turned by more than this many times `β_max` (measured at
/// the chord's end, not predicted) is cut to a fraction of its length and taken again, up to
/// [`OVERSHOOT_CUTS`] times and not below `dt_min`: the closed-form length trusts the
/// first-order prediction, which misses a turn that the field makes within the step (a fold
/// or a near-singular point on a swept surface). Such steps crossed a 90° turn in one step
/// on Hamiltonian fields far from the origin, and the chart's triangles between them folded.
pub const OVERSHOOT: f64 = 2.0;
/// How many times a default-mode step that overshot ([`OVERSHOOT`]) is cut.
pub const OVERSHOOT_CUTS: u32 = 8;

/// A Newton correction within this many tolerances that is more than half the one before it
/// marks the rounding floor of the chord equation: `G` is evaluated with rounding noise, and
/// the corrections then jump between a few values just above the tolerance.
const STALL_TOLERANCES: f64 = 64.0;

/// Which limit, if any, an accepted step ran into.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StepLimit {
    /// α landed inside `[β_min, β_max]`.
    #[default]
    None,
    /// Δt hit `dt_min` or `dt_max`, so α may lie outside the band.
    Clamped,
    /// Paper mode: the retry budget ran out. Default mode: the chord's Newton solve found
    /// no root at the Δt chosen, and the step was halved until it did.
    Budget,
}

/// An accepted step.
#[derive(Clone, Debug)]
pub struct Step<T> {
    /// The new point `p_{i+1}`.
    pub point: Vec3<T>,
    /// The direction handed to the next step (projected there by eq. 7).
    pub carry: Vec3<T>,
    /// The tangent `w_i` used at `p_i`.
    pub tangent: Vec3<T>,
    /// The unit normal `n_i` at `p_i`.
    pub normal: Vec3<T>,
    /// The Δt used: the step length.
    pub dt: T,
    /// The predicted normal-turn angle α of the accepted Δt, radians.
    pub alpha_predicted: f64,
    /// The first-order prediction of the unit normal at the new point, `v_i + Δt J_v w_i`
    /// normalised, in `f64` (what the sampler's fence tests the other curves against).
    pub next_normal: [f64; 3],
    /// How many Δt retries (paper) or Newton iterations (default, over every length tried)
    /// the step took.
    pub iterations: u32,
    /// A limit the step ran into.
    pub limit: StepLimit,
}

/// The unit normal at `p`, or [`StepStop::SingularNormal`].
#[inline]
pub fn unit_normal<T: Scalar, F: NormalField<T>>(
    field: &F,
    p: &Vec3<T>,
) -> Result<(Vec3<T>, Vec3<T>, T), StepStop> {
    let v = field.normal(p);
    match v.normalize() {
        Some((n, len)) => Ok((v, n, len)),
        None => Err(StepStop::SingularNormal),
    }
}

/// `normalize(v + Δt J_v w)` in `f64` (the zero vector if that vanishes or is not finite).
fn predicted_normal<T: Scalar>(v: &Vec3<T>, jw: &Vec3<T>, dt: &T) -> [f64; 3] {
    let (v, jw, dt) = (v.to_f64(), jw.to_f64(), dt.to_f64());
    let u = [0, 1, 2].map(|k| v[k] + dt * jw[k]);
    let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        u.map(|x| x / len)
    } else {
        [0.0; 3]
    }
}

/// `normalize(w − (n·w) n)`: eq. 7, the tangent part of `w`.
#[inline]
pub fn project_tangent<T: Scalar>(w: &Vec3<T>, n: &Vec3<T>) -> Option<Vec3<T>> {
    let k = -n.dot(w);
    let t = w.add_scaled(&k, n);
    // A tangent part below a few ulps of |w| is noise: the direction was along the normal.
    let tiny = T::from_f64(64.0 * T::unit_roundoff());
    let (u, len) = t.normalize()?;
    if len <= tiny * w.norm() {
        None
    } else {
        Some(u)
    }
}

/// Takes one adaptive step from `p` (paper Steps 3–5), starting from the step size `dt`.
pub fn step<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    p: &Vec3<T>,
    w_prev: &Vec3<T>,
    dt: &T,
) -> Result<Step<T>, StepStop> {
    let (v, n, vlen) = unit_normal(field, p)?;
    let w = project_tangent(w_prev, &n).ok_or(StepStop::NoTangent)?;
    // One JVP per step, reused by every trial Δt below.
    let (_, jw) = field.normal_and_jvp(p, &w);
    if !jw.is_finite() {
        return Err(StepStop::NonFinite);
    }
    let angle = |dt: &T| v.angle_to(&v.add_scaled(dt, &jw));
    let dt_max = cfg.dt_max_at(p);

    match cfg.mode {
        Mode::Paper => {
            let mut dt = if cfg.girth.is_some() {
                scalar::min(dt.clone(), dt_max.clone())
            } else {
                dt.clone()
            };
            let mut limit = StepLimit::Budget;
            let mut iterations = 0;
            let mut alpha = angle(&dt);
            for _ in 0..=cfg.max_retries {
                if alpha < cfg.beta_min {
                    if dt >= dt_max {
                        limit = StepLimit::Clamped;
                        break;
                    }
                    dt = scalar::min(dt * cfg.grow.clone(), dt_max.clone());
                } else if alpha > cfg.beta_max {
                    if dt <= cfg.dt_min {
                        limit = StepLimit::Clamped;
                        break;
                    }
                    dt = scalar::max(dt * cfg.shrink.clone(), cfg.dt_min.clone());
                } else {
                    limit = StepLimit::None;
                    break;
                }
                iterations += 1;
                alpha = angle(&dt);
            }
            let point = p.add_scaled(&dt, &w);
            if !point.is_finite() {
                return Err(StepStop::NonFinite);
            }
            Ok(Step {
                point,
                next_normal: predicted_normal(&v, &jw, &dt),
                carry: w.clone(),
                tangent: w,
                normal: n,
                alpha_predicted: alpha.to_f64(),
                dt,
                iterations,
                limit,
            })
        }
        Mode::Default => {
            // Closed form for α(Δt) = α*: with J w = a n + b e (e ⊥ n, b ≥ 0),
            // tan α = Δt b / (|v| + Δt a), so Δt = |v| tan α* / (b − a tan α*).
            let a = jw.dot(&n);
            let b = jw.add_scaled(&(-a.clone()), &n).norm();
            let denom = b - a * cfg.tan_target.clone();
            let mut limit = StepLimit::None;
            let mut dt = if denom > T::zero() {
                vlen.clone() * cfg.tan_target.clone() / denom
            } else {
                dt_max.clone()
            };
            // Nor longer than the step that would turn the normal by α* across the curve: in
            // a flat direction (a cylinder's axis, a cone's generator) the curve's own turn
            // allows long steps, but the surface still curves sideways, and the triangles
            // between neighbouring curves should not be long slivers across that curvature.
            let across = n.cross(&w);
            let (_, jl) = field.normal_and_jvp(p, &across);
            let bl = jl.add_scaled(&(-jl.dot(&n)), &n).norm();
            let dt_across = vlen.clone() * cfg.tan_target.clone() / bl;
            if dt_across.is_finite() && dt_across < dt {
                dt = dt_across;
            }
            if !(dt.is_finite()) || dt > dt_max {
                dt = dt_max.clone();
                limit = StepLimit::Clamped;
            } else if dt < cfg.dt_min {
                dt = cfg.dt_min.clone();
                limit = StepLimit::Clamped;
            }
            let kappa = w.dot(&jw) / vlen.clone();
            let start = ChordStart {
                p,
                v0: &v,
                n: &n,
                w: &w,
            };
            let mut chord = drift_free_chord(field, cfg, &start, &dt, &kappa)?;
            let mut iterations = chord.iterations;
            let v_start = v.to_f64();
            let (mut halvings, mut cuts) = (0, 0);
            loop {
                if !chord.converged {
                    // No root near the osculating circle's chord: the field turns too fast
                    // over Δt. A shorter chord turns less; the step is marked as limited by
                    // the budget.
                    let half = dt.clone() * T::from_f64(0.5);
                    if halvings == CHORD_HALVINGS || half < cfg.dt_min {
                        return Err(StepStop::NoChord);
                    }
                    halvings += 1;
                    dt = half;
                    limit = StepLimit::Budget;
                } else {
                    // The turn the step made, against the band (see `OVERSHOOT`): a cosine
                    // comparison first, the angle only for a step that overshot.
                    if cuts == OVERSHOOT_CUTS
                        || !wider_than(v_start, chord.end_field, cfg.overshoot_cos)
                    {
                        break;
                    }
                    let turned =
                        Vec3::<f64>::from_f64(v_start).angle_to(&Vec3::from_f64(chord.end_field));
                    let overshoot = OVERSHOOT * cfg.beta_max.to_f64();
                    let cut = dt.clone() * T::from_f64((overshoot / turned).clamp(0.1, 0.5));
                    if cut < cfg.dt_min {
                        break;
                    }
                    cuts += 1;
                    dt = cut;
                }
                chord = drift_free_chord(field, cfg, &start, &dt, &kappa)?;
                iterations += chord.iterations;
            }
            // α only reports on the closed-form Δt here, so `f64` is enough (and it is the
            // same number for `f64` and `Dual<f64>`); MPFR is spared an arc tangent.
            let alpha = {
                let (v, jw) = (Vec3::from_f64(v_start), Vec3::from_f64(jw.to_f64()));
                v.angle_to(&v.add_scaled(&dt.to_f64(), &jw))
            };
            if limit == StepLimit::None
                && (alpha < cfg.beta_min.to_f64() || alpha > cfg.beta_max.to_f64())
            {
                limit = StepLimit::Clamped;
            }
            // The end tangent of a circular arc is the start tangent reflected in the chord.
            let cw = chord.direction.dot(&w);
            let carry = chord
                .direction
                .scale(&(cw.clone() + cw))
                .add_scaled(&-T::one(), &w);
            let point = if cfg.level_correction {
                on_level(field, cfg, p, &chord, &dt)
            } else {
                chord.point
            };
            Ok(Step {
                point,
                next_normal: predicted_normal(&v, &jw, &dt),
                carry,
                tangent: w,
                normal: n,
                alpha_predicted: alpha,
                dt,
                iterations,
                limit,
            })
        }
    }
}

/// A step of fixed length from `p` along the tangent part of `dir`, with the same rule as
/// the mode's steps (used to place the first point of an inserted curve on the surface).
///
/// In the default mode, a chord whose Newton solve finds no root is
/// [`StepStop::NoChord`]: the length is not the caller's to change.
pub fn step_fixed<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    p: &Vec3<T>,
    dir: &Vec3<T>,
    length: &T,
) -> Result<Vec3<T>, StepStop> {
    let (v, n, vlen) = unit_normal(field, p)?;
    let w = project_tangent(dir, &n).ok_or(StepStop::NoTangent)?;
    match cfg.mode {
        Mode::Paper => {
            let q = p.add_scaled(length, &w);
            if q.is_finite() {
                Ok(q)
            } else {
                Err(StepStop::NonFinite)
            }
        }
        Mode::Default => {
            let (_, jw) = field.normal_and_jvp(p, &w);
            let kappa = w.dot(&jw) / vlen;
            let start = ChordStart {
                p,
                v0: &v,
                n: &n,
                w: &w,
            };
            let chord = drift_free_chord(field, cfg, &start, length, &kappa)?;
            if chord.converged && cfg.level_correction {
                Ok(on_level(field, cfg, p, &chord, length))
            } else if chord.converged {
                Ok(chord.point)
            } else {
                Err(StepStop::NoChord)
            }
        }
    }
}

/// How far the straight chord from `p` to `q` ends off the level set through `p`, as
/// estimated for a field with a potential (`v = ∇F`).
///
/// A drift-free chord makes Simpson's rule for `∫ v·dp` along it vanish; Boole's rule on the
/// same segment is two orders higher, so their difference estimates what Simpson's rule
/// missed, the potential `F(q) − F(p)`, which divided by `|v(q)|` is a distance. Both rules
/// are exact where the potential is a cubic (every integrable field of the model): then the
/// estimate is rounding. Four field values, in `f64`.
///
/// With `weighted` ([`StepConfig::integrating_factor`]) the field is weighed by its
/// integrating factor along the segment first ([`Weighed`]).
pub(crate) fn chord_drift<T: Scalar, F: NormalField<T>>(
    field: &F,
    p: &Vec3<T>,
    q: &Vec3<T>,
    weighted: bool,
) -> f64 {
    if weighted {
        let d = q - p;
        let w = Weighed::along(field, p, &d);
        let speed = w.values[4].norm_squared().sqrt().to_f64() * w.factors[4].to_f64();
        return ((w.boole() - w.simpson()).to_f64() / speed).abs();
    }
    let (a, b) = (p.to_f64(), q.to_f64());
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let along = |t: f64| -> f64 {
        let x = Vec3::<T>::from_f64([a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]]);
        let v = field.normal(&x).to_f64();
        v[0] * d[0] + v[1] * d[1] + v[2] * d[2]
    };
    let [f0, f1, f2, f3] = [0.0, 0.25, 0.5, 0.75].map(along);
    let end = field.normal(q).to_f64();
    let f4 = end[0] * d[0] + end[1] * d[1] + end[2] * d[2];
    let simpson = (f0 + 4.0 * f2 + f4) / 6.0;
    let boole = (7.0 * (f0 + f4) + 32.0 * (f1 + f3) + 12.0 * f2) / 90.0;
    let speed = (end[0] * end[0] + end[1] * end[1] + end[2] * end[2]).sqrt();
    ((boole - simpson) / speed).abs()
}

/// Newton steps at most that [`on_level`] takes onto the level set.
const LEVEL_NEWTON_STEPS: usize = 6;

/// The end of `chord` (of `length`, from `p`) moved back onto the level set through `p`, on
/// a field `v = ∇F` whose potential is not a cubic.
///
/// The chord makes Simpson's rule for `F(q) − F(p) = ∫ v·dp` vanish, which is exact only for
/// potentials of degree four or less. Gauss–Legendre's five-point rule on the same segment
/// gives what the chord left of the rise to the eleventh order in the length (exact to degree
/// ten), and the end moves against it along `v(q)`: `q − (ΔF / |v(q)|²) v(q)`, again from
/// there while the move is long enough for its second-order term to count. (Simpson's rule
/// alone left a superellipsoid's curves 7.3e-4 of its size off; Boole's rule left tori 10⁻⁹
/// off, this one at rounding.)
///
/// On a field that is not a gradient but has one as a multiple, `v = g ∇F` (unit normals),
/// `∫ v·dp` is not the rise of any potential; with `cfg`'s integrating factor on, the rise is
/// that of `∫ v·dp / g` ([`Weighed`]) and the end moves by it over `|v(q)|² / g(q)`. That
/// rise is taken along the two halves of a path through the chord's middle moved onto the
/// surface: a step of 0.1 on a unit-normal ellipsoid ends 1.8·10⁻⁶ off it, against 1.5·10⁻⁵
/// along the chord itself (whose middle lies where the factor's change across the surface,
/// which `Weighed` does not know, counts).
fn on_level<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    p: &Vec3<T>,
    chord: &Chord<T>,
    length: &T,
) -> Vec3<T> {
    if cfg.integrating_factor {
        let d = chord.direction.scale(length);
        // (The field and its curl at `p` serve the whole chord and its first half.)
        let start = with_curl(field, p);
        let whole = Weighed::along_from(field, p, start.clone(), &d);
        // The factor's change across the surface is not in `Weighed`, and the chord's middle
        // lies off the surface by about κL²/8: the rise is taken along two halves through that
        // middle moved back onto the surface, each four times nearer to it.
        let middle = p.add_scaled(&T::from_f64(0.5), &d);
        let (v2, mu2) = (&whole.values[2], whole.factors[2].clone());
        let to_middle = whole.first_half();
        let middle = middle.add_scaled(&(-(to_middle / (v2.norm_squared() * mu2))), v2);
        let first = Weighed::along_from(field, p, start, &(&middle - p));
        let second = Weighed::along(field, &middle, &(&chord.point - &middle));
        let mu_middle = first.factors[4].clone();
        let rise = first.boole() + mu_middle.clone() * second.boole();
        let end = &second.values[4];
        let mu_end = mu_middle * second.factors[4].clone();
        let moved = chord
            .point
            .add_scaled(&(-(rise / (end.norm_squared() * mu_end))), end);
        return if moved.is_finite() {
            moved
        } else {
            chord.point.clone()
        };
    }
    // F(b) − F(a) along the segment from a to b.
    let rise_along = |a: &Vec3<T>, b: &Vec3<T>| {
        let d = b - a;
        cfg.rise_rule.iter().fold(T::zero(), |sum, (t, w)| {
            sum + w.clone() * field.normal(&a.add_scaled(t, &d)).dot(&d)
        })
    };
    // A move along v by ΔF/|v|² is a Newton step on F: it leaves F's second-order term in
    // the move, below rounding once the move is within √u of the step's length; a longer
    // one (a long step, or MPFR) is followed by another from where it ended.
    let settled = T::from_f64(T::unit_roundoff().sqrt()) * length.clone();
    let mut point = chord.point.clone();
    let mut rise = rise_along(p, &point);
    for _ in 0..LEVEL_NEWTON_STEPS {
        let end = field.normal(&point);
        let moved = point.add_scaled(&(-(rise.clone() / end.norm_squared())), &end);
        if !moved.is_finite() {
            break;
        }
        if (&moved - &point).norm() <= settled {
            return moved;
        }
        rise += rise_along(&point, &moved);
        point = moved;
    }
    point
}

/// The field along the segment `p + t d`, `t = 0, ¼, ½, ¾, 1`, with an integrating factor
/// `μ = 1/g` for a field `v = g ∇F` that is not a gradient, so that `μ v` is one and
/// `∫ μ v·dp` the rise of its potential (Boole's and Simpson's rules on `μ v·d`).
///
/// The factor's change along the surface is the field's own: `curl(μ v) = 0` gives
/// `∇ln μ × v = −curl v`, whose solution across `v` is `a = (curl v × v) / |v|²` (along `v`
/// it is free: another factor relabels the level sets). `ln μ` is `a·d` integrated from `p`
/// on the quadratic through its values at `t = 0, ½, 1` (three Jacobians, from which the
/// curl comes), and `μ(p) = 1`.
struct Weighed<T> {
    /// `v` at the five points.
    values: [Vec3<T>; 5],
    /// `μ` at the five points.
    factors: [T; 5],
    /// `μ v·d` at the five points.
    rates: [T; 5],
}

/// `v` and its curl at `x`, from the Jacobian (rows ∇vx, ∇vy, ∇vz).
fn with_curl<T: Scalar, F: NormalField<T>>(field: &F, x: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
    let (v, j) = crate::model::value_and_jacobian(field, x);
    let curl = Vec3::new(
        j[2].y.clone() - j[1].z.clone(),
        j[0].z.clone() - j[2].x.clone(),
        j[1].x.clone() - j[0].y.clone(),
    );
    (v, curl)
}

impl<T: Scalar> Weighed<T> {
    fn along<F: NormalField<T>>(field: &F, p: &Vec3<T>, d: &Vec3<T>) -> Self {
        Self::along_from(field, p, with_curl(field, p), d)
    }

    /// [`Weighed::along`] with `v` and its curl at `p` known ([`with_curl`]).
    fn along_from<F: NormalField<T>>(
        field: &F,
        p: &Vec3<T>,
        (v0, curl0): (Vec3<T>, Vec3<T>),
        d: &Vec3<T>,
    ) -> Self {
        let at = |t: f64| p.add_scaled(&T::from_f64(t), d);
        // a·d at a point.
        let rate = |v: &Vec3<T>, curl: &Vec3<T>| curl.cross(v).dot(d) / v.norm_squared();
        let with_rate = |x: &Vec3<T>| {
            let (v, curl) = with_curl(field, x);
            let a = rate(&v, &curl);
            (v, a)
        };
        let a0 = rate(&v0, &curl0);
        let (v2, a2) = with_rate(&at(0.5));
        let (v4, a4) = with_rate(&at(1.0));
        let (v1, v3) = (field.normal(&at(0.25)), field.normal(&at(0.75)));
        // ∫₀ᵗ of the quadratic through (0, a0), (½, a2), (1, a4).
        let b = T::from_f64(4.0) * a2.clone() - T::from_f64(3.0) * a0.clone() - a4.clone();
        let c = T::from_f64(2.0) * (a0.clone() + a4 - T::from_f64(2.0) * a2);
        let log_factor = |t: f64| {
            let t = T::from_f64(t);
            let t2 = t.clone() * t.clone();
            a0.clone() * t.clone()
                + b.clone() * t2.clone() / T::from_f64(2.0)
                + c.clone() * t2 * t / T::from_f64(3.0)
        };
        let factors = [0.0, 0.25, 0.5, 0.75, 1.0].map(|t| log_factor(t).exp());
        let values = [v0, v1, v2, v3, v4];
        let rates = [0, 1, 2, 3, 4].map(|k| factors[k].clone() * values[k].dot(d));
        Weighed {
            values,
            factors,
            rates,
        }
    }

    /// Boole's rule for `∫ μ v·dp`.
    fn boole(&self) -> T {
        let f = &self.rates;
        (T::from_f64(7.0) * (f[0].clone() + f[4].clone())
            + T::from_f64(32.0) * (f[1].clone() + f[3].clone())
            + T::from_f64(12.0) * f[2].clone())
            / T::from_f64(90.0)
    }

    /// Simpson's rule for `∫ μ v·dp` over the segment's first half.
    fn first_half(&self) -> T {
        let f = &self.rates;
        (f[0].clone() + T::from_f64(4.0) * f[1].clone() + f[2].clone()) / T::from_f64(12.0)
    }

    /// Simpson's rule for `∫ μ v·dp`.
    fn simpson(&self) -> T {
        let f = &self.rates;
        (f[0].clone() + T::from_f64(4.0) * f[2].clone() + f[4].clone()) / T::from_f64(6.0)
    }
}

struct Chord<T> {
    point: Vec3<T>,
    direction: Vec3<T>,
    /// The field at the chord's end as of Newton's last iteration (in `f64`).
    end_field: [f64; 3],
    iterations: u32,
    /// Whether Newton's method found the root (else the point is wherever it stopped).
    converged: bool,
}

/// Where a chord starts: at `p`, with the field `v0` and its unit normal `n` there, along the
/// unit tangent `w`.
struct ChordStart<'a, T> {
    p: &'a Vec3<T>,
    v0: &'a Vec3<T>,
    n: &'a Vec3<T>,
    w: &'a Vec3<T>,
}

/// The chord `p + L c`, `c = cos φ w + sin φ n`, with `φ` solving
/// `G(φ) = (v(p) + 4 v(p + L c/2) + v(p + L c)) · c = 0` by Newton's method.
///
/// `G = 0` says Simpson's rule for `∫ v·dp` along the chord vanishes. When `v = ∇F` with `F`
/// a polynomial of degree ≤ 3 (every integrable field of this model), Simpson's rule is
/// exact, so `F(p + L c) = F(p)`: the step stays on the level set. `G'(φ)` comes from two
/// JVPs through dual numbers.
///
/// When `T` is more precise than `f64` and the field offers [`NormalField::in_f64`], `φ` is
/// first solved in `f64` and then refined in `T`; otherwise Newton starts from the chord of
/// the osculating circle.
fn drift_free_chord<T: Scalar, F: NormalField<T>>(
    field: &F,
    cfg: &StepConfig<T>,
    start: &ChordStart<T>,
    length: &T,
    kappa: &T,
) -> Result<Chord<T>, StepStop> {
    let &ChordStart { p, v0, n, w } = start;
    let newton_budget = cfg.max_retries.clamp(4, 64);
    let seed = if T::unit_roundoff() < f64::unit_roundoff() {
        field.in_f64().and_then(|f64_field| {
            let [p, v0, n, w] = [p, v0, n, w].map(|x| Vec3::from_f64(x.to_f64()));
            let (length, kappa) = (length.to_f64(), kappa.to_f64());
            let start = ChordStart {
                p: &p,
                v0: &v0,
                n: &n,
                w: &w,
            };
            let guess = -(kappa * (0.5 * length));
            // Only a solve that converged the way Newton does near its root (every correction
            // smaller than the one before, in a few iterations) seeds `T`: started from the
            // same guess, the solve in `T` would then follow it to the same root. A solve
            // that wanders first may end at another root of G than the full-precision one
            // would, so `T` then starts from the guess itself, as without a seed.
            match chord_angle(
                &f64_field,
                &start,
                &length,
                guess,
                newton_budget,
                Solve::Seed,
                None,
            ) {
                Ok(root) if root.converged && root.settled && root.iterations <= 8 => {
                    Some((T::from_f64(root.phi), root.derivative.map(T::from_f64)))
                }
                _ => None,
            }
        })
    } else {
        None
    };
    let solve = if seed.is_some() {
        Solve::Refine
    } else {
        Solve::Full
    };
    // Initial guess without a seed: the chord of the osculating circle, φ ≈ −κL/2.
    let (guess, derivative) =
        seed.unwrap_or_else(|| (-(kappa.clone() * (length.clone() * T::from_f64(0.5))), None));
    let root = chord_angle(
        field,
        start,
        length,
        guess,
        newton_budget,
        solve,
        derivative,
    )?;
    let mut direction = w.scale(&root.cos);
    direction.add_scaled_assign(&root.sin, n);
    let point = p.add_scaled(length, &direction);
    if !point.is_finite() {
        return Err(StepStop::NonFinite);
    }
    Ok(Chord {
        point,
        direction,
        end_field: root.end_field,
        iterations: root.iterations,
        converged: root.converged,
    })
}

/// How [`chord_angle`] runs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Solve {
    /// From the osculating circle's guess to the tolerance, every iteration in `T`.
    Full,
    /// As `Full`, in `f64`, for a seed: also keeps the last derivative `G'`.
    Seed,
    /// Refining a seed good to `f64` (predicted stops, a value-only last step, rotated
    /// sine and cosine).
    Refine,
}

/// The chord angle found by [`chord_angle`], with its sine and cosine.
struct ChordAngle<T> {
    phi: T,
    sin: T,
    cos: T,
    /// The field at the chord's end for the last iteration's `φ`, in `f64`.
    end_field: [f64; 3],
    iterations: u32,
    converged: bool,
    /// Every correction after the first was smaller than the one before it (what a seed
    /// needs, see [`drift_free_chord`]).
    settled: bool,
    /// [`Solve::Seed`] only: `G'` from the last iteration, for the refinement's first step.
    derivative: Option<T>,
}

/// Newton's method for the chord angle from `phi`.
///
/// It stops when a correction falls below 16 units of roundoff of `φ`, or below
/// [`STALL_TOLERANCES`] times that without having halved the one before (the rounding floor).
///
/// When refining ([`Solve::Refine`]) a guess already good to `f64`, Newton converges
/// quadratically from the first iteration, `δₖ ≈ C δₖ₋₁²`, and three savings follow from
/// estimating `C` on the last two corrections:
/// - it stops once the next correction, `C δₖ²`, would fall below a quarter of the
///   tolerance (this saves the iteration that only confirms);
/// - when instead one more correction with the derivative kept from this iteration would
///   end within a quarter of the tolerance (its error is about `2C δₖ` times that
///   correction), it takes that last step with field values only, no Jacobian-vector
///   products, and stops if the correction it measures bears that out;
/// - it rotates the sine and cosine by each correction `δ` instead of evaluating them at
///   the new `φ` (equal to rounding; the series for a tiny `δ` is short at 256 bits).
fn chord_angle<T: Scalar, F: NormalField<T>>(
    field: &F,
    start: &ChordStart<T>,
    length: &T,
    mut phi: T,
    budget: usize,
    solve: Solve,
    seed_derivative: Option<T>,
) -> Result<ChordAngle<T>, StepStop> {
    let &ChordStart { p, v0, n, w } = start;
    let refining = solve == Solve::Refine;
    let four = T::from_f64(4.0);
    let half_len = length.clone() * T::from_f64(0.5);
    let tol = T::from_f64(16.0 * T::unit_roundoff());
    let (mut s, mut c) = phi.sin_cos();
    // d/dφ: the points move by (L/2) c⊥ and L c⊥.
    let middle_weight = four.clone() * half_len.clone();
    // The last correction's size. Refine only: the derivative to keep, with the error factor
    // `2C δ` it carries, when the next step is the last, value-only one.
    let mut previous = f64::INFINITY;
    // A seed's own `G'` (good to `f64`) serves the first step, value-only: from a seed good
    // to `f64` that step gains as many digits as a Newton step would (its error is the
    // seed's times the derivative's relative error), and saves two JVPs. It never ends the
    // solve (no previous correction to judge it by).
    let mut keep: Option<(T, f64)> = seed_derivative.map(|d| (d, f64::INFINITY));
    let mut derivative = None;
    let mut end_field = [f64::NAN; 3];
    let (mut iterations, mut converged, mut settled) = (0, false, true);
    while !converged && (iterations as usize) < budget {
        iterations += 1;
        // The vector updates below work in place (for MPFR: fewer fresh numbers); each
        // rounds exactly as the expression in its comment.
        let mut dir = w.scale(&c); // c w + s n
        dir.add_scaled_assign(&s, n);
        let pm = p.add_scaled(&half_len, &dir);
        let p1 = p.add_scaled(length, &dir);
        let kept = keep.take();
        let (sum, dg) = match &kept {
            Some((dg, _)) => {
                let mut sum = field.normal(&pm).scale(&four); // (v0 + 4 vm) + v1
                sum += v0;
                let v1 = field.normal(&p1);
                end_field = v1.to_f64();
                sum += &v1;
                (sum, dg.clone())
            }
            None => {
                let mut perp = n.scale(&c); // c n − s w
                perp.sub_scaled_assign(&s, w);
                let (vm, jm) = field.normal_and_jvp(&pm, &perp);
                let (v1, j1) = field.normal_and_jvp(&p1, &perp);
                end_field = v1.to_f64();
                let mut sum = vm.scale(&four); // (v0 + 4 vm) + v1
                sum += v0;
                sum += &v1;
                let mut dsum = jm.scale(&middle_weight); // 4 (L/2) jm + L j1
                dsum.add_scaled_assign(length, &j1);
                let dg = sum.dot(&perp) + dsum.dot(&dir);
                if solve == Solve::Seed {
                    derivative = Some(dg.clone());
                }
                (sum, dg)
            }
        };
        let g = sum.dot(&dir);
        if !(g.is_finite() && dg.is_finite()) || dg.is_zero() {
            return Err(StepStop::NonFinite);
        }
        let delta = g / dg.clone();
        phi -= delta.clone();
        if refining {
            // sin(φ − δ) = s cos δ − c sin δ, cos(φ − δ) = c cos δ + s sin δ.
            let (sd, cd) = small_angle_sin_cos(&delta);
            let rotated_sin = s.product(&cd) - c.product(&sd);
            c = c.product(&cd) + s.product(&sd);
            s = rotated_sin;
        } else {
            (s, c) = phi.sin_cos();
        }
        let limit = tol.clone() * scalar::max(T::one(), phi.abs());
        let d = delta.abs();
        converged = d <= limit;
        let d = d.to_f64();
        // At the rounding floor (see `STALL_TOLERANCES`) the solve is as good as it gets.
        // Newton from the osculating guess converges in two or three iterations where it
        // converges at all, so the check waits for the fourth.
        if !converged && iterations >= 4 {
            converged = d <= STALL_TOLERANCES * limit.to_f64() && d > 0.5 * previous;
        }
        settled &= d < previous;
        if refining && !converged {
            let quarter = 0.25 * limit.to_f64();
            let shrinking = previous.is_finite() && d < 0.25 * previous;
            converged = match kept {
                Some((_, factor)) => shrinking && d * factor <= quarter,
                None if shrinking => {
                    let c_estimate = d / (previous * previous);
                    let next = c_estimate * d * d;
                    if next <= quarter {
                        true
                    } else {
                        let factor = 2.0 * c_estimate * d;
                        if next * factor <= quarter {
                            keep = Some((dg, factor));
                        }
                        false
                    }
                }
                None => false,
            };
        }
        previous = d;
    }
    Ok(ChordAngle {
        phi,
        sin: s,
        cos: c,
        end_field,
        iterations,
        converged,
        settled,
        derivative,
    })
}

/// `(sin δ, cos δ)` for a Newton correction `|δ| < 2⁻¹⁰` by their Taylor series, summed
/// until a term falls below a quarter unit of roundoff of `δ`: a handful of products where
/// MPFR's general sine would reduce and sum at full length (a few terms at `δ ≈ 10⁻¹⁶`
/// and 256 bits; none beyond `δ` and `1` once `δ²` is below the roundoff).
fn small_angle_sin_cos<T: Scalar>(delta: &T) -> (T, T) {
    let magnitude = delta.to_f64().abs();
    if magnitude.is_nan() || magnitude >= 1.0 / 1024.0 {
        return delta.sin_cos();
    }
    let floor = 0.25 * T::unit_roundoff() * magnitude;
    let (mut sin, mut cos) = (delta.clone(), T::one());
    let (mut term, mut term_magnitude) = (delta.clone(), magnitude);
    // `term` is δᵏ/k!; its sign in the series follows k mod 4: + (1), − (2, 3), + (0).
    for k in 2..64_u32 {
        term_magnitude *= magnitude / f64::from(k);
        if term_magnitude < floor {
            break;
        }
        term *= delta;
        term /= T::from_f64(f64::from(k));
        match k % 4 {
            0 => cos += &term,
            1 => sin += &term,
            2 => cos -= &term,
            _ => sin -= &term,
        }
    }
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Invariant, LieField};
    use crate::preset::Preset;
    use crate::Angle;

    fn sphere() -> LieField<f64> {
        LieField::new(&Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).unwrap())
    }

    #[test]
    fn paper_step_lands_inside_the_band_and_drifts_outward() {
        let mut params = Preset::Fig3.params();
        params.mode = Mode::Paper;
        let params = params.resolve::<f64, _>(&sphere()).unwrap();
        let cfg = StepConfig::<f64>::new(&params);
        let p = Vec3::new(0.0, 0.0, 1.0);
        let s = step(&sphere(), &cfg, &p, &Vec3::new(1.0, 0.0, 0.0), &params.dt).unwrap();
        assert_eq!(s.limit, StepLimit::None);
        assert!(
            s.alpha_predicted >= params.beta_min.radians()
                && s.alpha_predicted <= params.beta_max.radians()
        );
        // Explicit Euler leaves the sphere by 1 + Δt²/2 to first order.
        let r = s.point.norm();
        assert!(r > 1.0 + 0.4 * s.dt * s.dt, "{r}");
    }

    /// Unit normals of the ellipsoid `x² + 4 y² + 16 z² = 1`: integrable, not a gradient.
    struct UnitEllipsoid;
    impl<T: Scalar> NormalField<T> for UnitEllipsoid {
        fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
            self.normal_and_jvp(p, &Vec3::zero()).0
        }
        fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
            let k = |x: f64| T::from_f64(x);
            let g = Vec3::new(p.x.clone(), k(4.0) * p.y.clone(), k(16.0) * p.z.clone());
            let dg = Vec3::new(w.x.clone(), k(4.0) * w.y.clone(), k(16.0) * w.z.clone());
            let len = g.norm_squared().sqrt();
            let n = g.scale(&(T::one() / len.clone()));
            // d(g/|g|) = (dg − n (n·dg)) / |g|
            let along = n.dot(&dg);
            let jw = dg.add_scaled(&-along, &n).scale(&(T::one() / len));
            (n, jw)
        }
    }

    #[test]
    fn unit_normals_are_weighed_back_onto_their_level_set() {
        let field = UnitEllipsoid;
        let level = |q: [f64; 3]| q[0] * q[0] + 4.0 * q[1] * q[1] + 16.0 * q[2] * q[2];
        let p0 = [0.6f64, 0.3, 0.1].map(|x| x / level([0.6, 0.3, 0.1]).sqrt());
        let params = crate::MeshParams::at(p0).resolve::<f64, _>(&field).unwrap();
        assert!(params.level_correction && params.integrating_factor);
        // How far a step of 0.1 along each axis ends off the ellipsoid (|F − 1| / |∇F|).
        let off = |weighted: bool| {
            let mut params = params.clone();
            params.integrating_factor = weighted;
            let cfg = StepConfig::<f64>::new(&params);
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
                .map(|dir| {
                    let q = step_fixed(
                        &field,
                        &cfg,
                        &Vec3::from_f64(p0),
                        &Vec3::from_f64(dir),
                        &0.1,
                    )
                    .unwrap()
                    .to_f64();
                    let g = [q[0], 4.0 * q[1], 16.0 * q[2]];
                    (level(q) - 1.0).abs()
                        / (2.0 * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt())
                })
                .into_iter()
                .fold(0.0, f64::max)
        };
        let (plain, weighed) = (off(false), off(true));
        // Measured: 1.1e-3 plain, 1.8e-6 weighed (1.5e-5 weighed along the whole chord).
        assert!(
            weighed < 5e-6 && weighed < plain / 200.0,
            "{weighed:e} against {plain:e}"
        );
        // A gradient of one's own has no curl: its correction is the plain one.
        let radial = crate::model::FnField::new(|p: &Vec3<crate::scalar::Dual<f64>>| p.clone());
        let params = crate::MeshParams::at([1.0, 0.0, 0.0])
            .resolve::<f64, _>(&radial)
            .unwrap();
        assert!(params.level_correction && !params.integrating_factor);
    }

    /// `v = (x⁷, y⁷, z⁷)`, the gradient of `(x⁸ + y⁸ + z⁸) / 8`: a potential of degree eight,
    /// beyond Simpson's and Boole's rules, within Gauss–Legendre's five points.
    struct Octic;
    impl<T: Scalar> NormalField<T> for Octic {
        fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
            self.normal_and_jvp(p, &Vec3::zero()).0
        }
        fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
            let power = |x: &T, k: usize| (0..k).fold(T::one(), |acc, _| acc * x.clone());
            let v = Vec3::new(power(&p.x, 7), power(&p.y, 7), power(&p.z, 7));
            let seven = T::from_f64(7.0);
            let jw = Vec3::new(
                seven.clone() * power(&p.x, 6) * w.x.clone(),
                seven.clone() * power(&p.y, 6) * w.y.clone(),
                seven * power(&p.z, 6) * w.z.clone(),
            );
            (v, jw)
        }
    }

    /// How far steps of 0.2 from a point on `x⁸ + y⁸ + z⁸ = 1`, along each axis, end off it
    /// (`|ΔF| / |∇F|`), in `T`; and the same without the level correction.
    fn octic_steps_off<T: Scalar>() -> (f64, f64) {
        let p0 = [0.9f64, 0.5, 0.3];
        let level = p0.iter().map(|x| x.powi(8)).sum::<f64>();
        let p0 = p0.map(|x| x / level.powf(0.125));
        let params = crate::MeshParams::at(p0).resolve::<T, _>(&Octic).unwrap();
        assert!(params.level_correction && !params.integrating_factor);
        let octic = |q: &Vec3<T>| {
            let eighth = |x: &T| {
                let x2 = x.clone() * x.clone();
                let x4 = x2.clone() * x2;
                x4.clone() * x4
            };
            eighth(&q.x) + eighth(&q.y) + eighth(&q.z)
        };
        let off = |correct: bool| {
            let mut params = params.clone();
            params.level_correction = correct;
            let cfg = StepConfig::<T>::new(&params);
            let start = Vec3::<T>::from_f64(p0);
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
                .map(|dir| {
                    let q = step_fixed(
                        &Octic,
                        &cfg,
                        &start,
                        &Vec3::from_f64(dir),
                        &T::from_f64(0.2),
                    )
                    .unwrap();
                    let f = octic(&q) - octic(&start);
                    let g = Octic.normal(&q).norm_squared().sqrt() * T::from_f64(8.0);
                    (f / g).abs().to_f64()
                })
                .into_iter()
                .fold(0.0, f64::max)
        };
        (off(true), off(false))
    }

    #[test]
    fn a_potential_of_degree_eight_is_corrected_onto_its_level_set_to_rounding() {
        let (corrected, chord) = octic_steps_off::<f64>();
        assert!(
            corrected < 1e-15 && chord > 1e-6,
            "{corrected:e}, chord {chord:e}"
        );
    }

    /// The rule's nodes are `T`'s own: rounded to `f64` they would leave 10⁻¹⁷ in MPFR.
    #[cfg(feature = "mpfr")]
    #[test]
    fn a_potential_of_degree_eight_is_corrected_to_rounding_at_256_bits() {
        let (corrected, chord) = octic_steps_off::<crate::scalar::Mpfr<256>>();
        assert!(
            corrected < 1e-70 && chord > 1e-6,
            "{corrected:e}, chord {chord:e}"
        );
    }

    #[test]
    fn default_step_stays_on_the_sphere_to_rounding() {
        let params = Preset::Fig3.params().resolve::<f64, _>(&sphere()).unwrap();
        let cfg = StepConfig::<f64>::new(&params);
        let mut p = Vec3::new(0.0, 0.0, 1.0);
        let mut w = Vec3::new(1.0, 0.0, 0.0);
        for _ in 0..100 {
            let s = step(&sphere(), &cfg, &p, &w, &params.dt).unwrap();
            p = s.point;
            w = s.carry;
        }
        assert!((p.norm() - 1.0).abs() < 1e-14, "{}", p.norm() - 1.0);
    }

    #[test]
    fn default_step_stays_on_an_ellipsoid_to_rounding() {
        let inv = Invariant::from_numbers(&[1.0, 4.0, 16.0, 0.0, 0.0, 0.0]).unwrap();
        let f = LieField::<f64>::new(&inv);
        let pot = inv.potential().unwrap();
        let params = Preset::Fig3.params().resolve::<f64, _>(&f).unwrap();
        let cfg = StepConfig::<f64>::new(&params);
        let mut p = Vec3::new(0.6, 0.3, 0.1);
        let f0 = pot(p.to_f64());
        let mut w = Vec3::new(0.0, 1.0, 0.0);
        for _ in 0..200 {
            let s = step(&f, &cfg, &p, &w, &params.dt).unwrap();
            p = s.point;
            w = s.carry;
        }
        assert!(((pot(p.to_f64()) - f0) / f0).abs() < 1e-13);
    }

    /// A random 12-number invariant (uniform in [−1, 1]), far from integrable, whose mesh
    /// ran into the chord equation's failure below.
    const RANDOM_B: [f64; 12] = [
        0.766767652883025,
        0.6385596756714826,
        0.7279689393970303,
        -0.4431578709722057,
        -0.16940696557660284,
        -0.2824576693367504,
        0.768385654396434,
        0.9154624079279825,
        -0.6981581884177821,
        -0.6475645430192594,
        -0.5360862663609285,
        -0.5333278326382778,
    ];

    /// The fig3 parameters (every length explicit), resolved on `field`.
    fn fig3(field: &LieField<f64>) -> Resolved {
        Preset::Fig3.params().resolve::<f64, _>(field).unwrap()
    }

    fn field(numbers: &[f64]) -> LieField<f64> {
        LieField::new(&Invariant::from_numbers(numbers).unwrap())
    }

    fn v3(x: [f64; 3]) -> Vec3<f64> {
        Vec3::new(x[0], x[1], x[2])
    }

    /// The chord from `p` to `q` in [`drift_free_chord`]'s terms: its unit direction `c`,
    /// `v0`, `n`, `κ`, and the residual of `G = (v(p) + 4 v(m) + v(q)) · c` relative to
    /// the size of its terms.
    fn simpson_residual(field: &LieField<f64>, p: &Vec3<f64>, q: &Vec3<f64>) -> f64 {
        let c = (q - p).normalize().unwrap().0;
        let m = p.add_scaled(&0.5, &(q - p));
        let [a, b, e] = [p, &m, q].map(|x| field.normal(x));
        let sum = (&(&a + &b.scale(&4.0)) + &e).dot(&c);
        sum.abs() / (a.norm() + 4.0 * b.norm() + e.norm())
    }

    /// The chord of `length` that `step` would take from `p` towards the tangent part of
    /// `w_prev`.
    fn chord_from(
        field: &LieField<f64>,
        cfg: &StepConfig<f64>,
        p: &Vec3<f64>,
        w_prev: &Vec3<f64>,
        length: f64,
    ) -> Chord<f64> {
        let (v, n, vlen) = unit_normal(field, p).unwrap();
        let w = project_tangent(w_prev, &n).unwrap();
        let (_, jw) = field.normal_and_jvp(p, &w);
        let kappa = w.dot(&jw) / vlen;
        let start = ChordStart {
            p,
            v0: &v,
            n: &n,
            w: &w,
        };
        drift_free_chord(field, cfg, &start, &length, &kappa).unwrap()
    }

    #[test]
    fn a_step_whose_chord_has_no_root_is_halved_until_it_has_one() {
        // Near the middle of the flat face of the ellipsoid x² + y² + 100 z² = 1, the face's
        // radius of curvature (10) lets the band (8°–16°) ask for a step of 1.4, longer than
        // the face is wide: no chord of that length lies on the surface.
        let field = field(&[1.0, 1.0, 100.0, 0.0, 0.0, 0.0]);
        let r: f64 = 0.02;
        let p0 = [r, 0.0, ((1.0 - r * r) / 100.0).sqrt()];
        let mut params = Preset::Fig3.params();
        params.p0 = p0;
        params.beta_min = Angle::from_degrees(8.0);
        params.beta_max = Angle::from_degrees(16.0);
        params.dt_min = Some(1e-6);
        params.dt_max = Some(10.0);
        let params = params.resolve::<f64, _>(&field).unwrap();
        let cfg = StepConfig::<f64>::new(&params);
        let (p, w_prev) = (v3(p0), v3([1.0, 0.0, 0.0]));

        let s = step(&field, &cfg, &p, &w_prev, &params.dt).unwrap();
        assert_eq!(s.limit, StepLimit::Budget);
        assert!(s.dt < 1.0 && s.dt > 0.1, "{}", s.dt);
        // Twice as long (the length before the last halving) has no root.
        let longer = chord_from(&field, &cfg, &p, &w_prev, 2.0 * s.dt);
        assert!(!longer.converged);
        assert!(((&s.point - &p).norm() - s.dt).abs() <= 1e-15);
        assert!(simpson_residual(&field, &p, &s.point) <= 1e-14);
    }

    #[test]
    fn an_inserted_point_whose_chord_has_no_root_is_refused() {
        let field = field(&RANDOM_B);
        let cfg = StepConfig::<f64>::new(&fig3(&field));
        let p = v3([
            -0.04993907333125075,
            -0.01103549756507502,
            0.019740638468274334,
        ]);
        let dir = v3([
            -0.657016916014753,
            -0.056215121850791056,
            0.09663218032426707,
        ]);
        let stop = step_fixed(&field, &cfg, &p, &dir, &0.33323008047310865).unwrap_err();
        assert_eq!(stop, StepStop::NoChord);
        // A tenth of the way has a root, and the point is placed.
        let q = step_fixed(&field, &cfg, &p, &dir, &0.033323008047310865).unwrap();
        assert!(simpson_residual(&field, &p, &q) <= 1e-14);
    }

    /// Where the field is large, `G` carries rounding noise above the tolerance and Newton's
    /// corrections jump between values near 3e-15 (about twice the tolerance for φ ≈ 0.1): the
    /// solve used to spend all 64 iterations there and mark the step as budget-limited.
    #[test]
    fn a_chord_at_the_rounding_floor_stops_without_spending_the_budget() {
        let field = field(&RANDOM_B);
        let cfg = StepConfig::<f64>::new(&fig3(&field));
        let p = v3([
            -1.4453399213738807,
            -2.3699200997477745,
            -0.8339886987957766,
        ]);
        let w = v3([
            -0.6101524646644646,
            -0.013585284404352206,
            0.792167539041794,
        ]);
        let chord = chord_from(&field, &cfg, &p, &w, 0.011841414060809012);
        assert!(chord.converged);
        assert!(chord.iterations <= 8, "{}", chord.iterations);
        let r = simpson_residual(&field, &p, &chord.point);
        assert!(r <= 1e-13, "{r:e}");
    }

    #[test]
    fn small_angle_sine_and_cosine_match_the_library_functions() {
        for d in [3e-4, -2e-5, 1e-9, 1e-16, 5e-20, 0.0] {
            let (s, c) = small_angle_sin_cos(&d);
            assert!((s - d.sin()).abs() <= f64::EPSILON * d.abs(), "{d}");
            assert!((c - d.cos()).abs() <= f64::EPSILON, "{d}");
        }
    }

    #[cfg(feature = "mpfr")]
    #[test]
    fn small_angle_sine_and_cosine_hold_at_256_bits() {
        use crate::scalar::Mpfr;
        let ulp = Mpfr::<256>::from_f64(2.0 * Mpfr::<256>::unit_roundoff());
        for d in [3e-4, -2e-5, 1e-9, 1e-16, -1e-33, 1e-40, 1e-70] {
            let d = Mpfr::<256>::from_f64(d) / Mpfr::from_f64(3.0);
            let (s, c) = small_angle_sin_cos(&d);
            let (ws, wc) = d.sin_cos();
            assert!((s - ws).abs() <= ulp.clone() * d.abs(), "{d}");
            assert!((c - wc).abs() <= ulp, "{d}");
        }
    }

    /// A field that hides its `f64` copy, so the chord runs every iteration in `T`.
    #[cfg(feature = "mpfr")]
    struct Unseeded<F>(F);

    #[cfg(feature = "mpfr")]
    impl<T: Scalar, F: NormalField<T>> NormalField<T> for Unseeded<F> {
        fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
            self.0.normal(p)
        }
        fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
            self.0.normal_and_jvp(p, w)
        }
    }

    #[cfg(feature = "mpfr")]
    #[test]
    fn a_chord_seeded_in_f64_lands_where_the_full_precision_solve_lands() {
        use crate::scalar::Mpfr;
        type M = Mpfr<256>;
        for preset in [Preset::Fig3, Preset::Fig6] {
            let seeded = LieField::<M>::new(&preset.invariant());
            assert!(seeded.in_f64().is_some());
            let unseeded = Unseeded(seeded.clone());
            let params = preset.params().resolve::<M, _>(&seeded).unwrap();
            let cfg = StepConfig::<M>::new(&params);
            let mut p = Vec3::<M>::from_f64(params.p0);
            let mut w = Vec3::<M>::from_f64([1.0, 0.0, 0.0]);
            let dt = M::from_f64(params.dt);
            let (mut fewer, mut steps) = (0, 0);
            for _ in 0..12 {
                let a = step(&seeded, &cfg, &p, &w, &dt).unwrap();
                let b = step(&unseeded, &cfg, &p, &w, &dt).unwrap();
                let gap = (&a.point - &b.point).norm();
                assert!(gap.to_f64() < 1e-74, "{preset}: {gap}");
                assert_eq!(a.limit, b.limit);
                fewer += usize::from(a.iterations < b.iterations);
                steps += 1;
                (p, w) = (a.point, a.carry);
            }
            assert_eq!(
                fewer, steps,
                "{preset}: the seed saves iterations at every step"
            );
        }
    }

    /// Counts the Jacobian-vector products evaluated in `T`; offers the field's `f64` copy.
    #[cfg(feature = "mpfr")]
    struct CountingJvps<F>(F, std::sync::atomic::AtomicUsize);

    #[cfg(feature = "mpfr")]
    impl<T: Scalar, F: NormalField<T>> NormalField<T> for CountingJvps<F> {
        fn normal(&self, p: &Vec3<T>) -> Vec3<T> {
            self.0.normal(p)
        }
        fn normal_and_jvp(&self, p: &Vec3<T>, w: &Vec3<T>) -> (Vec3<T>, Vec3<T>) {
            self.1.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            self.0.normal_and_jvp(p, w)
        }
        fn in_f64(&self) -> Option<&dyn NormalField<f64>> {
            self.0.in_f64()
        }
        fn has_cubic_potential(&self) -> bool {
            self.0.has_cubic_potential()
        }
    }

    /// The seed's own `G'` takes the refinement's first step, so a 256-bit chord needs one
    /// Newton iteration with Jacobian-vector products (two of them, at the chord's middle and
    /// end) besides the step's own two at `p` (along the curve, and across it for the
    /// sideways limit on Δt); the other iterations use field values only.
    #[cfg(feature = "mpfr")]
    #[test]
    fn a_seeded_chord_makes_one_newton_iteration_with_jvps_at_256_bits() {
        use crate::scalar::Mpfr;
        type M = Mpfr<256>;
        for preset in [Preset::Fig3, Preset::Fig6] {
            let field = CountingJvps(LieField::<M>::new(&preset.invariant()), Default::default());
            let params = preset.params().resolve::<M, _>(&field).unwrap();
            let cfg = StepConfig::<M>::new(&params);
            let mut p = Vec3::<M>::from_f64(params.p0);
            let mut w = Vec3::<M>::from_f64([1.0, 0.0, 0.0]);
            let dt = M::from_f64(params.dt);
            for _ in 0..12 {
                field.1.store(0, std::sync::atomic::Ordering::Relaxed);
                let s = step(&field, &cfg, &p, &w, &dt).unwrap();
                let jvps = field.1.load(std::sync::atomic::Ordering::Relaxed);
                assert_eq!(jvps, 2 + 2, "{preset}");
                assert!(s.iterations >= 2, "{preset}: {}", s.iterations);
                (p, w) = (s.point, s.carry);
            }
        }
    }

    #[test]
    fn a_vanishing_normal_stops_the_curve() {
        let params = fig3(&sphere());
        let cfg = StepConfig::<f64>::new(&params);
        let r = step(
            &sphere(),
            &cfg,
            &Vec3::zero(),
            &Vec3::new(1.0, 0.0, 0.0),
            &0.1,
        );
        assert_eq!(r.unwrap_err(), StepStop::SingularNormal);
    }
}
