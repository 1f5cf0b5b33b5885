//! Hash grids over points, at the cell sizes the queries need: O(1) neighbourhood queries
//! for the gap, closure and fence tests of the sampler.

use crate::geom::vec3::FastHash;
use std::collections::HashMap;

type Cell = (i32, i32, i32);

/// The query radius, in cells, that the grid's cell sizes are tuned to. A query visits about
/// `(1 + 2ρ)³` cells, most of them empty (the points lie on a surface), and every point of a
/// patch of surface about `(1 + 2ρ)/ρ` radii wide. Since the fence (`Sampler::crosses`)
/// tests every candidate point of its queries, a candidate costs more than a cell lookup
/// (a hash probe, usually a cache miss) would at ρ = 0.15, the choice before it: at
/// ρ = 0.35 sampling the 10⁵-triangle sphere of the benchmarks takes 276M instructions
/// instead of 384M (callgrind), and ρ = 0.6 saves only 1% more for twice the lookups.
/// The answers do not depend on ρ, only the cost.
const TARGET_REACH: f64 = 0.35;

/// What a cell lookup (a hash probe, often a cache miss) costs against a candidate tested,
/// in [`off_level_cost`].
const LOOKUP_COST: f64 = 5.0;

/// What filing a point in one level costs, relative to a query on its own level (a hash
/// insert against a few cell lookups and a few dozen candidates).
const FILE_COST: f64 = 0.25;

/// The levels are also reviewed, between the reviews at each doubling, as soon as the
/// queries since the last review have cost this many queries per point filed beyond what
/// they would have on their own levels.
const EARLY_REVIEW: f64 = 0.5;

/// What a query costs on cells `2^d` times smaller than its own level's (`d < 0`: larger),
/// relative to one on its own level. A query of `ρ` cells ([`TARGET_REACH`] on its own
/// level) looks up the `(1 + 2ρ)³` cells of its box, and tests every point on the part of
/// the surface they hold: a patch `(1 + 2ρ) / ρ` query radii wide, with points about a query
/// radius apart, so `((1 + 2ρ) / ρ)²` of them. On cells too small the lookups grow as `8^d`,
/// on cells too large the candidates as `4^|d|`: a query 16 times its level's size costs
/// about 190 on-level queries, one 2 times its size 1.7. (A flat `3^|d|`, the model before,
/// kept the 10:1 elliptic cylinder `[1, 100, 0]` from its rim on one level for the 5% of its
/// queries that wanted cells 16 times as wide: they made 50% of its 34M cell lookups.)
fn off_level_cost(d: i32) -> f64 {
    let cost = |d: i32| {
        let scale = f64::from(d).exp2();
        let wide = 1.0 + 2.0 * TARGET_REACH * scale;
        LOOKUP_COST * wide.powi(3) + (wide / (TARGET_REACH * scale)).powi(2)
    };
    cost(d) / cost(0)
}

/// The index in [`off_level_costs`] of `d` levels off.
fn off(d: i32) -> usize {
    (d.clamp(-OFF_LEVELS, OFF_LEVELS) + OFF_LEVELS) as usize
}

/// Queries more than this many levels off are priced as this many ([`off`]).
const OFF_LEVELS: i32 = 40;

/// [`off_level_cost`] for `d` in `-OFF_LEVELS..=OFF_LEVELS` (index `d + OFF_LEVELS`), worked
/// out once: every query off its level adds it to [`Grid::excess`].
fn off_level_costs() -> &'static [f64; 2 * OFF_LEVELS as usize + 1] {
    static COSTS: std::sync::OnceLock<[f64; 2 * OFF_LEVELS as usize + 1]> =
        std::sync::OnceLock::new();
    COSTS.get_or_init(|| std::array::from_fn(|i| off_level_cost(i as i32 - OFF_LEVELS)))
}

/// Levels are indexed by `k` in `-MAX_LEVEL..=MAX_LEVEL`: cells of `2^k` base cells.
const MAX_LEVEL: i32 = 60;

/// A filed point: its index, and a copy of its position, so that a query reads the
/// candidates' positions from the bucket it scans rather than from all over the point list.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Filed {
    pub index: u32,
    pub at: [f64; 3],
}

/// One bucketing of all the points, in cubic cells of side `1 / inv`.
struct Level {
    /// Cells of `2^k` base cells.
    k: i32,
    inv: f64,
    buckets: HashMap<Cell, Vec<Filed>, FastHash>,
}

impl Level {
    fn new(k: i32, base_inv: f64) -> Level {
        Level {
            k,
            inv: base_inv * (-f64::from(k)).exp2(),
            buckets: HashMap::default(),
        }
    }

    #[inline]
    fn key(&self, p: [f64; 3]) -> Cell {
        let k = |x: f64| crate::geom::grid::floor_clamped(x * self.inv);
        (k(p[0]), k(p[1]), k(p[2]))
    }

    fn file(&mut self, p: [f64; 3], index: u32) {
        let key = self.key(p);
        self.buckets
            .entry(key)
            .or_default()
            .push(Filed { index, at: p });
    }
}

