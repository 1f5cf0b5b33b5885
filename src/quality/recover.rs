//! Invariants recovered from a mesh alone (the paper's notion of quality).
//!
//! Vertex normals are estimated from the mesh alone, never from the stored field normals: face
//! normals with Max's weights give a first tangent plane, over which a cubic height function
//! fitted to the two-ring gives the normal to third order ([`jet_normals`]). Since `n ∥ A p + B (p∘p)`, each vertex gives three equations
//! `n × (A p + B (p∘p)) = 0` that are linear in the entries of `A` (and `B`); the least-squares
//! solution of unit norm is the right singular vector of the smallest singular value. It is
//! scaled to the reference by least squares and decomposed in either reading of the angles
//! ([`AngleReading`]): `A = diag(λ) Rx(θ) Ry(φ) Rz(ψ)` or `A = Rᵀ diag(λ) R`.

use crate::geom::vec3::{cross, dot, normalize, sub};
use crate::model::{AngleReading, Invariant};
use crate::triangulate::Mesh;
use nalgebra::{DMatrix, Matrix3};

/// What was recovered.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Recovery {
    /// Recovered `A` (row-major), scaled to the reference when one was given, else to unit
    /// Frobenius norm of `[A B]`.
    pub a: [[f64; 3]; 3],
    /// Recovered `B` (zero for the linear model).
    pub b: [[f64; 3]; 3],
    /// `(λ1, λ2, λ3, θ, φ, ψ)` of the recovered `A`, angles in radians, in the reading
    /// [`Recovery::reading`] (see [`decompose_in`]).
    pub a_invariant: [f64; 6],
    /// How [`Recovery::a_invariant`]'s angles are read: the reference's reading when a
    /// reference was given, else the literal one.
    pub reading: AngleReading,
    /// RMS of the equations' residual at unit norm (0 when some field fits every vertex
    /// normal exactly).
    pub residual: f64,
    /// `‖[A B]_recovered − [A B]_reference‖ / ‖[A B]_reference‖`, when a reference was given.
    pub relative_error: Option<f64>,
}

