//! liemesh against a grid-based mesher on the unit sphere, at about 10⁵ triangles each:
//! `fast-surface-nets` (naive surface nets on a signed-distance grid) and liemesh's sphere
//! workload (`liemesh bench`'s `sphere-1e5`). Prints one row per mesher: triangles, median
//! time, the largest vertex drift off the sphere and the largest angle between a face's normal
//! and the sphere's normal at the face's centroid.
//!
//! ```sh
//! cargo run --release --example vs_surface_nets
//! ```

#[allow(dead_code)]
#[path = "../src/cli/workloads.rs"]
mod workloads;

use fast_surface_nets::ndshape::{RuntimeShape, Shape};
use fast_surface_nets::{surface_nets, SurfaceNetsBuffer};
use liemesh::model::LieField;
use std::time::Instant;

/// Runs of each mesher; the median time is printed.
const RUNS: usize = 5;

/// The largest `| |p| − 1 |` and the largest face-normal error (degrees) of a triangle soup on
/// the unit sphere.
fn errors(points: &[[f64; 3]], triangles: &[[u32; 3]]) -> (f64, f64) {
    let drift = points
        .iter()
        .map(|p| ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs())
        .fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| points[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let m = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
        let dot = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
        let nn = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let mm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        if nn > 0.0 && mm > 0.0 {
            // Either orientation: surface nets' winding is its own convention.
            let cos = (dot / (nn * mm)).abs().min(1.0);
            worst = worst.max(cos.acos().to_degrees());
        }
    }
    (drift, worst)
}

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Surface nets: radius 64 voxels in a grid with a voxel of margin (about 10⁵ triangles).
    let radius = 64.0f32;
    let n = 2 * radius as u32 + 4;
    let shape = RuntimeShape::<u32, 3>::new([n, n, n]);
    let centre = (n as f32 - 1.0) / 2.0;
    let mut times = Vec::new();
    let mut buffer = SurfaceNetsBuffer::default();
    for _ in 0..RUNS {
        let start = Instant::now();
        let mut sdf = vec![0.0f32; shape.usize()];
        for (i, value) in sdf.iter_mut().enumerate() {
            let [x, y, z] = shape.delinearize(i as u32);
            let d = [x, y, z].map(|c| c as f32 - centre);
            *value = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - radius;
        }
        surface_nets(&sdf, &shape, [0; 3], [n - 1; 3], &mut buffer);
        times.push(start.elapsed().as_secs_f64());
    }
    let points: Vec<[f64; 3]> = buffer
        .positions
        .iter()
        .map(|p| p.map(|c| f64::from((c - centre) / radius)))
        .collect();
    let triangles: Vec<[u32; 3]> = buffer
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let (drift, normal) = errors(&points, &triangles);
    println!("| mesher | triangles | ms (median of {RUNS}) | largest drift off the sphere | largest face-normal error (°) |");
    println!("|---|---:|---:|---:|---:|");
    println!(
        "| fast-surface-nets 0.2 (f32 grid, SDF sampling included) | {} | {:.1} | {:.1e} | {:.2} |",
        triangles.len(),
        median(times) * 1e3,
        drift,
        normal
    );

    // liemesh: the sphere workload of `liemesh bench` at about 10⁵ triangles.
    let (invariant, params) = workloads::workload_params(false, 100_000);
    let field = LieField::<f64>::new(&invariant);
    let mut times = Vec::new();
    let mut mesh = None;
    for _ in 0..RUNS {
        let start = Instant::now();
        let run = liemesh::run(&field, &params)?;
        times.push(start.elapsed().as_secs_f64());
        mesh = Some(run.mesh);
    }
    let mesh = mesh.expect("at least one run");
    let (drift, normal) = errors(&mesh.vertices, &mesh.triangles);
    println!(
        "| liemesh (f64, validated, closed) | {} | {:.1} | {:.1e} | {:.2} |",
        mesh.triangles.len(),
        median(times) * 1e3,
        drift,
        normal
    );
    Ok(())
}
