//! The chart's Delaunay triangulation, by spade's bulk load or, for a large chart whose hull
//! is far from its outline, by insertion in Morton order.
//!
//! spade's bulk load inserts the points outwards from their mean, keeping the triangulation's
//! outline star-shaped, and makes its hull convex at the end by filling the pockets between
//! far-reaching parts of the outline with triangles that it then legalizes by flips. A chart
//! whose curves end at very different distances from `p0` (a triply periodic surface, where
//! fronts meet all over it and long curves reach out between short ones) leaves deep pockets,
//! and the flips that fill them cost far more than the insertion: a gyroid's chart of 866,478
//! points took 41 s, 40 s of it in that last step, where insertion one point at a time in
//! Morton order took 4 s for the same number of faces. On an ordinary chart the bulk load is
//! two to three times quicker than that insertion (0.18 s against 0.54 s for the 392,348
//! points of the 10⁶-triangle sphere), so it stays the rule.
//!
//! The choice is made from the points alone, before either runs: the chart must have at least
//! [`POCKETED_MIN_POINTS`] points and the convex hull of its outline's extreme points must
//! cover at least [`POCKETED_AREA_RATIO`] times the outline's area (both measured over
//! [`SECTORS`] angular sectors about the mean). Cocircular points (every fan of curves from
//! `p0` has them) are split by the order of insertion, so the two ways give different,
//! equally Delaunay triangulations: the choice is a function of the chart, and no chart of the
//! gallery, the figures or the benchmarks reaches it (their ratios are 1.00–1.46).

use super::{cross2, sector, sub2, ChartVertex};
use spade::{ConstrainedDelaunayTriangulation, HasPosition, InsertionError, Triangulation as _};

/// A chart with fewer points than this is bulk loaded whatever its shape: below it even deep
/// pockets cost little (the gyroid's first 400,000 points bulk load in 0.35 s).
pub(super) const POCKETED_MIN_POINTS: usize = 100_000;

/// The ratio of hull to outline area from which a large chart is inserted in Morton order.
/// Measured over [`SECTORS`] sectors: 3.3–3.8 for gyroid charts of 8·10⁵ points whose bulk
/// loads took 8–41 s; 1.00–1.03 for the benchmarks' 10⁶-triangle charts, at most 1.46 for the
/// gallery's.
pub(super) const POCKETED_AREA_RATIO: f64 = 2.0;

/// Angular sectors about the chart's mean in which its outline is measured.
const SECTORS: usize = 64;

type Chart = ConstrainedDelaunayTriangulation<ChartVertex>;

/// The Delaunay triangulation of `vertices` (no constraints yet).
pub(super) fn triangulate(vertices: Vec<ChartVertex>) -> Result<Chart, InsertionError> {
    if !pocketed(&vertices) {
        return Chart::bulk_load(vertices);
    }
    let mut cdt = Chart::new();
    for v in in_morton_order(vertices) {
        cdt.insert(v)?;
    }
    Ok(cdt)
}

/// Whether the chart is large and its convex hull far larger than its outline (see the
/// module docs).
fn pocketed(vertices: &[ChartVertex]) -> bool {
    let n = vertices.len();
    if n < POCKETED_MIN_POINTS {
        return false;
    }
    let xy = |v: &ChartVertex| {
        let p = v.position();
        [p.x, p.y]
    };
    let mut mean = [0.0, 0.0];
    for v in vertices {
        let [x, y] = xy(v);
        mean = [mean[0] + x, mean[1] + y];
    }
    let mean = [mean[0] / n as f64, mean[1] / n as f64];
    // The farthest point of each sector of the pseudo-angle (no arctangent per point); each
    // sector's true angular width comes from its bounds.
    let mut far = [(0.0_f64, [0.0_f64; 2]); SECTORS];
    for v in vertices {
        let [x, y] = xy(v);
        let d = [x - mean[0], y - mean[1]];
        if let Some(s) = sector(SECTORS, d) {
            let r2 = d[0] * d[0] + d[1] * d[1];
            if r2 > far[s].0 {
                far[s] = (r2, [x, y]);
            }
        }
    }
    let outline: f64 = (0..SECTORS).map(|s| far[s].0 * sector_width(s) / 2.0).sum();
    let extremes: Vec<[f64; 2]> = far.iter().filter(|f| f.0 > 0.0).map(|f| f.1).collect();
    outline > 0.0 && hull_area(extremes) >= POCKETED_AREA_RATIO * outline
}

/// The angle (radians) that sector `s` of [`SECTORS`] spans: pseudo-angles
/// `[4s/SECTORS, 4(s+1)/SECTORS)` ([`super::pseudo_angle`]).
fn sector_width(s: usize) -> f64 {
    // The angle of pseudo-angle q: the inverse of `pseudo_angle` on each quadrant.
    let angle = |q: f64| {
        let quadrant = (q.floor() as i32).clamp(0, 3);
        let t = q - quadrant as f64; // 0..1 within the quadrant
        let within = t.atan2(1.0 - t); // angle of (1 − t, t)
        quadrant as f64 * std::f64::consts::FRAC_PI_2 + within
    };
    let step = 4.0 / SECTORS as f64;
    angle(step * (s + 1) as f64) - angle(step * s as f64)
}

