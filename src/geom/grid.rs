//! Broad phase for triangle faces: grids of cubic cells over their bounding boxes.
//!
//! Mesh triangles are nearly uniform in size, but adaptive meshes (an ellipsoid's flat sides
//! against its tips) still vary by a factor of fifty. So the grid has levels: level `l` has
//! cells of side `h·4^l`, `h` about a typical box ([`cell_size`]: the median longest side),
//! and a face lives at the lowest level whose cells are at least half its box's longest
//! side, so it covers at most three cells per axis there. Faces at different levels meet
//! at the coarser one, where the finer face is also filed, as a guest. A face beyond the
//! last level ([`MAX_LEVELS`]) goes on an outlier list and is compared by box with every
//! face. Cell coordinates are clamped to a window of 2¹⁹ cells per axis and level, so keys
//! pack into a `u64` and huge coordinates cannot overflow; the clamp is monotone, so boxes
//! that overlap still share a cell. Boxes with a non-finite coordinate are never filed and
//! never reported.
//!
//! Two uses:
//! * [`PairGrid`]: every pair of overlapping boxes of a whole mesh, each once (a pair is
//!   reported in the cell holding the lowest corner of the boxes' intersection, at the
//!   coarser face's level), by ranges of cells so that callers can split the work. Built by a
//!   radix sort of (cell, face) entries: no hashing.
//! * [`FaceGrid`]: incremental — insert faces one at a time and ask, before inserting a new
//!   triangle, which inserted faces' boxes overlap its box (hashed cells per level).

use super::intersect::Tri;
use super::predicates::P3;
use super::vec3::FastHash;
use std::collections::HashMap;
use std::ops::Range;

/// Number of grid levels (cells grow fourfold per level); faces larger than the last
/// level's cells are outliers.
pub(crate) const MAX_LEVELS: usize = 20;

/// Cells per axis of one level's window (coordinates outside are clamped to its edge).
const WINDOW: i64 = 1 << 19;

/// A query box covering more cells than this at some level scans that level's faces instead.
#[cfg_attr(not(test), allow(dead_code))]
const MAX_QUERY_CELLS: u64 = 512;

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
            for (k, &x) in p.iter().enumerate() {
                b.min[k] = b.min[k].min(x);
                b.max[k] = b.max[k].max(x);
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

/// A closed axis-aligned box in `f32`, enclosing the [`Aabb`] it was made from: half the
/// memory of an `Aabb` (the broad phase of a validation holds one per face: 24 MB at 10⁶
/// faces). Bounds are moved outwards and clamped to `±f32::MAX`: a lower bound of one box is
/// still at most an upper bound of another where it was (clamping is monotone), so boxes
/// that overlap still do. A box with a NaN coordinate stays non-finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Box32 {
    min: [f32; 3],
    max: [f32; 3],
}

impl Box32 {
    /// An `f32` box holding `b` (clamped to the finite `f32` range), a few `f32` ulps wider.
    #[inline]
    pub fn enclosing(b: &Aabb) -> Box32 {
        // Without a branch on the rounding (it goes either way at random, and every face's
        // six bounds go through here): moved out by 2⁻²² of the value and by twice the
        // least subnormal `f32` before rounding to nearest, which moves a value by at most
        // half of that, the bound ends up outside. The clamps keep NaN.
        const RELATIVE: f64 = 1.0 / (1u64 << 22) as f64;
        const ABSOLUTE: f64 = 2.0 * 1.401_298_464_324_817e-45;
        let down = |x: f64| ((x - x.abs() * RELATIVE - ABSOLUTE) as f32).clamp(-f32::MAX, f32::MAX);
        let up = |x: f64| ((x + x.abs() * RELATIVE + ABSOLUTE) as f32).clamp(-f32::MAX, f32::MAX);
        Box32 {
            min: b.min.map(down),
            max: b.max.map(up),
        }
    }

    /// Lowest corner.
    #[inline]
    fn lo(&self) -> P3 {
        self.min.map(f64::from)
    }

    /// Highest corner.
    #[inline]
    fn hi(&self) -> P3 {
        self.max.map(f64::from)
    }

