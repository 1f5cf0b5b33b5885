//! # liemesh
//!
//! Adaptive triangle meshes of surfaces defined by Lie-algebra invariants (Sagara & Makino,
//! "A High Quality Mesh Generation with Automatic Differentiation for Surfaces Defined by
//! Hamiltonian Lie Algebra"), generic over the scalar type so that every number can be
//! audited against MPFR.
//!
//! The pipeline, one module per stage, data flowing one way:
//! [`scalar`] → [`model`] → [`trace`] → [`sample`] → [`triangulate`] → [`quality`] → [`io`].
//!
//! ```
//! use liemesh::{generate, model::{Invariant, LieField}, preset::Preset};
//!
//! // The unit sphere (Table 2, Fig. 1–3), meshed by the proposed method in f64.
//! let invariant = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0])?;
//! let field = LieField::<f64>::new(&invariant);
//! let mesh = generate(&field, &Preset::Fig3.params())?;
//! let topology = liemesh::quality::Topology::of(&mesh);
//! assert!(topology.closed && topology.euler_characteristic == 2);
//! for v in &mesh.vertices {
//!     let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
//!     assert!((r - 1.0).abs() < 1e-12);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Cargo features
//!
//! | feature | default | what it adds | dependencies |
//! |---|---|---|---|
//! | `serde` | yes | `Serialize`/`Deserialize` for [`Mesh`], [`MeshParams`], the invariant, the quality, audit and [`io::report`] types | serde |
//! | `toml` | yes | `io::invariant_file`: an invariant and mesher parameters in a TOML file (implies `serde`) | toml |
//! | `parallel` | yes | relaxation, flips and refinement of large meshes on rayon's thread pool; without it they run on the calling thread, with bit-identical results | rayon |
//! | `cli` | yes | the `liemesh` executable (implies the three above); nothing in the library | clap, serde_json, indicatif, tiny-skia, png, svg |
//! | `mpfr` | no | `scalar::Mpfr<BITS>`, MPFR floats of `BITS` bits (builds GMP and MPFR from source; needs `m4`) | rug |
//!
//! A program that only meshes depends on `liemesh = { version = "0.1", default-features =
//! false }`: the mesher, the model, the scalars, quality measures, audits and the PLY, OBJ and
//! STL writers and readers, on num-traits, nalgebra, spade, robust, thiserror and rustc-hash.
#![warn(missing_docs)]
#![deny(rustdoc::broken_intra_doc_links)]

pub mod audit;
mod error;
mod geom;
pub mod io;
pub mod mesh;
pub mod model;
mod par;
mod params;
pub mod preset;
pub mod progress;
pub mod quality;
pub mod sample;
pub mod scalar;
pub mod trace;
pub mod triangulate;

pub use error::MeshError;
pub use mesh::{Mesh, Provenance};
pub use model::NormalField;
pub use params::{Angle, MeshParams, Method, Mode, Resolved, Scales};
pub use progress::{Progress, Stage};

// The fuzz targets' checks (`fuzz/src/lib.rs`, written against the public API as
// `liemesh::...`), compiled into the unit tests too.
#[cfg(test)]
extern crate self as liemesh;
#[cfg(test)]
#[allow(dead_code)]
#[path = "../fuzz/src/lib.rs"]
mod fuzz_checks;

/// The README's examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

use scalar::Scalar;

/// Everything one meshing run produced.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct MeshRun<T> {
    /// The sample points in the working precision, with curves and step records.
    pub samples: sample::Samples<T>,
    /// The chart triangulation behind the mesh.
    pub chart: triangulate::ChartTriangulation,
    /// The mesh.
    pub mesh: Mesh,
    /// The mesh's vertices in the working precision (`mesh.vertices` rounded to `f64`).
    pub vertices: Vec<scalar::Vec3<T>>,
    /// What refinement to [`MeshParams::max_normal_error`] did, if it was asked for.
    pub refinement: Option<triangulate::Refinement>,
    /// What stitching where fronts met did.
    pub stitched: triangulate::Stitched,
    /// What was undone so that the mesh does not cross itself.
    pub untangled: triangulate::Untangled,
    /// The mesh's validation (always valid: an invalid mesh is an error).
    pub validation: mesh::Validation,
    /// The parameters with their automatic values worked out.
    pub params: Resolved,
    /// How long each stage took.
    pub timings: Timings,
}

