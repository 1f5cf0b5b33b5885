//! The paper's six figures as ready-made jobs.
//!
//! The paper prints the invariants (Table 2) but not `p0`, `w00`, Δt, the β band, δ or δ'.
//! The values here are chosen so that the figures' story holds: with 15 curves the mesh is
//! coarse far from `p0`, with 40 it is crowded near `p0`, and the proposed method is even
//! everywhere, with a triangle count between the two (fig1 < fig3 < fig2, fig4 < fig6 < fig5).
//!
//! | preset | invariant | method | p0 | terminal condition |
//! |---|---|---|---|---|
//! | fig1 | sphere (Table 2, rows 1–3 of Fig. 1–3) | previous, 15 curves | (0, 0, 1) | closed surface |
//! | fig2 | sphere | previous, 40 curves | (0, 0, 1) | closed surface |
//! | fig3 | sphere | proposed | (0, 0, 1) | closed surface |
//! | fig4 | Table 2, Fig. 4–6 (non-linear) | previous, 15 curves | see [`FIG46_P0`] | geodesic radius [`FIG46_RADIUS`] |
//! | fig5 | same | previous, 40 curves | same | same |
//! | fig6 | same | proposed | same | same |
//!
//! All presets use `w00 = (1, 0, 0)`, Δt = 0.1, β ∈ [4°, 8°], δ = 1.5, δ' = 0.6, steps clamped
//! to [0.001, 1], insertion at 1.8 steps, merging at 0.7 steps.

use crate::model::Invariant;
use crate::params::{MeshParams, Method, Mode};

/// Table 2, Fig. 1–3: `A = I`, `B = C = 0` — the unit sphere.
pub const SPHERE_INVARIANT: [f64; 18] = [
    1.0, 1.0, 1.0, 0.0, 0.0, 0.0, //
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, //
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
];

/// Table 2, Fig. 4–6, row k = `(λ1k, λ2k, λ3k, θk, φk, ψk)`.
pub const FIG46_INVARIANT: [f64; 18] = [
    -0.1, -0.5, -0.6, -0.4, 1.0, -1.0, //
    -0.5, 0.6, 0.4, 0.1, 0.5, 0.0, //
    0.1, 0.2, -0.4, 0.0, 0.5, 0.5,
];

/// Initial point of fig4–6: `(1, −1, −1)/√3`, where the field is far from its singular
/// points and closest to integrable among the directions we scanned (integrability defect
/// `|v·(∇×v)|/|v|² ≈ 0.29`), so neighbouring curves neither fold over each other nor need
/// clamped steps within the radius.
pub const FIG46_P0: [f64; 3] = [INV_SQRT_3, -INV_SQRT_3, -INV_SQRT_3];

const INV_SQRT_3: f64 = 0.577_350_269_189_625_8;

/// Largest geodesic radius of fig4–6.
pub const FIG46_RADIUS: f64 = 1.0;

/// One of the paper's figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Preset {
    /// Sphere, previous method, 15 curves.
    Fig1,
    /// Sphere, previous method, 40 curves.
    Fig2,
    /// Sphere, proposed method.
    Fig3,
    /// Non-linear invariant, previous method, 15 curves.
    Fig4,
    /// Non-linear invariant, previous method, 40 curves.
    Fig5,
    /// Non-linear invariant, proposed method.
    Fig6,
}

impl Preset {
    /// All six, in order.
    pub const ALL: [Preset; 6] = [
        Preset::Fig1,
        Preset::Fig2,
        Preset::Fig3,
        Preset::Fig4,
        Preset::Fig5,
        Preset::Fig6,
    ];

    /// `"fig1"` … `"fig6"`.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Fig1 => "fig1",
            Preset::Fig2 => "fig2",
            Preset::Fig3 => "fig3",
            Preset::Fig4 => "fig4",
            Preset::Fig5 => "fig5",
            Preset::Fig6 => "fig6",
        }
    }

    /// The invariant of the figure (Table 2).
    pub fn invariant(self) -> Invariant {
        let numbers: &[f64] = match self {
            Preset::Fig1 | Preset::Fig2 | Preset::Fig3 => &SPHERE_INVARIANT,
            _ => &FIG46_INVARIANT,
        };
        Invariant::from_numbers(numbers).expect("Table 2 invariants are valid")
    }

    /// The mesher parameters of the figure (every length explicit, as in the paper).
    pub fn params(self) -> MeshParams {
        let (method, curves) = match self {
            Preset::Fig1 | Preset::Fig4 => (Method::Previous, 15),
            Preset::Fig2 | Preset::Fig5 => (Method::Previous, 40),
            Preset::Fig3 | Preset::Fig6 => (Method::Proposed, 15),
        };
        let sphere = matches!(self, Preset::Fig1 | Preset::Fig2 | Preset::Fig3);
        MeshParams {
            method,
            curves,
            mode: Mode::Default,
            p0: if sphere { [0.0, 0.0, 1.0] } else { FIG46_P0 },
            w00: Some([1.0, 0.0, 0.0]),
            dt: Some(0.1),
            dt_min: Some(0.001),
            dt_max: Some(1.0),
            max_radius: Some(if sphere { 10.0 } else { FIG46_RADIUS }),
            bounding_box: Some(10.0),
            ..MeshParams::default()
        }
    }
}

impl std::fmt::Display for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