    /// Whether the closed boxes have a common point (never for a non-finite box).
    #[inline]
    fn overlaps(&self, o: &Box32) -> bool {
        self.min[0] <= o.max[0]
            && o.min[0] <= self.max[0]
            && self.min[1] <= o.max[1]
            && o.min[1] <= self.max[1]
            && self.min[2] <= o.max[2]
            && o.min[2] <= self.max[2]
    }

    /// [`Box32::overlaps`] with every comparison evaluated, for loops that must not branch
    /// on each pair.
    #[inline]
    fn overlaps_branchless(&self, o: &Box32) -> bool {
        (self.min[0] <= o.max[0])
            & (o.min[0] <= self.max[0])
            & (self.min[1] <= o.max[1])
            & (o.min[1] <= self.max[1])
            & (self.min[2] <= o.max[2])
            & (o.min[2] <= self.max[2])
    }

    /// Whether every coordinate is finite.
    #[inline]
    fn is_finite(&self) -> bool {
        self.min.iter().chain(&self.max).all(|x| x.is_finite())
    }

    /// The longest side (in `f64`, where it cannot overflow).
    pub fn extent(&self) -> f64 {
        (0..3)
            .map(|k| f64::from(self.max[k]) - f64::from(self.min[k]))
            .fold(0.0, f64::max)
    }
}