/// Points bucketed by cubic cells, at one or more cell sizes (levels) a factor of two apart.
///
/// Each query is answered at the level whose cells are nearest [`TARGET_REACH`] of its
/// radius among those made. Query radii follow the step lengths, which on a strongly
/// anisotropic surface (a flattened ellipsoid: long steps across its faces, short ones round
/// its rim) span two orders of magnitude: one cell size fitted to their mean had the long
/// queries over the faces scan up to 95,000 candidates each (1,358 a query on average, for 11
/// within reach). So every time the number of points doubles (and sooner when queries run
/// far off their levels), the levels are chosen anew for the queries since the last review
/// by a cost model ([`Grid::review`]): a level is made by filing every point (amortised O(1)
/// per point and level) and dropped when no longer worth filing in; the common surface keeps
/// a single level. Queries return the same answers whatever the levels; only their cost
/// depends on them.
pub(crate) struct Grid {
    /// Inverse of the base cell (level 0).
    base_inv: f64,
    /// The levels, by ascending `k`; never empty.
    levels: Vec<Level>,
    /// Points filed.
    len: usize,
    /// The number of points at which the levels are next reviewed.
    next_review: usize,
    /// How many queries since the last review would have used each level (index
    /// `k + MAX_LEVEL`).
    wanted: std::cell::RefCell<Vec<u32>>,
    /// What the queries since the last review cost beyond that, in queries on their own
    /// levels ([`off_level_cost`]).
    excess: std::cell::Cell<f64>,
}

impl Grid {
    pub(crate) fn new(cell: f64) -> Self {
        let base_inv = 1.0 / cell;
        Grid {
            base_inv,
            levels: vec![Level::new(0, base_inv)],
            len: 0,
            next_review: 256,
            wanted: std::cell::RefCell::new(vec![0; 2 * MAX_LEVEL as usize + 1]),
            excess: std::cell::Cell::new(0.0),
        }
    }

    /// Files the last of `positions` (index `positions.len() − 1`); the others must have been
    /// filed before, in order. The grid files them all again in a level it makes.
    pub(crate) fn push(&mut self, positions: &[[f64; 3]]) {
        let Some((&p, _)) = positions.split_last() else {
            return;
        };
        debug_assert_eq!(positions.len(), self.len + 1, "points are filed in order");
        for level in &mut self.levels {
            level.file(p, self.len as u32);
        }
        self.len += 1;
        if self.len >= self.next_review {
            self.next_review = 2 * self.len;
            self.review(positions, true);
        } else if self.excess.get() >= EARLY_REVIEW * self.len as f64 {
            self.review(positions, false);
        }
    }

    /// Chooses the levels for the queries since the last review, as if the next ones ask
    /// alike: the set that costs least (their queries on the nearest level, plus filing the
    /// points in each level, plus filing all points so far in each level made), by adding
    /// the best level while that helps. A regular review (`drop`) starts from none, an
    /// early one from the current levels. Keeps the current levels if no query came.
    fn review(&mut self, positions: &[[f64; 3]], drop: bool) {
        self.excess.set(0.0);
        let wanted = std::mem::replace(
            &mut *self.wanted.borrow_mut(),
            vec![0; 2 * MAX_LEVEL as usize + 1],
        );
        let asked: Vec<(i32, f64)> = (-MAX_LEVEL..=MAX_LEVEL)
            .map(|k| (k, f64::from(wanted[(k + MAX_LEVEL) as usize])))
            .filter(|&(_, n)| n > 0.0)
            .collect();
        if asked.is_empty() {
            return;
        }
        let n = positions.len() as f64;
        let current: Vec<i32> = self.levels.iter().map(|l| l.k).collect();
        let costs = off_level_costs();
        let cost = |set: &[i32]| {
            let queries: f64 = asked
                .iter()
                .map(|&(k, count)| {
                    let cheapest = set.iter().map(|&s| costs[off(k - s)]).reduce(f64::min);
                    count * cheapest.unwrap_or(1.0)
                })
                .sum();
            let made = set.iter().filter(|k| !current.contains(k)).count() as f64;
            queries + FILE_COST * n * (set.len() as f64 + made)
        };
        let mut chosen: Vec<i32> = if drop { Vec::new() } else { current.clone() };
        loop {
            let best = asked
                .iter()
                .filter(|(k, _)| !chosen.contains(k))
                .map(|&(k, _)| {
                    let mut with = chosen.clone();
                    with.push(k);
                    (cost(&with), k)
                })
                .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            match best {
                Some((c, k)) if chosen.is_empty() || c < cost(&chosen) => chosen.push(k),
                _ => break,
            }
        }
        chosen.sort_unstable();
        if chosen == current {
            return;
        }
        let mut old = std::mem::take(&mut self.levels);
        for k in chosen {
            let level = match old.iter().position(|l| l.k == k) {
                Some(i) => old.swap_remove(i),
                None => {
                    let mut level = Level::new(k, self.base_inv);
                    for (i, &p) in positions.iter().enumerate() {
                        level.file(p, i as u32);
                    }
                    level
                }
            };
            self.levels.push(level);
        }
    }

