//! Mesher parameters: everything the paper's Step 1 sets, plus terminal conditions and budgets.

use crate::error::MeshError;

/// How curves are laid out (DESIGN.md §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase", tag = "kind"))]
pub enum Method {
    /// The previous method (paper refs \[5\]\[6\]): `curves` curves at uniform angles, no insertion.
    Previous {
        /// Number of curves leaving `p0`.
        curves: usize,
    },
    /// The proposed method: the Step 2 fan (first points at least Δt apart) and Step 6
    /// insertion of new curves where neighbouring curves diverge.
    Proposed,
}

/// How one step is taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
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

/// When a curve ends (the paper's Step 7), besides budgets and singular points.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Terminal {
    /// Largest arc length from `p0` along a curve.
    pub max_radius: f64,
    /// Half-size of the axis-aligned box around the origin that points must stay in.
    pub bounding_box: f64,
    /// End a curve when it runs into points that other curves laid down (closed surfaces),
    /// and close the remaining hole with a second chart.
    pub close: bool,
}

impl Default for Terminal {
    fn default() -> Self {
        Terminal {
            max_radius: 10.0,
            bounding_box: 100.0,
            close: true,
        }
    }
}

/// Hard limits on every loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Budget {
    /// Most sample points in total.
    pub max_points: usize,
    /// Most curves (initial and inserted).
    pub max_curves: usize,
    /// Most accepted steps on one curve.
    pub max_steps_per_curve: usize,
    /// Most Δt retries within one step (paper mode), or Newton iterations for one chord
    /// (default mode, clamped to 4..=64; a chord that finds no root is retried at half the
    /// length, up to [`CHORD_HALVINGS`](crate::trace::CHORD_HALVINGS) times).
    pub max_retries: usize,
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            max_points: 4_000_000,
            max_curves: 200_000,
            max_steps_per_curve: 100_000,
            max_retries: 64,
        }
    }
}

/// All parameters of one meshing run. Angles are in radians.
///
/// The defaults are the fig3 preset's: see [`crate::preset`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MeshParams {
    /// Curve layout.
    pub method: Method,
    /// Step rule.
    pub mode: Mode,
    /// Initial point.
    pub p0: [f64; 3],
    /// Initial direction (projected onto the tangent plane at `p0`).
    pub w00: [f64; 3],
    /// Initial step size Δt.
    pub dt: f64,
    /// Smallest step allowed (steps are clamped to `[dt_min, dt_max]`).
    pub dt_min: f64,
    /// Largest step allowed.
    pub dt_max: f64,
    /// β_min: smallest normal turn per step, radians.
    pub beta_min: f64,
    /// β_max: largest normal turn per step, radians.
    pub beta_max: f64,
    /// δ > 1: step growth when the normal turns less than β_min.
    pub grow: f64,
    /// δ' in (0, 1): step shrink when it turns more than β_max.
    pub shrink: f64,
    /// Insert a curve when neighbouring curves are more than `gap` × the local step apart
    /// (proposed method).
    pub gap: f64,
    /// End a curve when it comes closer than `merge` × the local step to a neighbour
    /// (proposed method; must be below `gap / 2` so that inserting and merging cannot chase
    /// each other).
    pub merge: f64,
    /// Terminal conditions.
    pub terminal: Terminal,
    /// Budgets.
    pub budget: Budget,
    /// Refinement: split faces whose normal error (the angle between the face and the field
    /// normal at its centroid) exceeds this many radians, after the mesh is built. `None`
    /// (the presets' choice) leaves the mesh as built.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub max_normal_error: Option<f64>,
}

impl Default for MeshParams {
    fn default() -> Self {
        crate::preset::Preset::Fig3.params()
    }
}

impl MeshParams {
    /// Checks every parameter; the error says which one is wrong and what is allowed.
    pub fn validate(&self) -> Result<(), MeshError> {
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
        for (i, &x) in self.w00.iter().enumerate() {
            finite(["w00.x", "w00.y", "w00.z"][i], x)?;
        }
        for (name, v) in [
            ("dt", self.dt),
            ("dt_min", self.dt_min),
            ("dt_max", self.dt_max),
            ("beta_min", self.beta_min),
            ("beta_max", self.beta_max),
            ("grow", self.grow),
            ("shrink", self.shrink),
            ("gap", self.gap),
            ("merge", self.merge),
            ("max_radius", self.terminal.max_radius),
            ("bounding_box", self.terminal.bounding_box),
        ] {
            finite(name, v)?;
        }
        if self.dt <= 0.0 {
            return Err(MeshError::StepSize {
                name: "dt",
                value: self.dt,
                why: "Δt must be greater than 0",
            });
        }
        if self.dt_min <= 0.0 {
            return Err(MeshError::StepSize {
                name: "dt_min",
                value: self.dt_min,
                why: "the smallest step must be greater than 0",
            });
        }
        if self.dt_max < self.dt_min {
            return Err(MeshError::StepSize {
                name: "dt_max",
                value: self.dt_max,
                why: "the largest step must not be below dt_min",
            });
        }
        let deg = |r: f64| r.to_degrees();
        if !(self.beta_min > 0.0
            && self.beta_min < self.beta_max
            && self.beta_max < std::f64::consts::FRAC_PI_2)
        {
            return Err(MeshError::AngleBand {
                min_deg: deg(self.beta_min),
                max_deg: deg(self.beta_max),
            });
        }
        if self.grow <= 1.0 {
            return Err(MeshError::GrowthFactor(self.grow));
        }
        if !(self.shrink > 0.0 && self.shrink < 1.0) {
            return Err(MeshError::ShrinkFactor(self.shrink));
        }
        if !(self.gap > 0.5 && self.gap <= 100.0) {
            return Err(MeshError::OutOfRange {
                name: "gap",
                value: self.gap,
                why: "the insertion threshold must lie in (0.5, 100] step lengths",
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
            finite("max_normal_error", e)?;
            if !(e > 0.0 && e < std::f64::consts::FRAC_PI_2) {
                return Err(MeshError::OutOfRange {
                    name: "max_normal_error_deg",
                    value: e.to_degrees(),
                    why: "the bound on the face-normal error must lie strictly between 0° and 90°",
                });
            }
        }
        if self.terminal.max_radius <= 0.0 {
            return Err(MeshError::OutOfRange {
                name: "max_radius",
                value: self.terminal.max_radius,
                why: "the largest geodesic radius must be greater than 0",
            });
        }
        if self.terminal.bounding_box <= 0.0 {
            return Err(MeshError::OutOfRange {
                name: "bounding_box",
                value: self.terminal.bounding_box,
                why: "the bounding box half-size must be greater than 0",
            });
        }
        let b = &self.budget;
        for (name, v) in [
            ("max_points", b.max_points),
            ("max_curves", b.max_curves),
            ("max_steps_per_curve", b.max_steps_per_curve),
            ("max_retries", b.max_retries),
        ] {
            if v == 0 {
                return Err(MeshError::ZeroBudget(name));
            }
        }
        let fan = match self.method {
            Method::Previous { curves } if curves < 3 => {
                return Err(MeshError::TooFewCurves(curves))
            }
            Method::Previous { curves } => curves,
            Method::Proposed => 6,
        };
        if b.max_curves < fan {
            return Err(MeshError::OutOfRange {
                name: "max_curves",
                value: b.max_curves as f64,
                why: "the curve budget must allow the initial fan (6 curves for the proposed \
                      method, `curves` for the previous one)",
            });
        }
        Ok(())
    }
}