impl<T> MeshRun<T> {
    /// What cut the run short, each in words (empty when nothing did): a budget, or
    /// crossings that took most of the mesh away. The mesh is then valid but smaller than
    /// the terminal conditions alone would have made it.
    pub fn cut_short(&self) -> Vec<String> {
        let p = &self.params;
        let mut why = Vec::new();
        if self.samples.hit_point_budget {
            why.push(format!(
                "the point budget (max_points = {}) ran out before the geodesic radius \
                 (max_radius = {:.3e}) or the bounding box (half-size {:.3e} about the origin) \
                 stopped the curves; a larger max_points lets them go on, a smaller max_radius \
                 makes the mesh smaller",
                p.max_points, p.max_radius, p.bounding_box
            ));
        }
        if self.samples.curves.len() >= p.max_curves {
            why.push(format!(
                "the curve budget (max_curves = {}) stopped insertions",
                p.max_curves
            ));
        }
        let ends = self.samples.ends();
        if ends.budget > 0 && !self.samples.hit_point_budget {
            why.push(format!(
                "{} curve{} ended on a budget (max_steps = {} steps per curve, or no chord \
                 within max_retries = {} Newton iterations, or no step down to dt_min = {:.3e} \
                 short enough to follow how sharply the surface bends; a smaller dt_min lets \
                 them go on)",
                ends.budget,
                if ends.budget == 1 { "" } else { "s" },
                p.max_steps,
                p.max_retries,
                p.dt_min
            ));
        }
        if self.stitched.budget_hit {
            why.push("the stitching of meeting fronts ran out of its operation budget".into());
        }
        // Crossing faces are cut out with what they cut off (`untangle`); where that is
        // most of the mesh, what is left is no longer the surface the curves swept. (Curves
        // that are not stopped where they meet, `close = false`, run over one another on a
        // surface they go round: a cylinder came out as 2 of 149,118 faces.)
        let (removed, kept) = (self.untangled.removed, self.mesh.triangles.len());
        if removed > kept {
            why.push(format!(
                "{removed} of the {} faces crossed others and were cut out, with what they \
                 cut off{}",
                removed + kept,
                if p.close {
                    ""
                } else {
                    " (without close, curves run on over the surface other curves swept)"
                }
            ));
        }
        if let Some(r) = &self.refinement {
            if r.over_limit > 0 {
                why.push(format!(
                    "refinement left {} face{} over the normal-error bound{}",
                    r.over_limit,
                    if r.over_limit == 1 { "" } else { "s" },
                    if r.stalled {
                        " (it stalled: smaller faces only tilted more)"
                    } else {
                        ""
                    }
                ));
            }
        }
        why
    }
}

/// How many times a run is sampled again with shorter automatic steps (see
/// [`SHORTER_STEPS`]): when its curves all ended at their first step, or, on a field of one's
/// own integrable at `p0`, when some ended as at a singular point or found no chord.
const SHORTER_STEP_RETRIES: usize = 2;

/// A retry for curves that ended too soon (see [`SHORTER_STEP_RETRIES`]) may lay at most this
/// many times the samples of the run before it. The superellipsoid below took 9 times as
/// many; a heart-shaped surface whose field vanishes along a curve (`(x² + 9/4 y² + z² − 1)³ −
/// x² z³ − 9/80 y² z³`), tried without this bound, crawled towards that curve for 80–145 s
/// and 3–4 million triangles where the first run took 3–4 s.
const SHORTER_STEP_GROWTH: usize = 16;