/// The area of the convex hull of `points` (Andrew's monotone chain).
fn hull_area(mut points: Vec<[f64; 2]>) -> f64 {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let turn = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| cross2(sub2(a, o), sub2(b, o));
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        for k in 0..points.len() {
            let q = if pass == 0 {
                points[k]
            } else {
                points[points.len() - 1 - k]
            };
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let m = hull.len();
    (0..m)
        .map(|i| cross2(hull[i], hull[(i + 1) % m]))
        .sum::<f64>()
        / 2.0
}

/// `vertices` sorted along a Morton (Z-order) curve over their bounding box, ties in their
/// given order: each insertion then starts its walk beside the last one.
fn in_morton_order(mut vertices: Vec<ChartVertex>) -> Vec<ChartVertex> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in &vertices {
        let p = v.position();
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    let cell = |x: f64, k: usize| {
        let span = hi[k] - lo[k];
        if span > 0.0 {
            ((x - lo[k]) / span * 65_535.0) as u32
        } else {
            0
        }
    };
    let key = |v: &ChartVertex| {
        let p = v.position();
        let (x, y) = (cell(p.x, 0), cell(p.y, 1));
        (0..16).fold(0u64, |k, b| {
            k | u64::from((x >> b) & 1) << (2 * b) | u64::from((y >> b) & 1) << (2 * b + 1)
        })
    };
    vertices.sort_by_cached_key(key);
    vertices
}

#[cfg(test)]
mod tests {
    use super::*;
    use spade::Point2;

    fn vertex(i: usize, x: f64, y: f64) -> ChartVertex {
        ChartVertex {
            position: Point2::new(x, y),
            index: i as u32,
        }
    }

    /// A disc of points with a few long spikes: the hull (spanned by the spikes) is many times
    /// the disc.
    fn spiked(n: usize, spikes: usize, reach: f64) -> Vec<ChartVertex> {
        let mut v = Vec::new();
        let mut rng = crate::geom::rng::XorShift64::new(7);
        while v.len() < n {
            let (x, y) = (2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0);
            if x * x + y * y < 1.0 {
                v.push(vertex(v.len(), x, y));
            }
        }
        for s in 0..spikes {
            let a = std::f64::consts::TAU * s as f64 / spikes as f64;
            for k in 1..=200 {
                // Jittered, so that no four points are cocircular.
                let r = 1.0 + (reach - 1.0) * (k as f64 + rng.uniform(-0.3, 0.3)) / 200.0;
                let a = a + rng.uniform(-1e-3, 1e-3);
                v.push(vertex(v.len(), r * a.cos(), r * a.sin()));
            }
        }
        v
    }

    #[test]
    fn sector_widths_make_a_full_turn() {
        let total: f64 = (0..SECTORS).map(sector_width).sum();
        assert!((total - std::f64::consts::TAU).abs() < 1e-12, "{total}");
        // The pseudo-angle of a direction falls in the sector whose true bounds hold it.
        for k in 0..1000 {
            let a = std::f64::consts::TAU * (k as f64 + 0.5) / 1000.0;
            let s = sector(SECTORS, [a.cos(), a.sin()]).unwrap();
            let start: f64 = (0..s).map(sector_width).sum();
            assert!(
                start <= a + 1e-12 && a < start + sector_width(s) + 1e-12,
                "{a} in {s}"
            );
        }
    }

    #[test]
    fn a_large_disc_is_bulk_loaded_and_a_spiked_one_inserted() {
        let disc = spiked(POCKETED_MIN_POINTS, 0, 1.0);
        assert!(!pocketed(&disc));
        let spikes = spiked(POCKETED_MIN_POINTS, 6, 8.0);
        assert!(pocketed(&spikes));
        // Below the size bound, spikes do not matter.
        assert!(!pocketed(&spiked(POCKETED_MIN_POINTS / 2, 6, 8.0)));
    }

    #[test]
    fn insertion_in_morton_order_is_delaunay_over_every_point() {
        let points = spiked(3000, 5, 6.0);
        let n = points.len();
        let by_insertion = {
            let mut cdt = Chart::new();
            for v in in_morton_order(points.clone()) {
                cdt.insert(v).unwrap();
            }
            cdt
        };
        let bulk = Chart::bulk_load(points).unwrap();
        assert_eq!(by_insertion.num_vertices(), n);
        // Random points are in general position: both are the one Delaunay triangulation.
        let faces = |cdt: &Chart| {
            let mut f: Vec<[u32; 3]> = cdt
                .inner_faces()
                .map(|face| {
                    let mut t = face.vertices().map(|v| v.data().index);
                    t.sort_unstable();
                    t
                })
                .collect();
            f.sort_unstable();
            f
        };
        assert_eq!(faces(&by_insertion), faces(&bulk));
    }
}
