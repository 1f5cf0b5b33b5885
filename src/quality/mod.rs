//! Measuring a mesh: shape, fidelity to the field, topology, and the invariant recovered
//! from the mesh alone.
//!
//! [`QualityReport::measure`] gathers everything into one serialisable report (the `quality`
//! section of `--report` JSON).

mod fidelity;
mod recover;
mod shape;
mod topology;

pub use crate::geom::face_error_deg;
pub use fidelity::{
    diagonal, drift, face_normal_error, integrability_defect, step_quality, Drift, StepQuality,
};
pub use recover::{decompose, decompose_in, jet_normals, mesh_normals, recover, Recovery};
pub use shape::Shape;
pub use topology::Topology;

use crate::model::{Invariant, InvariantKind, LieField};
use crate::params::MeshParams;
use crate::sample::Samples;
use crate::scalar::Scalar;
use crate::triangulate::Mesh;

/// Every quality measure of one mesh. Angles in degrees.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct QualityReport {
    /// Triangle shape.
    pub shape: Shape,
    /// Achieved normal turn per accepted step and prediction error.
    pub steps: StepQuality,
    /// Largest angle between a face normal and the field normal at the face's centroid.
    pub face_normal_error_max: f64,
    /// Mean of that angle.
    pub face_normal_error_mean: f64,
    /// Topology.
    pub topology: Topology,
    /// Drift from the level set (fields with a potential only).
    pub drift: Option<Drift>,
    /// Largest integrability defect `|v·(∇×v)|/|v|²` over the vertices.
    pub integrability_defect_max: f64,
    /// Mean integrability defect.
    pub integrability_defect_mean: f64,
    /// The invariant recovered from the mesh.
    pub recovery: Recovery,
}

impl QualityReport {
    /// Measures a mesh made from `invariant` with `params` (`samples` are that run's samples).
    pub fn measure<T: Scalar>(
        invariant: &Invariant,
        params: &MeshParams,
        samples: &Samples<T>,
        mesh: &Mesh,
    ) -> QualityReport {
        let field = LieField::<f64>::new(invariant);
        let (face_max, face_mean) = face_normal_error(&field, mesh);
        let (defect_max, defect_mean) = integrability_defect(&field, mesh);
        let hamiltonian = invariant.kind() == InvariantKind::Hamiltonian
            && invariant.rows()[1][..3].iter().any(|&x| x != 0.0);
        QualityReport {
            shape: Shape::of(mesh),
            steps: step_quality(
                &field,
                samples,
                (params.beta_min.radians(), params.beta_max.radians()),
            ),
            face_normal_error_max: face_max,
            face_normal_error_mean: face_mean,
            topology: Topology::of(mesh),
            drift: drift(invariant, mesh, params.p0),
            integrability_defect_max: defect_max,
            integrability_defect_mean: defect_mean,
            recovery: recover(mesh, hamiltonian, Some(invariant)),
        }
    }
}
