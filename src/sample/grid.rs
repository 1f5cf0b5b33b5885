//! A uniform hash grid over points: O(1) neighbourhood queries for the gap and
//! closure tests of the sampler.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A small multiplicative hasher: cell keys are three small integers, SipHash is overkill.
#[derive(Default)]
pub(crate) struct CellHasher(u64);

impl Hasher for CellHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(5) ^ b as u64).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
        }
    }
    #[inline]
    fn write_i32(&mut self, i: i32) {
        self.0 =
            (self.0.rotate_left(5) ^ (i as u32 as u64)).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type Cell = (i32, i32, i32);

/// Point indices bucketed by cubic cells of side `cell`.
pub(crate) struct Grid {
    cell: f64,
    inv: f64,
    buckets: HashMap<Cell, Vec<u32>, BuildHasherDefault<CellHasher>>,
}

impl Grid {
    pub(crate) fn new(cell: f64) -> Self {
        Grid {
            cell,
            inv: 1.0 / cell,
            buckets: HashMap::default(),
        }
    }

    #[inline]
    fn key(&self, p: [f64; 3]) -> Cell {
        let k = |x: f64| (x * self.inv).floor().clamp(-1e9, 1e9) as i32;
        (k(p[0]), k(p[1]), k(p[2]))
    }

    pub(crate) fn insert(&mut self, p: [f64; 3], index: u32) {
        let key = self.key(p);
        self.buckets.entry(key).or_default().push(index);
    }

    /// Calls `f` for every stored index whose cell meets the ball of `radius` around `p`
    /// (a superset of the points within `radius`), in a deterministic order.
    ///
    /// When the cube of cells around `p` has more cells than the grid has buckets (a radius of
    /// many cells: an initial Δt far below the step lengths), every bucket is visited
    /// instead, which is cheaper and still a superset.
    pub(crate) fn for_each_near(&self, p: [f64; 3], radius: f64, mut f: impl FnMut(u32)) {
        let r = (radius / self.cell).ceil().max(0.0);
        let cube = (2.0 * r + 1.0).powi(3);
        if cube.is_nan() || cube > self.buckets.len() as f64 {
            for &i in self.buckets.values().flatten() {
                f(i);
            }
            return;
        }
        let r = r as i32;
        let (cx, cy, cz) = self.key(p);
        for dx in -r..=r {
            for dy in -r..=r {
                for dz in -r..=r {
                    if let Some(bucket) = self.buckets.get(&(cx + dx, cy + dy, cz + dz)) {
                        for &i in bucket {
                            f(i);
                        }
                    }
                }
            }
        }
    }
}