/// The factor the automatic Δt, dt_min and dt_max are divided by for each such retry.
/// A superellipsoid `|x|^4.5 + |y/1.5|^4.5 + |z/0.8|^4.5 = 1` started at the middle of its flat
/// top face resolved Δt = 36 for a surface 3 across and laid no sample beyond `p0`; with a
/// sixteenth it closes (7,910 triangles), with a quarter it does not. Started near the edge of
/// that face, `dt_min` came out as a hundredth of its size, too long for the rounded edges:
/// 58 curves ended there as at a singular point and a hole of 16 edges stayed; with a
/// sixteenth it closes (8,108 triangles).
const SHORTER_STEPS: f64 = 16.0;

/// Wall-clock seconds each stage of [`run`] took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Tracing the curves (sampling).
    pub sampling: f64,
    /// The chart triangulation, stitching where fronts meet and, in the default mode, the
    /// flips to surface Delaunay.
    pub triangulating: f64,
    /// Relaxation and edge flips (default mode).
    pub improving: f64,
    /// Refinement to a normal-error bound.
    pub refining: f64,
    /// Validation, and undoing crossings if there were any.
    pub validating: f64,
}

/// Samples and triangulates the surface of `field` (the whole pipeline), keeping the
/// intermediate results.
///
/// With the `parallel` feature, meshes of a few thousand vertices and more are relaxed and
/// flipped on rayon's current thread pool (call it inside rayon's `ThreadPool::install` to
/// choose the threads); the result is bit-identical for any number of threads, and without
/// the feature.
///
/// [`run_observed`] is the same run reporting its progress.
pub fn run<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &MeshParams,
) -> Result<MeshRun<T>, MeshError> {
    run_observed(field, params, &|_| {})
}

