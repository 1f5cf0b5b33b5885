//! Broad phase for triangle faces: a uniform grid of cubic cells over their bounding boxes.
//!
//! Mesh triangles are nearly uniform in size, so a cell about as large as a typical box
//! ([`cell_size`]: the median of the boxes' longest sides) files each face in a few cells
//! and keeps a handful of faces per cell. A face whose box would cover more than
//! [`MAX_CELLS_PER_FACE`] cells (an outlier) is kept on a separate list instead and compared
//! by box with every face, so a few huge faces cost `O(n)` each rather than filling the grid.
//! Cell coordinates are clamped to ±2²⁰ so that keys pack into a `u64` and huge coordinates
//! cannot overflow; the clamp is monotone, so overlapping boxes still share a cell.
//! Boxes with a non-finite coordinate are never filed and never reported.
//!
//! Two uses:
//! * [`PairGrid`]: every pair of overlapping boxes of a whole mesh, each once (a pair is
//!   reported in the cell holding the lowest corner of the boxes' intersection), by cell
//!   ranges so that callers can split the work.
//! * [`FaceGrid`]: incremental — insert faces one at a time and ask, before inserting a new
//!   triangle, which inserted faces' boxes overlap its box.

use super::intersect::Tri;
use super::predicates::P3;
use super::vec3::FastHash;
use std::collections::HashMap;
use std::ops::Range;

/// Most cells a face is filed in; larger faces go on the outlier list.
pub(crate) const MAX_CELLS_PER_FACE: u64 = 64;

/// Cell coordinates are clamped to `[−CLAMP, CLAMP]`.
const CLAMP: i64 = 1 << 20;

/// A closed axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Aabb {
    /// Lowest corner.
    pub min: P3,
    /// Highest corner.
    pub max: P3,
}

impl Aabb {
    /// The box of a triangle's corners.
    #[inline]
    pub fn of_triangle(t: &Tri) -> Aabb {
        let mut b = Aabb {
            min: t[0],
            max: t[0],
        };
        for p in &t[1..] {
            for k in 0..3 {
                b.min[k] = b.min[k].min(p[k]);
                b.max[k] = b.max[k].max(p[k]);
            }
        }
        // f64::min ignores a NaN; keep it visible so that the box counts as non-finite.
        if t.iter().flatten().any(|x| !x.is_finite()) {
            b.min[0] = f64::NAN;
        }
        b
    }

    /// Whether the closed boxes have a common point (never for a non-finite box).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min[0] <= o.max[0]
            && o.min[0] <= self.max[0]
            && self.min[1] <= o.max[1]
            && o.min[1] <= self.max[1]
            && self.min[2] <= o.max[2]
            && o.min[2] <= self.max[2]
    }

    /// Whether every coordinate is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.min.iter().chain(&self.max).all(|x| x.is_finite())
    }

    /// The longest side.
    fn extent(&self) -> f64 {
        (0..3)
            .map(|k| self.max[k] - self.min[k])
            .fold(0.0, f64::max)
    }
}

/// A cell size for `boxes`: the median longest side of the finite boxes (half of them fit in
/// one cell per axis), or a fallback when that is zero (all boxes points) or undefined.
pub(crate) fn cell_size(boxes: &[Aabb]) -> f64 {
    let mut ext: Vec<f64> = boxes
        .iter()
        .filter(|b| b.is_finite())
        .map(Aabb::extent)
        .filter(|e| e.is_finite())
        .collect();
    if ext.is_empty() {
        return 1.0;
    }
    let mid = ext.len() / 2;
    let (_, &mut median, _) = ext.select_nth_unstable_by(mid, f64::total_cmp);
    if median > 0.0 {
        return median;
    }
    let largest = ext.iter().copied().fold(0.0, f64::max);
    if largest > 0.0 {
        largest / 1024.0
    } else {
        1.0
    }
}

/// The cell index of coordinate `x` (clamped; `x` finite).
#[inline]
fn cell_of(x: f64, inv: f64) -> i64 {
    // `as` saturates on overflow (±∞ → i64 bounds), and the clamp keeps keys packable.
    ((x * inv).floor() as i64).clamp(-CLAMP, CLAMP)
}

