//! `liemesh mesh`.

use super::progress::{grouped, with_progress, Status};
use super::CliError;
use clap::Args;
use liemesh::io::invariant_file::InvariantFile;
use liemesh::io::report::{FailureReport, Job, Report, VertexDerivatives};
use liemesh::io::{self, WriteOptions};
use liemesh::model::{AngleReading, Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::quality::Drift;
use liemesh::scalar::{Dual, Scalar, ScalarKind};
use liemesh::{Mesh, MeshError, MeshParams, Mode};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `liemesh mesh`.
#[derive(Debug, Clone, Args)]
pub struct MeshArgs {
    /// One of the paper's figures.
    #[arg(long, value_parser = super::preset_parser(), conflicts_with = "invariant")]
    pub preset: Option<Preset>,
    /// A TOML invariant file (`invariant = [...]` and an optional `[mesh]` table).
    #[arg(long, value_name = "FILE")]
    pub invariant: Option<PathBuf>,
    /// How the invariant's angles are read (wins over the file's `angles`): `literal` is the
    /// paper's eq. 2, A = diag(λ) R; `quadric` is A = Rᵀ diag(λ) R, a turned quadric.
    #[arg(long, value_enum, value_name = "READING")]
    pub angles: Option<AnglesArg>,
    /// Also write d(vertex)/d(invariant number N) for every vertex, N counting from 1 in the
    /// invariant's 6 numbers (or the 18 of Table 2's rows): PLY vertex properties `d_nN_x`,
    /// `d_nN_y`, `d_nN_z` and the report's `derivatives`. Repeat for several numbers.
    #[arg(long, value_name = "N")]
    pub derivative: Vec<usize>,
    /// Output mesh: .ply (binary unless --ascii), .obj or .stl.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Write PLY as ASCII.
    #[arg(long)]
    pub ascii: bool,
    /// Write a JSON report of the run (of a run that failed: what was asked and why it failed).
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Scalar type of the computation.
    #[arg(long, value_enum, default_value = "f64")]
    pub scalar: ScalarArg,
    /// Also draw the mesh into this picture (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// Picture options for --png.
    #[command(flatten)]
    pub picture: super::render::PictureArgs,
    /// Print nothing on success.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the report as JSON on standard output instead of the summary (also when the run
    /// fails).
    #[arg(long)]
    pub json: bool,
    /// Parameter overrides (they win over the preset and the file).
    #[command(flatten)]
    pub overrides: Overrides,
}

/// `--angles` values (the library's [`AngleReading`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AnglesArg {
    /// A = diag(λ) Rx(θ) Ry(φ) Rz(ψ), the paper's eq. 2.
    Literal,
    /// A = Rᵀ diag(λ) R: the quadric with axes scaled by λ, turned.
    Quadric,
}

impl From<AnglesArg> for AngleReading {
    fn from(a: AnglesArg) -> AngleReading {
        match a {
            AnglesArg::Literal => AngleReading::Literal,
            AnglesArg::Quadric => AngleReading::Quadric,
        }
    }
}

/// `--scalar` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ScalarArg {
    /// IEEE single precision.
    F32,
    /// IEEE double precision.
    F64,
    /// Dual<f64> (the mesh is the real part).
    Dual,
    /// Mpfr<256> (needs a build with `--features mpfr`).
    Mpfr,
}

impl From<ScalarArg> for ScalarKind {
    fn from(s: ScalarArg) -> ScalarKind {
        match s {
            ScalarArg::F32 => ScalarKind::F32,
            ScalarArg::F64 => ScalarKind::F64,
            ScalarArg::Dual => ScalarKind::Dual,
            ScalarArg::Mpfr => ScalarKind::Mpfr,
        }
    }
}

