//! The stitcher's proximity indexes: points, and triangles, bucketed by cubic cells.
//!
//! Points ([`PointGrid`]) are filed in cells of one size. Triangles ([`FaceGrid`]) are filed
//! at the finest of several levels whose cells they span few of (at most
//! [`MAX_CELLS_PER_FACE`]), level `k` having cells `4^k` times the base cell's side; a query
//! visits the cells its box meets at every level that holds a triangle. On a mesh of
//! triangles of about one size every triangle lands on the base level and this is a
//! one-level grid. Where sizes differ by orders of magnitude (a flattened ellipsoid's rim
//! against its faces, a hyperboloid's narrow waist), the large triangles do not sit in one
//! list that every query visits: on `[1, 1, 100, 0, 0, 0]` from `(1, 0, 0)` such a list made
//! the stitching spend its whole budget of visits before it closed the surface.
//! Likewise a query far larger than a level's cells (a long hole edge beside small
//! triangles) walks a coarser index of that level's cells, not every cell its box meets,
//! nor every triangle of the level.

use crate::geom::rows::compressed_rows;
use crate::geom::vec3::FastHash;
use std::cell::OnceCell;
use std::collections::HashMap;

/// A cell's integer coordinates (at the base level, or a coarser one).
type Cell = (i32, i32, i32);

/// The base-level cell of point `p` for cells of side `1 / inv`.
fn cell_of(inv: f64, p: [f64; 3]) -> Cell {
    let k = |x: f64| crate::geom::grid::floor_clamped(x * inv);
    (k(p[0]), k(p[1]), k(p[2]))
}

/// How many cells the box of cells from `lo` to `hi` holds (saturating: a box from corner
/// to corner of the clamped range holds more than an `i64` counts).
fn cell_count(lo: Cell, hi: Cell) -> i64 {
    let side = |a: i32, b: i32| i64::from(b) - i64::from(a) + 1;
    side(lo.0, hi.0)
        .saturating_mul(side(lo.1, hi.1))
        .saturating_mul(side(lo.2, hi.2))
}

/// A triangle is filed at the finest level where its box meets at most this many cells.
const MAX_CELLS_PER_FACE: i64 = 64;
/// A query whose box meets more cells than this at a level goes through the finest of the
/// level's coarse indexes where it meets at most this many (see [`Level::coarse`]), or, if
/// there is none, visits the level's every triangle.
const MAX_CELLS_PER_QUERY: i64 = 4096;
/// A coarse cell of a level's `d`-th coarse index is `2^(d·COARSE_BITS)` of the level's
/// cells wide.
const COARSE_BITS: u32 = 3;
/// A level's coarse indexes: up to cells `8^4 = 4096` of its own wide.
const COARSE_INDEXES: usize = 4;
/// Each level's cells are `2^LEVEL_BITS` times as wide as the level below's.
const LEVEL_BITS: u32 = 2;
/// Levels above the base one: cells up to `4^16 ≈ 4·10⁹` base cells wide.
const MAX_LEVEL: u32 = 16;

/// The cell `2^bits` times as wide that holds cell `c` (floor division on each axis).
fn shifted(c: Cell, bits: u32) -> Cell {
    (c.0 >> bits, c.1 >> bits, c.2 >> bits)
}

/// The cell of a level's `depth`-th coarse index that holds the level's cell `c`.
fn coarse_cell(c: Cell, depth: u32) -> Cell {
    shifted(c, COARSE_BITS * depth)
}

/// The cell at `level` that holds base-level cell `c` (floor division by `4^level`).
fn coarse(c: Cell, level: u32) -> Cell {
    shifted(c, LEVEL_BITS * level)
}

/// A level's rows (or a [`PointGrid`]'s cells) by coarse cell, each with its own cell (see
/// [`Level::coarse`]).
type CoarseIndex = HashMap<Cell, Vec<(Cell, u32)>, FastHash>;