/// A cell size for boxes of longest sides `extents` (of the finite boxes): their median, or
/// a fallback when that is zero (most boxes points) or undefined.
pub(crate) fn cell_size(extents: impl IntoIterator<Item = f64>) -> f64 {
    let mut ext: Vec<f64> = extents.into_iter().filter(|e| e.is_finite()).collect();
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

/// A usable base cell side for any input.
fn base_cell(cell: f64) -> f64 {
    if cell.is_finite() && cell > 0.0 && (1.0 / cell).is_finite() {
        cell
    } else {
        1.0
    }
}

/// The level of a box of longest side `extent` with base cell `h` (`None`: an outlier).
#[inline]
fn level_of(extent: f64, h: f64) -> Option<usize> {
    let mut side = 2.0 * h;
    for l in 0..MAX_LEVELS {
        if extent <= side {
            return Some(l);
        }
        side *= 4.0;
    }
    None
}

/// The cell index of coordinate `x` (finite) in cells of `1 / inv`.
#[inline]
fn cell_of(x: f64, inv: f64) -> i64 {
    // floor by truncation: `f64::floor` is a libm call on baseline x86-64, and this runs for
    // every filed cell. `as` saturates on overflow (±∞ → i64 bounds); callers clamp.
    let y = x * inv;
    let t = y as i64;
    if (t as f64) > y {
        // saturating: y below i64::MIN saturates t to i64::MIN, which is already the floor.
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `y.floor().clamp(-1e9, 1e9) as i32` (NaN: 0) without `f64::floor`, a libm call on
/// baseline x86-64: truncation, one down for negative non-integers (exact below 2⁶³ in
/// magnitude; beyond, `as` saturates and the clamp decides as before).
#[inline]
pub(crate) fn floor_clamped(y: f64) -> i32 {
    let t = y as i64;
    let t = if (t as f64) > y {
        t.saturating_sub(1)
    } else {
        t
    };
    t.clamp(-1_000_000_000, 1_000_000_000) as i32
}

/// `x`'s low 21 bits spread to every third bit (Morton interleaving).
#[inline]
fn spread3(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The Morton code of a cell: cells near in space get near codes, so sorted entries of
/// neighbouring cells read nearby faces.
#[inline]
fn morton(c: [u32; 3]) -> u64 {
    spread3(c[0] as u64) << 2 | spread3(c[1] as u64) << 1 | spread3(c[2] as u64)
}

/// One level of a [`PairGrid`]: its cell size and the window of cells its keys cover.
#[derive(Clone, Copy, Debug)]
struct Level {
    inv: f64,
    /// Lowest cell of the window, per axis.
    lo: [i64; 3],
    /// Bits per axis of the window (2^bits cells).
    bits: u32,
    /// First key of this level.
    offset: u64,
}

impl Level {
    /// A level of cells of side `side` whose window covers `[gmin, gmax]` (clamped to
    /// [`WINDOW`] cells per axis).
    fn new(side: f64, gmin: &P3, gmax: &P3, offset: u64) -> Level {
        let inv = 1.0 / side;
        let lo = [0, 1, 2].map(|k| cell_of(gmin[k], inv));
        let span = (0..3)
            .map(|k| {
                (cell_of(gmax[k], inv) as i128 - lo[k] as i128 + 1).clamp(1, WINDOW as i128) as u64
            })
            .max()
            .unwrap_or(1);
        let bits = 64 - (span - 1).leading_zeros();
        Level {
            inv,
            lo,
            bits,
            offset,
        }
    }
    /// Number of keys of this level.
    fn size(&self) -> u64 {
        1 << (3 * self.bits)
    }
    /// The clamped cell of `p`, relative to the window.
    #[inline]
    fn cell(&self, p: &P3) -> [u32; 3] {
        let top = (1i64 << self.bits) - 1;
        let c = |k: usize| {
            cell_of(p[k], self.inv)
                .saturating_sub(self.lo[k])
                .clamp(0, top) as u32
        };
        [c(0), c(1), c(2)]
    }
}

/// Bits of a [`PairGrid`] entry below the face id: the three "lowest cell of the face's
/// range on this axis" flags.
const FLAG_BITS: u32 = 3;

/// All overlapping pairs of a fixed set of boxes (face `i` is `boxes[i]`).
///
/// Each entry is one `u64`: the cell's key (level offset plus Morton code), a guest flag,
/// the face id, and for each axis whether the cell is the lowest the face covers on it.
/// A pair of faces filed together is reported in the cell that is the lowest of both on
/// every axis — where the lowest corner of their boxes' intersection lies — which the flags
/// tell without reading the boxes. Sorting on the guest flag too puts a cell's own faces
/// before its guests, so guest pairs (which meet at their own level) are never visited.
pub(crate) struct PairGrid {
    boxes: Vec<Box32>,
    /// Entries sorted by key, faces ascending within a cell.
    filed: Vec<u64>,
    /// Start of each occupied cell's entries in `filed`, then the end.
    runs: Vec<u32>,
    /// Outliers, ascending.
    big: Vec<u32>,
    /// Position of the guest flag.
    guest_bit: u32,
}

impl PairGrid {
    /// Files `boxes` in levels of cells with base side `cell` (see [`cell_size`]). Boxes in
    /// a spatial order ([`spatial_order`]) make the pair loop read nearby memory.
    pub fn new(boxes: Vec<Box32>, cell: f64) -> PairGrid {
        let id_bits = 64 - (boxes.len() as u64).leading_zeros();
        let guest_bit = id_bits + FLAG_BITS;
        let tag_bits = guest_bit + 1;
        let mut h = base_cell(cell);
        let (mut gmin, mut gmax) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for b in boxes.iter().filter(|b| b.is_finite()) {
            for k in 0..3 {
                gmin[k] = gmin[k].min(f64::from(b.min[k]));
                gmax[k] = gmax[k].max(f64::from(b.max[k]));
            }
        }
        // Levels whose keys fit beside the tags in 64 bits; coarser cells if they do not
        // (any cell size is correct, only slower).
        let (level, big, levels, used) = loop {
            let mut level = vec![u8::MAX; boxes.len()];
            let mut big = Vec::new();
            let mut used = [false; MAX_LEVELS];
            for (i, b) in boxes.iter().enumerate() {
                if !b.is_finite() {
                    continue;
                }
                match level_of(b.extent(), h) {
                    Some(l) => {
                        level[i] = l as u8;
                        used[l] = true;
                    }
                    None => big.push(i as u32),
                }
            }
            let top = used.iter().rposition(|&u| u).map_or(0, |l| l + 1);
            let mut levels = Vec::with_capacity(top);
            let (mut offset, mut side) = (0u64, h);
            for _ in 0..top {
                let l = Level::new(side, &gmin, &gmax, offset);
                offset = offset.saturating_add(l.size());
                levels.push(l);
                side *= 4.0;
            }
            let key_bits = 64 - offset.leading_zeros();
            if key_bits + tag_bits <= 64 {
                break (level, big, levels, used);
            }
            if !(h * 2.0).is_finite() {
                // Cannot happen for finite boxes (one cell per axis fits); stay correct anyway.
                let all = (0..boxes.len() as u32).filter(|&i| boxes[i as usize].is_finite());
                break (level, all.collect(), Vec::new(), used);
            }
            h *= 2.0;
        };
        // Cells of the coarser levels that hold faces of their own: guests are filed only
        // there (elsewhere they would meet nobody). A bitset per level, when it is small.
        let mut occupied: Vec<Option<Vec<u64>>> = levels
            .iter()
            .map(|l| (l.size() <= 1 << 24).then(|| vec![0u64; (l.size() as usize).div_ceil(64)]))
            .collect();
        for (b, &l) in boxes.iter().zip(&level) {
            let l = l as usize;
            if l == 0 || l >= levels.len() {
                continue;
            }
            if let Some(bits) = occupied[l].as_mut() {
                let lev = &levels[l];
                let (lo, hi) = (lev.cell(&b.lo()), lev.cell(&b.hi()));
                for x in lo[0]..=hi[0] {
                    for y in lo[1]..=hi[1] {
                        for z in lo[2]..=hi[2] {
                            let k = morton([x, y, z]);
                            bits[(k / 64) as usize] |= 1 << (k % 64);
                        }
                    }
                }
            }
        }
        let has_natives = |lv: usize, key: u64| {
            occupied[lv]
                .as_ref()
                .is_none_or(|bits| bits[(key / 64) as usize] >> (key % 64) & 1 == 1)
        };
        // Entries by chunks of faces (in parallel on large meshes), concatenated in face
        // order: the same entries in the same order for any number of threads.
        let file = |range: Range<usize>| {
            let mut filed: Vec<u64> = Vec::with_capacity(4 * range.len());
            for i in range {
                let (b, l) = (&boxes[i], level[i] as usize);
                if l >= levels.len() {
                    continue;
                }
                // At its own level, and as a guest at every coarser occupied level.
                for (lv, lev) in levels.iter().enumerate().skip(l) {
                    if lv > l && !used[lv] {
                        continue;
                    }
                    let guest = lv > l;
                    let id = (guest as u64) << guest_bit | (i as u64) << FLAG_BITS;
                    let (lo, hi) = (lev.cell(&b.lo()), lev.cell(&b.hi()));
                    for x in lo[0]..=hi[0] {
                        let (mx, fx) = (spread3(x as u64) << 2, (x == lo[0]) as u64);
                        for y in lo[1]..=hi[1] {
                            let my = mx + (spread3(y as u64) << 1);
                            let fy = fx | ((y == lo[1]) as u64) << 1;
                            for z in lo[2]..=hi[2] {
                                let code = my + spread3(z as u64);
                                if guest && !has_natives(lv, code) {
                                    continue;
                                }
                                let low = fy | ((z == lo[2]) as u64) << 2;
                                filed.push((lev.offset + code) << tag_bits | id | low);
                            }
                        }
                    }
                }
            }
            // A chunk that outgrew its guess holds up to twice its entries; trimmed (in place)
            // before they are gathered, the chunks take no more than the gathered array.
            filed.shrink_to_fit();
            filed
        };
        let n = boxes.len();
        let chunks = if n >= crate::par::MIN_CHEAP { 16 } else { 1 };
        let mut filed = if chunks == 1 {
            file(0..n)
        } else {
            crate::par::map(chunks, 2, |c| file(c * n / chunks..(c + 1) * n / chunks)).concat()
        };
        let key_bits = levels
            .last()
            .map_or(0, |l| 64 - (l.offset + l.size() - 1).leading_zeros());
        radix_sort(&mut filed, guest_bit, tag_bits + key_bits);
        let mut runs = Vec::new();
        // A run is a cell: same key, natives then guests.
        for (n, &e) in filed.iter().enumerate() {
            if n == 0 || filed[n - 1] >> tag_bits != e >> tag_bits {
                runs.push(n as u32);
            }
        }
        runs.push(filed.len() as u32);
        PairGrid {
            boxes,
            filed,
            runs,
            big,
            guest_bit,
        }
    }

    /// Number of occupied cells (the range of [`PairGrid::pairs_in_cells`]).
    pub fn cells(&self) -> usize {
        self.runs.len() - 1
    }

    /// Calls `f(i, j)`, `i < j`, for the overlapping pairs of filed faces whose lowest common
    /// corner lies in one of the cells `range` (at the coarser face's level); over all cells,
    /// every such pair exactly once.
    pub fn pairs_in_cells(&self, range: Range<usize>, mut f: impl FnMut(u32, u32)) {
        let ids = (1u64 << (self.guest_bit - FLAG_BITS)) - 1;
        let id = |e: u64| ((e >> FLAG_BITS) & ids) as u32;
        // The entries that pair with the current one, collected without a branch per pair:
        // whether a pair counts is unpredictable (about a third do), and a mispredicted branch
        // costs more than the comparisons.
        let mut hits: Vec<u32> = Vec::new();
        for c in range {
            let run = &self.filed[self.runs[c] as usize..self.runs[c + 1] as usize];
            hits.clear();
            hits.resize(run.len(), 0);
            for (n, &a) in run.iter().enumerate() {
                // Natives come first; from the first guest on, every pair is two guests.
                if a >> self.guest_bit & 1 == 1 {
                    break;
                }
                let ia = id(a);
                let ba = &self.boxes[ia as usize];
                let mut found = 0;
                for (m, &b) in run.iter().enumerate().skip(n + 1) {
                    // Reported only in the cell that is both faces' lowest on every axis.
                    let lowest = (a | b) & 7 == 7;
                    hits[found] = m as u32;
                    found +=
                        (lowest & ba.overlaps_branchless(&self.boxes[id(b) as usize])) as usize;
                }
                for &m in &hits[..found] {
                    let ib = id(run[m as usize]);
                    f(ia.min(ib), ia.max(ib));
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
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn for_each_pair(&self, mut f: impl FnMut(u32, u32)) {
        self.pairs_in_cells(0..self.cells(), &mut f);
        self.pairs_with_outliers(f);
    }
}

/// `0..n` in the Morton order of the points `at(i)` (non-finite points last), so that items
/// near in space can be stored near in memory. `at` is called twice per item.
pub(crate) fn spatial_order(n: usize, at: impl Fn(usize) -> P3 + Sync) -> Vec<u32> {
    let (mut gmin, mut gmax) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let finite = |c: &P3| c.iter().all(|x| x.is_finite());
    for i in 0..n {
        let c = at(i);
        if finite(&c) {
            for k in 0..3 {
                gmin[k] = gmin[k].min(c[k]);
                gmax[k] = gmax[k].max(c[k]);
            }
        }
    }
    // No finite point: the bounds are still ±∞ the wrong way round.
    if gmin[0] > gmax[0] {
        return (0..n as u32).collect();
    }
    // 2^10 cells per axis over the points' box: fine enough for locality.
    let side = (0..3).map(|k| gmax[k] - gmin[k]).fold(0.0, f64::max) / 1023.0;
    let level = Level::new(base_cell(side), &gmin, &gmax, 0);
    let id_bits = 64 - (n as u64).leading_zeros();
    let mut keyed: Vec<u64> = crate::par::map(n, crate::par::MIN_CHEAP, |i| {
        let c = at(i);
        let key = if finite(&c) {
            morton(level.cell(&c))
        } else {
            level.size()
        };
        key << id_bits | i as u64
    });
    let key_bits = 64 - level.size().leading_zeros();
    radix_sort(&mut keyed, id_bits, id_bits + key_bits);
    keyed
        .into_iter()
        .map(|e| (e & ((1 << id_bits) - 1)) as u32)
        .collect()
}

/// Stable least-significant-digit radix sort of `v` by bits `lo..hi`, in as few passes of at
/// most [`MAX_DIGIT`] bits as cover the range (digits split evenly: the grid's 26-bit keys
/// take two passes of 13 bits rather than three of 11).
pub(crate) fn radix_sort(v: &mut Vec<u64>, lo: u32, hi: u32) {
    if hi <= lo {
        return;
    }
    let passes = (hi - lo).div_ceil(MAX_DIGIT);
    let digit_bits = (hi - lo).div_ceil(passes);
    let mask = (1u64 << digit_bits) - 1;
    let mut buf = vec![0u64; v.len()];
    let mut count = vec![0usize; (1 << digit_bits) + 1];
    let mut shift = lo;
    while shift < hi {
        count.fill(0);
        let digit = |e: u64| ((e >> shift) & mask) as usize;
        for &e in v.iter() {
            count[digit(e) + 1] += 1;
        }
        for d in 0..1 << digit_bits {
            count[d + 1] += count[d];
        }
        for &e in v.iter() {
            let d = digit(e);
            buf[count[d]] = e;
            count[d] += 1;
        }
        std::mem::swap(v, &mut buf);
        shift += digit_bits;
    }
}

/// Widest digit of [`radix_sort`]: 8192 counters (64 KiB) stay in the L2 cache while a pass
/// scatters into as many runs.
const MAX_DIGIT: u32 = 13;

/// An incremental grid: faces are inserted (and removed) by id, and queried by box.
///
/// Each face lives at its level (as in [`PairGrid`]) in hashed cells; a query visits the
/// cells its box covers at every occupied level, or scans a level's faces when its box
/// covers more than a few hundred of that level's cells. Ids index an internal table, so
/// they should be dense (face indices); the table grows to the largest id inserted.
// The mesher's incremental check (next step) is its user; tested here.
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) struct FaceGrid {
    h: f64,
    /// Cells per level, keyed by packed (clamped) cell coordinates.
    cells: Vec<HashMap<u64, Vec<u32>, FastHash>>,
    /// Faces per level, for scans.
    members: Vec<Vec<u32>>,
    /// Outliers (larger than the last level's cells).
    big: Vec<u32>,
    /// Box and level of each inserted id.
    boxes: Vec<Option<(Aabb, u8)>>,
    len: usize,
}

/// Packed key of a cell, clamped to ±2²⁰ per axis (monotone).
#[inline]
// The mesher's incremental check (next step) is its user; tested here.
#[cfg_attr(not(test), allow(dead_code))]
fn hash_key(c: [i64; 3]) -> u64 {
    let u = |x: i64| (x.clamp(-(1 << 20), 1 << 20) + (1 << 20)) as u64;
    (u(c[0]) << 42) | (u(c[1]) << 21) | u(c[2])
}

/// Clamped cell range of `b` in cells of `1 / inv`, and its number of cells.
#[inline]
// The mesher's incremental check (next step) is its user; tested here.
#[cfg_attr(not(test), allow(dead_code))]
fn hash_range(b: &Aabb, inv: f64) -> ([i64; 3], [i64; 3], u64) {
    let c = |x: f64| cell_of(x, inv).clamp(-(1 << 20), 1 << 20);
    let lo = [0, 1, 2].map(|k| c(b.min[k]));
    let hi = [0, 1, 2].map(|k| c(b.max[k]));
    let n = (0..3).map(|k| (hi[k] - lo[k] + 1) as u64).product();
    (lo, hi, n)
}

// The mesher's incremental check (next step) is its user; tested here.
#[cfg_attr(not(test), allow(dead_code))]
impl FaceGrid {
    /// An empty grid with base cells of side `cell` (e.g. a typical edge length; see
    /// [`cell_size`]).
    pub fn new(cell: f64) -> FaceGrid {
        FaceGrid {
            h: base_cell(cell),
            cells: Vec::new(),
            members: Vec::new(),
            big: Vec::new(),
            boxes: Vec::new(),
            len: 0,
        }
    }

    fn inv(&self, level: usize) -> f64 {
        1.0 / (self.h * 4f64.powi(level as i32))
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
        self.len += 1;
        let Some(l) = level_of(b.extent(), self.h) else {
            self.boxes[i] = Some((b, u8::MAX));
            self.big.push(id);
            return;
        };
        self.boxes[i] = Some((b, l as u8));
        if self.cells.len() <= l {
            self.cells.resize_with(l + 1, HashMap::default);
            self.members.resize_with(l + 1, Vec::new);
        }
        self.members[l].push(id);
        let (lo, hi, _) = hash_range(&b, self.inv(l));
        let cells = &mut self.cells[l];
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    cells.entry(hash_key([x, y, z])).or_default().push(id);
                }
            }
        }
    }

    /// Removes face `id` (nothing if absent).
    pub fn remove(&mut self, id: u32) {
        let Some((b, l)) = self.boxes.get_mut(id as usize).and_then(Option::take) else {
            return;
        };
        self.len -= 1;
        let l = l as usize;
        if l >= self.cells.len() {
            self.big.retain(|&x| x != id);
            return;
        }
        self.members[l].retain(|&x| x != id);
        let (lo, hi, _) = hash_range(&b, self.inv(l));
        let cells = &mut self.cells[l];
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let k = hash_key([x, y, z]);
                    if let Some(v) = cells.get_mut(&k) {
                        v.retain(|&x| x != id);
                        if v.is_empty() {
                            cells.remove(&k);
                        }
                    }
                }
            }
        }
    }

    /// The ids of the inserted faces whose boxes overlap `b`, ascending and without
    /// repetitions, in `out` (cleared first).
    pub fn query(&self, b: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        if !b.is_finite() {
            return;
        }
        for l in 0..self.cells.len() {
            if self.members[l].is_empty() {
                continue;
            }
            let (lo, hi, n) = hash_range(b, self.inv(l));
            if n > MAX_QUERY_CELLS || n > self.members[l].len() as u64 {
                out.extend(
                    self.members[l]
                        .iter()
                        .copied()
                        .filter(|&i| self.overlaps(i, b)),
                );
                continue;
            }
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        if let Some(v) = self.cells[l].get(&hash_key([x, y, z])) {
                            out.extend(v.iter().copied().filter(|&i| self.overlaps(i, b)));
                        }
                    }
                }
            }
        }
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
            .is_some_and(|(o, _)| o.overlaps(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::rng::XorShift64;

    fn random_boxes(rng: &mut XorShift64, n: usize, outliers: usize) -> Vec<Aabb> {
        let mut boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let c = rng.in_cube(1.0);
                // The first `outliers` boxes spread over three orders of magnitude.
                let s = if i < outliers {
                    10f64.powf(rng.uniform(-3.0, 0.3))
                } else {
                    0.05
                };
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

    /// The longest sides of the finite boxes, for [`cell_size`].
    fn extents(boxes: &[Aabb]) -> impl Iterator<Item = f64> + '_ {
        boxes.iter().filter(|b| b.is_finite()).map(Aabb::extent)
    }

    fn brute(boxes: &[Box32]) -> Vec<(u32, u32)> {
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
        for (n, outliers) in [(0, 0), (1, 0), (50, 0), (400, 5), (400, 40), (400, 200)] {
            let exact = random_boxes(&mut rng, n, outliers);
            let boxes: Vec<Box32> = exact.iter().map(Box32::enclosing).collect();
            for cell in [cell_size(extents(&exact)), 1e-3, 0.3, 10.0, f64::NAN, 0.0] {
                let grid = PairGrid::new(boxes.clone(), cell);
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
                // Every pair of overlapping `f64` boxes is among them.
                for (i, a) in exact.iter().enumerate() {
                    for (j, b) in exact.iter().enumerate().skip(i + 1) {
                        if a.overlaps(b) {
                            assert!(got.binary_search(&(i as u32, j as u32)).is_ok());
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn f32_boxes_enclose_their_boxes_and_keep_every_overlap() {
        let mut rng = XorShift64::new(23);
        let special = [
            0.0,
            -0.0,
            1.0,
            0.1,
            -0.1,
            1e-45,
            -1e-45,
            1e-300,
            -1e-300,
            3.4e38,
            3.5e38,
            -3.5e38,
            1e300,
            -1e300,
            f64::MAX,
            f64::MIN,
        ];
        let mut values = special.to_vec();
        values.extend(
            (0..2000)
                .map(|_| f64::from_bits(rng.next_u64()))
                .filter(|x| x.is_finite()),
        );
        values.extend((0..2000).map(|_| rng.uniform(-10.0, 10.0)));
        for &x in &values {
            for &y in &values[..64] {
                let exact = Aabb {
                    min: [x.min(y); 3],
                    max: [x.max(y); 3],
                };
                let b = Box32::enclosing(&exact);
                assert!(b.is_finite(), "{x:e} {y:e}");
                let (lo, hi) = (b.lo()[0], b.hi()[0]);
                // Outwards, except where clamped to the f32 range.
                assert!(lo <= exact.min[0] || lo == -f32::MAX as f64, "{x:e} {y:e}");
                assert!(hi >= exact.max[0] || hi == f32::MAX as f64, "{x:e} {y:e}");
                // Loose by a few ulps at most (where not clamped).
                if (1e-37..=1e38).contains(&exact.min[0].abs()) {
                    assert!(
                        exact.min[0] - lo <= 1e-6 * exact.min[0].abs(),
                        "{x:e} {y:e}"
                    );
                }
                // A point box at x overlaps exactly the boxes that hold x, and more only where
                // rounding or clamping merged bounds.
                let point = Aabb {
                    min: [x; 3],
                    max: [x; 3],
                };
                if exact.overlaps(&point) {
                    assert!(b.overlaps(&Box32::enclosing(&point)), "{x:e} {y:e}");
                }
            }
        }
        let nan = Box32::enclosing(&Aabb::of_triangle(&[
            [f64::NAN, 0.0, 0.0],
            [0.0; 3],
            [0.0; 3],
        ]));
        assert!(!nan.is_finite());
    }

    #[test]
    fn face_grid_queries_match_brute_force() {
        let mut rng = XorShift64::new(9);
        let boxes = random_boxes(&mut rng, 300, 6);
        let mut grid = FaceGrid::new(cell_size(extents(&boxes)));
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
        assert!(!grid.is_empty());
        let t: Tri = [[0.0; 3], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]];
        grid.query_triangle(&t, &mut out);
        let b = Aabb::of_triangle(&t);
        let expected: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&j| boxes[j as usize].overlaps(&b))
            .collect();
        assert_eq!(out, expected);
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
    fn floor_clamped_is_floor_clamp_and_cast() {
        let mut rng = XorShift64::new(17);
        let special = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            -1.0,
            2.0,
            -2.5,
            4503599627370495.5,
            -4503599627370495.5,
            9007199254740993.0,
            1e9 - 0.5,
            -1e9 - 0.5,
            1e9 + 3.0,
            -1e9 - 3.0,
            9.3e18,
            -9.3e18,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        let mut values = special.to_vec();
        values.extend((0..100_000).map(|_| f64::from_bits(rng.next_u64())));
        values.extend((0..100_000).map(|_| rng.uniform(-3e9, 3e9)));
        for y in values {
            assert_eq!(floor_clamped(y), y.floor().clamp(-1e9, 1e9) as i32, "{y:e}");
        }
    }

    #[test]
    fn cell_size_ignores_outliers_and_degenerate_input() {
        let unit = |s: f64| Aabb {
            min: [0.0; 3],
            max: [s, 0.0, 0.0],
        };
        let mut boxes = vec![unit(1.0); 9];
        boxes.push(unit(1e9));
        assert_eq!(cell_size(extents(&boxes)), 1.0);
        assert_eq!(
            cell_size(extents(&[unit(0.0), unit(0.0), unit(8.0)])),
            8.0 / 1024.0
        );
        assert_eq!(cell_size(extents(&[])), 1.0);
        assert_eq!(cell_size([f64::NAN, f64::INFINITY, 2.0]), 2.0);
    }
}
