//! Invariants and the matrices they define (paper eq. 2–4, DESIGN.md §1).

use crate::scalar::{Scalar, Vec3};
use thiserror::Error;

/// A 3×3 matrix as three rows.
pub type Mat3<T> = [Vec3<T>; 3];

/// What is wrong with a list of invariant numbers.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum InvariantError {
    /// The count is none of 6, 12, 18.
    #[error(
        "an invariant has 6 numbers (linear: λ1 λ2 λ3 θ φ ψ), 12 (Hamiltonian, the paper's text \
         order λ11 λ12 λ13 λ21 λ22 λ23 λ31 λ32 λ33 θ1 φ1 ψ1) or 18 (Hamiltonian, the three rows \
         of the paper's Table 2); got {0}"
    )]
    WrongCount(usize),
    /// A number is NaN or infinite.
    #[error("invariant number {index} (counting from 1) is {value}; every number must be finite")]
    NonFinite {
        /// One-based position of the offending number.
        index: usize,
        /// The value found.
        value: f64,
    },
    /// Every λ is zero: the matrices are zero whatever the angles, and so is the field, at
    /// every point.
    #[error(
        "every λ of the invariant is 0, so its normal field vanishes everywhere and there is \
         no surface to mesh; give at least one non-zero λ (the angles alone do not make a field)"
    )]
    ZeroField,
}

/// Which Lie algebra an invariant belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum InvariantKind {
    /// 6 numbers, `v = A p`.
    Linear,
    /// 12 or 18 numbers, `H = [[A, B], [C, −Aᵀ]]`.
    Hamiltonian,
}

/// How a point of 3-space is lifted to R⁶ before `H` is applied.
///
/// The paper's eq. 5 applies the 6×6 `H` to a point without saying how a point of R³
/// becomes a vector of R⁶. This project reads it as `ℓ(p) = (p, p∘p)` (componentwise
/// squares), so that `v(p)`, the upper block of `H ℓ(p)`, is `A p + B (p∘p)`: linear when
/// `B = 0`, non-linear otherwise, as the paper's figures 4–6 are. `C` then does not change
/// the 3-D field; it stays part of the invariant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Lift {
    /// `ℓ(p) = (p, p∘p)`.
    #[default]
    Squares,
}

impl Lift {
    /// The lower half of the lifted point (the upper half is `p` itself).
    #[inline(always)]
    pub fn lower<T: Scalar>(self, p: &Vec3<T>) -> Vec3<T> {
        match self {
            Lift::Squares => {
                let square = |x: &T| x.product(x);
                Vec3::new(square(&p.x), square(&p.y), square(&p.z))
            }
        }
    }

    /// The derivative of [`Lift::lower`] at `p` along `w`, rounded as a dual-number pass
    /// rounds it (`w p + p w` for a square).
    #[inline(always)]
    pub fn lower_derivative<T: Scalar>(self, p: &Vec3<T>, w: &Vec3<T>) -> Vec3<T> {
        match self {
            Lift::Squares => {
                let derivative = |x: &T, dx: &T| {
                    let mut r = dx.product(x);
                    r.add_product(x, dx);
                    r
                };
                Vec3::new(
                    derivative(&p.x, &w.x),
                    derivative(&p.y, &w.y),
                    derivative(&p.z, &w.z),
                )
            }
        }
    }
}