/// The coarse index of `cells` (each a cell and its row or index), by the coarse cell
/// `to_coarse` puts each in.
fn coarse_index(
    cells: impl Iterator<Item = (Cell, u32)>,
    to_coarse: impl Fn(Cell) -> Cell,
) -> CoarseIndex {
    let mut index = CoarseIndex::default();
    for (cell, id) in cells {
        index.entry(to_coarse(cell)).or_default().push((cell, id));
    }
    index
}

/// Calls `f` with the row or index of every entry of `index` whose own cell lies in the box
/// of cells from `lo` to `hi`, looking up the coarse cells (`to_coarse`) the box meets.
fn walk_coarse(
    index: &CoarseIndex,
    lo: Cell,
    hi: Cell,
    to_coarse: impl Fn(Cell) -> Cell,
    mut f: impl FnMut(u32),
) {
    let (clo, chi) = (to_coarse(lo), to_coarse(hi));
    for x in clo.0..=chi.0 {
        for y in clo.1..=chi.1 {
            for z in clo.2..=chi.2 {
                for &(c, id) in index.get(&(x, y, z)).into_iter().flatten() {
                    if in_box(c, lo, hi) {
                        f(id);
                    }
                }
            }
        }
    }
}

/// Whether cell `c` lies in the box of cells from `lo` to `hi`.
fn in_box(c: Cell, lo: Cell, hi: Cell) -> bool {
    (lo.0..=hi.0).contains(&c.0) && (lo.1..=hi.1).contains(&c.1) && (lo.2..=hi.2).contains(&c.2)
}

/// The triangles filed at one level.
///
/// The triangles given at construction are filed once, in compressed rows by cell (no list
/// per cell to grow); triangles inserted later go to lists of their own, by row.
struct Level {
    /// The row of each cell that holds a triangle.
    rows: HashMap<Cell, u32, FastHash>,
    /// The first triangles of row `r` are `filed[start[r]..start[r + 1]]`.
    start: Vec<u32>,
    filed: Vec<u32>,
    /// Triangles inserted later, by row.
    later: Vec<Vec<u32>>,
    /// The rows by coarse cell (see [`coarse_cell`]), with their cells, one index per
    /// coarseness: each made at the first query whose box meets more than
    /// [`MAX_CELLS_PER_QUERY`] cells at the finer ones (a hole edge far longer than the
    /// triangles beside it, as next to a flat ellipsoid's rim), so that such a query visits
    /// the triangles near its box rather than the whole level. On `[1, 1, 150]` meshed from
    /// its rim, 124 whole-level scans were 52.6M of the stitching's 55M visits and ran its
    /// budget out.
    coarse: [OnceCell<CoarseIndex>; COARSE_INDEXES],
}

impl Default for Level {
    /// No triangle: no row (`start` holds the end of the last row).
    fn default() -> Self {
        Level {
            rows: HashMap::default(),
            start: vec![0],
            filed: Vec::new(),
            later: Vec::new(),
            coarse: std::array::from_fn(|_| OnceCell::new()),
        }
    }
}

impl Level {
    /// Whether any triangle is filed here (a row is made only for a triangle).
    fn used(&self) -> bool {
        !self.rows.is_empty()
    }