/// Every mesher parameter as a flag. Each flag is applied onto [`MeshParams`] through serde
/// under its key in the invariant file's `[mesh]` table (no field-by-field copy: a test
/// checks that every flag names a parameter).
#[derive(Debug, Clone, Default, Args, serde::Serialize)]
pub struct Overrides {
    /// Curve layout: `proposed` or `previous`.
    #[arg(long, value_parser = ["proposed", "previous"])]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method: Option<String>,
    /// Number of curves of the previous method (implies --method previous).
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curves: Option<usize>,
    /// Step rule: `default` (drift-free) or `paper` (explicit Euler, retry loop).
    #[arg(long, value_parser = ["default", "paper"])]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// Initial point `x,y,z`.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p0: Option<[f64; 3]>,
    /// Initial direction `x,y,z` (default: the axis least aligned with the normal at p0).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub w00: Option<[f64; 3]>,
    /// Initial step Δt (default: from the surface's curvature at p0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// Smallest step.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt_min: Option<f64>,
    /// Largest step.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt_max: Option<f64>,
    /// β_min in degrees.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite, value_name = "DEG")]
    #[serde(rename = "beta_min_deg", skip_serializing_if = "Option::is_none")]
    pub beta_min: Option<f64>,
    /// β_max in degrees.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite, value_name = "DEG")]
    #[serde(rename = "beta_max_deg", skip_serializing_if = "Option::is_none")]
    pub beta_max: Option<f64>,
    /// Growth factor δ > 1.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grow: Option<f64>,
    /// Shrink factor δ' in (0, 1).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shrink: Option<f64>,
    /// Insert a curve when neighbours are this many steps apart (1 to 100).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// End a curve closer than this many steps to a neighbour.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub merge: Option<f64>,
    /// Largest geodesic radius (default: from the surface's size at p0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_radius: Option<f64>,
    /// Half-size of the bounding box around the origin (default: from the surface's size).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bounding_box: Option<f64>,
    /// Do not stop curves where fronts meet nor stitch them (`close = false`); on a surface
    /// the curves go round, they then run over one another, and the faces that cross are
    /// cut out.
    #[arg(long)]
    #[serde(skip)]
    pub no_close: bool,
    /// Point budget.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_points: Option<usize>,
    /// Curve budget.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_curves: Option<usize>,
    /// Steps-per-curve budget.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<usize>,
    /// Retries-per-step budget (paper mode), or Newton iterations per chord (default mode,
    /// 4 to 64).
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_retries: Option<usize>,
    /// Refine the mesh until no face's normal deviates from the field normal at its
    /// centroid by more than this many degrees (splits the longest edges of the worst faces)
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite, value_name = "DEG")]
    #[serde(
        rename = "max_normal_error_deg",
        skip_serializing_if = "Option::is_none"
    )]
    pub max_normal_error: Option<f64>,
}

impl Overrides {
    /// `params` with the flags given applied on top.
    pub fn apply(&self, params: MeshParams) -> Result<MeshParams, CliError> {
        let bad = |e: serde_json::Error| CliError::Usage(format!("parameters: {e}"));
        let mut value = serde_json::to_value(&params).map_err(bad)?;
        let flags = serde_json::to_value(self).map_err(bad)?;
        let (Some(target), Some(given)) = (value.as_object_mut(), flags.as_object()) else {
            return Err(CliError::Usage("parameters are not a table".into()));
        };
        for (key, v) in given {
            target.insert(key.clone(), v.clone());
        }
        if self.curves.is_some() && self.method.is_none() {
            target.insert("method".into(), "previous".into());
        }
        if self.no_close {
            target.insert("close".into(), false.into());
        }
        // A non-finite number in the file reaches the JSON as null and fails here: the
        // parameters' own check names it. (The flags are finite by their parser, and the
        // combination is checked in full when the run resolves it.)
        serde_json::from_value(value).map_err(|e| match params.check() {
            Err(named) => CliError::Usage(named.to_string()),
            Ok(()) => bad(e),
        })
    }
}

pub(super) fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers like 0,0,1; got \"{s}\""
        ));
    }
    let mut v = [0.0; 3];
    for (i, p) in parts.iter().enumerate() {
        v[i] = parse_finite(p).map_err(|e| format!("{e} (in \"{s}\")"))?;
    }
    Ok(v)
}

/// A finite number (NaN and infinities are refused here, with the flag's name, rather than
/// deep in the run).
pub(super) fn parse_finite(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!("\"{s}\" is not a finite number")),
        Err(_) => Err(format!("\"{s}\" is not a number")),
    }
}