/// Vertex normals of `mesh` from its faces alone (unit; zero where undefined), with Max's
/// weights: each face contributes `(e₁ × e₂) / (|e₁|² |e₂|²)` for its two edges at the vertex,
/// which is exact for vertices on a sphere and second-order accurate on smooth surfaces,
/// where plain area weights are only first-order on irregular meshes.
pub fn mesh_normals(mesh: &Mesh) -> Vec<[f64; 3]> {
    let mut acc = vec![[0.0; 3]; mesh.vertices.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let v = t[k] as usize;
            let p = mesh.vertices[v];
            let a = mesh.vertices[t[(k + 1) % 3] as usize];
            let b = mesh.vertices[t[(k + 2) % 3] as usize];
            let (u, w) = (sub(a, p), sub(b, p));
            let n = cross(u, w);
            let weight = dot(u, u) * dot(w, w);
            if weight > 0.0 {
                for c in 0..3 {
                    acc[v][c] += n[c] / weight;
                }
            }
        }
    }
    acc.into_iter()
        .map(|n| {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if l > 0.0 {
                [n[0] / l, n[1] / l, n[2] / l]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// Vertex normals of `mesh` from its vertex positions, third-order accurate: around each
/// vertex, the surface is fitted as a height function of degree three over the tangent plane of
/// [`mesh_normals`] (an osculating jet, through the vertex, on its two-ring), and the normal is
/// the jet's at the vertex. Where the two-ring has too few points for a well-posed fit (fewer
/// than 12, as at the corner of an open mesh), the [`mesh_normals`] normal is kept.
pub fn jet_normals(mesh: &Mesh) -> Vec<[f64; 3]> {
    let first = mesh_normals(mesh);
    let n = mesh.vertices.len();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    // Each vertex's fit is independent (an SVD of a dozen or more rows): on rayon's pool.
    crate::par::map(n, crate::par::MIN_COSTLY, |i| {
        let n0 = first[i];
        if n0 == [0.0; 3] {
            return n0;
        }
        let mut ring: Vec<u32> = Vec::new();
        for &j in &neighbours[i] {
            ring.push(j);
            ring.extend(&neighbours[j as usize]);
        }
        ring.sort_unstable();
        ring.dedup();
        ring.retain(|&j| j as usize != i);
        if ring.len() < 12 {
            return n0;
        }
        // Tangent frame (t1, t2, n0).
        let helper = if n0[0].abs() < 0.6 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let t1 = normalize(cross(helper, n0));
        let t2 = cross(n0, t1);
        let p = mesh.vertices[i];
        let local: Vec<[f64; 3]> = ring
            .iter()
            .map(|&j| {
                let q = mesh.vertices[j as usize];
                let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                [dot(d, t1), dot(d, t2), dot(d, n0)]
            })
            .collect();
        // Uniform scaling keeps the slopes and conditions the monomials.
        let r = local
            .iter()
            .map(|d| (d[0] * d[0] + d[1] * d[1]).sqrt())
            .fold(0.0_f64, f64::max);
        if r <= 0.0 {
            return n0;
        }
        // The cubic jet z(x, y) in the scaled frame, one row of monomials per neighbour.
        let m = DMatrix::from_row_iterator(
            local.len(),
            9,
            local.iter().flat_map(|d| {
                let (x, y) = (d[0] / r, d[1] / r);
                [
                    x,
                    y,
                    x * x,
                    x * y,
                    y * y,
                    x * x * x,
                    x * x * y,
                    x * y * y,
                    y * y * y,
                ]
            }),
        );
        let b = nalgebra::DVector::from_iterator(local.len(), local.iter().map(|d| d[2] / r));
        let svd = m.svd(true, true);
        // Too few independent directions (points on a curve): keep the first estimate.
        let smax = svd.singular_values.max();
        if svd.singular_values.min() <= 1e-8 * smax {
            return n0;
        }
        let Ok(x) = svd.solve(&b, 0.0) else {
            return n0;
        };
        let (a1, a2) = (x[0], x[1]);
        normalize([
            n0[0] - a1 * t1[0] - a2 * t2[0],
            n0[1] - a1 * t1[1] - a2 * t2[1],
            n0[2] - a1 * t1[2] - a2 * t2[2],
        ])
    })
}

/// Fits the field to `mesh`; `hamiltonian` adds the 9 entries of `B`. With a `reference`
/// invariant, the fit is scaled to it, its relative error reported, and `A` decomposed in the
/// reference's reading of the angles, as close to the reference's numbers as the
/// decomposition's symmetries allow.
pub fn recover(mesh: &Mesh, hamiltonian: bool, reference: Option<&Invariant>) -> Recovery {
    let normals = jet_normals(mesh);
    let unknowns = if hamiltonian { 18 } else { 9 };
    let used: Vec<usize> = (0..mesh.vertices.len())
        .filter(|&i| normals[i] != [0.0; 3])
        .collect();
    // Scale points to O(1) for conditioning; A and B are rescaled back below.
    let scale = used
        .iter()
        .map(|&i| mesh.vertices[i].iter().fold(0.0_f64, |m, x| m.max(x.abs())))
        .fold(0.0_f64, f64::max)
        .max(1e-300);
    let points: Vec<([f64; 3], [f64; 3])> = used
        .iter()
        .map(|&i| {
            let p = mesh.vertices[i].map(|x| x / scale);
            (p, p.map(|x| x * x))
        })
        .collect();
    let solve = |weights: &[f64]| {
        let mut m = DMatrix::<f64>::zeros(3 * used.len(), unknowns);
        for (row, &i) in used.iter().enumerate() {
            let (p, q) = points[row];
            let n = normals[i];
            let wt = weights[row];
            // (n × (A p))_r = Σ_jk ε_rjk n_j (A p)_k; (A p)_k = Σ_l A_kl p_l.
            for r in 0..3 {
                let (j, k) = ((r + 1) % 3, (r + 2) % 3);
                for l in 0..3 {
                    // + n_j A_kl p_l − n_k A_jl p_l
                    m[(3 * row + r, 3 * k + l)] += wt * n[j] * p[l];
                    m[(3 * row + r, 3 * j + l)] -= wt * n[k] * p[l];
                    if hamiltonian {
                        m[(3 * row + r, 9 + 3 * k + l)] += wt * n[j] * q[l];
                        m[(3 * row + r, 9 + 3 * j + l)] -= wt * n[k] * q[l];
                    }
                }
            }
        }
        // Normal equations MᵀM (unknowns × unknowns) keep the eigenproblem small.
        let eig = (m.transpose() * &m).symmetric_eigen();
        let (imin, &lmin) = eig
            .eigenvalues
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .expect("at least 9 unknowns");
        (eig.eigenvectors.column(imin).clone_owned(), lmin)
    };
    let (first, _) = solve(&vec![1.0; used.len()]);
    // Second pass: divide each equation by |v(p)| of the first fit, so that every vertex
    // contributes the sine of its normal's angle error, whatever the field's magnitude.
    let field_norm = |row: usize| {
        let (p, q) = points[row];
        let mut v = [0.0; 3];
        for r in 0..3 {
            for l in 0..3 {
                v[r] += first[3 * r + l] * p[l];
                if hamiltonian {
                    v[r] += first[9 + 3 * r + l] * q[l];
                }
            }
        }
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    };
    let weights: Vec<f64> = (0..used.len())
        .map(|row| {
            let f = field_norm(row);
            if f > 0.0 {
                1.0 / f
            } else {
                0.0
            }
        })
        .collect();
    let (x, lmin) = solve(&weights);
    // The smallest eigenvalue is the reweighted residual's sum of squares at unit norm.
    let residual = lmin.max(0.0).sqrt();
    let mut a = [[0.0; 3]; 3];
    let mut b = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            a[r][c] = x[3 * r + c];
            if hamiltonian {
                // B multiplies p∘p = scale² (p/scale)∘(p/scale): undo against A's single scale.
                b[r][c] = x[9 + 3 * r + c] / scale;
            }
        }
    }
    let flat = |a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]| -> Vec<f64> {
        a.iter()
            .flatten()
            .chain(b.iter().flatten())
            .copied()
            .collect()
    };
    let mut relative_error = None;
    let fit = flat(&a, &b);
    let k = match reference {
        Some(inv) => {
            let ra = inv.a_matrix::<f64>().map(|r| r.to_f64());
            let rb = if hamiltonian {
                inv.b_matrix::<f64>().map(|r| r.to_f64())
            } else {
                [[0.0; 3]; 3]
            };
            let refv = flat(&ra, &rb);
            let dot: f64 = fit.iter().zip(&refv).map(|(x, y)| x * y).sum();
            let ff: f64 = fit.iter().map(|x| x * x).sum();
            let rr: f64 = refv.iter().map(|x| x * x).sum();
            let k = if ff > 0.0 { dot / ff } else { 0.0 };
            let err: f64 = fit
                .iter()
                .zip(&refv)
                .map(|(x, y)| (k * x - y).powi(2))
                .sum();
            relative_error = Some((err / rr.max(1e-300)).sqrt());
            k
        }
        None => {
            let ff: f64 = fit.iter().map(|x| x * x).sum::<f64>().sqrt();
            if ff > 0.0 {
                1.0 / ff
            } else {
                0.0
            }
        }
    };
    for r in 0..3 {
        for c in 0..3 {
            a[r][c] *= k;
            b[r][c] *= k;
        }
    }
    let reading = reference.map_or(AngleReading::Literal, Invariant::reading);
    let near = reference.map(|inv| {
        let mut row = [0.0; 6];
        row.copy_from_slice(&inv.rows()[0]);
        row
    });
    Recovery {
        a_invariant: decompose_in(&a, reading, near.as_ref()),
        reading,
        a,
        b,
        residual,
        relative_error,
    }
}