    /// Calls `f` for every triangle filed in a cell from `lo` to `hi` (cells of this level).
    fn near(&self, lo: Cell, hi: Cell, f: &mut impl FnMut(u32)) {
        if cell_count(lo, hi) > MAX_CELLS_PER_QUERY {
            let Some(depth) = (1..=COARSE_INDEXES as u32).find(|&d| {
                cell_count(coarse_cell(lo, d), coarse_cell(hi, d)) <= MAX_CELLS_PER_QUERY
            }) else {
                self.filed.iter().for_each(|&t| f(t));
                self.later.iter().flatten().for_each(|&t| f(t));
                return;
            };
            let to_coarse = |c: Cell| coarse_cell(c, depth);
            let coarse = self.coarse[depth as usize - 1]
                .get_or_init(|| coarse_index(self.rows.iter().map(|(&c, &r)| (c, r)), to_coarse));
            walk_coarse(coarse, lo, hi, to_coarse, |r| self.row(r, f));
            return;
        }
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    if let Some(&r) = self.rows.get(&(x, y, z)) {
                        self.row(r, f);
                    }
                }
            }
        }
    }

    /// Calls `f` for every triangle of row `r`.
    #[inline]
    fn row(&self, r: u32, f: &mut impl FnMut(u32)) {
        let r = r as usize;
        let first = &self.filed[self.start[r] as usize..self.start[r + 1] as usize];
        first.iter().chain(&self.later[r]).for_each(|&t| f(t));
    }

    fn insert(&mut self, f: u32, lo: Cell, hi: Cell) {
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    let row = match self.rows.entry((x, y, z)) {
                        std::collections::hash_map::Entry::Occupied(e) => *e.get(),
                        std::collections::hash_map::Entry::Vacant(e) => {
                            // A new row, with none of the first triangles.
                            self.start.push(self.filed.len() as u32);
                            self.later.push(Vec::new());
                            let row = self.later.len() as u32 - 1;
                            let cell = (x, y, z);
                            for (d, coarse) in (1..).zip(&mut self.coarse) {
                                if let Some(coarse) = coarse.get_mut() {
                                    coarse
                                        .entry(coarse_cell(cell, d))
                                        .or_default()
                                        .push((cell, row));
                                }
                            }
                            *e.insert(row)
                        }
                    };
                    self.later[row as usize].push(f);
                }
            }
        }
    }
}

/// Triangles bucketed by the cells their bounding boxes meet, at several cell sizes (see
/// the module docs).
pub(super) struct FaceGrid {
    inv: f64,
    levels: Vec<Level>,
    /// Triangles that fit no level (a corner not finite, or a box wider than the coarsest
    /// cells): visited by every query.
    unfiled: Vec<u32>,
}

impl FaceGrid {
    /// A grid of base cells of side `cell` holding the triangles `tris` of the points `pos`.
    pub(super) fn new(cell: f64, pos: &[[f64; 3]], tris: &[[u32; 3]]) -> Self {
        let inv = 1.0 / cell;
        let mut grid = FaceGrid {
            inv,
            levels: Vec::new(),
            unfiled: Vec::new(),
        };
        // Each vertex's base cell (`None` at a non-finite coordinate): the cells of a
        // triangle's box run from its corners' lowest cells to their highest, since a
        // coordinate's cell never decreases as it grows.
        let vertex_cells: Vec<Option<Cell>> = pos
            .iter()
            .map(|p| p.iter().all(|x| x.is_finite()).then(|| cell_of(inv, *p)))
            .collect();
        // (row, triangle) for each cell a triangle's box meets, by level.
        let mut entries: Vec<Vec<(u32, u32)>> = Vec::new();
        for (f, t) in tris.iter().enumerate() {
            let [Some(a), Some(b), Some(c)] = t.map(|v| vertex_cells[v as usize]) else {
                grid.unfiled.push(f as u32);
                continue;
            };
            let lo = (
                a.0.min(b.0).min(c.0),
                a.1.min(b.1).min(c.1),
                a.2.min(b.2).min(c.2),
            );
            let hi = (
                a.0.max(b.0).max(c.0),
                a.1.max(b.1).max(c.1),
                a.2.max(b.2).max(c.2),
            );
            let Some((level, lo, hi)) = grid.level_for(lo, hi) else {
                grid.unfiled.push(f as u32);
                continue;
            };
            if entries.len() <= level {
                entries.resize_with(level + 1, Vec::new);
            }
            let rows = &mut grid.levels[level].rows;
            for x in lo.0..=hi.0 {
                for y in lo.1..=hi.1 {
                    for z in lo.2..=hi.2 {
                        let next = rows.len() as u32;
                        let row = *rows.entry((x, y, z)).or_insert(next);
                        entries[level].push((row, f as u32));
                    }
                }
            }
        }
        for (level, entries) in grid.levels.iter_mut().zip(&entries) {
            let rows = level.rows.len();
            let (start, filed) =
                compressed_rows(rows, entries.iter().map(|&(r, f)| (r as usize, f)))
                    .expect("every entry's row is one of the level's");
            level.start = start;
            level.filed = filed;
            level.later = vec![Vec::new(); rows];
        }
        grid
    }

