//! `liemesh paper`: the paper's six figures and Table 3, reproduced.

use super::picture::{render_to_file, RenderOptions};
use super::CliError;
use clap::Args;
use liemesh::io::{self, WriteOptions};
use liemesh::preset::Preset;
use liemesh::quality::Topology;
use liemesh::scalar::ScalarKind;
use liemesh::Mesh;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `liemesh paper`.
#[derive(Debug, Clone, Args)]
pub struct PaperArgs {
    /// Directory for fig1..fig6 (.ply and .png) and table.md; created if missing.
    #[arg(short, long, value_name = "DIR", default_value = "paper")]
    pub output: PathBuf,
}

/// Table 3 of the paper: (number of meshes, seconds on a 443 MHz UltraSPARC III).
pub const PAPER_TABLE3: [(Preset, usize, f64); 6] = [
    (Preset::Fig1, 945, 2.47),
    (Preset::Fig2, 4360, 4.51),
    (Preset::Fig3, 3605, 3.54),
    (Preset::Fig4, 709, 2.64),
    (Preset::Fig5, 2532, 4.41),
    (Preset::Fig6, 1497, 4.00),
];

/// One row of the comparison.
#[derive(Clone, Debug)]
pub struct PaperRow {
    /// The figure.
    pub preset: Preset,
    /// Meshes (triangles) the paper reports.
    pub paper_meshes: usize,
    /// Seconds the paper reports.
    pub paper_seconds: f64,
    /// Our triangles.
    pub triangles: usize,
    /// Our vertices.
    pub vertices: usize,
    /// Our wall-clock milliseconds (sampling and triangulation, f64).
    pub milliseconds: f64,
    /// Our mesh's topology.
    pub topology: Topology,
    /// Smallest interior angle of any triangle, degrees.
    pub min_angle_degrees: f64,
}

impl PaperRow {
    /// Paper's time over ours.
    pub fn speedup(&self) -> f64 {
        self.paper_seconds * 1e3 / self.milliseconds
    }
}

/// Smallest interior angle of any triangle of `mesh`, in degrees (180 for an empty mesh).
pub fn min_angle_degrees(mesh: &Mesh) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let angle = |u: [f64; 3], v: [f64; 3]| {
        let dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let cross = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let c = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
        c.atan2(dot)
    };
    let mut smallest = std::f64::consts::PI;
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.vertices[i as usize]);
        for k in 0..3 {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            smallest = smallest.min(angle(sub(b, a), sub(c, a)));
        }
    }
    smallest.to_degrees()
}

/// Runs the six presets in f64, writing `DIR/figN.ply` and `DIR/figN.png`.
pub fn reproduce(dir: &std::path::Path) -> Result<Vec<PaperRow>, CliError> {
    std::fs::create_dir_all(dir).map_err(|source| CliError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut rows = Vec::new();
    for (preset, paper_meshes, paper_seconds) in PAPER_TABLE3 {
        let outcome = super::mesh::mesh_invariant(
            &preset.invariant(),
            &preset.params(),
            ScalarKind::F64,
            false,
            &super::progress::Status::default(),
        )?;
        let mesh = &outcome.mesh;
        io::write_mesh(
            mesh,
            &dir.join(format!("{preset}.ply")),
            &WriteOptions::default(),
        )?;
        render_to_file(
            mesh,
            dir.join(format!("{preset}.png")),
            &RenderOptions::default(),
        )?;
        rows.push(PaperRow {
            preset,
            paper_meshes,
            paper_seconds,
            triangles: mesh.triangles.len(),
            vertices: mesh.vertices.len(),
            milliseconds: outcome.seconds * 1e3,
            topology: Topology::of(mesh),
            min_angle_degrees: min_angle_degrees(mesh),
        });
    }
    Ok(rows)
}

/// The comparison as a Markdown table (deterministic except for the time columns).
pub fn markdown_table(rows: &[PaperRow]) -> String {
    let mut s = String::new();
    s.push_str("| preset | paper meshes | paper s | our triangles | our vertices | our ms | paper time / ours | closed | Euler χ | min angle (°) |\n");
    s.push_str("|---|---:|---:|---:|---:|---:|---:|---|---:|---:|\n");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {} | {} | {:.1} | {:.0} | {} | {} | {:.2} |",
            r.preset,
            r.paper_meshes,
            r.paper_seconds,
            r.triangles,
            r.vertices,
            r.milliseconds,
            r.speedup(),
            if r.topology.closed { "yes" } else { "no" },
            r.topology.euler_characteristic,
            r.min_angle_degrees,
        );
    }
    s
}

fn text_table(rows: &[PaperRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<6} {:>12} {:>8} {:>10} {:>9} {:>9} {:>8} {:>6} {:>5} {:>9}",
        "preset",
        "paper meshes",
        "paper s",
        "triangles",
        "vertices",
        "ours ms",
        "ratio",
        "closed",
        "euler",
        "min angle"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<6} {:>12} {:>8.2} {:>10} {:>9} {:>9.1} {:>8.0} {:>6} {:>5} {:>9.2}",
            r.preset.name(),
            r.paper_meshes,
            r.paper_seconds,
            r.triangles,
            r.vertices,
            r.milliseconds,
            r.speedup(),
            if r.topology.closed { "yes" } else { "no" },
            r.topology.euler_characteristic,
            r.min_angle_degrees,
        );
    }
    s
}

pub(super) fn run(args: &PaperArgs) -> Result<ExitCode, CliError> {
    let rows = reproduce(&args.output)?;
    let table = args.output.join("table.md");
    let mut md = String::from(
        "Table 3 of the paper (443 MHz UltraSPARC III) against liemesh (f64, this machine); \
         ratio = paper seconds / our seconds.\n\n",
    );
    md.push_str(&markdown_table(&rows));
    std::fs::write(&table, md).map_err(|source| CliError::Write {
        path: table.clone(),
        source,
    })?;
    println!("Table 3: paper (443 MHz UltraSPARC III) vs liemesh (f64); ratio = paper time / ours");
    print!("{}", text_table(&rows));
    println!(
        "wrote {} (fig1..fig6 .ply and .png, table.md)",
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