#[inline]
fn cell_range(b: &Aabb, inv: f64) -> ([i64; 3], [i64; 3]) {
    let lo = [0, 1, 2].map(|k| cell_of(b.min[k], inv));
    let hi = [0, 1, 2].map(|k| cell_of(b.max[k], inv));
    (lo, hi)
}

#[inline]
fn cell_count(lo: &[i64; 3], hi: &[i64; 3]) -> u64 {
    (0..3).map(|k| (hi[k] - lo[k] + 1) as u64).product()
}

#[inline]
fn key(c: [i64; 3]) -> u64 {
    let u = |x: i64| (x + CLAMP) as u64;
    (u(c[0]) << 42) | (u(c[1]) << 21) | u(c[2])
}

/// Calls `f` with every cell of the range.
#[inline]
fn for_cells(lo: [i64; 3], hi: [i64; 3], mut f: impl FnMut([i64; 3])) {
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                f([x, y, z]);
            }
        }
    }
}

/// `1 / cell`, with a usable value for any input.
fn inverse(cell: f64) -> f64 {
    let inv = 1.0 / cell;
    if inv.is_finite() && inv > 0.0 {
        inv
    } else {
        1.0
    }
}

/// All overlapping pairs of a fixed set of boxes (face `i` is `boxes[i]`).
pub(crate) struct PairGrid<'a> {
    boxes: &'a [Aabb],
    inv: f64,
    /// Coordinates of each occupied cell.
    cells: Vec<[i64; 3]>,
    /// Faces of cell `c` are `entries[starts[c]..starts[c + 1]]`, ascending.
    starts: Vec<u32>,
    entries: Vec<u32>,
    /// Outliers, ascending.
    big: Vec<u32>,
}

impl<'a> PairGrid<'a> {
    /// Files `boxes` in cells of side `cell` (see [`cell_size`]).
    pub fn new(boxes: &'a [Aabb], cell: f64) -> PairGrid<'a> {
        let inv = inverse(cell);
        let mut ids: HashMap<u64, u32, FastHash> =
            HashMap::with_capacity_and_hasher(boxes.len(), FastHash::default());
        let mut cells = Vec::new();
        let mut filed: Vec<(u32, u32)> = Vec::with_capacity(3 * boxes.len());
        let mut big = Vec::new();
        for (i, b) in boxes.iter().enumerate() {
            if !b.is_finite() {
                continue;
            }
            let (lo, hi) = cell_range(b, inv);
            if cell_count(&lo, &hi) > MAX_CELLS_PER_FACE {
                big.push(i as u32);
                continue;
            }
            for_cells(lo, hi, |c| {
                let next = cells.len() as u32;
                let id = *ids.entry(key(c)).or_insert(next);
                if id == next {
                    cells.push(c);
                }
                filed.push((id, i as u32));
            });
        }
        // Counting sort by cell; faces stay ascending within a cell.
        let mut starts = vec![0u32; cells.len() + 1];
        for &(c, _) in &filed {
            starts[c as usize + 1] += 1;
        }
        for c in 0..cells.len() {
            starts[c + 1] += starts[c];
        }
        let mut fill = starts.clone();
        let mut entries = vec![0u32; filed.len()];
        for &(c, i) in &filed {
            entries[fill[c as usize] as usize] = i;
            fill[c as usize] += 1;
        }
        PairGrid {
            boxes,
            inv,
            cells,
            starts,
            entries,
            big,
        }
    }

    /// Number of occupied cells (the range of [`PairGrid::pairs_in_cells`]).
    pub fn cells(&self) -> usize {
        self.cells.len()
    }

    /// Number of outliers.
    pub fn outliers(&self) -> usize {
        self.big.len()
    }

    /// Calls `f(i, j)`, `i < j`, for the overlapping pairs of filed faces whose lowest common
    /// corner lies in one of the cells `range`; over all cells, every such pair exactly once.
    pub fn pairs_in_cells(&self, range: Range<usize>, mut f: impl FnMut(u32, u32)) {
        for c in range {
            let cell = self.cells[c];
            let faces = &self.entries[self.starts[c] as usize..self.starts[c + 1] as usize];
            for (n, &i) in faces.iter().enumerate() {
                let bi = &self.boxes[i as usize];
                for &j in &faces[n + 1..] {
                    let bj = &self.boxes[j as usize];
                    if !bi.overlaps(bj) {
                        continue;
                    }
                    // Report the pair only in the cell of the lowest common corner.
                    let home = [0, 1, 2].map(|k| cell_of(bi.min[k].max(bj.min[k]), self.inv));
                    if home == cell {
                        f(i, j);
                    }
                }
            }
        }
    }

    /// Calls `f(i, j)`, `i < j`, once for every overlapping pair involving an outlier.
    pub fn pairs_with_outliers(&self, mut f: impl FnMut(u32, u32)) {
        for &i in &self.big {
            let bi = &self.boxes[i as usize];
            for (j, bj) in self.boxes.iter().enumerate() {
                let j = j as u32;
                // Outlier pairs once (from the smaller id); outlier–filed pairs from here.
                if j == i || (j < i && self.big.binary_search(&j).is_ok()) {
                    continue;
                }
                if bi.overlaps(bj) {
                    f(i.min(j), i.max(j));
                }
            }
        }
    }

    /// Calls `f(i, j)`, `i < j`, once for every pair of overlapping finite boxes.
    pub fn for_each_pair(&self, mut f: impl FnMut(u32, u32)) {
        self.pairs_in_cells(0..self.cells(), &mut f);
        self.pairs_with_outliers(f);
    }
}

/// An incremental grid: faces are inserted (and removed) by id, and queried by box.
///
/// Ids index an internal table, so they should be dense (face indices); the table grows to
/// the largest id inserted.
pub(crate) struct FaceGrid {
    inv: f64,
    cells: HashMap<u64, Vec<u32>, FastHash>,
    big: Vec<u32>,
    boxes: Vec<Option<Aabb>>,
    len: usize,
}

impl FaceGrid {
    /// An empty grid with cells of side `cell` (e.g. a typical edge length; see
    /// [`cell_size`]).
    pub fn new(cell: f64) -> FaceGrid {
        FaceGrid {
            inv: inverse(cell),
            cells: HashMap::default(),
            big: Vec::new(),
            boxes: Vec::new(),
            len: 0,
        }
    }

