//! Mesh surfaces of your own, written once for every scalar type, and audit them.
//!
//! A [`FieldFormula`] is the normal field written once, generic over the scalar type; wrapped
//! in [`Formula`] it runs in `f32`, `f64`, `Dual<f64>` and `Mpfr<N>`, its Jacobian-vector
//! products come from dual numbers, and `audit::audit_field` can compare its `f64` mesh with
//! the same mesh at 256 bits. Two fields: a torus (genus 1) and an ellipsoid written by hand.
//!
//! Run with `cargo run --release --example custom_field` (add `--features mpfr` for the MPFR
//! rows of the audit). With a file name after `--` (`.ply`, `.obj` or `.stl`) it also writes
//! the torus's mesh there, for `liemesh render` or any mesh viewer.

use liemesh::audit::audit_field;
use liemesh::io::{write_mesh, WriteOptions};
use liemesh::model::{FieldFormula, Formula};
use liemesh::scalar::{Scalar, Vec3};
use liemesh::{generate, MeshParams};

/// The torus `(√(x² + y²) − R)² + z² = a²`: a quarter of the gradient of its quartic
/// `(|p|² + R² − a²)² − 4R²(x² + y²)`.
#[derive(Clone)]
struct Torus {
    big: f64,
    small: f64,
}

impl FieldFormula for Torus {
    fn normal<T: Scalar>(&self, p: &Vec3<T>) -> Vec3<T> {
        let c = |x: f64| T::from_f64(x);
        let s = p.norm_squared() + c(self.big * self.big - self.small * self.small);
        let around = s.clone() - c(2.0 * self.big * self.big);
        Vec3::new(
            p.x.clone() * around.clone(),
            p.y.clone() * around,
            p.z.clone() * s,
        )
    }
}

/// The ellipsoid `(x/a)² + (y/b)² + (z/c)² = 1`: half the gradient.
#[derive(Clone)]
struct Ellipsoid {
    axes: [f64; 3],
}

impl FieldFormula for Ellipsoid {
    fn normal<T: Scalar>(&self, p: &Vec3<T>) -> Vec3<T> {
        let k = |i: usize| T::from_f64(1.0 / (self.axes[i] * self.axes[i]));
        Vec3::new(p.x.clone() * k(0), p.y.clone() * k(1), p.z.clone() * k(2))
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let torus = Formula(Torus {
        big: 2.0,
        small: 0.75,
    });
    let ellipsoid = Formula(Ellipsoid {
        axes: [1.0, 1.5, 2.0],
    });
    // Start on the surface; every other parameter follows its size and curvature there.
    let torus_params = MeshParams::at([2.75, 0.0, 0.0]);
    let ellipsoid_params = MeshParams::at([1.0, 0.0, 0.0]);

    // A formula runs in every scalar type, so say which one meshes it (`::<f64, _>`).
    let torus_mesh = generate::<f64, _>(&torus, &torus_params)?;
    let ellipsoid_mesh = generate::<f64, _>(&ellipsoid, &ellipsoid_params)?;
    for (name, mesh) in [
        ("torus R = 2, a = 0.75", &torus_mesh),
        ("ellipsoid 1 × 1.5 × 2", &ellipsoid_mesh),
    ] {
        let v = mesh.validate();
        println!("{name}: {} triangles, {v}", mesh.triangles.len());
    }
    if let Some(path) = std::env::args_os().nth(1) {
        write_mesh(&torus_mesh, path.as_ref(), &WriteOptions::default())?;
        println!("torus written to {}", path.to_string_lossy());
    }
    // The same formula in single precision.
    let mesh32 = generate::<f32, _>(&torus, &torus_params)?;
    println!("torus in f32: {} triangles", mesh32.triangles.len());

    println!("\naudit of the ellipsoid (every row must pass):");
    for row in audit_field(&ellipsoid, &ellipsoid_params, "ellipsoid") {
        println!(
            "  {:<5} {:<38} {:<16} {:.3e} (bound {:.1e})",
            if row.pass { "pass" } else { "FAIL" },
            row.check,
            row.scalar,
            row.measured,
            row.bound
        );
    }
    Ok(())
}
