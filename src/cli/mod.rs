//! The `liemesh` command line: the binary's own modules, not part of the library (a program
//! that depends on liemesh gets the mesher without clap, indicatif, tiny-skia, png, svg or
//! serde_json). The tests in `tests/cli*.rs` run the built executable.
//!
//! Exit codes: 0 success, 1 a check failed (e.g. an audit row), 2 bad input or an error
//! (the message on standard error says what was wrong and what to do).

mod audit;
mod batch;
mod bench;
mod mesh;
mod paper;
mod picture;
mod progress;
mod quality;
mod render;
mod workloads;

use clap::builder::TypedValueParser as _;
use clap::{Parser, Subcommand};
use liemesh::preset::Preset;
use std::process::ExitCode;
use thiserror::Error;

pub use mesh::MeshArgs;

/// Adaptive meshes of surfaces defined by Lie-algebra invariants.
#[derive(Debug, Parser)]
#[command(name = "liemesh", version, about, long_about = None)]
pub struct Cli {
    /// What to do; without a command, meshes the fig6 preset into `out/`.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
// Parsed once per process: the size of the `Mesh` variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Mesh a preset or an invariant file and write the mesh (and a report).
    Mesh(MeshArgs),
    /// Run the accuracy audits (AD prediction order, JVPs, scalar agreement) and print a table.
    Audit(audit::AuditArgs),
    /// Draw a mesh file as a wireframe picture (.png or .svg).
    Render(render::RenderArgs),
    /// Measure fig1..fig6 in both modes and print the quality table.
    Quality(quality::QualityArgs),
    /// Recover the invariant from a mesh file alone (vertex positions and face normals).
    Recover(quality::RecoverArgs),
    /// Reproduce the paper: fig1..fig6 meshes and pictures, and Table 3 side by side.
    Paper(paper::PaperArgs),
    /// Time the performance workloads, judge them against their targets and print a table or JSON.
    Bench(bench::BenchArgs),
    /// Mesh every invariant file of a folder (or list) in parallel: one mesh + report each.
    Batch(batch::BatchArgs),
}

/// Any error the command line reports (exit code 2).
#[derive(Debug, Error)]
pub enum CliError {
    /// Mesh generation failed.
    #[error(transparent)]
    Mesh(#[from] liemesh::MeshError),
    /// Reading or writing a mesh failed.
    #[error(transparent)]
    Io(#[from] liemesh::io::IoError),
    /// The invariant file is invalid.
    #[error(transparent)]
    InvariantFile(#[from] liemesh::io::invariant_file::InvariantFileError),
    /// The arguments contradict each other or name something unavailable.
    #[error("{0}")]
    Usage(String),
    /// Drawing a picture failed.
    #[error(transparent)]
    Render(#[from] picture::RenderError),
    /// Writing a report failed.
    #[error("cannot write '{path}': {source}")]
    Write {
        /// The file.
        path: std::path::PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// A preset as a command-line value: `fig1` … `fig6`, each with its description in `--help`.
/// (The library's [`Preset`] does not depend on clap.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct PresetArg(Preset);

impl clap::ValueEnum for PresetArg {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [PresetArg; 6] = [
            PresetArg(Preset::Fig1),
            PresetArg(Preset::Fig2),
            PresetArg(Preset::Fig3),
            PresetArg(Preset::Fig4),
            PresetArg(Preset::Fig5),
            PresetArg(Preset::Fig6),
        ];
        &ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        let help = match self.0 {
            Preset::Fig1 => "Sphere, previous method, 15 curves",
            Preset::Fig2 => "Sphere, previous method, 40 curves",
            Preset::Fig3 => "Sphere, proposed method",
            Preset::Fig4 => "Non-linear invariant, previous method, 15 curves",
            Preset::Fig5 => "Non-linear invariant, previous method, 40 curves",
            Preset::Fig6 => "Non-linear invariant, proposed method",
        };
        Some(clap::builder::PossibleValue::new(self.0.name()).help(help))
    }
}

/// The value parser of every `--preset` flag.
fn preset_parser() -> impl clap::builder::TypedValueParser<Value = Preset> {
    clap::builder::EnumValueParser::<PresetArg>::new().map(|p| p.0)
}

/// Parses the process arguments, runs, and turns the result into an exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("liemesh: error: {}", for_the_command_line(&e));
            // A mesh that failed its own validation is a failed check (1), not bad input (2).
            match e {
                CliError::Mesh(liemesh::MeshError::Invalid(_)) => ExitCode::from(1),
                _ => ExitCode::from(2),
            }
        }
    }
}

/// The error message as a command-line user needs it: the library's messages name parameters
/// (`dt`, `beta_min`, ...), which are also the flags' names, except where the library names
/// its own API.
fn for_the_command_line(e: &CliError) -> String {
    match e {
        CliError::Mesh(liemesh::MeshError::TooFewCurves(n)) => {
            format!("the previous method needs at least 3 curves (got {n}); use --curves 3 or more")
        }
        e => e.to_string(),
    }
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<ExitCode, CliError> {
    match cli.command {
        Some(Command::Mesh(args)) => mesh::run(&args),
        Some(Command::Audit(args)) => audit::run(&args),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Quality(args)) => quality::run(&args),
        Some(Command::Recover(args)) => quality::recover_cmd(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Batch(args)) => batch::run(&args),
        Some(Command::Paper(args)) => paper::run(&args),
        None => mesh::run(&MeshArgs::default_job()),
    }
}