    /// The level for a query of `radius`: the one whose cells are nearest (by ratio)
    /// [`TARGET_REACH`] radii. Notes the level the query would ideally use, and what it
    /// costs beyond that.
    #[inline]
    fn level_for(&self, radius: f64) -> &Level {
        let ideal = (radius * self.base_inv / TARGET_REACH).log2();
        let want = if ideal.is_nan() {
            0
        } else {
            ideal
                .round()
                .clamp(-f64::from(MAX_LEVEL), f64::from(MAX_LEVEL)) as i32
        };
        let mut level = &self.levels[0];
        for l in &self.levels[1..] {
            if (l.k - want).abs() < (level.k - want).abs() {
                level = l;
            }
        }
        if let Ok(mut wanted) = self.wanted.try_borrow_mut() {
            let n = &mut wanted[(want + MAX_LEVEL) as usize];
            *n = n.saturating_add(1);
        }
        if level.k != want {
            let extra = off_level_costs()[off(want - level.k)] - 1.0;
            self.excess.set(self.excess.get() + extra);
        }
        level
    }

    /// Whether `f(index, position)` holds for some stored point whose cell meets the ball of
    /// `radius` around `p` (a superset of the points within `radius`); stops at the first
    /// that does.
    ///
    /// When the ball's bounding box meets more cells than the level has buckets (a radius of
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
        let level = self.level_for(radius);
        let lo = level.key([p[0] - radius, p[1] - radius, p[2] - radius]);
        let hi = level.key([p[0] + radius, p[1] + radius, p[2] + radius]);
        let cells = (hi.0 as f64 - lo.0 as f64 + 1.0)
            * (hi.1 as f64 - lo.1 as f64 + 1.0)
            * (hi.2 as f64 - lo.2 as f64 + 1.0);
        if radius.is_nan() || cells > level.buckets.len() as f64 {
            return level.buckets.values().flatten().any(|e| f(e.index, e.at));
        }
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    if let Some(bucket) = level.buckets.get(&(x, y, z)) {
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

    /// The cell sides of the grid's levels, ascending.
    fn cells(grid: &Grid) -> Vec<f64> {
        grid.levels.iter().map(|l| 1.0 / l.inv).collect()
    }

    #[test]
    fn the_cell_follows_the_query_radii() {
        let points = sphere_points(4000);
        for (cell, radius) in [(1e-3, 0.02), (2.0, 0.02), (0.02, 0.002)] {
            let grid = filled(cell, &points, radius);
            let sides = cells(&grid);
            assert_eq!(sides.len(), 1, "started at {cell}: {sides:?}");
            let reach = radius / sides[0];
            assert!(
                (TARGET_REACH / 2.0..=TARGET_REACH * 2.0).contains(&reach),
                "started at {cell}: queries of {radius} span {reach} cells"
            );
        }
    }

    #[test]
    fn queries_of_two_sizes_get_a_level_each_and_the_same_answers() {
        let points = sphere_points(4000);
        let mut grid = Grid::new(0.01);
        for (i, &p) in points.iter().enumerate() {
            grid.any_near(p, if i % 2 == 0 { 0.005 } else { 0.3 }, |_, _| false);
            grid.push(&points[..=i]);
        }
        let sides = cells(&grid);
        assert_eq!(sides.len(), 2, "{sides:?}");
        for (&side, radius) in sides.iter().zip([0.005, 0.3]) {
            let reach = radius / side;
            assert!((TARGET_REACH / 2.0..=TARGET_REACH * 2.0).contains(&reach));
        }
        for (k, &q) in sphere_points(4100)[4000..].iter().enumerate() {
            let radius = [0.003, 0.02, 0.1, 0.5][k % 4];
            let hit = grid.any_near(q, radius, |_, at| dist(at, q) <= radius);
            let want = points.iter().any(|&p| dist(p, q) <= radius);
            assert_eq!(hit, want, "radius {radius}");
        }
    }

    /// One query in 150 sixteen times the size of the rest is worth a level of its own:
    /// on the small queries' cells each costs the lookups of about 190 of them.
    #[test]
    fn a_few_queries_far_larger_than_the_rest_get_a_level_of_their_own() {
        assert!((150.0..250.0).contains(&off_level_cost(4)));
        assert!((1.3..2.0).contains(&off_level_cost(1)));
        assert!(off_level_cost(-1) < off_level_cost(1) && off_level_cost(0) == 1.0);
        let points = sphere_points(8000);
        let mut grid = Grid::new(0.01);
        for (i, &p) in points.iter().enumerate() {
            let radius = if i % 150 == 0 { 0.056 } else { 0.0035 };
            grid.any_near(p, radius, |_, _| false);
            grid.push(&points[..=i]);
        }
        let sides = cells(&grid);
        assert_eq!(sides.len(), 2, "{sides:?}");
        assert!((sides[1] / sides[0] - 16.0).abs() < 1e-9, "{sides:?}");
    }

    #[test]
    fn a_grid_without_queries_keeps_its_cell() {
        let points = sphere_points(1000);
        let mut grid = Grid::new(0.25);
        for i in 0..points.len() {
            grid.push(&points[..=i]);
        }
        assert_eq!(cells(&grid), [0.25]);
    }
}