/// [`run`], calling `observe` with a [`Progress`] report as each stage starts, every
/// [`progress::SAMPLING_REPORT_EVERY`] steps of the sampling and as each refinement round
/// starts (never from an inner loop). `observe` is called on the calling thread; the mesh
/// is the same as [`run`]'s.
///
/// ```
/// use liemesh::{model::{Invariant, LieField}, preset::Preset, Stage};
/// use std::cell::RefCell;
///
/// let sphere = Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0])?;
/// let field = LieField::<f64>::new(&sphere);
/// let stages = RefCell::new(Vec::new());
/// let run = liemesh::run_observed(&field, &Preset::Fig3.params(), &|p| {
///     if stages.borrow().last() != Some(&p.stage) {
///         stages.borrow_mut().push(p.stage);
///     }
/// })?;
/// // The sphere closes (stitching runs) and is improved in the default mode.
/// assert_eq!(
///     stages.into_inner(),
///     [Stage::Sampling, Stage::Triangulating, Stage::Stitching, Stage::Improving, Stage::Validating]
/// );
/// assert!(!run.mesh.triangles.is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run_observed<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &MeshParams,
    observe: &dyn Fn(Progress),
) -> Result<MeshRun<T>, MeshError> {
    let clock = std::time::Instant::now();
    let mut timings = Timings::default();
    let lap = |slot: &mut f64, since: &mut f64| {
        let now = clock.elapsed().as_secs_f64();
        *slot = now - *since;
        *since = now;
    };
    let mut since = 0.0;
    let mut resolved = params.resolve::<T, F>(field)?;
    let mut samples = sample::sample_resolved(field, &resolved, observe)?;
    // Automatic steps sized at a flat spot (the middle of a superellipsoid's face: the
    // centres of curvature far away) can be longer than the whole surface, so that every
    // curve ends at its first step; they are shortened and the sampling run again.
    //
    // On a field of one's own integrable at `p0`, they can also be too long for the surface
    // farther on (a superellipsoid's rounded edges seen from its flat face): curves end there
    // as at a singular point, or find no chord down to `dt_min`. Such a run is tried again
    // with shorter steps and at most `SHORTER_STEP_GROWTH` times its samples, and the try is
    // kept only if every curve then ends otherwise: where the field does vanish (a surface
    // with a singular curve), shorter steps only crawl nearer to it, so the first run stays.
    // (The model's own fields size their steps by the quadric, and a sweep or a cone does
    // meet singular points.)
    let automatic = params.dt.is_none() && params.dt_min.is_none() && params.dt_max.is_none();
    let ended_short = |samples: &sample::Samples<T>| {
        let ends = samples.ends();
        ends.singular + ends.budget > 0
    };
    for _ in 0..SHORTER_STEP_RETRIES {
        let first_steps_only = samples.points.len() < 3;
        let ends_too_soon =
            resolved.level_correction && !samples.hit_point_budget && ended_short(&samples);
        if !automatic || !(first_steps_only || ends_too_soon) {
            break;
        }
        let mut shorter = resolved.clone();
        shorter.dt /= SHORTER_STEPS;
        shorter.dt_min /= SHORTER_STEPS;
        shorter.dt_max /= SHORTER_STEPS;
        if first_steps_only {
            samples = sample::sample_resolved(field, &shorter, observe)?;
            resolved = shorter;
            continue;
        }
        let budget = SHORTER_STEP_GROWTH.saturating_mul(samples.points.len());
        shorter.given.max_points = budget.min(resolved.max_points);
        match sample::sample_resolved(field, &shorter, observe) {
            Ok(again) if !again.hit_point_budget && !ended_short(&again) => {
                shorter.given.max_points = resolved.max_points;
                (resolved, samples) = (shorter, again);
            }
            _ => break,
        }
    }
    let params = &resolved;
    lap(&mut timings.sampling, &mut since);
    // A budget too small for any mesh is named as such, not as the failure it leads to.
    let too_small = || MeshError::PointBudgetTooSmall {
        max_points: params.max_points,
        points: samples.points.len(),
    };
    if samples.hit_point_budget && samples.points.len() < 3 {
        return Err(too_small());
    }
    let (points, curves) = (samples.points.len(), samples.curves.len());
    observe(Progress::at(Stage::Triangulating, points, curves, 0));
    let improve = params.mode == Mode::Default;
    // The axis of the hole the field knows, which no face may meet.
    let axis = params.hole.map(|h| h.axis());
    let chart = triangulate::chart_triangulation(&samples)?;
    let (mut mesh, mut vertices, stitched) =
        assemble(field, params, &samples, &chart, improve, axis, observe);
    lap(&mut timings.triangulating, &mut since);
    // Where every vertex was before relaxation, for taking back a relaxation move that makes
    // faces cross. Everything up to here is deterministic, so that state is rebuilt from the
    // samples and their chart triangulation on the rare run that needs it rather than copied
    // on every run (a copy of the whole mesh held through relaxation and validation: 48 MB at
    // 10⁶ triangles). A mesh made mostly by the stitching is copied instead: rebuilding it
    // would stitch it all again (40 s of a gyroid's run), and the two states are the same.
    let stitched_most = improve && 4 * stitched.added >= mesh.triangles.len();
    let mut copied = stitched_most.then(|| (mesh.clone(), vertices.clone()));
    // Called at most once (its result is kept in `before`), so the copy is handed over.
    let mut before_relaxation = || {
        let (mut mesh, working) = match copied.take() {
            Some(copy) => copy,
            None => {
                let (mesh, working, _) =
                    assemble(field, params, &samples, &chart, improve, axis, &|_| {});
                (mesh, working)
            }
        };
        // Without the faces peeled off beside a singular point below, should untangling go
        // back to these triangles.
        triangulate::peel_faces_beside_singular_points(field, &samples, &mut mesh);
        Some(triangulate::Before {
            positions: mesh.vertices,
            normals: mesh.normals,
            working,
            triangles: mesh.triangles,
        })
    };
    if improve {
        observe(Progress::at(
            Stage::Improving,
            mesh.vertices.len(),
            curves,
            mesh.triangles.len(),
        ));
        triangulate::relax(field, params, &mut mesh, &mut vertices, &[]);
    }
    lap(&mut timings.improving, &mut since);
    let refinement = params.max_normal_error.map(|limit| {
        let (points, triangles) = (mesh.vertices.len(), mesh.triangles.len());
        observe(Progress::at(Stage::Refining, points, curves, triangles));
        let on_round = |round, points, triangles| {
            observe(Progress {
                round,
                ..Progress::at(Stage::Refining, points, curves, triangles)
            })
        };
        let limit = limit.degrees();
        triangulate::refine(field, params, limit, &mut mesh, &mut vertices, &on_round)
    });
    lap(&mut timings.refining, &mut since);
    // Validation, decided exactly; crossings are undone (see `triangulate::untangle`).
    // Fans that meet only at a vertex are cut apart first: p0's component is then a
    // manifold through its vertices as well as its edges.
    observe(Progress::at(
        Stage::Validating,
        mesh.vertices.len(),
        curves,
        mesh.triangles.len(),
    ));
    // No face may span the hole the field knows: the stitching and the flips hold to that,
    // and a face that relaxation or refinement carried across it goes here.
    let across = triangulate::drop_across(&mut mesh, axis);
    // Faces far off the surface beside a cone's apex are peeled off the boundary, at the
    // vertices' final places.
    let peeled = triangulate::peel_faces_beside_singular_points(field, &samples, &mut mesh);
    // Pinched vertices are cut apart and only the main component is kept. The validation
    // finds both (and the faces it leaves out of its topology, which those passes may drop),
    // so on the usual mesh, which has none of them, the passes are skipped.
    let (mut validation, mut boundary) = mesh::validate_with_boundary(&mesh);
    // Crossings that relaxation made are first relaxed away again with their vertices pinned
    // (not after refinement, which added vertices since).
    let mut pinned = 0;
    let mut before = None;
    if improve && refinement.is_none() && !validation.self_intersections.is_empty() {
        before = before_relaxation();
        if let Some(b) = &before {
            pinned =
                triangulate::relax_pinned(field, params, &mut mesh, &mut vertices, b, |p, t| {
                    mesh::crossings(p, t)
                });
        }
        if pinned > 0 {
            (validation, boundary) = mesh::validate_with_boundary(&mesh);
        }
    }
    let untidy = !validation.non_manifold_vertices.is_empty()
        || !validation.degenerate_faces.is_empty()
        || !validation.out_of_range_faces.is_empty()
        || validation.components > 1;
    if untidy {
        triangulate::unpinch(&mut mesh.triangles);
        triangulate::keep_main_component(&mut mesh);
        (validation, boundary) = mesh::validate_with_boundary(&mesh);
    }
    let mut untangled = triangulate::Untangled::default();
    if !validation.self_intersections.is_empty() {
        if improve && before.is_none() {
            before = before_relaxation();
        }
        untangled = triangulate::untangle(&mut mesh, &mut vertices, before.as_ref(), |p, t| {
            mesh::crossings(p, t)
        });
        (validation, boundary) = mesh::validate_with_boundary(&mesh);
    }
    untangled.pinned = pinned;
    untangled.removed += across;
    untangled.off_surface = peeled;
    let mut stitched = stitched;
    stitched.holes = triangulate::holes(&samples, params, &mesh, &boundary, axis);
    triangulate::drop_unused(&mut mesh, &mut vertices);
    // The refinement's count of faces over the bound, on the mesh as returned.
    let mut refinement = refinement;
    if let (Some(r), Some(limit)) = (refinement.as_mut(), params.max_normal_error) {
        r.over_limit = triangulate::faces_over(field, &mesh, limit.degrees());
    }
    lap(&mut timings.validating, &mut since);
    if !validation.is_valid() {
        return Err(MeshError::Invalid(Box::new(validation)));
    }
    if mesh.triangles.is_empty() {
        if samples.hit_point_budget {
            return Err(too_small());
        }
        let swept = model::LocalShape::at::<T, F>(field, params.p0)
            .is_none_or(|shape| !shape.is_integrable());
        return Err(MeshError::Empty {
            points: samples.points.len(),
            swept,
            dt_max: params.dt_max,
        });
    }
    Ok(MeshRun {
        samples,
        chart,
        mesh,
        vertices,
        refinement,
        stitched,
        untangled,
        validation,
        params: resolved,
        timings,
    })
}

