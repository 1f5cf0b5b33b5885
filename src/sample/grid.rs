//! A uniform hash grid over points: O(1) neighbourhood queries for the gap and
//! closure tests of the sampler.

use crate::geom::vec3::FastHash;
use std::collections::HashMap;

type Cell = (i32, i32, i32);

/// The query radius, in cells, that the grid's cell size is tuned to. A query visits about
/// `(1 + 2ρ)³` cells, most of them empty (the points lie on a surface), and every point of a
/// patch of surface about `(1 + 2ρ)/ρ` radii wide. Since the fence (`Sampler::crosses`)
/// tests every candidate point of its queries, a candidate costs more than a cell lookup
/// (a hash probe, usually a cache miss) would at ρ = 0.15, the choice before it: at
/// ρ = 0.35 sampling the 10⁵-triangle sphere of the benchmarks takes 276M instructions
/// instead of 384M (callgrind), and ρ = 0.6 saves only 1% more for twice the lookups.
/// The answers do not depend on ρ, only the cost.
const TARGET_REACH: f64 = 0.35;

/// The cell is chosen anew when the mean query radius leaves this factor around
/// [`TARGET_REACH`] cells.
const RETUNE_FACTOR: f64 = 1.6;

/// A filed point: its index, and a copy of its position, so that a query reads the
/// candidates' positions from the bucket it scans rather than from all over the point list.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Filed {
    pub index: u32,
    pub at: [f64; 3],
}

/// Points bucketed by cubic cells of side `1 / inv`.
///
/// The cell size starts at a guess and follows the query radii: every time the number of
/// points doubles, the mean radius asked for since the last review is compared with the cell
/// and, if they are far apart, all points are filed anew (amortised O(1) per point). Queries
/// return the same answers whatever the cell size; only their cost depends on it.
pub(crate) struct Grid {
    inv: f64,
    buckets: HashMap<Cell, Vec<Filed>, FastHash>,
    /// Points filed.
    len: usize,
    /// The number of points at which the cell size is next reviewed.
    next_review: usize,
    /// Sum of the query radii (in cells) and number of queries since the last review.
    reach: std::cell::Cell<(f64, u32)>,
}

impl Grid {
    pub(crate) fn new(cell: f64) -> Self {
        Grid {
            inv: 1.0 / cell,
            buckets: HashMap::default(),
            len: 0,
            next_review: 256,
            reach: std::cell::Cell::new((0.0, 0)),
        }
    }

    #[inline]
    fn key(&self, p: [f64; 3]) -> Cell {
        let k = |x: f64| crate::geom::grid::floor_clamped(x * self.inv);
        (k(p[0]), k(p[1]), k(p[2]))
    }

    /// Files the last of `positions` (index `positions.len() − 1`); the others must have been
    /// filed before, in order. The grid refiles them all when it changes its cell size.
    pub(crate) fn push(&mut self, positions: &[[f64; 3]]) {
        let Some((&p, _)) = positions.split_last() else {
            return;
        };
        debug_assert_eq!(positions.len(), self.len + 1, "points are filed in order");
        self.file(p, self.len as u32);
        self.len += 1;
        if self.len >= self.next_review {
            self.next_review = 2 * self.len;
            self.review(positions);
        }
    }

    /// Refiles every point with a cell of `TARGET_REACH` mean query radii, if the current
    /// cell is more than [`RETUNE_FACTOR`] off it.
    fn review(&mut self, positions: &[[f64; 3]]) {
        let (sum, queries) = self.reach.replace((0.0, 0));
        if queries == 0 {
            return;
        }
        let mean = sum / f64::from(queries);
        let off = mean / TARGET_REACH;
        if (1.0 / RETUNE_FACTOR..=RETUNE_FACTOR).contains(&off) || !(off.is_finite() && off > 0.0) {
            return;
        }
        // `mean` is in cells: the new cell is `mean / TARGET_REACH` old cells.
        let inv = self.inv / off;
        if !(inv.is_finite() && inv > 0.0) {
            return;
        }
        self.inv = inv;
        self.buckets.clear();
        for (i, &p) in positions.iter().enumerate() {
            self.file(p, i as u32);
        }
    }

