//! `liemesh audit`: the accuracy audits of [`liemesh::audit`] as a table or JSON.
//!
//! Exit code 0 when every row passes, 1 when any row fails.

use super::CliError;
use clap::Args;
use liemesh::audit::{self, Row};
use liemesh::io::invariant_file::InvariantFile;
use liemesh::preset::Preset;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `liemesh audit`.
#[derive(Debug, Clone, Default, Args)]
pub struct AuditArgs {
    /// Audit this preset; repeat the flag for several. All six when omitted.
    #[arg(long, value_parser = super::preset_parser())]
    pub preset: Vec<Preset>,
    /// Audit the surface of this invariant file (its `[mesh]` parameters included) instead
    /// of presets; repeat the flag for several.
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub invariant: Vec<PathBuf>,
    /// Print the rows as a JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The line printed when the build has no MPFR.
pub const NO_MPFR_NOTE: &str =
    "note: the MPFR rows (Mpfr<256> references, Mpfr<64>, Mpfr<512> central differences) \
     need a build with MPFR: cargo run --release --features mpfr -- audit";

/// Formats rows as a fixed-width table (one row per line, the note last).
pub fn format_table(rows: &[Row]) -> String {
    let header = [
        "check", "scalar", "surface", "measured", "bound", "result", "note",
    ];
    let cells: Vec<[String; 7]> = rows
        .iter()
        .map(|r| {
            [
                r.check.clone(),
                r.scalar.clone(),
                r.preset.clone().unwrap_or_else(|| "-".into()),
                format!("{:.3e}", r.measured),
                format!("{:.3e}", r.bound),
                if r.pass { "pass" } else { "FAIL" }.to_string(),
                r.note.clone(),
            ]
        })
        .collect();
    let mut width = [0usize; 6];
    for row in std::iter::once(header.map(String::from)).chain(cells.iter().cloned()) {
        for (w, c) in width.iter_mut().zip(&row) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |row: &[String; 7]| {
        let mut s = String::new();
        for (i, c) in row.iter().enumerate() {
            if i < 6 {
                let pad = width[i] - c.chars().count();
                // Numbers right-aligned, text left-aligned.
                if i == 3 || i == 4 {
                    s.push_str(&" ".repeat(pad));
                    s.push_str(c);
                } else {
                    s.push_str(c);
                    s.push_str(&" ".repeat(pad));
                }
                s.push_str("  ");
            } else {
                s.push_str(c);
            }
        }
        s.trim_end().to_string()
    };
    let mut out = line(&header.map(String::from));
    out.push('\n');
    for row in &cells {
        out.push_str(&line(row));
        out.push('\n');
    }
    let failed = rows.iter().filter(|r| !r.pass).count();
    out.push_str(&format!(
        "{} rows, {} passed, {} failed\n",
        rows.len(),
        rows.len() - failed,
        failed
    ));
    out
}

/// Runs the audits of the chosen presets and prints them.
pub(super) fn run(args: &AuditArgs) -> Result<ExitCode, CliError> {
    let presets = if args.preset.is_empty() {
        Preset::ALL.to_vec()
    } else {
        args.preset.clone()
    };
    let rows = if args.invariant.is_empty() {
        audit::run_all(&presets)
    } else {
        let mut rows = Vec::new();
        for path in &args.invariant {
            let file = InvariantFile::read(path)?;
            let label = path.file_stem().map_or_else(
                || path.display().to_string(),
                |s| s.to_string_lossy().into(),
            );
            rows.extend(audit::audit_field(&file.invariant, &file.params, &label));
        }
        rows
    };
    let mut text = if args.json {
        let mut t = serde_json::to_string_pretty(&rows).map_err(|e| CliError::Write {
            path: "<standard output>".into(),
            source: std::io::Error::other(e),
        })?;
        t.push('\n');
        t
    } else {
        format_table(&rows)
    };
    if !audit::MPFR_AVAILABLE {
        if args.json {
            // Standard output stays valid JSON.
            eprintln!("{NO_MPFR_NOTE}");
        } else {
            text.push_str(NO_MPFR_NOTE);
            text.push('\n');
        }
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        // A reader that went away (`liemesh audit | head`) is not an error of the audit.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            return Err(CliError::Write {
                path: "<standard output>".into(),
                source: e,
            })
        }
        _ => {}
    }
    Ok(if rows.iter().all(|r| r.pass) {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use clap::Parser;

    fn row(pass: bool) -> Row {
        Row {
            check: "some check".into(),
            scalar: "f64".into(),
            preset: None,
            measured: if pass { 0.5 } else { 2.0 },
            bound: 1.0,
            pass,
            note: "a note".into(),
        }
    }

    #[test]
    fn table_marks_failures_and_counts_them() {
        let t = format_table(&[row(true), row(false)]);
        let lines: Vec<&str> = t.lines().collect();
        assert!(lines[0].starts_with("check"));
        assert!(lines[1].contains("pass") && lines[1].ends_with("a note"));
        assert!(lines[2].contains("FAIL"));
        assert_eq!(lines[3], "2 rows, 1 passed, 1 failed");
    }

    #[test]
    fn audit_takes_repeated_presets_and_json() {
        let cli = Cli::try_parse_from([
            "liemesh", "audit", "--preset", "fig3", "--preset", "fig6", "--json",
        ])
        .unwrap();
        match cli.command {
            Some(Command::Audit(a)) => {
                assert_eq!(a.preset, vec![Preset::Fig3, Preset::Fig6]);
                assert!(a.json);
            }
            other => panic!("{other:?}"),
        }
    }
}
