//! `liemesh quality` and `liemesh recover`.

use super::CliError;
use clap::Args;
use liemesh::io::invariant_file::InvariantFile;
use liemesh::model::{AngleReading, Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::quality::{decompose_in, recover, QualityReport};
use liemesh::Mode;
use serde::Serialize;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `liemesh quality`.
#[derive(Debug, Clone, Args)]
pub struct QualityArgs {
    /// Presets to measure (all six by default).
    #[arg(long, value_parser = super::preset_parser())]
    pub preset: Vec<Preset>,
    /// Measure the surface of this invariant file (its `[mesh]` parameters included) instead
    /// of presets; repeat the flag for several.
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub invariant: Vec<PathBuf>,
    /// Print the rows as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One row of the quality table.
#[derive(Clone, Debug, Serialize)]
pub struct QualityRow {
    /// Preset.
    pub preset: String,
    /// `default` or `paper`.
    pub mode: String,
    /// Triangles.
    pub triangles: usize,
    /// Wall-clock milliseconds of meshing.
    pub milliseconds: f64,
    /// The full report.
    pub quality: QualityReport,
}

/// Meshes `preset` in `mode` and measures it.
pub fn quality_row(preset: Preset, mode: Mode) -> Result<QualityRow, CliError> {
    quality_row_of(preset.name(), &preset.invariant(), preset.params(), mode)
}

/// Meshes `invariant` with `params` in `mode` and measures it; `label` names it in the row.
pub fn quality_row_of(
    label: &str,
    invariant: &Invariant,
    mut params: liemesh::MeshParams,
    mode: Mode,
) -> Result<QualityRow, CliError> {
    params.mode = mode;
    let start = Instant::now();
    let run = liemesh::run(&LieField::<f64>::new(invariant), &params)?;
    let milliseconds = start.elapsed().as_secs_f64() * 1e3;
    let quality = QualityReport::measure(invariant, &params, &run.samples, &run.mesh);
    Ok(QualityRow {
        preset: label.into(),
        mode: match mode {
            Mode::Default => "default".into(),
            Mode::Paper => "paper".into(),
        },
        triangles: run.mesh.triangles.len(),
        milliseconds,
        quality,
    })
}

pub(super) fn run(args: &QualityArgs) -> Result<ExitCode, CliError> {
    let presets = if args.preset.is_empty() {
        Preset::ALL.to_vec()
    } else {
        args.preset.clone()
    };
    let mut rows = Vec::new();
    if args.invariant.is_empty() {
        for p in presets {
            for mode in [Mode::Default, Mode::Paper] {
                rows.push(quality_row(p, mode)?);
            }
        }
    }
    for path in &args.invariant {
        let file = InvariantFile::read(path)?;
        let label = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into(),
        );
        for mode in [Mode::Default, Mode::Paper] {
            rows.push(quality_row_of(
                &label,
                &file.invariant,
                file.params.clone(),
                mode,
            )?);
        }
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("rows serialise")
        );
        return Ok(ExitCode::SUCCESS);
    }
    println!("| surface | mode | triangles | min angle | 1% min angle | max face-normal error | drift max (rel.) | recovery error | integrability defect max | ms |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in &rows {
        let q = &r.quality;
        println!(
            "| {} | {} | {} | {:.1}° | {:.1}° | {:.2}° | {} | {:.1e} | {:.2} | {:.1} |",
            r.preset,
            r.mode,
            r.triangles,
            q.shape.min_angle,
            q.shape.min_angle_p1,
            q.face_normal_error_max,
            q.drift
                .map(|d| format!("{:.1e}", d.max))
                .unwrap_or_else(|| "—".into()),
            q.recovery.relative_error.unwrap_or(f64::NAN),
            q.integrability_defect_max,
            r.milliseconds
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Arguments of `liemesh recover`.
#[derive(Debug, Clone, Args)]
pub struct RecoverArgs {
    /// The mesh (.ply or .obj).
    pub mesh: PathBuf,
    /// Fit the Hamiltonian model `A p + B (p∘p)` (18 unknowns) instead of `A p`.
    #[arg(long)]
    pub hamiltonian: bool,
    /// Compare with this preset's invariant.
    #[arg(long, value_parser = super::preset_parser(), conflicts_with = "invariant")]
    pub preset: Option<Preset>,
    /// Compare with the invariant in this file.
    #[arg(long)]
    pub invariant: Option<PathBuf>,
    /// Read the recovered angles this way (default: the reference's reading, else literal).
    #[arg(long, value_enum, value_name = "READING")]
    pub angles: Option<super::mesh::AnglesArg>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

pub(super) fn recover_cmd(args: &RecoverArgs) -> Result<ExitCode, CliError> {
    let mesh = liemesh::io::read_mesh(&args.mesh)?;
    let reference: Option<Invariant> = match (&args.preset, &args.invariant) {
        (Some(p), _) => Some(p.invariant()),
        (None, Some(f)) => Some(InvariantFile::read(f)?.invariant),
        (None, None) => None,
    };
    let mut r = recover(&mesh, args.hamiltonian, reference.as_ref());
    if let Some(reading) = args.angles.map(AngleReading::from) {
        if reading != r.reading {
            r.reading = reading;
            r.a_invariant = decompose_in(&r.a, reading, None);
        }
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&r).expect("recovery serialises")
        );
        return Ok(ExitCode::SUCCESS);
    }
    let inv = r.a_invariant;
    println!(
        "recovered A invariant (λ1 λ2 λ3 θ φ ψ, angles in radians, {} reading): {:.6} {:.6} {:.6} {:.6} {:.6} {:.6}",
        r.reading.name(),
        inv[0], inv[1], inv[2], inv[3], inv[4], inv[5]
    );
    for (name, m) in [("A", r.a), ("B", r.b)] {
        if name == "B" && !args.hamiltonian {
            continue;
        }
        for (i, row) in m.iter().enumerate() {
            let label = if i == 0 {
                format!("{name} =")
            } else {
                "   ".into()
            };
            println!(
                "{label} [{:>10.6} {:>10.6} {:>10.6}]",
                row[0], row[1], row[2]
            );
        }
    }
    println!("fit residual (RMS): {:.3e}", r.residual);
    if let Some(e) = r.relative_error {
        println!("relative error against the reference: {e:.3e}");
    }
    // A 12- or 18-number reference is a Hamiltonian invariant, which the linear fit cannot
    // give back (a relative error near 1 with no word why).
    let numbers = reference.as_ref().map_or(0, |r| r.numbers().len());
    if numbers > 6 && !args.hamiltonian {
        println!(
            "note: the reference is a Hamiltonian invariant ({numbers} numbers); add \
             --hamiltonian to fit one"
        );
    }
    Ok(ExitCode::SUCCESS)
}