/// What [`assemble`] gives: the mesh, its vertices in the working precision and what the
/// stitching did.
type Assembled<T> = (Mesh, Vec<scalar::Vec3<T>>, triangulate::Stitched);

/// The mesh as it stands before relaxation: the samples' chart triangulation `chart`, stitched
/// where fronts meet (when the run closes its mesh) and then flipped to surface Delaunay
/// (when it is improved). A function of its arguments alone: [`run_observed`] builds it
/// again to take relaxation moves back.
fn assemble<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &Resolved,
    samples: &sample::Samples<T>,
    chart: &triangulate::ChartTriangulation,
    improve: bool,
    axis: Option<[[f64; 3]; 2]>,
    observe: &dyn Fn(Progress),
) -> Assembled<T> {
    // A mesh that is stitched is flipped to surface Delaunay once it is whole, not as a chart.
    let mut mesh = triangulate::mesh_of_chart(samples, chart, improve && !params.close);
    // The mesh's vertices in the working precision, found by provenance.
    let mut vertices = triangulate::sample_vertices(samples, &mesh);
    let stitched = if params.close {
        observe(Progress::at(
            Stage::Stitching,
            mesh.vertices.len(),
            samples.curves.len(),
            mesh.triangles.len(),
        ));
        let stitched = triangulate::stitch(field, params, samples, chart, &mut mesh, &mut vertices);
        if improve {
            triangulate::flip_to_surface_delaunay(&mut mesh, axis);
        }
        stitched
    } else {
        Default::default()
    };
    (mesh, vertices, stitched)
}

