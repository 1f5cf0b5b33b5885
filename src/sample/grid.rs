//! A uniform hash grid over points: O(1) neighbourhood queries for the gap and
//! closure tests of the sampler.

use crate::scalar::f64x3::FastHash;
use std::collections::HashMap;

type Cell = (i32, i32, i32);

/// Point indices bucketed by cubic cells of side `cell`.
pub(crate) struct Grid {
    inv: f64,
    buckets: HashMap<Cell, Vec<u32>, FastHash>,
}

impl Grid {
    pub(crate) fn new(cell: f64) -> Self {
        Grid {
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

    /// Whether `f` holds for some stored index whose cell meets the ball of `radius` around
    /// `p` (a superset of the points within `radius`); stops at the first that does.
    ///
    /// When the ball's bounding box meets more cells than the grid has buckets (a radius of
    /// many cells: an initial Δt far below the step lengths), every bucket is visited
    /// instead, which is cheaper and still a superset.
    pub(crate) fn any_near(
        &self,
        p: [f64; 3],
        radius: f64,
        mut f: impl FnMut(u32) -> bool,
    ) -> bool {
        // Only the cells the ball's bounding box meets: about 1.4³ of them for a radius of
        // 0.7 cells, not the 27 of a cube of radius one cell.
        let radius = radius.max(0.0);
        let lo = self.key([p[0] - radius, p[1] - radius, p[2] - radius]);
        let hi = self.key([p[0] + radius, p[1] + radius, p[2] + radius]);
        let cells = (hi.0 as f64 - lo.0 as f64 + 1.0)
            * (hi.1 as f64 - lo.1 as f64 + 1.0)
            * (hi.2 as f64 - lo.2 as f64 + 1.0);
        if radius.is_nan() || cells > self.buckets.len() as f64 {
            return self.buckets.values().flatten().any(|&i| f(i));
        }
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    if let Some(bucket) = self.buckets.get(&(x, y, z)) {
                        if bucket.iter().any(|&i| f(i)) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}
