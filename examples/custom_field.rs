//! Mesh a surface given by your own closure: the gradient of an ellipsoid
//! `x² + (y/1.5)² + (z/2)² = 1`, written once for `Dual<f64>` so that the mesher gets both
//! the normal and its derivative from one forward-mode pass.
//!
//! Run with `cargo run --release --example custom_field`.

use liemesh::model::FnField;
use liemesh::quality::Topology;
use liemesh::scalar::{Dual, Vec3};
use liemesh::{generate, MeshParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (a2, b2, c2) = (1.0, 1.5 * 1.5, 2.0 * 2.0);
    // ∇(x²/a² + y²/b² + z²/c²) / 2
    let field = FnField::new(move |p: &Vec3<Dual<f64>>| {
        Vec3::new(
            p.x.clone() / Dual::constant(a2),
            p.y.clone() / Dual::constant(b2),
            p.z.clone() / Dual::constant(c2),
        )
    });
    // Start on the shortest axis, heading along the middle one; the step lengths and the
    // terminal conditions follow the surface's size and curvature there.
    let mut params = MeshParams::at([1.0, 0.0, 0.0]);
    params.w00 = Some([0.0, 1.0, 0.0]);
    let mesh = generate(&field, &params)?;
    let topology = Topology::of(&mesh);
    println!("ellipsoid x² + (y/1.5)² + (z/2)² = 1, proposed method from p0 = (1, 0, 0)");
    println!("  vertices   {}", mesh.vertices.len());
    println!("  triangles  {}", mesh.triangles.len());
    println!(
        "  topology   {} (Euler characteristic {})",
        if topology.closed { "closed" } else { "open" },
        topology.euler_characteristic
    );
    let worst = mesh
        .vertices
        .iter()
        .map(|v| (v[0] * v[0] / a2 + v[1] * v[1] / b2 + v[2] * v[2] / c2 - 1.0).abs())
        .fold(0.0_f64, f64::max);
    println!("  largest |f(v) - 1| over the vertices: {worst:.3e}");
    Ok(())
}