/// `A = diag(λ) Rx(θ) Ry(φ) Rz(ψ)` → `(λ1, λ2, λ3, θ, φ, ψ)`, with `λ` signs chosen so that
/// the rotation has determinant +1 and the first non-zero λ is positive when both work.
pub fn decompose(a: &[[f64; 3]; 3]) -> [f64; 6] {
    let mut lambda = [0.0; 3];
    let mut r = Matrix3::<f64>::zeros();
    for i in 0..3 {
        let n = (a[i][0].powi(2) + a[i][1].powi(2) + a[i][2].powi(2)).sqrt();
        lambda[i] = n;
        for j in 0..3 {
            r[(i, j)] = if n > 0.0 { a[i][j] / n } else { 0.0 };
        }
    }
    if r.determinant() < 0.0 {
        // Flip the sign of the row with the smallest λ (least visible).
        let i = (0..3)
            .min_by(|&x, &y| lambda[x].total_cmp(&lambda[y]))
            .unwrap();
        lambda[i] = -lambda[i];
        for j in 0..3 {
            r[(i, j)] = -r[(i, j)];
        }
    }
    let phi = r[(0, 2)].clamp(-1.0, 1.0).asin();
    let psi = (-r[(0, 1)]).atan2(r[(0, 0)]);
    let theta = (-r[(1, 2)]).atan2(r[(2, 2)]);
    [lambda[0], lambda[1], lambda[2], theta, phi, psi]
}

