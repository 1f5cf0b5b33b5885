//! `liemesh batch`: meshes many invariant files in parallel (rayon), one mesh and one JSON
//! report per input.
//!
//! Output files depend only on the inputs, never on the number of threads or on timing: each
//! input is meshed by the same sequential pipeline, and the reports leave the wall-clock time
//! out (`seconds` is written as 0; the summary on standard output has the times).
//!
//! Each failing input's error is printed once, on standard error; the table on standard
//! output marks the input `FAILED`.

use super::mesh::{mesh_invariant, write_json};
use super::progress::Status;
use super::CliError;
use clap::Args;
use liemesh::io::invariant_file::InvariantFile;
use liemesh::io::report::{Job, Report};
use liemesh::io::{self, MeshFormat, WriteOptions};
use liemesh::scalar::ScalarKind;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `liemesh batch`.
#[derive(Debug, Clone, Args)]
pub struct BatchArgs {
    /// Invariant files (`.toml`), or folders whose `.toml` files are all meshed.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output folder: `<stem>.<format>` and `<stem>.json` for every input.
    #[arg(short, long, default_value = "out/batch")]
    pub output: PathBuf,
    /// Mesh format written: ply (binary), obj or stl.
    #[arg(long, default_value = "ply")]
    pub format: String,
    /// Print nothing but errors.
    #[arg(long)]
    pub quiet: bool,
}

/// What happened to one input.
#[derive(Debug, Clone)]
pub struct BatchItem {
    /// The invariant file.
    pub input: PathBuf,
    /// The mesh written, or why there is none.
    pub result: Result<BatchDone, BatchFailure>,
}

/// Why one input has no mesh.
#[derive(Debug, Clone)]
pub struct BatchFailure {
    /// The error, as `liemesh mesh` would print it.
    pub message: String,
    /// Whether the mesh failed its own validation (a failed check, exit code 1, as for
    /// `liemesh mesh`) rather than the input being unusable (exit code 2).
    pub invalid_mesh: bool,
}

/// One input meshed successfully.
#[derive(Debug, Clone)]
pub struct BatchDone {
    /// The mesh file written.
    pub mesh: PathBuf,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Whether the mesh is closed.
    pub closed: bool,
    /// Boundary loops where the surface goes on (see the `mesh` summary's `holes`).
    pub holes: usize,
    /// What cut the run short, if anything (the `mesh` summary's `INCOMPLETE`).
    pub cut_short: Vec<String>,
    /// Wall-clock seconds of this input (meshing and writing).
    pub seconds: f64,
}

/// The invariant files named by `inputs`: files as given, folders expanded to their `.toml`
/// files in name order.
pub fn collect_inputs(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, CliError> {
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|source| CliError::Write {
                path: input.clone(),
                source,
            })?;
            let mut found: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "toml"))
                .collect();
            found.sort();
            files.extend(found);
        } else {
            files.push(input.clone());
        }
    }
    if files.is_empty() {
        return Err(CliError::Usage(
            "no invariant files found (pass .toml files or folders holding them)".into(),
        ));
    }
    let mut stems: Vec<&std::ffi::OsStr> = files.iter().filter_map(|f| f.file_stem()).collect();
    stems.sort();
    if let Some(w) = stems.windows(2).find(|w| w[0] == w[1]) {
        return Err(CliError::Usage(format!(
            "two inputs are named '{}': their outputs would overwrite each other",
            w[0].to_string_lossy()
        )));
    }
    Ok(files)
}

fn mesh_one(input: &Path, out: &Path, format: MeshFormat) -> Result<BatchDone, CliError> {
    let t0 = Instant::now();
    let file = InvariantFile::read(input)?;
    let params = file.params;
    let outcome = mesh_invariant(
        &file.invariant,
        &params,
        ScalarKind::F64,
        true,
        &Status::default(),
    )?;
    let stem = input.file_stem().unwrap_or_default().to_string_lossy();
    let mesh_path = out.join(format!("{stem}.{}", format.extension()));
    let report_path = out.join(format!("{stem}.json"));
    io::write_mesh(
        &outcome.mesh,
        &mesh_path,
        &WriteOptions { ply_ascii: false },
    )?;
    // `seconds: 0.0`: the report must not depend on timing (see the module docs).
    let job = Job::new(None, &file.invariant, ScalarKind::F64, &params);
    let mut report = Report::new(job, &outcome.mesh, outcome.curves, 0.0);
    outcome.fill(&mut report);
    write_json(&report_path, &report)?;
    Ok(BatchDone {
        mesh: mesh_path,
        triangles: report.triangles,
        closed: report.closed,
        holes: report.stitched.holes,
        cut_short: report.cut_short.clone(),
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Meshes every input in parallel into `out`; the items come back in input order.
pub fn batch(files: &[PathBuf], out: &Path, format: MeshFormat) -> Vec<BatchItem> {
    files
        .par_iter()
        .map(|input| BatchItem {
            input: input.clone(),
            result: mesh_one(input, out, format).map_err(|e| BatchFailure {
                message: e.to_string(),
                invalid_mesh: matches!(e, CliError::Mesh(liemesh::MeshError::Invalid(_))),
            }),
        })
        .collect()
}

/// `liemesh batch`.
pub fn run(args: &BatchArgs) -> Result<ExitCode, CliError> {
    let format = MeshFormat::from_path(Path::new(&format!("x.{}", args.format)))?;
    let files = collect_inputs(&args.inputs)?;
    let t0 = Instant::now();
    let items = batch(&files, &args.output, format);
    let wall = t0.elapsed().as_secs_f64();
    let failed = items.iter().filter(|i| i.result.is_err()).count();
    if !args.quiet {
        for item in &items {
            match &item.result {
                Ok(d) => {
                    println!(
                        "{:<40} {:>9} triangles  {:<6} {:>9.1} ms  {}",
                        item.input.display(),
                        d.triangles,
                        if d.closed { "closed" } else { "open" },
                        d.seconds * 1e3,
                        d.mesh.display()
                    );
                    // What `liemesh mesh` would say about the same run, so that a cut-short
                    // or holed mesh does not pass for a finished one.
                    if d.holes > 0 {
                        println!(
                            "{:<40} holes: {} boundary loop{} where the surface goes on",
                            "",
                            d.holes,
                            if d.holes == 1 { "" } else { "s" }
                        );
                    }
                    if !d.cut_short.is_empty() {
                        println!("{:<40} INCOMPLETE {}", "", d.cut_short.join("; "));
                    }
                }
                // The error itself goes to standard error, once (below).
                Err(_) => println!("{:<40} FAILED", item.input.display()),
            }
        }
        let cpu: f64 = items
            .iter()
            .filter_map(|i| i.result.as_ref().ok().map(|d| d.seconds))
            .sum();
        println!(
            "{} input(s), {} meshed, {failed} failed; {:.1} ms wall, {:.1} ms summed over inputs, \
             {} thread(s)",
            items.len(),
            items.len() - failed,
            wall * 1e3,
            cpu * 1e3,
            rayon::current_num_threads()
        );
    }
    if failed > 0 {
        let mut unusable = false;
        for item in &items {
            if let Err(e) = &item.result {
                eprintln!("liemesh: error: {}: {}", item.input.display(), e.message);
                unusable |= !e.invalid_mesh;
            }
        }
        // As `liemesh mesh`: bad input is 2; meshes that failed their validation, 1.
        return Ok(ExitCode::from(if unusable { 2 } else { 1 }));
    }
    Ok(ExitCode::SUCCESS)
}
