//! The workloads that `liemesh bench` times and the criterion benchmarks (`benches/liemesh.rs`)
//! measure, defined once: this file is a module of the binary and is included into the
//! benchmarks with `#[path]`, so it uses the library only through its public API.

use liemesh::model::{Invariant, LieField};
use liemesh::preset::Preset;
use liemesh::{Angle, MeshError, MeshParams};

/// The face-normal error the fidelity workload must reach (degrees): what grid-based implicit
/// meshers show at about 10^5 sphere triangles.
pub const FIDELITY_LIMIT_DEG: f64 = 0.7;

/// The fidelity scan stops beyond this many triangles (`--tiny`: a twentieth of it).
pub const FIDELITY_MAX_TRIANGLES: usize = 400_000;

/// The curve-insertion gap and merge distance (steps) the fidelity scan tries besides the
/// presets' 1.8 and 0.7. Just before a new curve starts, neighbouring curves are almost a gap
/// apart, and the faces between them are the obtuse ones whose normals stray most; at 1.3
/// steps fewer of them need refining on the sphere.
pub const FIDELITY_CLOSER_GAP: [f64; 2] = [1.3, 0.55];

/// Parameters for the sphere (`ellipsoid = false`) or the ellipsoid `(1, 4, 16, 0, 0, 0)`
/// meshed by the proposed method with the β band scaled so that the sphere gets roughly
/// `target` triangles (fig3 gives about 2000 at β ∈ [4°, 8°]; count ∝ 1/β²).
pub fn workload_params(ellipsoid: bool, target: usize) -> (Invariant, MeshParams) {
    let numbers: [f64; 6] = if ellipsoid {
        [1.0, 4.0, 16.0, 0.0, 0.0, 0.0]
    } else {
        [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
    };
    let invariant = Invariant::from_numbers(&numbers).expect("valid invariant");
    let mut params = Preset::Fig3.params();
    // The ellipsoid gets about 4.6 times the sphere's count at the same β band.
    let base = if ellipsoid { 9000.0 } else { 2000.0 };
    let s = (target as f64 / base).sqrt();
    params.beta_min = params.beta_min / s;
    params.beta_max = params.beta_max / s;
    params.dt = params.dt.map(|dt| dt / s);
    params.p0 = if ellipsoid {
        [0.0, 0.0, 0.25]
    } else {
        [0.0, 0.0, 1.0]
    };
    (invariant, params)
}

/// What the fidelity scan found: the parameters of its mesh and what that mesh is like.
#[derive(Debug, Clone)]
pub struct FidelityScan {
    /// The invariant (sphere or ellipsoid).
    pub invariant: Invariant,
    /// The parameters of the mesh found, refinement to [`FIDELITY_LIMIT_DEG`] included.
    pub params: MeshParams,
    /// Triangles of that mesh.
    pub triangles: usize,
    /// Vertices the refinement added to it.
    pub refined: usize,
    /// Its largest face-normal error, degrees.
    pub max_error_deg: f64,
    /// Whether it is within the limit (otherwise it is the trial with the lowest error).
    pub reached: bool,
}

/// Scans the β band of [`workload_params`] downward (each trial 15 % narrower), at its own
/// insertion gap and at [`FIDELITY_CLOSER_GAP`], refining each mesh to [`FIDELITY_LIMIT_DEG`],
/// and keeps the mesh with the fewest triangles that got there. A scan at one gap stops once
/// its mesh before refinement has more triangles than the best so far (narrower bands only
/// add more), or beyond `max_triangles`. If none got there (the rounds or the point budget ran
/// out), it keeps the trial with the lowest error, `reached == false`.
pub fn fidelity_scan(ellipsoid: bool, max_triangles: usize) -> Result<FidelityScan, MeshError> {
    let (invariant, base) = workload_params(ellipsoid, if ellipsoid { 9000 } else { 2000 });
    let field = LieField::<f64>::new(&invariant);
    let trial = |[gap, merge]: [f64; 2], scale: f64| {
        let mut params = base.clone();
        params.gap = gap;
        params.merge = merge;
        params.beta_min = params.beta_min * scale;
        params.beta_max = params.beta_max * scale;
        params.dt = params.dt.map(|dt| dt * scale);
        params.max_normal_error = Some(Angle::from_degrees(FIDELITY_LIMIT_DEG));
        params
    };
    // The coarsest within the limit, else the lowest error.
    let mut reached: Option<FidelityScan> = None;
    let mut lowest: Option<FidelityScan> = None;
    for gap in [[base.gap, base.merge], FIDELITY_CLOSER_GAP] {
        // Start 4× coarser than the fig3 band.
        let mut scale = 4.0;
        while scale > 1e-3 {
            let params = trial(gap, scale);
            let run = liemesh::run(&field, &params)?;
            let (error, _) = liemesh::quality::face_normal_error(&field, &run.mesh);
            let refined = run.refinement.map_or(0, |r| r.added);
            let triangles = run.mesh.triangles.len();
            // Each added vertex split two triangles in two.
            let unrefined = triangles.saturating_sub(2 * refined);
            let within = error <= FIDELITY_LIMIT_DEG && triangles <= max_triangles;
            let seen = || FidelityScan {
                invariant: invariant.clone(),
                params: params.clone(),
                triangles,
                refined,
                max_error_deg: error,
                reached: within,
            };
            if lowest.as_ref().is_none_or(|l| error < l.max_error_deg) {
                lowest = Some(seen());
            }
            if within && reached.as_ref().is_none_or(|r| triangles < r.triangles) {
                reached = Some(seen());
            }
            if triangles > max_triangles
                || reached.as_ref().is_some_and(|r| unrefined > r.triangles)
            {
                break;
            }
            scale *= 0.85;
        }
    }
    Ok(reached.or(lowest).expect("at least one trial"))
}