impl MeshArgs {
    /// The job `liemesh` runs without arguments: the fig6 preset into `out/fig6.ply`.
    pub fn default_job() -> MeshArgs {
        MeshArgs {
            preset: Some(Preset::Fig6),
            invariant: None,
            angles: None,
            derivative: Vec::new(),
            output: Some(PathBuf::from("out/fig6.ply")),
            ascii: false,
            report: Some(PathBuf::from("out/fig6.json")),
            scalar: ScalarArg::F64,
            png: None,
            picture: super::render::PictureArgs {
                view: [2.0, -3.0, 1.6],
                perspective: None,
                color_by: "none".into(),
                size: 800,
            },
            quiet: false,
            json: false,
            overrides: Overrides::default(),
        }
    }

    /// The invariant and parameters these arguments describe.
    pub fn job(&self) -> Result<(Option<Preset>, Invariant, MeshParams), CliError> {
        let (preset, invariant, mut params) = match (&self.preset, &self.invariant) {
            (Some(p), None) => (Some(*p), p.invariant(), p.params()),
            (None, Some(path)) => {
                let file = InvariantFile::read(path)?;
                (None, file.invariant, file.params)
            }
            (None, None) => (
                Some(Preset::Fig6),
                Preset::Fig6.invariant(),
                Preset::Fig6.params(),
            ),
            (Some(_), Some(_)) => {
                return Err(CliError::Usage(
                    "give either --preset or --invariant, not both".into(),
                ))
            }
        };
        params = self.overrides.apply(params)?;
        let invariant = match self.angles {
            Some(a) => invariant.with_reading(a.into()),
            None => invariant,
        };
        Ok((preset, invariant, params))
    }
}

/// The result of meshing an invariant.
#[derive(Clone, Debug)]
pub struct MeshOutcome {
    /// The mesh (f64).
    pub mesh: Mesh,
    /// Number of curves traced.
    pub curves: usize,
    /// Wall-clock seconds of sampling and triangulation.
    pub seconds: f64,
    /// The quality report, when asked for.
    pub quality: Option<liemesh::quality::QualityReport>,
    /// What refinement to a normal-error bound did, when asked for.
    pub refinement: Option<liemesh::triangulate::Refinement>,
    /// The parameters with their automatic values.
    pub resolved: liemesh::Resolved,
    /// How many curves ended for each reason.
    pub curve_ends: liemesh::sample::CurveEnds,
    /// The budgets that cut the run short, in words.
    pub cut_short: Vec<String>,
    /// What stitching did.
    pub stitched: liemesh::triangulate::Stitched,
    /// What untangling did.
    pub untangled: liemesh::triangulate::Untangled,
    /// The mesh's validation.
    pub validation: liemesh::mesh::Validation,
}

impl MeshOutcome {
    /// Carries what the run found into `report`.
    pub fn fill(&self, report: &mut Report) {
        report.quality = self.quality.clone();
        report.refinement = self.refinement;
        report.resolved = Some(self.resolved.clone());
        report.curve_ends = self.curve_ends;
        report.cut_short = self.cut_short.clone();
        report.stitched = self.stitched;
        report.untangled = self.untangled;
        report.validation = Some(self.validation.clone());
    }
}

fn mesh_in<T: Scalar>(
    invariant: &Invariant,
    params: &MeshParams,
    measure: bool,
    status: &Status,
) -> Result<MeshOutcome, MeshError> {
    let field = LieField::<T>::new(invariant);
    let start = Instant::now();
    let run = liemesh::run_observed(&field, params, &|p| status.report(p))?;
    let seconds = start.elapsed().as_secs_f64();
    let quality = measure.then(|| {
        status.step(format!(
            "measuring the quality of {} triangles",
            grouped(run.mesh.triangles.len())
        ));
        liemesh::quality::QualityReport::measure(invariant, params, &run.samples, &run.mesh)
    });
    let cut_short = run.cut_short();
    Ok(MeshOutcome {
        curves: run.samples.curves.len(),
        curve_ends: run.samples.ends(),
        mesh: run.mesh,
        seconds,
        quality,
        refinement: run.refinement,
        resolved: run.params,
        cut_short,
        stitched: run.stitched,
        untangled: run.untangled,
        validation: run.validation,
    })
}