/// `A` → `(λ1, λ2, λ3, θ, φ, ψ)` in either reading of the angles (radians).
///
/// A matrix has several decompositions: in the literal reading, signs of `λ` trade with the
/// rows of `R` ([`decompose`] chooses); in the quadric reading, any order of the eigenvalues
/// and any signs of the eigenvectors give the same `A = Rᵀ diag(λ) R` (its symmetric part is
/// used). With `near` (e.g. the invariant the mesh was made from), the decomposition closest to
/// it is returned (λ by absolute difference, angles modulo 2π); without, the one whose angles
/// are smallest.
pub fn decompose_in(a: &[[f64; 3]; 3], reading: AngleReading, near: Option<&[f64; 6]>) -> [f64; 6] {
    match reading {
        AngleReading::Literal => decompose(a),
        AngleReading::Quadric => decompose_quadric(a, near),
    }
}

fn decompose_quadric(a: &[[f64; 3]; 3], near: Option<&[f64; 6]>) -> [f64; 6] {
    let sym = Matrix3::from_fn(|i, j| 0.5 * (a[i][j] + a[j][i]));
    let eig = sym.symmetric_eigen();
    let wrap = |x: f64| {
        let t = std::f64::consts::TAU;
        x - t * (x / t).round()
    };
    let cost = |c: &[f64; 6]| match near {
        Some(n) => (0..3)
            .map(|i| (c[i] - n[i]).powi(2) + wrap(c[i + 3] - n[i + 3]).powi(2))
            .sum::<f64>(),
        None => c[3..].iter().map(|x| x.abs()).sum(),
    };
    const ORDERS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut best: Option<([f64; 6], f64)> = None;
    for order in ORDERS {
        for signs in 0..8u32 {
            // Rows of R are the eigenvectors (the columns of `eig.eigenvectors`).
            let mut r = Matrix3::<f64>::zeros();
            for (row, &k) in order.iter().enumerate() {
                let sign = if signs >> row & 1 == 1 { -1.0 } else { 1.0 };
                for j in 0..3 {
                    r[(row, j)] = sign * eig.eigenvectors[(j, k)];
                }
            }
            if r.determinant() < 0.0 {
                continue;
            }
            let phi = r[(0, 2)].clamp(-1.0, 1.0).asin();
            let psi = (-r[(0, 1)]).atan2(r[(0, 0)]);
            let theta = (-r[(1, 2)]).atan2(r[(2, 2)]);
            let lambda = order.map(|k| eig.eigenvalues[k]);
            let c = [lambda[0], lambda[1], lambda[2], theta, phi, psi];
            let k = cost(&c);
            if best.as_ref().is_none_or(|(_, b)| k < *b) {
                best = Some((c, k));
            }
        }
    }
    best.expect("half of the sign choices have determinant +1")
        .0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quadric_reading_decomposes_back_to_its_numbers() {
        let numbers = [0.5, 2.0, 3.0, 0.3, -0.4, 1.1];
        let inv = Invariant::from_numbers(&numbers)
            .unwrap()
            .with_reading(AngleReading::Quadric);
        let a = inv.a_matrix::<f64>().map(|r| r.to_f64());
        let d = decompose_in(&a, AngleReading::Quadric, Some(&numbers));
        for (x, y) in d.iter().zip(numbers) {
            assert!((x - y).abs() < 1e-12, "{d:?}");
        }
        // Without a hint: the same matrix, whichever decomposition is chosen.
        let d = decompose_in(&a, AngleReading::Quadric, None);
        let back = Invariant::from_numbers(&d)
            .unwrap()
            .with_reading(AngleReading::Quadric)
            .a_matrix::<f64>()
            .map(|r| r.to_f64());
        for i in 0..3 {
            for j in 0..3 {
                assert!((back[i][j] - a[i][j]).abs() < 1e-12, "{back:?} {a:?}");
            }
        }
    }

    #[test]
    fn decompose_inverts_the_invariant_matrix() {
        let inv = Invariant::from_numbers(&[0.5, 2.0, 3.0, 0.3, -0.4, 1.1]).unwrap();
        let a = inv.a_matrix::<f64>().map(|r| r.to_f64());
        let d = decompose(&a);
        for (x, y) in d.iter().zip([0.5, 2.0, 3.0, 0.3, -0.4, 1.1]) {
            assert!((x - y).abs() < 1e-12, "{d:?}");
        }
    }
}
