//! Invariant files: an invariant and, optionally, any mesher parameter, in TOML.
//!
//! ```toml
//! # 6 numbers (linear), 12 (the paper's text order) or 18 (Table 2's three rows).
//! invariant = [1.0, 4.0, 16.0, 0.0, 0.0, 0.0]
//!
//! [mesh]            # every key is optional; missing ones keep their defaults
//! method = "proposed"   # or "previous" (then `curves` sets their number)
//! mode = "default"      # or "paper"
//! p0 = [0.0, 0.0, 1.0]
//! dt = 0.05
//! beta_min_deg = 4.0
//! beta_max_deg = 8.0
//! ```
//!
//! Unknown keys and values of the wrong type are errors that name the key.

use crate::model::{Invariant, InvariantError};
use crate::params::{MeshParams, Method, Mode};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What can be wrong with an invariant file.
#[derive(Debug, Error)]
pub enum InvariantFileError {
    /// The file could not be read.
    #[error("cannot read invariant file '{path}': {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The TOML is malformed, a key is unknown, or a value has the wrong type.
    #[error("invariant file '{path}': {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// toml's description, naming the key and what is allowed.
        message: String,
    },
    /// The invariant numbers are invalid.
    #[error("invariant file '{path}': key `invariant`: {source}")]
    Invariant {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: InvariantError,
    },
    /// A parameter combination is invalid.
    #[error("invariant file '{path}': key `mesh.{key}`: {message}")]
    Parameter {
        /// The file.
        path: PathBuf,
        /// The key.
        key: &'static str,
        /// What is allowed.
        message: String,
    },
}

/// Overrides of [`MeshParams`], as written in a file or on the command line
/// (angles in degrees).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamsPatch {
    /// `"proposed"` or `"previous"`.
    pub method: Option<String>,
    /// Number of curves of the previous method.
    pub curves: Option<usize>,
    /// `"default"` or `"paper"`.
    pub mode: Option<String>,
    /// Initial point.
    pub p0: Option<[f64; 3]>,
    /// Initial direction.
    pub w00: Option<[f64; 3]>,
    /// Initial step Δt.
    pub dt: Option<f64>,
    /// Smallest step.
    pub dt_min: Option<f64>,
    /// Largest step.
    pub dt_max: Option<f64>,
    /// β_min in degrees.
    pub beta_min_deg: Option<f64>,
    /// β_max in degrees.
    pub beta_max_deg: Option<f64>,
    /// δ.
    pub grow: Option<f64>,
    /// δ'.
    pub shrink: Option<f64>,
    /// Insertion threshold in steps.
    pub gap: Option<f64>,
    /// Merge threshold in steps.
    pub merge: Option<f64>,
    /// Largest geodesic radius.
    pub max_radius: Option<f64>,
    /// Bounding box half-size.
    pub bounding_box: Option<f64>,
    /// Close closed surfaces.
    pub close: Option<bool>,
    /// Point budget.
    pub max_points: Option<usize>,
    /// Curve budget.
    pub max_curves: Option<usize>,
    /// Steps per curve budget.
    pub max_steps: Option<usize>,
    /// Retry budget per step.
    pub max_retries: Option<usize>,
    /// Refine faces whose normal error exceeds this many degrees.
    pub max_normal_error_deg: Option<f64>,
}

