//! The run report: counts, topology, time and parameters of one meshing run (what the
//! command line writes as JSON).

use crate::model::Invariant;
use crate::params::MeshParams;
use crate::quality::Topology;
use crate::scalar::ScalarKind;
use crate::triangulate::Mesh;
use crate::MeshError;

/// What a meshing run was asked to do: everything needed to run it again. Both reports
/// start with it ([`Report`], [`FailureReport`]); in JSON its fields sit at the top level.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Job {
    /// Preset name, if the run used one.
    pub preset: Option<String>,
    /// The invariant's numbers (6 or 18).
    pub invariant: Vec<f64>,
    /// Whether `H` lies in sp(6).
    pub hamiltonian_in_sp6: bool,
    /// Scalar type the run worked in.
    pub scalar: ScalarKind,
    /// The parameters given.
    pub parameters: MeshParams,
}

impl Job {
    /// Meshing `invariant` with `parameters` in `scalar` (from the preset named `preset`).
    pub fn new(
        preset: Option<String>,
        invariant: &Invariant,
        scalar: ScalarKind,
        parameters: &MeshParams,
    ) -> Job {
        Job {
            preset,
            invariant: invariant.numbers(),
            hamiltonian_in_sp6: invariant.is_in_sp6(),
            scalar,
            parameters: parameters.clone(),
        }
    }
}

/// What a meshing run reports: counts, topology, time, and everything needed to rerun it.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Report {
    /// What was asked.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub job: Job,
    /// Mesh vertices.
    pub vertices: usize,
    /// Mesh triangles.
    pub triangles: usize,
    /// Integral curves traced (initial and inserted).
    pub curves: usize,
    /// No boundary, manifold and consistently oriented.
    pub closed: bool,
    /// `V − E + F`.
    pub euler_characteristic: i64,
    /// Number of boundary loops.
    pub boundary_loops: usize,
    /// Full topology.
    pub topology: Topology,
    /// Wall-clock seconds for sampling and triangulation.
    pub seconds: f64,
    /// The automatic parameters as worked out for this surface (`scales`, `w00`, `dt`,
    /// `dt_min`, `dt_max`, `max_radius`, `bounding_box`).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub resolved: Option<crate::params::Resolved>,
    /// How many curves ended for each reason.
    #[cfg_attr(feature = "serde", serde(default))]
    pub curve_ends: crate::sample::CurveEnds,
    /// What cut the run short, in words ([`crate::MeshRun::cut_short`]); empty for a
    /// complete run.
    #[cfg_attr(feature = "serde", serde(default))]
    pub cut_short: Vec<String>,
    /// What stitching where fronts met did.
    #[cfg_attr(feature = "serde", serde(default))]
    pub stitched: crate::triangulate::Stitched,
    /// What was undone so that the mesh does not cross itself, nor stand far off the surface
    /// beside a singular point.
    #[cfg_attr(feature = "serde", serde(default))]
    pub untangled: crate::triangulate::Untangled,
    /// The exact validation of the mesh written.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub validation: Option<crate::mesh::Validation>,
    /// Quality measures (shape, fidelity, topology, recovered invariant), when measured.
    pub quality: Option<crate::quality::QualityReport>,
    /// What refinement to [`MeshParams::max_normal_error`] did, when it was asked for.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub refinement: Option<crate::triangulate::Refinement>,
    /// The derivatives of the vertices with respect to invariant numbers, when asked for.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Vec::is_empty")
    )]
    pub derivatives: Vec<VertexDerivatives>,
}

/// What a meshing run that failed reports: what was asked, and why it failed (what the
/// command line writes as JSON in place of a [`Report`] when there is no mesh to report on).
/// A reader tells the two apart by the `error` field, which only this one has.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FailureReport {
    /// What was asked.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub job: Job,
    /// Why the run failed, in the words of its [`MeshError`].
    pub error: String,
    /// The validation the mesh failed, when it came out invalid ([`MeshError::Invalid`]).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub validation: Option<crate::mesh::Validation>,
}

impl FailureReport {
    /// The report of `job`, which failed with `error`.
    pub fn new(job: Job, error: &MeshError) -> FailureReport {
        FailureReport {
            job,
            error: error.to_string(),
            validation: match error {
                MeshError::Invalid(v) => Some((**v).clone()),
                _ => None,
            },
        }
    }
}

/// `d(vertex)/d(number)` for every vertex, with respect to one invariant number
/// ([`crate::differentiate`]).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct VertexDerivatives {
    /// The invariant number, counting from 1 in [`Invariant::numbers`] (6 numbers, or the
    /// 18 of Table 2's three rows).
    pub number: usize,
    /// The PLY vertex properties that hold them (`{stem}_x`, `{stem}_y`, `{stem}_z`).
    pub ply_properties: [String; 3],
    /// The largest `|d(vertex)/d(number)|`.
    pub max_norm: f64,
    /// One derivative per vertex, in the mesh's vertex order.
    pub values: Vec<[f64; 3]>,
}

impl VertexDerivatives {
    /// The PLY property stem for invariant number `number` (from 1): `d_n{number}`.
    pub fn stem(number: usize) -> String {
        format!("d_n{number}")
    }

    /// The summary of `values`, the derivatives with respect to invariant number `number`.
    pub fn new(number: usize, values: Vec<[f64; 3]>) -> VertexDerivatives {
        let stem = Self::stem(number);
        VertexDerivatives {
            number,
            ply_properties: ["x", "y", "z"].map(|a| format!("{stem}_{a}")),
            max_norm: values
                .iter()
                .map(|d| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt())
                .fold(0.0, f64::max),
            values,
        }
    }
}

impl Report {
    /// Builds the report of `job`, which made `mesh` from `curves` curves in `seconds`.
    pub fn new(job: Job, mesh: &Mesh, curves: usize, seconds: f64) -> Report {
        let topology = Topology::of(mesh);
        Report {
            job,
            vertices: mesh.vertices.len(),
            triangles: mesh.triangles.len(),
            curves,
            closed: topology.closed,
            euler_characteristic: topology.euler_characteristic,
            boundary_loops: topology.boundary_loops,
            topology,
            seconds,
            resolved: None,
            curve_ends: Default::default(),
            cut_short: Vec::new(),
            stitched: Default::default(),
            untangled: Default::default(),
            validation: None,
            quality: None,
            refinement: None,
            derivatives: Vec::new(),
        }
    }
}
