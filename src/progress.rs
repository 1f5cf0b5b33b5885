//! Progress reports of a meshing run ([`run_observed`](crate::run_observed)): which stage the
//! pipeline is in and how far it got, for a caller that shows them (the `liemesh` executable
//! draws them as a spinner) or logs them.
//!
//! Reports come as each stage starts, every [`SAMPLING_REPORT_EVERY`] steps of the sampler's
//! outer loop and as each refinement round starts, never from an inner loop: observing costs a
//! few dozen calls of the observer per second, and [`run`](crate::run) observes with a
//! function that does nothing.

/// The stages of a meshing run, in the order they run.
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Stage {
    /// Tracing the fan of curves from `p0` (the sample points).
    Sampling,
    /// The chart triangulation of the sample points.
    Triangulating,
    /// Stitching the mesh where fronts meet (only when closing is on).
    Stitching,
    /// Relaxation and surface-Delaunay flips (default mode only).
    Improving,
    /// Refinement to the normal-error bound (only when one is asked for).
    Refining,
    /// Validation, and undoing crossings if there are any.
    Validating,
}

impl Stage {
    /// The stage's name as a lower-case word (`"sampling"`, `"triangulating"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Sampling => "sampling",
            Stage::Triangulating => "triangulating",
            Stage::Stitching => "stitching",
            Stage::Improving => "improving",
            Stage::Refining => "refining",
            Stage::Validating => "validating",
        }
    }
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One progress report: the stage the run is in and its counts so far.
///
/// Counts that do not apply to a stage are 0: `triangles` while sampling and triangulating,
/// `round` outside refinement.
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// The stage running.
    pub stage: Stage,
    /// Sample points laid down so far while sampling, all of them while triangulating, and
    /// the mesh's vertices in the later stages.
    pub points: usize,
    /// Curves traced so far, inserted ones included (their final number after sampling).
    pub curves: usize,
    /// Triangles of the mesh as the stage starts (for refinement: as the round starts).
    pub triangles: usize,
    /// The refinement round about to run, counting from 1; 0 as refinement starts (measuring
    /// every face's normal error) and outside refinement.
    pub round: usize,
}

impl Progress {
    /// A report of `stage` with the given counts and no refinement round.
    pub(crate) fn at(stage: Stage, points: usize, curves: usize, triangles: usize) -> Progress {
        Progress {
            stage,
            points,
            curves,
            triangles,
            round: 0,
        }
    }
}

/// The sampler reports once every this many passes of its outer loop (each pass lays down a
/// point or ends a curve).
pub const SAMPLING_REPORT_EVERY: usize = 1024;
