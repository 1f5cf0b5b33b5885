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
        if r64.mesh.canonical_triangles() == rmp.mesh.canonical_triangles() {
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