/// Meshes `invariant` with `params` in the scalar type `scalar`; with `measure`, also
/// measures the mesh's quality. What it is doing goes to `status`.
pub fn mesh_invariant(
    invariant: &Invariant,
    params: &MeshParams,
    scalar: ScalarKind,
    measure: bool,
    status: &Status,
) -> Result<MeshOutcome, CliError> {
    Ok(match scalar {
        ScalarKind::F32 => mesh_in::<f32>(invariant, params, measure, status)?,
        ScalarKind::F64 => mesh_in::<f64>(invariant, params, measure, status)?,
        ScalarKind::Dual => mesh_in::<Dual<f64>>(invariant, params, measure, status)?,
        ScalarKind::Mpfr => {
            #[cfg(feature = "mpfr")]
            {
                mesh_in::<liemesh::scalar::Mpfr<256>>(invariant, params, measure, status)?
            }
            #[cfg(not(feature = "mpfr"))]
            {
                return Err(CliError::Usage(
                    "--scalar mpfr needs a build with MPFR: rerun with `cargo run --release --features mpfr -- ...`"
                        .into(),
                ));
            }
        }
    })
}

pub(super) fn run(args: &MeshArgs) -> Result<ExitCode, CliError> {
    let (preset, invariant, params) = args.job()?;
    if let Some(out) = &args.output {
        io::MeshFormat::from_path(out)?;
    }
    check_derivative_args(args, &invariant)?;
    for path in [&args.output, &args.report, &args.png]
        .into_iter()
        .flatten()
    {
        check_output_folder(path)?;
    }
    if let Some(png) = &args.png {
        super::picture::picture_format(png)?;
        super::picture::check_options(&args.picture.options())?;
    }
    let scalar = ScalarKind::from(args.scalar);
    let measure = args.report.is_some() || args.json;
    let job = Job::new(
        preset.map(|p| p.name().to_string()),
        &invariant,
        scalar,
        &params,
    );
    let (outcome, derivatives) = with_progress(args.quiet, |status| {
        let outcome = match mesh_invariant(&invariant, &params, scalar, measure, status) {
            Err(CliError::Mesh(e)) => {
                // The report says why there is no mesh (`--report`, `--json`); the error
                // still goes to the terminal and the exit code.
                let failure = FailureReport::new(job.clone(), &e);
                publish(args, &failure)?;
                return Err(CliError::Mesh(e));
            }
            other => other?,
        };
        let derivatives = derivatives(args, &invariant, &params, &outcome.mesh, status)?;
        if let Some(out) = &args.output {
            status.step(format!("writing {}", out.display()));
            write_mesh_with(args, out, &outcome.mesh, &derivatives)?;
        }
        if let Some(png) = &args.png {
            status.step(format!("drawing {}", png.display()));
            super::picture::render_to_file(&outcome.mesh, png, &args.picture.options())?;
        }
        Ok::<_, CliError>((outcome, derivatives))
    })?;
    let mut report = Report::new(job, &outcome.mesh, outcome.curves, outcome.seconds);
    outcome.fill(&mut report);
    report.derivatives = derivatives;
    publish(args, &report)?;
    if !args.json && !args.quiet {
        // The paper mode's explicit-Euler chords leave the surface (a cone's run past the
        // apex onto a hyperboloid): the summary says by how much, on fields with a potential.
        let paper_drift = (params.mode == Mode::Paper)
            .then(|| match &outcome.quality {
                Some(q) => q.drift,
                None => liemesh::quality::drift(&invariant, &outcome.mesh, params.p0),
            })
            .flatten();
        print_summary(
            &report,
            paper_drift,
            args.output.as_deref(),
            args.report.as_deref(),
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Writes `report` where `--report` says and prints it as JSON if `--json` asks.
fn publish<S: serde::Serialize>(args: &MeshArgs, report: &S) -> Result<(), CliError> {
    if let Some(path) = &args.report {
        write_json(path, report)?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(report).expect("reports serialise")
        );
    }
    Ok(())
}

/// The derivatives `--derivative` asks for: one dual-number run per number, whose mesh must
/// be the `f64` run's; the arguments are as [`check_derivative_args`] allows.
fn derivatives(
    args: &MeshArgs,
    invariant: &Invariant,
    params: &MeshParams,
    mesh: &Mesh,
    status: &Status,
) -> Result<Vec<VertexDerivatives>, CliError> {
    // `run` checked the arguments (`check_derivative_args`) before meshing.
    let mut out = Vec::new();
    for &number in &args.derivative {
        // The 6 numbers of a linear invariant are the first row of the 18-number layout.
        let index = number - 1;
        status.step(format!("differentiating by invariant number {number}"));
        let d = liemesh::differentiate(&LieField::<f64>::seeded(invariant, index), params)?;
        if d.mesh.vertices != mesh.vertices || d.mesh.triangles != mesh.triangles {
            return Err(CliError::Usage(format!(
                "--derivative {number}: the dual-number run decided differently from the f64 \
                 run (this is a bug; please report it with the invariant file)"
            )));
        }
        out.push(VertexDerivatives::new(number, d.d_vertices));
    }
    Ok(out)
}

/// What `--derivative` needs of the other arguments, checked before the mesh is made (a
/// conflict found after a long run wastes it).
fn check_derivative_args(args: &MeshArgs, invariant: &Invariant) -> Result<(), CliError> {
    if args.derivative.is_empty() {
        return Ok(());
    }
    if args.scalar != ScalarArg::F64 {
        return Err(CliError::Usage(
            "--derivative differentiates the f64 run: leave out --scalar or give --scalar f64"
                .into(),
        ));
    }
    if let Some(out) = &args.output {
        if io::MeshFormat::from_path(out)? != io::MeshFormat::Ply {
            return Err(CliError::Usage(format!(
                "--derivative writes PLY vertex properties: give an output ending in .ply, not {}",
                out.display()
            )));
        }
    }
    let count = invariant.numbers().len();
    if let Some(number) = args
        .derivative
        .iter()
        .find(|&&number| number == 0 || number > count)
    {
        return Err(CliError::Usage(format!(
            "--derivative {number}: the invariant has {count} numbers, counted from 1"
        )));
    }
    Ok(())
}

/// An output's folder is made if missing, so a path is unusable only where some part of
/// its folder is a file: said before the mesh is made, not after.
fn check_output_folder(path: &Path) -> Result<(), CliError> {
    let mut folder = path.parent();
    while let Some(f) = folder.filter(|f| !f.as_os_str().is_empty()) {
        if f.exists() {
            if f.is_dir() {
                return Ok(());
            }
            return Err(CliError::Usage(format!(
                "cannot write {}: {} is a file, not a folder",
                path.display(),
                f.display()
            )));
        }
        folder = f.parent();
    }
    Ok(())
}

/// Writes the mesh, with the derivatives as PLY vertex properties when there are any.
fn write_mesh_with(
    args: &MeshArgs,
    out: &Path,
    mesh: &Mesh,
    derivatives: &[VertexDerivatives],
) -> Result<(), CliError> {
    if derivatives.is_empty() {
        io::write_mesh(
            mesh,
            out,
            &WriteOptions {
                ply_ascii: args.ascii,
            },
        )?;
        return Ok(());
    }
    let stems: Vec<String> = derivatives
        .iter()
        .map(|d| VertexDerivatives::stem(d.number))
        .collect();
    let extra: Vec<io::VertexVectors> = derivatives
        .iter()
        .zip(&stems)
        .map(|(d, stem)| io::VertexVectors {
            name: stem,
            values: &d.values,
        })
        .collect();
    let encoding = if args.ascii {
        io::PlyEncoding::Ascii
    } else {
        io::PlyEncoding::BinaryLittleEndian
    };
    let write = || -> Result<(), io::IoError> {
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|source| io::IoError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        let file = std::fs::File::create(out).map_err(|source| io::IoError::Io {
            path: out.to_path_buf(),
            source,
        })?;
        let mut w = std::io::BufWriter::new(file);
        io::write_ply_with(mesh, &extra, &mut w, encoding)?;
        std::io::Write::flush(&mut w).map_err(|source| io::IoError::Io {
            path: out.to_path_buf(),
            source,
        })
    };
    Ok(write()?)
}

pub(super) fn write_json<S: serde::Serialize>(path: &Path, value: &S) -> Result<(), CliError> {
    let write = || -> std::io::Result<()> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let mut text = serde_json::to_string_pretty(value).map_err(std::io::Error::other)?;
        text.push('\n');
        std::fs::write(path, text)
    };
    write().map_err(|source| CliError::Write {
        path: path.to_path_buf(),
        source,
    })
}

fn print_summary(
    r: &Report,
    paper_drift: Option<Drift>,
    mesh: Option<&Path>,
    report: Option<&Path>,
) {
    let name = r.job.preset.as_deref().unwrap_or("invariant");
    println!("liemesh: {name} ({} scalars)", r.job.scalar);
    println!("  vertices   {}", r.vertices);
    println!("  triangles  {}", r.triangles);
    println!("  curves     {}", r.curves);
    println!(
        "  topology   {} (Euler characteristic {}, {} boundary loop{})",
        if r.closed { "closed" } else { "open" },
        r.euler_characteristic,
        r.boundary_loops,
        if r.boundary_loops == 1 { "" } else { "s" }
    );
    let e = &r.curve_ends;
    println!(
        "  curve ends {} met other fronts, {} merged, {} at the radius, {} at the box, {} \
         singular, {} on a budget",
        e.collision, e.merge, e.radius, e.bounding_box, e.singular, e.budget
    );
    if let Some(v) = &r.validation {
        println!("  validation {v}");
    }
    let holes = r.stitched.holes;
    if holes > 0 {
        println!(
            "  holes      {holes} boundary loop{} where the surface goes on (none of its \
             vertices at the radius, the box, a singular point or a budget; or, round a band's \
             waist, a loop that does not go round it): fronts that met and were not stitched, \
             or a swept surface cut back",
            if holes == 1 { "" } else { "s" }
        );
    }
    if r.untangled.removed + r.untangled.reverted > 0 {
        println!(
            "  untangled  {} relaxation moves taken back, {} crossing faces removed",
            r.untangled.reverted, r.untangled.removed
        );
    }
    let off = r.untangled.off_surface;
    if off > 0 {
        println!(
            "  singular   {off} face{} more than {}° off the surface beside a singular point \
             removed: the mesh stops short of it there",
            if off == 1 { "" } else { "s" },
            liemesh::triangulate::SINGULAR_FAN_DEG
        );
    }
    if let Some(d) = paper_drift {
        println!(
            "  drift      vertices up to {:.1e} of the mesh's diagonal off p0's level set (rms \
             {:.1e}): the paper mode's explicit-Euler chords leave the surface; the default \
             mode stays on it",
            d.max, d.rms
        );
    }
    if !r.cut_short.is_empty() {
        println!("  INCOMPLETE {}", r.cut_short.join("; "));
    }
    println!("  time       {:.2} ms", r.seconds * 1e3);
    if let (Some(f), Some(limit)) = (&r.refinement, r.job.parameters.max_normal_error) {
        let limit = limit.degrees();
        println!(
            "  refinement {} vertices in {} round{}; {}",
            f.added,
            f.rounds,
            if f.rounds == 1 { "" } else { "s" },
            if f.over_limit == 0 {
                format!("every face within {limit}° of the field normal")
            } else if f.stalled {
                format!(
                    "{} faces still over {limit}° (the rounds stopped making progress: smaller \
                     faces only tilted more, their corners not on one surface, which the \
                     paper's chords drift off and a non-integrable field does not have)",
                    f.over_limit
                )
            } else {
                format!(
                    "{} faces still over {limit}° (the rounds or the point budget ran out, or \
                     splits there would fold the mesh)",
                    f.over_limit
                )
            }
        );
    }
    if let Some(m) = mesh {
        println!("  mesh       {}", m.display());
    }
    if let Some(p) = report {
        println!("  report     {}", p.display());
    }
}