/// How the three angles of an invariant row turn its matrix (DESIGN.md §1). Angles are in
/// radians; `R = Rx(θ) Ry(φ) Rz(ψ)`, each a right-handed rotation about a coordinate axis.
///
/// ```
/// use liemesh::model::{AngleReading, Invariant};
/// // The unit sphere turned by any angles is still the unit sphere in the quadric reading...
/// let turned = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.3, 0.5, 0.7])?
///     .with_reading(AngleReading::Quadric);
/// let a = turned.a_matrix::<f64>();
/// assert!((a[0].x - 1.0).abs() < 1e-15 && a[0].y.abs() < 1e-15);
/// // ...but not in the paper's literal reading, where A = R is not symmetric.
/// let literal = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.3, 0.5, 0.7])?;
/// assert!((literal.a_matrix::<f64>()[0].y - literal.a_matrix::<f64>()[1].x).abs() > 0.1);
/// # Ok::<(), liemesh::model::InvariantError>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum AngleReading {
    /// The paper's eq. 2 read literally: `A = diag(λ) R`. Not symmetric once an angle is
    /// non-zero, so the field is then not a gradient and the surface is a swept one.
    #[default]
    Literal,
    /// A posed quadric: `A = Rᵀ diag(λ) R`, the quadric with axes scaled by `λ`, turned by
    /// `Rᵀ` (its principal axes are the rows of `R`). Symmetric, so the field is the gradient of
    /// `½ pᵀ A p` (plus the cubic terms of a diagonal `B`).
    Quadric,
}

impl AngleReading {
    /// The row's matrix, `(λ1, λ2, λ3, θ, φ, ψ)` read this way, in any scalar type.
    pub fn matrix<T: Scalar>(self, row: &[T]) -> Mat3<T> {
        match self {
            AngleReading::Literal => Invariant::row_matrix(row),
            AngleReading::Quadric => {
                let r = Invariant::row_matrix(&[
                    T::one(),
                    T::one(),
                    T::one(),
                    row[3].clone(),
                    row[4].clone(),
                    row[5].clone(),
                ]);
                // (Rᵀ Λ R)_ij = Σ_k R_ki λ_k R_kj, computed once per pair so that the matrix
                // is exactly symmetric (the field then is exactly a gradient).
                let entry = |i: usize, j: usize| {
                    let mut s = T::zero();
                    for (k, rk) in r.iter().enumerate() {
                        s.add_product(&rk[i].product(&row[k]), &rk[j]);
                    }
                    s
                };
                let (xy, xz, yz) = (entry(0, 1), entry(0, 2), entry(1, 2));
                [
                    Vec3::new(entry(0, 0), xy.clone(), xz.clone()),
                    Vec3::new(xy, entry(1, 1), yz.clone()),
                    Vec3::new(xz, yz, entry(2, 2)),
                ]
            }
        }
    }

    /// The name used in invariant files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            AngleReading::Literal => "literal",
            AngleReading::Quadric => "quadric",
        }
    }
}

/// The numbers that define a surface.
///
/// Stored in the 18-number form: row `k` is `(λ1k, λ2k, λ3k, θk, φk, ψk)`, angles in radians;
/// row 1 is `A`, row 2 is `B`, row 3 is `C`. A linear invariant has rows 2 and 3 zero. Each
/// row builds its matrix as its [`AngleReading`] says: `diag(λ) Rx(θ) Ry(φ) Rz(ψ)` (the
/// paper's eq. 2, the default) or `Rᵀ diag(λ) R` (a posed quadric).
///
/// ```
/// use liemesh::model::Invariant;
/// let sphere = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).unwrap();
/// let a = sphere.a_matrix::<f64>();
/// assert_eq!(a[1].y, 1.0);
/// // The paper's text form: λ11 λ12 λ13 λ21 λ22 λ23 λ31 λ32 λ33 θ1 φ1 ψ1.
/// let h = Invariant::from_numbers(&[1.0, 0.5, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
/// assert!(h.is_in_sp6());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Invariant {
    kind: InvariantKind,
    rows: [[f64; 6]; 3],
    #[cfg_attr(feature = "serde", serde(default))]
    reading: AngleReading,
}

