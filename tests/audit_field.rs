//! The audits of fields of one's own (issue: your own surface, end to end): a torus and an
//! ellipsoid written once as [`FieldFormula`]s, and an invariant file, audited in every scalar
//! type — with the `mpfr` feature against `Mpfr<256>` meshes and `Mpfr<512>` central
//! differences.

use liemesh::audit::{audit_field, Row};
use liemesh::model::{FieldFormula, Formula};
use liemesh::scalar::{Scalar, Vec3};
use liemesh::MeshParams;

/// The torus `(√(x² + y²) − R)² + z² = a²` (a quarter of its quartic's gradient).
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

/// A user quadric: the ellipsoid `(x/a)² + (y/b)² + (z/c)² = 1`, half its gradient.
#[derive(Clone)]
struct Ellipsoid([f64; 3]);

impl FieldFormula for Ellipsoid {
    fn normal<T: Scalar>(&self, p: &Vec3<T>) -> Vec3<T> {
        let k = |i: usize| T::from_f64(1.0 / (self.0[i] * self.0[i]));
        Vec3::new(p.x.clone() * k(0), p.y.clone() * k(1), p.z.clone() * k(2))
    }
}

fn assert_all_pass(rows: &[Row]) {
    let failed: Vec<&Row> = rows.iter().filter(|r| !r.pass).collect();
    assert!(failed.is_empty(), "failed rows: {failed:#?}");
    // With MPFR the references are Mpfr<256> meshes and Mpfr<512> central differences.
    let mpfr_rows = rows
        .iter()
        .filter(|r| r.check.contains("Mpfr") || r.scalar.contains("Mpfr"))
        .count();
    if cfg!(feature = "mpfr") {
        assert!(mpfr_rows >= 6, "{rows:#?}");
    }
}

#[test]
fn a_torus_written_once_passes_every_audit() {
    let torus = Formula(Torus {
        big: 2.0,
        small: 0.75,
    });
    let rows = audit_field(&torus, &MeshParams::at([2.75, 0.0, 0.0]), "torus");
    assert_all_pass(&rows);
    assert!(
        rows[0].note.contains("closed") && rows[0].note.contains("genus 1"),
        "{}",
        rows[0].note
    );
}

#[test]
fn an_ellipsoid_written_once_passes_every_audit() {
    let ellipsoid = Formula(Ellipsoid([1.0, 1.5, 2.0]));
    let rows = audit_field(&ellipsoid, &MeshParams::at([1.0, 0.0, 0.0]), "ellipsoid");
    assert_all_pass(&rows);
}

#[cfg(feature = "toml")]
#[test]
fn an_invariant_file_passes_every_audit() {
    let file = liemesh::io::invariant_file::InvariantFile::read(std::path::Path::new(
        "examples/surfaces/cubic.toml",
    ))
    .unwrap();
    assert_all_pass(&audit_field(&file.invariant, &file.params, "cubic"));
}
