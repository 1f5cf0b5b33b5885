//! Accuracy audits (DESIGN.md §4): the figures that say how far the numbers can be trusted,
//! produced as data.
//!
//! Every audit is a function returning [`Row`]s: what was checked, in which scalar type, for
//! which preset, the measured figure, the bound it must stay within and whether it does.
//! [`run_all`] runs every audit for a list of presets; `liemesh audit` prints the result as a
//! table and `tests/audit_*.rs` assert it.
//!
//! | module | check | reference |
//! |---|---|---|
//! | [`prediction`] | the first-order prediction `v + Δt J w` of the normal at `p + Δt w` is off by `O(Δt²)` (log-log slope 2); exact for a linear field | the exact `v(p + Δt w)` in the same precision |
//! | [`jvp`] | the dual-number JVP `J_v(p) w` | closed form in double-double; `Dual<Mpfr<256>>`; an `Mpfr<512>` central difference |
//! | [`scalars`] | the whole mesh in `f32`, `f64`, `Dual<f64>`, `Mpfr<64>` | the same mesh in `Mpfr<256>` (or `f64` without MPFR) |
//! | [`field`] | all of the above, and validity, for any field built in every scalar type (an invariant file, a formula of one's own) | as above, probed on the field's own mesh |
//!
//! The MPFR references need the `mpfr` cargo feature; without it the `f64`/dual rows still
//! run (their references are then `f64` and double-double), and [`MPFR_AVAILABLE`] says so.
//!
//! ```
//! use liemesh::audit;
//! use liemesh::preset::Preset;
//!
//! let rows = audit::run_all(&[Preset::Fig6]);
//! assert!(rows.iter().all(|r| r.pass), "{rows:#?}");
//! ```

pub mod field;
pub mod jvp;
pub mod prediction;
pub mod scalars;

use crate::model::Invariant;
use crate::preset::Preset;

pub use crate::geom::rng::XorShift64;
pub use field::audit_field;

/// Whether this build has the `mpfr` feature, i.e. whether the MPFR rows are produced.
pub const MPFR_AVAILABLE: bool = cfg!(feature = "mpfr");

/// One audit figure.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Row {
    /// What was checked, with the unit of `measured` (e.g. `"vertex error / bbox diagonal"`).
    pub check: String,
    /// The scalar type under test, e.g. `"f64"`, `"Dual<f64>"`, `"Mpfr<256>"`.
    pub scalar: String,
    /// The preset(s) the figure belongs to (comma-separated when several presets share the
    /// invariant being checked), or `None` for checks on other inputs (random invariants).
    pub preset: Option<String>,
    /// The measured figure (NaN when the check could not run; the row then fails).
    pub measured: f64,
    /// The bound `measured` must not exceed.
    pub bound: f64,
    /// Whether the check passed.
    pub pass: bool,
    /// How the figure was obtained, what was compared, and anything notable.
    pub note: String,
}

impl Row {
    /// A row that passes when `measured ≤ bound` (a NaN measurement fails).
    pub fn at_most(
        check: impl Into<String>,
        scalar: impl Into<String>,
        preset: Option<&str>,
        measured: f64,
        bound: f64,
        note: impl Into<String>,
    ) -> Row {
        Row {
            check: check.into(),
            scalar: scalar.into(),
            preset: preset.map(str::to_string),
            measured,
            bound,
            pass: measured <= bound,
            note: note.into(),
        }
    }

    /// A failed row for a check that could not be carried out (`note` says why).
    pub fn failed(
        check: impl Into<String>,
        scalar: impl Into<String>,
        preset: Option<&str>,
        bound: f64,
        note: impl Into<String>,
    ) -> Row {
        Row {
            check: check.into(),
            scalar: scalar.into(),
            preset: preset.map(str::to_string),
            measured: f64::NAN,
            bound,
            pass: false,
            note: note.into(),
        }
    }
}

/// The distinct invariants of `presets`, each with the comma-separated names of the presets
/// that share it (in the order given).
pub fn invariant_groups(presets: &[Preset]) -> Vec<(Invariant, String)> {
    let mut groups: Vec<(Invariant, Vec<&'static str>)> = Vec::new();
    for p in presets {
        let inv = p.invariant();
        match groups.iter_mut().find(|(i, _)| *i == inv) {
            Some((_, names)) => {
                if !names.contains(&p.name()) {
                    names.push(p.name());
                }
            }
            None => groups.push((inv, vec![p.name()])),
        }
    }
    groups
        .into_iter()
        .map(|(inv, names)| (inv, names.join(",")))
        .collect()
}

/// Runs every audit: the field checks ([`prediction`], [`jvp`]) once per distinct invariant
/// of `presets` and once on random linear invariants (rows without a preset), then the
/// whole-mesh scalar agreement ([`scalars`]) for each preset.
///
/// Without the `mpfr` feature only the rows whose reference needs no MPFR are produced.
pub fn run_all(presets: &[Preset]) -> Vec<Row> {
    let mut rows = Vec::new();
    for (inv, label) in invariant_groups(presets) {
        rows.extend(field_rows(std::slice::from_ref(&inv), Some(&label)));
    }
    let linear = jvp::random_linear_invariants(jvp::RANDOM_INVARIANTS, jvp::SEED);
    rows.extend(field_rows(&linear, None));
    for &p in presets {
        rows.extend(scalars::scalar_agreement(p));
    }
    rows
}

/// The prediction and JVP rows of a set of invariants (all linear or all not).
fn field_rows(invariants: &[Invariant], label: Option<&str>) -> Vec<Row> {
    let mut rows = Vec::new();
    let linear = invariants.iter().all(prediction::is_linear);
    if linear {
        rows.push(prediction::linear_prediction_exact::<f64>(
            invariants, label,
        ));
        #[cfg(feature = "mpfr")]
        rows.push(prediction::linear_prediction_exact::<
            crate::scalar::Mpfr<256>,
        >(invariants, label));
    } else {
        rows.push(prediction::prediction_order::<f64>(invariants, label));
        #[cfg(feature = "mpfr")]
        rows.push(prediction::prediction_order::<crate::scalar::Mpfr<256>>(
            invariants, label,
        ));
    }
    rows.push(jvp::jvp_vs_double_double(invariants, label));
    #[cfg(feature = "mpfr")]
    {
        rows.push(jvp::jvp_vs_mpfr(invariants, label));
        rows.push(jvp::jvp_vs_central_difference(invariants, label));
    }
    rows
}