    fn file(&mut self, p: [f64; 3], index: u32) {
        let key = self.key(p);
        self.buckets
            .entry(key)
            .or_default()
            .push(Filed { index, at: p });
    }

    /// Whether `f(index, position)` holds for some stored point whose cell meets the ball of
    /// `radius` around `p` (a superset of the points within `radius`); stops at the first
    /// that does.
    ///
    /// When the ball's bounding box meets more cells than the grid has buckets (a radius of
    /// many cells: an initial Δt far below the step lengths), every bucket is visited
    /// instead, which is cheaper and still a superset.
    pub(crate) fn any_near(
        &self,
        p: [f64; 3],
        radius: f64,
        mut f: impl FnMut(u32, [f64; 3]) -> bool,
    ) -> bool {
        // Only the cells the ball's bounding box meets: about (1 + 2ρ)³ for a radius of ρ
        // cells.
        let radius = radius.max(0.0);
        let (sum, queries) = self.reach.get();
        if radius.is_finite() && queries < u32::MAX {
            self.reach.set((sum + radius * self.inv, queries + 1));
        }
        let lo = self.key([p[0] - radius, p[1] - radius, p[2] - radius]);
        let hi = self.key([p[0] + radius, p[1] + radius, p[2] + radius]);
        let cells = (hi.0 as f64 - lo.0 as f64 + 1.0)
            * (hi.1 as f64 - lo.1 as f64 + 1.0)
            * (hi.2 as f64 - lo.2 as f64 + 1.0);
        if radius.is_nan() || cells > self.buckets.len() as f64 {
            return self.buckets.values().flatten().any(|e| f(e.index, e.at));
        }
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    if let Some(bucket) = self.buckets.get(&(x, y, z)) {
                        if bucket.iter().any(|e| f(e.index, e.at)) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic points on the unit sphere.
    fn sphere_points(n: usize) -> Vec<[f64; 3]> {
        let mut rng = crate::geom::rng::XorShift64::new(3);
        (0..n).map(|_| rng.unit_vector()).collect()
    }

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    /// Files `points` one by one, asking a query of `radius` around each before it is filed.
    fn filled(cell: f64, points: &[[f64; 3]], radius: f64) -> Grid {
        let mut grid = Grid::new(cell);
        for (i, &p) in points.iter().enumerate() {
            grid.any_near(p, radius, |_, _| false);
            grid.push(&points[..=i]);
        }
        grid
    }

    #[test]
    fn queries_see_every_point_within_the_radius_whatever_the_cell() {
        let points = sphere_points(3000);
        let queries = sphere_points(3100);
        for cell in [1e-3, 0.05, 0.3, 5.0] {
            let grid = filled(cell, &points, 0.04);
            for (k, &q) in queries[3000..].iter().enumerate() {
                let radius = [0.0, 0.01, 0.05, 0.2][k % 4];
                let mut seen = vec![false; points.len()];
                grid.any_near(q, radius, |j, at| {
                    assert_eq!(at, points[j as usize]);
                    seen[j as usize] = true;
                    false
                });
                for (j, &p) in points.iter().enumerate() {
                    assert!(
                        seen[j] || dist(p, q) > radius,
                        "cell {cell}: point {j} missed"
                    );
                }
                let hit = grid.any_near(q, radius, |_, at| dist(at, q) <= radius);
                let want = points.iter().any(|&p| dist(p, q) <= radius);
                assert_eq!(hit, want, "cell {cell}, radius {radius}");
            }
        }
    }

    #[test]
    fn the_cell_follows_the_query_radii() {
        let points = sphere_points(4000);
        for (cell, radius) in [(1e-3, 0.02), (2.0, 0.02), (0.02, 0.002)] {
            let grid = filled(cell, &points, radius);
            let reach = radius * grid.inv;
            assert!(
                (TARGET_REACH / RETUNE_FACTOR..=TARGET_REACH * RETUNE_FACTOR).contains(&reach),
                "started at {cell}: queries of {radius} span {reach} cells"
            );
        }
    }

    #[test]
    fn a_grid_without_queries_keeps_its_cell() {
        let points = sphere_points(1000);
        let mut grid = Grid::new(0.25);
        for i in 0..points.len() {
            grid.push(&points[..=i]);
        }
        assert_eq!(grid.inv, 4.0);
    }
}