    /// Number of faces in the grid.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the grid holds no face.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Inserts face `id` with box `b` (replacing an earlier box of the same id). A box with a
    /// non-finite coordinate is not inserted: it would never overlap anything.
    pub fn insert(&mut self, id: u32, b: Aabb) {
        self.remove(id);
        if !b.is_finite() {
            return;
        }
        let i = id as usize;
        if self.boxes.len() <= i {
            self.boxes.resize(i + 1, None);
        }
        self.boxes[i] = Some(b);
        self.len += 1;
        let (lo, hi) = cell_range(&b, self.inv);
        if cell_count(&lo, &hi) > MAX_CELLS_PER_FACE {
            self.big.push(id);
            return;
        }
        let cells = &mut self.cells;
        for_cells(lo, hi, |c| cells.entry(key(c)).or_default().push(id));
    }

    /// Removes face `id` (nothing if absent).
    pub fn remove(&mut self, id: u32) {
        let Some(b) = self.boxes.get_mut(id as usize).and_then(Option::take) else {
            return;
        };
        self.len -= 1;
        let (lo, hi) = cell_range(&b, self.inv);
        if cell_count(&lo, &hi) > MAX_CELLS_PER_FACE {
            self.big.retain(|&x| x != id);
            return;
        }
        let cells = &mut self.cells;
        for_cells(lo, hi, |c| {
            if let Some(v) = cells.get_mut(&key(c)) {
                v.retain(|&x| x != id);
                if v.is_empty() {
                    cells.remove(&key(c));
                }
            }
        });
    }

    /// The ids of the inserted faces whose boxes overlap `b`, ascending and without
    /// repetitions, in `out` (cleared first).
    pub fn query(&self, b: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        if !b.is_finite() {
            return;
        }
        let (lo, hi) = cell_range(b, self.inv);
        if cell_count(&lo, &hi) > MAX_CELLS_PER_FACE {
            // A large query box: scanning every face is cheaper than every cell.
            out.extend(
                self.boxes
                    .iter()
                    .enumerate()
                    .filter(|(_, o)| o.is_some_and(|o| o.overlaps(b)))
                    .map(|(i, _)| i as u32),
            );
            return;
        }
        for_cells(lo, hi, |c| {
            if let Some(v) = self.cells.get(&key(c)) {
                out.extend(v.iter().copied().filter(|&i| self.overlaps(i, b)));
            }
        });
        out.extend(self.big.iter().copied().filter(|&i| self.overlaps(i, b)));
        out.sort_unstable();
        out.dedup();
    }