    /// The finest level at which the box of base cells from `lo` to `hi` meets at most
    /// [`MAX_CELLS_PER_FACE`] cells, and the box's cells there; the levels up to it exist
    /// afterwards. `None` if none does.
    fn level_for(&mut self, lo: Cell, hi: Cell) -> Option<(usize, Cell, Cell)> {
        let level = (0..=MAX_LEVEL)
            .find(|&k| cell_count(coarse(lo, k), coarse(hi, k)) <= MAX_CELLS_PER_FACE)?;
        let k = level as usize;
        if self.levels.len() <= k {
            self.levels.resize_with(k + 1, Level::default);
        }
        Some((k, coarse(lo, level), coarse(hi, level)))
    }

    /// The base cells of the box of the points `c`.
    fn range(&self, c: &[[f64; 3]]) -> (Cell, Cell) {
        let lo = [0, 1, 2].map(|k| c.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1, 2].map(|k| c.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
        (cell_of(self.inv, lo), cell_of(self.inv, hi))
    }

    /// Files triangle `f` with corners `c`.
    pub(super) fn insert(&mut self, f: u32, c: [[f64; 3]; 3]) {
        if !c.iter().flatten().all(|x| x.is_finite()) {
            self.unfiled.push(f);
            return;
        }
        let (lo, hi) = self.range(&c);
        match self.level_for(lo, hi) {
            Some((level, lo, hi)) => self.levels[level].insert(f, lo, hi),
            None => self.unfiled.push(f),
        }
    }

    /// Calls `f` for every triangle filed in a cell the box of the points `c` meets (maybe
    /// repeatedly, in no particular order).
    pub(super) fn near(&self, c: &[[f64; 3]], mut f: impl FnMut(u32)) {
        self.unfiled.iter().for_each(|&t| f(t));
        let (lo, hi) = self.range(c);
        for (k, level) in self.levels.iter().enumerate().filter(|(_, l)| l.used()) {
            let k = k as u32;
            level.near(coarse(lo, k), coarse(hi, k), &mut f);
        }
    }
}

/// Points bucketed by cubic cells (points are only ever added).
pub(super) struct PointGrid {
    inv: f64,
    /// The points, in the order they were filed.
    filed: Vec<u32>,
    /// The index in `cells` of each cell that holds a point.
    index: HashMap<Cell, u32, FastHash>,
    /// The cells that hold points, with their points.
    cells: Vec<(Cell, Vec<u32>)>,
    /// The cells holding points by coarse cell, `4^(d + 1)` cells wide in the `d`-th
    /// index, each with its index in `cells`: each made at the first query whose box meets
    /// more cells than [`MAX_CELLS_PER_POINT_QUERY`] and few coarse ones, then kept up to
    /// date. Where the stitched edges are far longer than the grid's cells (an elliptic
    /// cylinder 10:1 met from its flat side: edges of `dt_max` beside ones a hundredth of
    /// that) a query looked up, or scanned, tens of thousands of cells: 40% of a 37 s run.
    coarse: [OnceCell<CoarseIndex>; POINT_COARSE_INDEXES],
}

/// How many coarse indexes a [`PointGrid`] may make: up to cells `4^8 = 65,536` of its own
/// wide.
const POINT_COARSE_INDEXES: usize = 8;
/// A point query whose box meets at most this many cells looks each of them up; a larger
/// one goes through the finest coarse index where its box meets at most
/// [`MAX_COARSE_CELLS_PER_POINT_QUERY`] coarse cells, or scans the cells that hold points.
const MAX_CELLS_PER_POINT_QUERY: i64 = 512;
/// See [`MAX_CELLS_PER_POINT_QUERY`].
const MAX_COARSE_CELLS_PER_POINT_QUERY: i64 = 64;

impl PointGrid {
    pub(super) fn new(cell: f64) -> Self {
        PointGrid {
            inv: 1.0 / cell,
            filed: Vec::new(),
            index: HashMap::default(),
            cells: Vec::new(),
            coarse: std::array::from_fn(|_| OnceCell::new()),
        }
    }
    /// The cell of the `d`-th coarse index that holds base cell `c`.
    fn coarse_of(c: Cell, d: usize) -> Cell {
        shifted(c, LEVEL_BITS * (d as u32 + 1))
    }
    /// How many points it holds.
    pub(super) fn len(&self) -> usize {
        self.filed.len()
    }
    /// The points filed after the first `n`.
    pub(super) fn filed_since(&self, n: usize) -> &[u32] {
        &self.filed[n..]
    }
    pub(super) fn insert(&mut self, v: u32, p: [f64; 3]) {
        self.filed.push(v);
        let cell = cell_of(self.inv, p);
        let next = self.cells.len() as u32;
        let i = *self.index.entry(cell).or_insert(next);
        if i == next {
            self.cells.push((cell, Vec::new()));
            for (d, index) in self.coarse.iter_mut().enumerate() {
                if let Some(index) = index.get_mut() {
                    index
                        .entry(Self::coarse_of(cell, d))
                        .or_default()
                        .push((cell, next));
                }
            }
        }
        self.cells[i as usize].1.push(v);
    }
    /// Calls `f` for every point within distance `r` of `p`, and for some others near it
    /// (those whose cells meet the box of radius `r` about `p`, and, if fewer cells hold
    /// points than the box meets, those of the cells next to it), in no particular order.
    pub(super) fn near(&self, p: [f64; 3], r: f64, mut f: impl FnMut(u32)) {
        let (mut lo, mut hi) = (
            cell_of(self.inv, p.map(|x| x - r)),
            cell_of(self.inv, p.map(|x| x + r)),
        );
        if cell_count(lo, hi) > self.cells.len() as i64 {
            // The cells next to the box too: a cell two or more beyond the box on some axis
            // is a whole cell farther than `r` from `p`, far beyond any rounding, so none of
            // its points is within `r`. (Which cells are visited does not depend on how they
            // are found: the stitcher counts the visits against its budget.)
            lo = (lo.0 - 1, lo.1 - 1, lo.2 - 1);
            hi = (hi.0 + 1, hi.1 + 1, hi.2 + 1);
        }
        let mut visit = |i: u32| self.cells[i as usize].1.iter().for_each(|&v| f(v));
        let count = cell_count(lo, hi);
        if count <= MAX_CELLS_PER_POINT_QUERY.min(self.cells.len() as i64) {
            for x in lo.0..=hi.0 {
                for y in lo.1..=hi.1 {
                    for z in lo.2..=hi.2 {
                        if let Some(&i) = self.index.get(&(x, y, z)) {
                            visit(i);
                        }
                    }
                }
            }
            return;
        }
        // A scan of the cells costs about a lookup per ten cells.
        let coarse = (0..POINT_COARSE_INDEXES)
            .find(|&d| {
                cell_count(Self::coarse_of(lo, d), Self::coarse_of(hi, d))
                    <= MAX_COARSE_CELLS_PER_POINT_QUERY
            })
            .filter(|_| self.cells.len() as i64 > 10 * MAX_COARSE_CELLS_PER_POINT_QUERY);
        let Some(d) = coarse else {
            for (i, (c, _)) in self.cells.iter().enumerate() {
                if in_box(*c, lo, hi) {
                    visit(i as u32);
                }
            }
            return;
        };
        let to_coarse = |c: Cell| Self::coarse_of(c, d);
        let index = self.coarse[d].get_or_init(|| {
            let cells = self.cells.iter().enumerate();
            coarse_index(cells.map(|(i, (c, _))| (*c, i as u32)), to_coarse)
        });
        walk_coarse(index, lo, hi, to_coarse, visit);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle whose box meets the query's box is visited, whatever its size.
    #[test]
    fn queries_find_small_and_large_triangles_alike() {
        let pos = vec![
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [0.0, 0.1, 0.0],
            [-50.0, -50.0, 0.0],
            [50.0, -50.0, 0.0],
            [0.0, 50.0, 0.0],
            [200.0, 200.0, 200.0],
            [200.1, 200.0, 200.0],
            [200.0, 200.1, 200.0],
        ];
        let tris = [[0, 1, 2], [3, 4, 5]];
        let mut grid = FaceGrid::new(0.1, &pos, &tris);
        grid.insert(2, [pos[6], pos[7], pos[8]]);
        // A level that only later insertions use.
        grid.insert(4, [[-5e3, -5e3, 0.0], [5e3, -5e3, 0.0], [0.0, 5e3, 0.0]]);
        grid.insert(3, [[f64::NAN; 3], pos[7], pos[8]]);
        // The large triangle went to a coarser level, not to the list every query visits.
        assert!(grid.levels.len() > 1 && grid.unfiled == [3]);
        let found = |q: [[f64; 3]; 2]| {
            let mut seen = Vec::new();
            grid.near(&q, |t| seen.push(t));
            seen.sort_unstable();
            seen.dedup();
            seen
        };
        // (Boxes are tested, not triangles: the large one's cells hold all the others.)
        assert_eq!(found([[0.01, 0.01, 0.0], [0.02, 0.02, 0.0]]), [0, 1, 3, 4]);
        assert_eq!(found([[30.0, -40.0, -0.1], [30.5, -39.5, 0.1]]), [1, 3, 4]);
        let far = [[200.05, 200.05, 200.0], [200.06, 200.06, 200.0]];
        assert_eq!(found(far), [2, 3, 4]);
        assert_eq!(
            found([[4e3, 4e3, 1.0], [4e3 + 0.05, 4e3 + 0.05, 1.05]]),
            [3, 4]
        );
        assert_eq!(
            found([[4e4, 4e4, 1.0], [4e4 + 0.05, 4e4 + 0.05, 1.05]]),
            [3]
        );
        // A query of many cells at a level visits that level's every triangle.
        assert_eq!(
            found([[-1e6, -1e6, -1e6], [1e6, 1e6, 1e6]]),
            [0, 1, 2, 3, 4]
        );
    }

    /// A query whose box meets far more cells than [`MAX_CELLS_PER_QUERY`] (a long hole edge
    /// beside small triangles) visits the triangles near its box, not the level's every one,
    /// and finds the rows made after the coarse index was.
    #[test]
    fn a_query_of_many_cells_visits_only_the_triangles_near_it() {
        // 10,000 small triangles along a line 1,000 cells long.
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for i in 0..10_000u32 {
            let x = f64::from(i) * 0.01;
            pos.extend([[x, 0.0, 0.0], [x + 0.005, 0.0, 0.0], [x, 0.005, 0.0]]);
            tris.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let mut grid = FaceGrid::new(0.1, &pos, &tris);
        let visited = |grid: &FaceGrid, q: [[f64; 3]; 2]| {
            let mut seen = Vec::new();
            grid.near(&q, |t| seen.push(t));
            seen.sort_unstable();
            seen.dedup();
            seen
        };
        // 20 cells wide: 8,000 cells, more than a query walks one by one.
        let query = [[10.0, -1.0, -1.0], [12.0, 1.0, 1.0]];
        let seen = visited(&grid, query);
        assert!(seen.contains(&1000) && seen.contains(&1199), "{seen:?}");
        assert!(seen.len() < 400, "{} triangles visited", seen.len());
        // A triangle in a cell of the box that held none, inserted after.
        grid.insert(
            10_000,
            [[11.0, 0.5, 0.5], [11.01, 0.5, 0.5], [11.0, 0.51, 0.5]],
        );
        assert!(visited(&grid, query).contains(&10_000));
        // 200 cells wide: too many cells for the first coarse index too.
        let seen = visited(&grid, [[40.0, -10.0, -10.0], [60.0, 10.0, 10.0]]);
        assert!(seen.contains(&4000) && seen.contains(&5999), "{seen:?}");
        assert!(seen.len() < 2100, "{} triangles visited", seen.len());
    }

    /// Against brute force, on triangles whose sizes span six orders of magnitude, filed at
    /// construction and inserted later: every triangle whose box meets the query's box is
    /// visited.
    #[test]
    fn queries_visit_every_triangle_whose_box_meets_theirs() {
        let mut rng = crate::geom::rng::XorShift64::new(7);
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for t in 0..600u32 {
            let size = 10f64.powf(rng.uniform(-3.0, 3.0));
            let centre = rng.in_cube(100.0);
            for _ in 0..3 {
                let d = rng.in_cube(size);
                pos.push([0, 1, 2].map(|k| centre[k] + d[k]));
            }
            tris.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        let corners = |t: [u32; 3]| t.map(|v| pos[v as usize]);
        let mut grid = FaceGrid::new(0.05, &pos, &tris[..300]);
        for (f, &t) in tris.iter().enumerate().skip(300) {
            grid.insert(f as u32, corners(t));
        }
        let boxed = |c: &[[f64; 3]]| {
            let lo = [0, 1, 2].map(|k| c.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
            let hi = [0, 1, 2].map(|k| c.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
            (lo, hi)
        };
        for _ in 0..300 {
            let size = 10f64.powf(rng.uniform(-3.0, 2.0));
            let (a, b) = (rng.in_cube(100.0), rng.in_cube(size));
            let query = [a, [0, 1, 2].map(|k| a[k] + b[k])];
            let mut seen = vec![false; tris.len()];
            grid.near(&query, |t| seen[t as usize] = true);
            let (qlo, qhi) = boxed(&query);
            for (f, &t) in tris.iter().enumerate() {
                let (lo, hi) = boxed(&corners(t));
                let meets = (0..3).all(|k| lo[k] <= qhi[k] && qlo[k] <= hi[k]);
                assert!(!meets || seen[f], "triangle {f} missed by {query:?}");
            }
        }
    }

    /// Against brute force, on points strewn over a thin sheet (as on a surface) and
    /// queries from a hundredth of a cell to thousands of cells wide, some before the rest of
    /// the points are filed (so that coarse indexes made then are kept up to date): each
    /// query visits exactly the points of the cells that meet its box (or, when fewer cells
    /// hold points than the box meets, also those of the cells next to it), whichever way
    /// it finds them, each once.
    #[test]
    fn point_queries_visit_exactly_the_cells_of_their_box() {
        let mut rng = crate::geom::rng::XorShift64::new(11);
        let cell = 0.01;
        let points: Vec<[f64; 3]> = (0..20_000)
            .map(|_| {
                let p = rng.in_cube(10.0);
                [p[0], p[1], 1e-3 * p[2]]
            })
            .collect();
        let mut grid = PointGrid::new(cell);
        let check = |grid: &PointGrid, filed: usize, rng: &mut crate::geom::rng::XorShift64| {
            let r = 10f64.powf(rng.uniform(-4.0, 1.5));
            let p = rng.in_cube(10.0);
            let mut seen = vec![0u32; points.len()];
            grid.near(p, r, |v| seen[v as usize] += 1);
            let (lo, hi) = (
                cell_of(grid.inv, p.map(|x| x - r)),
                cell_of(grid.inv, p.map(|x| x + r)),
            );
            let slack = i32::from(cell_count(lo, hi) > grid.cells.len() as i64);
            for (v, q) in points.iter().enumerate() {
                let c = cell_of(grid.inv, *q);
                let inside = v < filed
                    && (lo.0 - slack..=hi.0 + slack).contains(&c.0)
                    && (lo.1 - slack..=hi.1 + slack).contains(&c.1)
                    && (lo.2 - slack..=hi.2 + slack).contains(&c.2);
                assert_eq!(
                    seen[v],
                    u32::from(inside),
                    "point {v}, query {p:?} of radius {r}"
                );
            }
        };
        for (v, q) in points.iter().enumerate() {
            grid.insert(v as u32, *q);
            if v % 1000 == 999 {
                for _ in 0..20 {
                    check(&grid, v + 1, &mut rng);
                }
            }
        }
        assert!(grid.coarse.iter().filter(|c| c.get().is_some()).count() >= 2);
    }
}
