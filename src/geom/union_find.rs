//! Disjoint sets over small integer ids (vertices, faces, fans): components of meshes and of
//! their boundaries.

/// Disjoint sets over `0..n` (path halving; the lower root wins, for stable roots).
pub(crate) struct UnionFind(Vec<u32>);

impl UnionFind {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> UnionFind {
        UnionFind((0..n as u32).collect())
    }

    /// Back to `n` singletons, keeping the allocation.
    pub(crate) fn reset(&mut self, n: usize) {
        self.0.clear();
        self.0.extend(0..n as u32);
    }

    /// The root of `x`'s set.
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }

    /// Joins the sets of `a` and `b`; whether they were apart.
    pub(crate) fn union(&mut self, a: u32, b: u32) -> bool {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
        a != b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lower_root_wins() {
        let mut sets = UnionFind::new(5);
        assert!(sets.union(3, 1) && sets.union(4, 3) && !sets.union(1, 4));
        assert_eq!([0, 1, 2, 3, 4].map(|x| sets.find(x)), [0, 1, 2, 1, 1]);
        sets.reset(2);
        assert_eq!([sets.find(0), sets.find(1)], [0, 1]);
    }
}