/// Meshes the surface of `field` with `params`.
pub fn generate<T: Scalar, F: NormalField<T>>(
    field: &F,
    params: &MeshParams,
) -> Result<Mesh, MeshError> {
    run(field, params).map(|r| r.mesh)
}

/// A mesh and the derivative of every vertex with respect to one parameter of the field.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct MeshDerivatives {
    /// The mesh, identical to the `f64` run's (a dual number's real part rounds exactly as
    /// `f64` does, so every discrete decision is the `f64` run's).
    pub mesh: Mesh,
    /// `d(vertex)/d(parameter)` for every vertex of [`MeshDerivatives::mesh`], with the
    /// discrete decisions (steps, curves, triangles) held fixed.
    pub d_vertices: Vec<[f64; 3]>,
}

/// Meshes `field`, whose parameter of interest is the dual variable, and returns the mesh with
/// the derivative of every vertex with respect to that parameter: forward-mode AD through the
/// whole pipeline, in one run.
///
/// For an invariant number, seed it with [`model::LieField::seeded`]; for a parameter of a
/// field of one's own, write the field in `Dual<f64>` with the parameter as
/// `Dual::variable(value)`.
///
/// ```
/// use liemesh::model::{Invariant, LieField};
/// use liemesh::{differentiate, MeshParams};
///
/// // The ellipsoid λ1 x² + 4y² + 16z² = 1 at λ1 = 1, and d(vertex)/dλ1.
/// let invariant = Invariant::from_numbers(&[1.0, 4.0, 16.0, 0.0, 0.0, 0.0])?;
/// let d = differentiate(&LieField::<f64>::seeded(&invariant, 0), &MeshParams::at([0.6, 0.4, 0.0]))?;
/// // On the level set through p0, λ1 x² + … = λ1·0.36 + 0.64: differentiating,
/// // x² + 2 (λ1 x dx + 4 y dy + 16 z dz) = 0.36 at every vertex.
/// for (v, dv) in d.mesh.vertices.iter().zip(&d.d_vertices) {
///     let lhs = v[0] * v[0] + 2.0 * (v[0] * dv[0] + 4.0 * v[1] * dv[1] + 16.0 * v[2] * dv[2]);
///     assert!((lhs - 0.36).abs() < 1e-9, "{lhs}");
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn differentiate<F: NormalField<scalar::Dual<f64>>>(
    field: &F,
    params: &MeshParams,
) -> Result<MeshDerivatives, MeshError> {
    let run = run(field, params)?;
    let d_vertices = run
        .vertices
        .iter()
        .map(|v| [v.x.eps, v.y.eps, v.z.eps])
        .collect();
    Ok(MeshDerivatives {
        mesh: run.mesh,
        d_vertices,
    })
}