impl Invariant {
    /// Reads 6, 12 or 18 numbers (see [`InvariantError::WrongCount`] for the orders).
    pub fn from_numbers(numbers: &[f64]) -> Result<Self, InvariantError> {
        if let Some((i, &v)) = numbers.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(InvariantError::NonFinite {
                index: i + 1,
                value: v,
            });
        }
        let mut rows = [[0.0; 6]; 3];
        let kind = match numbers.len() {
            6 => {
                rows[0].copy_from_slice(numbers);
                InvariantKind::Linear
            }
            12 => {
                // λ11 λ12 λ13 λ21 λ22 λ23 λ31 λ32 λ33 θ1 φ1 ψ1
                for (i, row) in rows.iter_mut().enumerate() {
                    row[0] = numbers[i];
                    row[1] = numbers[3 + i];
                    row[2] = numbers[6 + i];
                }
                rows[0][3..6].copy_from_slice(&numbers[9..12]);
                InvariantKind::Hamiltonian
            }
            18 => {
                for (k, row) in rows.iter_mut().enumerate() {
                    row.copy_from_slice(&numbers[6 * k..6 * k + 6]);
                }
                InvariantKind::Hamiltonian
            }
            n => return Err(InvariantError::WrongCount(n)),
        };
        if rows.iter().all(|row| row[..3].iter().all(|&l| l == 0.0)) {
            return Err(InvariantError::ZeroField);
        }
        Ok(Invariant {
            kind,
            rows,
            reading: AngleReading::default(),
        })
    }

    /// The same numbers with the angles read as `reading` says.
    pub fn with_reading(mut self, reading: AngleReading) -> Self {
        self.reading = reading;
        self
    }

    /// How the angles are read.
    pub fn reading(&self) -> AngleReading {
        self.reading
    }

    /// Linear or Hamiltonian.
    pub fn kind(&self) -> InvariantKind {
        self.kind
    }

    /// The three rows `(λ1k, λ2k, λ3k, θk, φk, ψk)`.
    pub fn rows(&self) -> &[[f64; 6]; 3] {
        &self.rows
    }

    /// The defining numbers: 6 for a linear invariant, 18 (the Table 2 rows) otherwise.
    pub fn numbers(&self) -> Vec<f64> {
        match self.kind {
            InvariantKind::Linear => self.rows[0].to_vec(),
            InvariantKind::Hamiltonian => self.rows.iter().flatten().copied().collect(),
        }
    }

    /// `diag(λ) · Rx(θ) · Ry(φ) · Rz(ψ)` from one row, in any scalar type (the literal
    /// reading; [`AngleReading::matrix`] reads a row either way).
    pub fn row_matrix<T: Scalar>(row: &[T]) -> Mat3<T> {
        let (s1, c1) = (row[3].sin(), row[3].cos());
        let (s2, c2) = (row[4].sin(), row[4].cos());
        let (s3, c3) = (row[5].sin(), row[5].cos());
        let z = T::zero;
        let o = T::one;
        let rx = [
            Vec3::new(o(), z(), z()),
            Vec3::new(z(), c1.clone(), -s1.clone()),
            Vec3::new(z(), s1, c1),
        ];
        let ry = [
            Vec3::new(c2.clone(), z(), s2.clone()),
            Vec3::new(z(), o(), z()),
            Vec3::new(-s2, z(), c2),
        ];
        let rz = [
            Vec3::new(c3.clone(), -s3.clone(), z()),
            Vec3::new(s3, c3, z()),
            Vec3::new(z(), z(), o()),
        ];
        let r = mat_mul(&mat_mul(&rx, &ry), &rz);
        [
            r[0].scale(&row[0]),
            r[1].scale(&row[1]),
            r[2].scale(&row[2]),
        ]
    }

    /// The invariant's numbers in the 18-number layout, converted to `T`.
    pub fn parameters<T: Scalar>(&self) -> Vec<T> {
        self.rows
            .iter()
            .flatten()
            .map(|&x| T::from_f64(x))
            .collect()
    }

    /// `A` (paper eq. 2, or the posed quadric's matrix in [`AngleReading::Quadric`]).
    pub fn a_matrix<T: Scalar>(&self) -> Mat3<T> {
        self.reading.matrix(&self.parameters::<T>()[0..6])
    }
    /// `B` (row 2 of Table 2; diagonal in the 12-number form).
    pub fn b_matrix<T: Scalar>(&self) -> Mat3<T> {
        self.reading.matrix(&self.parameters::<T>()[6..12])
    }
    /// `C` (row 3 of Table 2; diagonal in the 12-number form).
    pub fn c_matrix<T: Scalar>(&self) -> Mat3<T> {
        self.reading.matrix(&self.parameters::<T>()[12..18])
    }

    /// `H = [[A, B], [C, −Aᵀ]]` (paper eq. 4) in `f64`, row-major.
    pub fn h_matrix(&self) -> [[f64; 6]; 6] {
        let (a, b, c) = (
            self.a_matrix::<f64>(),
            self.b_matrix::<f64>(),
            self.c_matrix::<f64>(),
        );
        let mut h = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] = a[i][j];
                h[i][j + 3] = b[i][j];
                h[i + 3][j] = c[i][j];
                h[i + 3][j + 3] = -a[j][i];
            }
        }
        h
    }

    /// Whether `H` lies in the Hamiltonian Lie algebra sp(6): exactly when `B` and `C` are
    /// symmetric (`Hᵀ J + J H = 0` for the standard symplectic `J`). Checked to a relative
    /// tolerance of 1e-12, since rotations are computed in floating point.
    pub fn is_in_sp6(&self) -> bool {
        let sym = |m: &Mat3<f64>| {
            let scale = (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| m[i][j].abs())
                .fold(0.0_f64, f64::max);
            (0..3).all(|i| (0..3).all(|j| (m[i][j] - m[j][i]).abs() <= 1e-12 * scale.max(1e-300)))
        };
        sym(&self.b_matrix()) && sym(&self.c_matrix())
    }

    /// `true` when `A` is symmetric and `B` is diagonal, so that the field is the gradient
    /// of the potential `F(p) = ½ pᵀ A p + Σ b_ii p_i³ / 3` and the surface is its level set.
    pub fn potential(&self) -> Option<impl Fn([f64; 3]) -> f64> {
        let a = self.a_matrix::<f64>();
        let b = self.b_matrix::<f64>();
        let scale = a
            .iter()
            .map(|r| r.to_f64().iter().fold(0.0_f64, |m, x| m.max(x.abs())))
            .fold(0.0_f64, f64::max)
            .max(1e-300);
        let a_sym = (0..3).all(|i| (0..3).all(|j| (a[i][j] - a[j][i]).abs() <= 1e-12 * scale));
        let b_diag = (0..3).all(|i| (0..3).all(|j| i == j || b[i][j].abs() <= 1e-12 * scale));
        if !(a_sym && b_diag) {
            return None;
        }
        let a = [a[0].to_f64(), a[1].to_f64(), a[2].to_f64()];
        let bd = [b[0].x, b[1].y, b[2].z];
        Some(move |p: [f64; 3]| {
            let mut f = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    f += 0.5 * p[i] * a[i][j] * p[j];
                }
                f += bd[i] * p[i] * p[i] * p[i] / 3.0;
            }
            f
        })
    }
}

