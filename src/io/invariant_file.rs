//! Invariant files: an invariant and, optionally, any mesher parameter, in TOML.
//!
//! ```toml
//! # 6 numbers (linear), 12 (the paper's text order) or 18 (Table 2's three rows);
//! # each row is λ1 λ2 λ3 θ φ ψ, angles in radians.
//! invariant = [1.0, 4.0, 16.0, 0.0, 0.0, 0.0]
//! angles = "literal"    # optional: "literal" (A = diag(λ) R, the paper's eq. 2, the
//!                       # default) or "quadric" (A = Rᵀ diag(λ) R, a turned quadric)
//!
//! [mesh]            # every key is optional; missing ones keep their defaults
//! method = "proposed"   # or "previous" (then `curves` sets their number)
//! mode = "default"      # or "paper"
//! p0 = [0.0, 0.0, 0.25]
//! dt = 0.05             # lengths left out follow the surface's size at p0
//! beta_min_deg = 4.0
//! beta_max_deg = 8.0
//! ```
//!
//! The `[mesh]` keys are [`MeshParams`]'s fields, angles in degrees (`*_deg`). Unknown keys
//! and values of the wrong type are errors that name the key.

use crate::model::{AngleReading, Invariant, InvariantError};
use crate::params::MeshParams;
use serde::Deserialize;
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
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileContents {
    invariant: Vec<f64>,
    #[serde(default)]
    angles: AngleReading,
    #[serde(default)]
    mesh: MeshParams,
}

/// An invariant file's contents: the invariant and the parameters (the defaults, overridden
/// by the file's `[mesh]` table).
#[derive(Clone, Debug, PartialEq)]
pub struct InvariantFile {
    /// The invariant.
    pub invariant: Invariant,
    /// The parameters.
    pub params: MeshParams,
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
        let invariant = Invariant::from_numbers(&contents.invariant)
            .map_err(|source| InvariantFileError::Invariant {
                path: path.to_path_buf(),
                source,
            })?
            .with_reading(contents.angles);
        Ok(InvariantFile {
            invariant,
            params: contents.mesh,
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
        assert_eq!(f.params, MeshParams::default());
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
        assert!(msg.contains("fast") && msg.contains("`proposed`"), "{msg}");
    }

    #[test]
    fn the_angles_are_read_literally_unless_the_file_says_quadric() {
        let f = parse("invariant = [1, 2, 3, 0.1, 0.2, 0.3]").unwrap();
        assert_eq!(f.invariant.reading(), AngleReading::Literal);
        let f = parse("invariant = [1, 2, 3, 0.1, 0.2, 0.3]\nangles = \"quadric\"").unwrap();
        assert_eq!(f.invariant.reading(), AngleReading::Quadric);
        let msg = parse("invariant = [1, 1, 1, 0, 0, 0]\nangles = \"degrees\"")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("degrees") && msg.contains("`quadric`"),
            "{msg}"
        );
    }

    /// A point or direction is three numbers: a fourth is refused, not dropped.
    #[test]
    fn points_and_directions_take_exactly_three_numbers() {
        let head = "invariant = [1, 4, 9, 0, 0, 0]\n[mesh]\n";
        let f = parse(&format!("{head}p0 = [1, 0, 0]\nw00 = [0, 1, 0]")).unwrap();
        assert_eq!(
            (f.params.p0, f.params.w00),
            ([1.0, 0.0, 0.0], Some([0.0, 1.0, 0.0]))
        );
        for bad in [
            "p0 = [1, 0, 0, 0]",
            "p0 = [1, 0]",
            "p0 = [1, 0, 0]\nw00 = [0, 1, 0, 5]",
            "w00 = []",
        ] {
            let msg = parse(&format!("{head}{bad}")).unwrap_err().to_string();
            assert!(
                msg.contains("expected an array of length 3"),
                "{bad}: {msg}"
            );
        }
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
