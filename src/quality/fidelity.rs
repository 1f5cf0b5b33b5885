//! How faithful the samples and the mesh are to the field.

use crate::geom::face_error_deg;
use crate::model::{jacobian, Invariant, NormalField};
use crate::sample::Samples;
use crate::scalar::{Scalar, Vec3};
use crate::triangulate::Mesh;

/// The normal turn actually achieved by the accepted steps (exact normals at both ends, not
/// the predicted one), and the error of the first-order prediction. Angles in degrees.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepQuality {
    /// Accepted steps measured.
    pub steps: usize,
    /// Smallest achieved normal turn.
    pub achieved_min: f64,
    /// Largest achieved normal turn.
    pub achieved_max: f64,
    /// Steps whose achieved turn lies outside `[β_min, β_max]`.
    pub outside_band: usize,
    /// Largest angle between the predicted normal `v + Δt J w` and the exact `v(p_{i+1})`.
    pub prediction_error_max: f64,
    /// Mean of that angle.
    pub prediction_error_mean: f64,
}

/// Angle between two vectors in degrees.
fn angle_deg(a: &Vec3<f64>, b: &Vec3<f64>) -> f64 {
    a.angle_to(b).to_degrees()
}

/// Measures every accepted step of `samples` against `field` (evaluated in `f64`).
pub fn step_quality<T: Scalar, F: NormalField<f64>>(
    field: &F,
    samples: &Samples<T>,
    beta: (f64, f64),
) -> StepQuality {
    let pos: Vec<Vec3<f64>> = samples
        .points
        .iter()
        .map(|p| Vec3::from_f64(p.to_f64()))
        .collect();
    let (lo, hi) = (beta.0.to_degrees(), beta.1.to_degrees());
    let mut q = StepQuality {
        achieved_min: f64::INFINITY,
        ..StepQuality::default()
    };
    let mut pred_sum = 0.0;
    for curve in &samples.curves {
        for pair in curve.points.windows(2) {
            let (i, j) = (pair[0] as usize, pair[1] as usize);
            let dt = samples.steps[j].dt;
            let vi = field.normal(&pos[i]);
            let vj = field.normal(&pos[j]);
            let Some((ni, _)) = vi.normalize() else {
                continue;
            };
            let chord = &pos[j] - &pos[i];
            let k = -ni.dot(&chord);
            let Some((w, _)) = chord.add_scaled(&k, &ni).normalize() else {
                continue;
            };
            let (_, jw) = field.normal_and_jvp(&pos[i], &w);
            let predicted = vi.add_scaled(&dt, &jw);
            let achieved = angle_deg(&vi, &vj);
            let err = angle_deg(&predicted, &vj);
            q.steps += 1;
            q.achieved_min = q.achieved_min.min(achieved);
            q.achieved_max = q.achieved_max.max(achieved);
            if achieved < lo || achieved > hi {
                q.outside_band += 1;
            }
            q.prediction_error_max = q.prediction_error_max.max(err);
            pred_sum += err;
        }
    }
    if q.steps > 0 {
        q.prediction_error_mean = pred_sum / q.steps as f64;
    } else {
        q.achieved_min = 0.0;
    }
    q
}

/// Angle between each face's normal and the field normal at its centroid, degrees:
/// `(max, mean)`.
pub fn face_normal_error<F: NormalField<f64>>(field: &F, mesh: &Mesh) -> (f64, f64) {
    let (mut max, mut sum) = (0.0_f64, 0.0);
    for t in &mesh.triangles {
        let e = face_error_deg(t.map(|i| mesh.vertices[i as usize]), |c| field.normal(c));
        max = max.max(e);
        sum += e;
    }
    let n = mesh.triangles.len().max(1) as f64;
    (max, sum / n)
}

/// Vertex drift from the level set through `p0`, for fields with a known potential.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Drift {
    /// Largest distance of a vertex from the level set (`|F(p) − F(p0)| / |∇F(p)|`), divided by
    /// the mesh's bounding-box diagonal.
    pub max: f64,
    /// Root mean square of the same.
    pub rms: f64,
}

/// The drift of `mesh`'s vertices from the level set of `invariant`'s potential through
/// `p0`, or `None` when the field has no known potential (non-symmetric `A` or non-diagonal
/// `B`: see [`Invariant::potential`]).
pub fn drift(invariant: &Invariant, mesh: &Mesh, p0: [f64; 3]) -> Option<Drift> {
    let f = invariant.potential()?;
    let field = crate::model::LieField::<f64>::new(invariant);
    let f0 = f(p0);
    let diag = diagonal(mesh).max(1e-300);
    let (mut max, mut sq) = (0.0_f64, 0.0);
    for v in &mesh.vertices {
        let g = field.normal(&Vec3::from_f64(*v)).norm();
        let d = if g > 0.0 { (f(*v) - f0).abs() / g } else { 0.0 } / diag;
        max = max.max(d);
        sq += d * d;
    }
    Some(Drift {
        max,
        rms: (sq / mesh.vertices.len().max(1) as f64).sqrt(),
    })
}

/// Bounding-box diagonal of the vertices.
pub fn diagonal(mesh: &Mesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in &mesh.vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    if mesh.vertices.is_empty() {
        return 0.0;
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// The integrability defect `|v·(∇×v)| / |v|²` at every vertex (from the AD Jacobian):
/// `(max, mean)`. Zero exactly when some surface has `v` as its normal near the vertex.
pub fn integrability_defect<F: NormalField<f64>>(field: &F, mesh: &Mesh) -> (f64, f64) {
    let (mut max, mut sum) = (0.0_f64, 0.0);
    for p in &mesh.vertices {
        let p = Vec3::from_f64(*p);
        let v = field.normal(&p);
        let j = jacobian(field, &p);
        let curl = Vec3::new(j[2].y - j[1].z, j[0].z - j[2].x, j[1].x - j[0].y);
        let vv = v.norm_squared();
        let d = if vv > 0.0 {
            v.dot(&curl).abs() / vv
        } else {
            0.0
        };
        max = max.max(d);
        sum += d;
    }
    (max, sum / mesh.vertices.len().max(1) as f64)
}
