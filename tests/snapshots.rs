//! Delaunay output (DESIGN.md §4): insta snapshots of the six presets' triangulations, and the
//! empty-circumcircle property of every chart triangulation, checked with exact predicates.
//!
//! The snapshots live in the top-level `snapshots/` folder. After an intended change of the
//! meshes, review and accept the new ones with `cargo insta review` (or regenerate them with
//! `INSTA_UPDATE=always cargo test --test suite snapshots::` and inspect the diff).

// The fuzz targets' checks (see `tests/suite.rs`).
use crate::fuzz_checks::{check_chart, check_chart_delaunay};
use liemesh::model::LieField;
use liemesh::preset::Preset;
use liemesh::quality::Topology;
use liemesh::{Angle, MeshParams, MeshRun, Mode};
use std::fmt::Write as _;

fn run(preset: Preset, params: &MeshParams) -> MeshRun<f64> {
    let field = LieField::<f64>::new(&preset.invariant());
    liemesh::run(&field, params).unwrap_or_else(|e| panic!("{preset}: {e}"))
}

/// A coordinate rounded to 1e-9, without a sign on zero.
fn coord(x: f64) -> String {
    let s = format!("{x:.9}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// The text of a snapshot: the report's counts, then the triangles (each rotated so that its
/// smallest index comes first, keeping the orientation, then sorted), then the vertices.
fn snapshot_text(run: &MeshRun<f64>) -> String {
    let mesh = &run.mesh;
    let topo = Topology::of(mesh);
    let mut out = String::new();
    writeln!(out, "vertices: {}", mesh.vertices.len()).unwrap();
    writeln!(out, "triangles: {}", mesh.triangles.len()).unwrap();
    writeln!(out, "curves: {}", run.samples.curves.len()).unwrap();
    writeln!(out, "closed: {}", topo.closed).unwrap();
    writeln!(out, "euler_characteristic: {}", topo.euler_characteristic).unwrap();
    writeln!(out, "boundary_loops: {}", topo.boundary_loops).unwrap();
    writeln!(out, "triangles (a b c, counter-clockwise):").unwrap();
    for [a, b, c] in mesh.canonical_triangles() {
        writeln!(out, "{a} {b} {c}").unwrap();
    }
    writeln!(out, "vertices (x y z):").unwrap();
    for v in &mesh.vertices {
        writeln!(out, "{} {} {}", coord(v[0]), coord(v[1]), coord(v[2])).unwrap();
    }
    out
}

/// Checks `run` against the snapshot `name`, made by the command `command`.
fn assert_run_snapshot(name: &str, command: &str, run: &MeshRun<f64>) {
    let text = snapshot_text(run);
    insta::with_settings!({
        snapshot_path => "../snapshots",
        prepend_module_to_snapshot => false,
        description => format!("{command}: counts, canonical triangles, vertices rounded to 1e-9"),
        omit_expression => true,
    }, {
        insta::assert_snapshot!(name, text);
    });
}

fn assert_preset_snapshot(preset: Preset) {
    assert_run_snapshot(
        preset.name(),
        &format!("liemesh mesh --preset {preset}"),
        &run(preset, &preset.params()),
    );
}

#[test]
fn fig1_triangulation_matches_its_snapshot() {
    assert_preset_snapshot(Preset::Fig1);
}

#[test]
fn fig2_triangulation_matches_its_snapshot() {
    assert_preset_snapshot(Preset::Fig2);
}

#[test]
fn fig3_triangulation_matches_its_snapshot() {
    assert_preset_snapshot(Preset::Fig3);
}

#[test]
fn fig4_triangulation_matches_its_snapshot() {
    assert_preset_snapshot(Preset::Fig4);
}

#[test]
fn fig5_triangulation_matches_its_snapshot() {
    assert_preset_snapshot(Preset::Fig5);
}

#[test]
fn fig6_triangulation_matches_its_snapshot() {
    assert_preset_snapshot(Preset::Fig6);
}

/// Refinement to a normal-error bound adds vertices by chords and flips: its output is as
/// deterministic as the rest.
#[test]
fn fig3_refined_to_one_degree_matches_its_snapshot() {
    let mut params = Preset::Fig3.params();
    params.max_normal_error = Some(Angle::from_degrees(1.0));
    let refined = run(Preset::Fig3, &params);
    assert!(refined
        .refinement
        .is_some_and(|r| r.added > 0 && r.over_limit == 0));
    assert_run_snapshot(
        "fig3-refined",
        "liemesh mesh --preset fig3 --max-normal-error 1",
        &refined,
    );
}

/// The snapshots can fail: changing a preset's parameters changes its triangulation and so
/// its snapshot text, while the same parameters give the same text twice (deterministic
/// output). In the default mode every step length comes from the predicted angle and Δt
/// does not enter the triangulation, so Δt is changed in the paper mode, where it is the
/// first trial step.
#[test]
fn a_changed_triangulation_changes_the_snapshot() {
    let params = Preset::Fig3.params();
    let base = snapshot_text(&run(Preset::Fig3, &params));
    assert!(
        base == snapshot_text(&run(Preset::Fig3, &params)),
        "not deterministic"
    );
    let mut narrower_band = params.clone();
    narrower_band.beta_max = params.beta_max * 0.9;
    assert!(base != snapshot_text(&run(Preset::Fig3, &narrower_band)));
    let mut paper = params;
    paper.mode = Mode::Paper;
    let paper_text = snapshot_text(&run(Preset::Fig3, &paper));
    assert!(base != paper_text);
    let mut smaller_step = paper.clone();
    smaller_step.dt = paper.dt.map(|dt| dt * 0.9);
    assert!(paper_text != snapshot_text(&run(Preset::Fig3, &smaller_step)));
}

#[test]
fn snapshot_triangles_are_canonical() {
    let text = snapshot_text(&run(Preset::Fig1, &Preset::Fig1.params()));
    let triangles: Vec<[u32; 3]> = text
        .lines()
        .skip_while(|l| !l.starts_with("triangles ("))
        .skip(1)
        .take_while(|l| !l.starts_with("vertices ("))
        .map(|l| {
            let v: Vec<u32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert!(!triangles.is_empty());
    assert!(triangles.iter().all(|t| t[0] < t[1] && t[0] < t[2]));
    assert!(triangles.windows(2).all(|w| w[0] < w[1]));
}

/// Every chart-1 triangulation is a constrained Delaunay triangulation: each interior edge
/// that is not a front constraint has neither opposite vertex strictly inside the other
/// triangle's circumcircle (exact `robust` predicates, the ones spade uses), and every
/// triangle is strictly counter-clockwise in the chart.
#[test]
fn chart_triangles_have_empty_circumcircles() {
    for preset in Preset::ALL {
        let r = run(preset, &preset.params());
        check_chart(&r.chart, r.samples.points.len()).unwrap_or_else(|v| panic!("{preset}: {v}"));
        let edges = check_chart_delaunay(&r.chart).unwrap_or_else(|v| panic!("{preset}: {v}"));
        // Nearly every chart edge is interior: the check is not vacuous.
        assert!(
            edges >= r.chart.triangles.len(),
            "{preset}: only {edges} edges checked for {} triangles",
            r.chart.triangles.len()
        );
    }
}

/// Curves that symmetry makes congruent (fig1 and fig2: a sphere traced from its pole) put
/// their points on exact circles about `p0`, and every quadrilateral between two neighbouring
/// curves is cocircular. `triangulate::chart_points` breaks those ties, so that no Delaunay
/// decision of chart 1 is left to rounding, where spade's exact predicates take their slow
/// path (fig2's points took four times as long to triangulate per point as fig3's): every
/// interior edge's in-circle determinant, in plain `f64`, is clear of its rounding by a wide
/// margin (the edges along the front are constraints, not decisions).
#[test]
fn congruent_curves_leave_no_cocircular_ties_in_the_chart() {
    for preset in Preset::ALL {
        let r = run(preset, &preset.params());
        let pos = &r.chart.chart;
        let on_front: std::collections::HashSet<u32> = r.chart.front.iter().copied().collect();
        let mut opposite = std::collections::HashMap::new();
        for t in &r.chart.triangles {
            for k in 0..3 {
                opposite.insert((t[k], t[(k + 1) % 3]), t[(k + 2) % 3]);
            }
        }
        let mut tightest = f64::INFINITY;
        for (&(a, b), &c) in &opposite {
            let Some(&d) = opposite.get(&(b, a)) else {
                continue;
            };
            if a > b || (on_front.contains(&a) && on_front.contains(&b)) {
                continue;
            }
            let [pa, pb, pc, pd] = [a, b, c, d].map(|i| pos[i as usize]);
            let (adx, ady) = (pa[0] - pd[0], pa[1] - pd[1]);
            let (bdx, bdy) = (pb[0] - pd[0], pb[1] - pd[1]);
            let (cdx, cdy) = (pc[0] - pd[0], pc[1] - pd[1]);
            let (al, bl, cl) = (
                adx * adx + ady * ady,
                bdx * bdx + bdy * bdy,
                cdx * cdx + cdy * cdy,
            );
            let det = al * (bdx * cdy - cdx * bdy)
                + bl * (cdx * ady - adx * cdy)
                + cl * (adx * bdy - bdx * ady);
            let permanent = al * ((bdx * cdy).abs() + (cdx * bdy).abs())
                + bl * ((cdx * ady).abs() + (adx * cdy).abs())
                + cl * ((adx * bdy).abs() + (bdx * ady).abs());
            tightest = tightest.min(det.abs() / permanent);
        }
        // Rounding leaves about 1e-15 of the permanent; without the ties broken, fig1 and
        // fig2 have determinants of exactly 0.
        assert!(
            tightest > 1e-12,
            "{preset}: an in-circle decision within {tightest:e} of its permanent"
        );
    }
}
