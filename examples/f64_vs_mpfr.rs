//! Audit f64 against 256-bit MPFR: mesh fig3 in both and print the largest vertex difference.
//!
//! Run with `cargo run --release --features mpfr --example f64_vs_mpfr`.

use liemesh::model::LieField;
use liemesh::preset::Preset;
use liemesh::run;
use liemesh::scalar::{Mpfr, Scalar};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let preset = Preset::Fig3;
    let invariant = preset.invariant();
    let params = preset.params();
    let r64 = run(&LieField::<f64>::new(&invariant), &params)?;
    let rmp = run(&LieField::<Mpfr<256>>::new(&invariant), &params)?;
    println!(
        "fig3: f64 {} points / {} triangles, Mpfr<256> {} points / {} triangles",
        r64.samples.points.len(),
        r64.mesh.triangles.len(),
        rmp.samples.points.len(),
        rmp.mesh.triangles.len()
    );
    println!(
        "same triangles: {}",
        if canonical(&r64.mesh.triangles) == canonical(&rmp.mesh.triangles) {
            "yes"
        } else {
            "no"
        }
    );
    let worst = r64
        .samples
        .points
        .iter()
        .zip(&rmp.samples.points)
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k].to_f64()).abs()))
        .fold(0.0_f64, f64::max);
    println!("largest |f64 - Mpfr<256>| over the vertex coordinates: {worst:.3e}");
    Ok(())
}

/// Triangles rotated to start at their smallest index, sorted: the same triangle set compares
/// equal however each triangle's listing starts.
fn canonical(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut v: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect();
    v.sort_unstable();
    v
}