    /// [`FaceGrid::query`] with the box of triangle `t`.
    pub fn query_triangle(&self, t: &Tri, out: &mut Vec<u32>) {
        self.query(&Aabb::of_triangle(t), out)
    }

    fn overlaps(&self, i: u32, b: &Aabb) -> bool {
        self.boxes
            .get(i as usize)
            .copied()
            .flatten()
            .is_some_and(|o| o.overlaps(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::audit::XorShift64;

    fn random_boxes(rng: &mut XorShift64, n: usize, outliers: usize) -> Vec<Aabb> {
        let mut boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let c = rng.in_cube(1.0);
                let s = if i < outliers { 1.5 } else { 0.05 };
                let t: Tri = [0, 1, 2].map(|_| {
                    let d = rng.in_cube(s);
                    [c[0] + d[0], c[1] + d[1], c[2] + d[2]]
                });
                Aabb::of_triangle(&t)
            })
            .collect();
        boxes.push(Aabb::of_triangle(&[
            [f64::NAN, 0.0, 0.0],
            [0.0; 3],
            [0.0; 3],
        ]));
        boxes.push(Aabb::of_triangle(&[
            [1e300, 0.0, 0.0],
            [-1e300, 0.0, 0.0],
            [0.0; 3],
        ]));
        boxes
    }

    fn brute(boxes: &[Aabb]) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if boxes[i].overlaps(&boxes[j]) {
                    v.push((i as u32, j as u32));
                }
            }
        }
        v
    }

    #[test]
    fn pair_grid_finds_every_overlapping_pair_once() {
        let mut rng = XorShift64::new(3);
        for (n, outliers) in [(0, 0), (1, 0), (50, 0), (400, 5), (400, 40)] {
            let boxes = random_boxes(&mut rng, n, outliers);
            for cell in [cell_size(&boxes), 1e-3, 0.3, 10.0, f64::NAN, 0.0] {
                let grid = PairGrid::new(&boxes, cell);
                let mut got = Vec::new();
                grid.for_each_pair(|i, j| {
                    assert!(i < j);
                    got.push((i, j))
                });
                let len = got.len();
                got.sort_unstable();
                got.dedup();
                assert_eq!(len, got.len(), "a pair was reported twice");
                assert_eq!(got, brute(&boxes), "n = {n}, cell = {cell}");
            }
        }
    }

    #[test]
    fn face_grid_queries_match_brute_force() {
        let mut rng = XorShift64::new(9);
        let boxes = random_boxes(&mut rng, 300, 6);
        let mut grid = FaceGrid::new(cell_size(&boxes));
        let mut out = Vec::new();
        for (i, b) in boxes.iter().enumerate() {
            grid.query(b, &mut out);
            let expected: Vec<u32> = (0..i as u32)
                .filter(|&j| boxes[j as usize].overlaps(b))
                .collect();
            assert_eq!(out, expected, "face {i}");
            grid.insert(i as u32, *b);
        }
        assert_eq!(grid.len(), boxes.len() - 1); // the NaN box is not kept
                                                 // Remove every other face; queries see only the rest.
        for i in (0..boxes.len() as u32).step_by(2) {
            grid.remove(i);
        }
        let probe = Aabb {
            min: [-0.5; 3],
            max: [0.5; 3],
        };
        grid.query(&probe, &mut out);
        let expected: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&j| j % 2 == 1 && boxes[j as usize].overlaps(&probe))
            .collect();
        assert_eq!(out, expected);
        let huge = Aabb {
            min: [-10.0; 3],
            max: [10.0; 3],
        };
        grid.query(&huge, &mut out);
        assert_eq!(out.len(), grid.len());
    }

    #[test]
    fn cell_size_ignores_outliers_and_degenerate_input() {
        let unit = |s: f64| Aabb {
            min: [0.0; 3],
            max: [s, 0.0, 0.0],
        };
        let mut boxes = vec![unit(1.0); 9];
        boxes.push(unit(1e9));
        assert_eq!(cell_size(&boxes), 1.0);
        assert_eq!(cell_size(&[unit(0.0), unit(0.0), unit(8.0)]), 8.0 / 1024.0);
        assert_eq!(cell_size(&[]), 1.0);
    }
}