fn mat_mul<T: Scalar>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    let col = |j: usize| Vec3::new(b[0][j].clone(), b[1][j].clone(), b[2][j].clone());
    let cols = [col(0), col(1), col(2)];
    let row = |i: usize| Vec3::new(a[i].dot(&cols[0]), a[i].dot(&cols[1]), a[i].dot(&cols[2]));
    [row(0), row(1), row(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twelve_number_form_builds_diagonal_b_and_c() {
        let n = [1., 2., 3., 4., 5., 6., 7., 8., 9., 0., 0., 0.];
        let inv = Invariant::from_numbers(&n).unwrap();
        let b = inv.b_matrix::<f64>();
        let c = inv.c_matrix::<f64>();
        assert_eq!((b[0].x, b[1].y, b[2].z), (2., 5., 8.));
        assert_eq!((c[0].x, c[1].y, c[2].z), (3., 6., 9.));
        let a = inv.a_matrix::<f64>();
        assert_eq!((a[0].x, a[1].y, a[2].z), (1., 4., 7.));
        assert!(inv.is_in_sp6());
    }

    #[test]
    fn eighteen_number_form_reads_table_rows() {
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        assert_eq!(inv.kind(), InvariantKind::Hamiltonian);
        assert_eq!(inv.numbers(), crate::preset::FIG46_INVARIANT.to_vec());
        // Row 2 has angles, so B = diag(λ·2) R is not symmetric: H is outside sp(6).
        assert!(!inv.is_in_sp6());
    }

    #[test]
    fn rotations_are_the_right_handed_ones_of_the_design() {
        // Rx(θ) alone: rows [1,0,0],[0,c,-s],[0,s,c].
        let t = 0.3_f64;
        let m = Invariant::row_matrix(&[1.0, 1.0, 1.0, t, 0.0, 0.0]);
        assert!((m[1].z + t.sin()).abs() < 1e-16 && (m[2].y - t.sin()).abs() < 1e-16);
        let m = Invariant::row_matrix(&[1.0, 1.0, 1.0, 0.0, t, 0.0]);
        assert!((m[0].z - t.sin()).abs() < 1e-16 && (m[2].x + t.sin()).abs() < 1e-16);
        let m = Invariant::row_matrix(&[1.0, 1.0, 1.0, 0.0, 0.0, t]);
        assert!((m[0].y + t.sin()).abs() < 1e-16 && (m[1].x - t.sin()).abs() < 1e-16);
    }

    #[test]
    fn h_has_minus_a_transpose_in_the_lower_right_block() {
        let inv = Invariant::from_numbers(&crate::preset::FIG46_INVARIANT).unwrap();
        let h = inv.h_matrix();
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(h[i + 3][j + 3], -h[j][i]);
            }
        }
    }

    #[test]
    fn wrong_counts_and_non_finite_numbers_are_rejected() {
        assert_eq!(
            Invariant::from_numbers(&[1.0; 7]),
            Err(InvariantError::WrongCount(7))
        );
        let mut n = [1.0; 6];
        n[2] = f64::NAN;
        assert!(matches!(
            Invariant::from_numbers(&n),
            Err(InvariantError::NonFinite { index: 3, .. })
        ));
    }

    #[test]
    fn an_invariant_whose_every_lambda_is_zero_is_rejected() {
        // Found by a sweep of a new user's inputs: `[0, 0, 0, 0, 0, 0]` was taken, and every
        // p0 then failed as "a singular point, choose another initial point".
        let zero_lambdas = |n: usize, angle: f64| {
            // The angles: 4th to 6th of each row of six; the last three of twelve.
            let mut v = vec![0.0; n];
            let angles: Vec<usize> = if n == 12 {
                vec![9, 10, 11]
            } else {
                (0..n).filter(|i| i % 6 >= 3).collect()
            };
            for i in angles {
                v[i] = angle;
            }
            v
        };
        for n in [6, 12, 18] {
            for angle in [0.0, 0.3] {
                assert_eq!(
                    Invariant::from_numbers(&zero_lambdas(n, angle)),
                    Err(InvariantError::ZeroField),
                    "{n} numbers"
                );
            }
            // One non-zero λ anywhere makes a field.
            let mut one = zero_lambdas(n, 0.3);
            let last_lambda = if n == 12 { 8 } else { n - 4 };
            one[last_lambda] = -0.5;
            assert!(Invariant::from_numbers(&one).is_ok(), "{n} numbers");
        }
    }
}