impl ParamsPatch {
    /// Applies the overrides to `params`; `Err((key, allowed))` for a bad enumeration value.
    pub fn apply(&self, params: &mut MeshParams) -> Result<(), (&'static str, String)> {
        if let Some(m) = &self.method {
            params.method = match m.as_str() {
                "proposed" => Method::Proposed,
                "previous" => Method::Previous {
                    curves: self.curves.unwrap_or(15),
                },
                other => {
                    return Err((
                        "method",
                        format!(
                            "got \"{other}\"; allowed values are \"proposed\" and \"previous\""
                        ),
                    ))
                }
            };
        } else if let (Some(n), Method::Previous { .. }) = (self.curves, params.method) {
            params.method = Method::Previous { curves: n };
        }
        if let Some(m) = &self.mode {
            params.mode = match m.as_str() {
                "default" => Mode::Default,
                "paper" => Mode::Paper,
                other => {
                    return Err((
                        "mode",
                        format!("got \"{other}\"; allowed values are \"default\" and \"paper\""),
                    ))
                }
            };
        }
        macro_rules! set {
            ($($field:ident => $target:expr),* $(,)?) => {
                $(if let Some(v) = self.$field { $target = v; })*
            };
        }
        set!(
            p0 => params.p0,
            w00 => params.w00,
            dt => params.dt,
            dt_min => params.dt_min,
            dt_max => params.dt_max,
            grow => params.grow,
            shrink => params.shrink,
            gap => params.gap,
            merge => params.merge,
            max_radius => params.terminal.max_radius,
            bounding_box => params.terminal.bounding_box,
            close => params.terminal.close,
            max_points => params.budget.max_points,
            max_curves => params.budget.max_curves,
            max_steps => params.budget.max_steps_per_curve,
            max_retries => params.budget.max_retries,
        );
        if let Some(d) = self.beta_min_deg {
            params.beta_min = d.to_radians();
        }
        if let Some(d) = self.beta_max_deg {
            params.beta_max = d.to_radians();
        }
        if let Some(d) = self.max_normal_error_deg {
            params.max_normal_error = Some(d.to_radians());
        }
        Ok(())
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileContents {
    invariant: Vec<f64>,
    #[serde(default)]
    mesh: ParamsPatch,
}

/// An invariant file's contents: the invariant and the parameters (defaults overridden by
/// the file's `[mesh]` table).
#[derive(Clone, Debug, PartialEq)]
pub struct InvariantFile {
    /// The invariant.
    pub invariant: Invariant,
    /// The overrides the file gave.
    pub patch: ParamsPatch,
}

impl InvariantFile {
    /// Reads and checks a file.
    pub fn read(path: &Path) -> Result<InvariantFile, InvariantFileError> {
        let text = std::fs::read_to_string(path).map_err(|source| InvariantFileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses file contents (`path` only names the file in errors).
    pub fn parse(text: &str, path: &Path) -> Result<InvariantFile, InvariantFileError> {
        let contents: FileContents =
            toml::from_str(text).map_err(|e| InvariantFileError::Syntax {
                path: path.to_path_buf(),
                message: one_line(&e),
            })?;
        let invariant = Invariant::from_numbers(&contents.invariant).map_err(|source| {
            InvariantFileError::Invariant {
                path: path.to_path_buf(),
                source,
            }
        })?;
        let mut probe = MeshParams::default();
        contents.mesh.apply(&mut probe).map_err(|(key, message)| {
            InvariantFileError::Parameter {
                path: path.to_path_buf(),
                key,
                message,
            }
        })?;
        Ok(InvariantFile {
            invariant,
            patch: contents.mesh,
        })
    }
}

/// toml's errors span several lines (with a source excerpt); keep the line number and the
/// message on one line.
fn one_line(e: &toml::de::Error) -> String {
    let msg = e.message().trim().replace('\n', " ");
    match e.span() {
        Some(span) => format!("at byte {}: {msg}", span.start),
        None => msg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<InvariantFile, InvariantFileError> {
        InvariantFile::parse(text, Path::new("test.toml"))
    }

    #[test]
    fn a_minimal_file_has_only_the_invariant() {
        let f = parse("invariant = [1, 4, 16, 0, 0, 0]").unwrap();
        assert_eq!(f.invariant.numbers(), vec![1.0, 4.0, 16.0, 0.0, 0.0, 0.0]);
        assert_eq!(f.patch, ParamsPatch::default());
    }

    #[test]
    fn an_unknown_key_is_named_with_the_allowed_ones() {
        let e = parse("invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\nstep = 0.1").unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("step") && msg.contains("dt"), "{msg}");
        assert!(!msg.contains('\n'));
    }

    #[test]
    fn a_bad_method_names_the_allowed_values() {
        let e = parse("invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\nmethod = \"fast\"").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("mesh.method") && msg.contains("\"proposed\""),
            "{msg}"
        );
    }

    #[test]
    fn a_wrong_count_names_the_key() {
        let msg = parse("invariant = [1, 1]").unwrap_err().to_string();
        assert!(
            msg.contains("`invariant`") && msg.contains("got 2"),
            "{msg}"
        );
    }
}
