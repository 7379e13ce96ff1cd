//! Centroid bins of one node (or of one share of a node's primitives) and the SAH sweep over
//! them.
//!
//! Bins hold only minima, maxima and counts, so merging the bins of several shares gives
//! exactly the bins of the whole node, whatever the shares were: the parallel top levels rely
//! on this to choose the same splits as a single thread.

use super::{PrimRef, Split, bin_index, half_area};
use glam::Vec3A;

pub(super) struct Bins<const NB: usize> {
    lo: [[Vec3A; NB]; 3],
    hi: [[Vec3A; NB]; 3],
    count: [[u32; NB]; 3],
}

impl<const NB: usize> Bins<NB> {
    pub(super) fn empty() -> Self {
        Self {
            lo: [[Vec3A::INFINITY; NB]; 3],
            hi: [[Vec3A::NEG_INFINITY; NB]; 3],
            count: [[0; NB]; 3],
        }
    }

    #[inline]
    fn add(&mut self, p: &PrimRef, cb_min: Vec3A, k: Vec3A) {
        let l = p.lo3();
        let h = p.hi3();
        let b = bin_index(l + h, cb_min, k, NB);
        for (a, &bin) in b.iter().enumerate() {
            self.lo[a][bin] = self.lo[a][bin].min(l);
            self.hi[a][bin] = self.hi[a][bin].max(h);
            self.count[a][bin] += 1;
        }
    }

    /// Bins `prims` by doubled centroid, with `cb_min` and `k` from [`super::bin_scale`] of the
    /// node's doubled-centroid box.
    pub(super) fn accumulate(prims: &[PrimRef], cb_min: Vec3A, k: Vec3A) -> Self {
        // Two interleaved sets of bins: neighbouring primitives usually fall into the same bin,
        // and with one set every update would wait on the store of the previous one.
        let mut even = Self::empty();
        let mut odd = Self::empty();
        let mut pairs = prims.chunks_exact(2);
        for pair in &mut pairs {
            even.add(&pair[0], cb_min, k);
            odd.add(&pair[1], cb_min, k);
        }
        for p in pairs.remainder() {
            even.add(p, cb_min, k);
        }
        even.merge(&odd);
        even
    }

    pub(super) fn merge(&mut self, other: &Self) {
        for a in 0..3 {
            for i in 0..NB {
                self.lo[a][i] = self.lo[a][i].min(other.lo[a][i]);
                self.hi[a][i] = self.hi[a][i].max(other.hi[a][i]);
                self.count[a][i] += other.count[a][i];
            }
        }
    }

    /// Primitives on the left of a split after `bin` along `axis`.
    pub(super) fn left_count(&self, axis: usize, bin: usize) -> usize {
        self.count[axis][..=bin].iter().map(|&c| c as usize).sum()
    }

    /// Cheapest plane between bins over the axes with a non-zero scale `k`, for a node of `n`
    /// primitives; None if no plane has primitives on both sides.
    pub(super) fn best_split(&self, k: Vec3A, n: usize) -> Option<Split> {
        let mut best: Option<(f32, usize, usize)> = None;
        for a in 0..3 {
            if k[a] == 0.0 {
                continue;
            }
            // Right-to-left sweep: cost of the right side of each split plane.
            let mut right_cost = [0.0f32; NB];
            let mut l = Vec3A::INFINITY;
            let mut h = Vec3A::NEG_INFINITY;
            let mut cnt = 0;
            for i in (1..NB).rev() {
                cnt += self.count[a][i];
                if cnt > 0 {
                    l = l.min(self.lo[a][i]);
                    h = h.max(self.hi[a][i]);
                    right_cost[i] = half_area(l, h) * cnt as f32;
                }
            }
            let mut l = Vec3A::INFINITY;
            let mut h = Vec3A::NEG_INFINITY;
            let mut cnt = 0;
            for i in 0..NB - 1 {
                cnt += self.count[a][i];
                if cnt == 0 {
                    continue;
                }
                l = l.min(self.lo[a][i]);
                h = h.max(self.hi[a][i]);
                if cnt as usize == n {
                    break;
                }
                let cost = half_area(l, h) * cnt as f32 + right_cost[i + 1];
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, a, i));
                }
            }
        }
        let (_, axis, bin) = best?;
        let mut left = crate::aabb::Aabb::EMPTY;
        let mut right = crate::aabb::Aabb::EMPTY;
        for i in 0..NB {
            if self.count[axis][i] == 0 {
                continue;
            }
            let side = if i <= bin { &mut left } else { &mut right };
            side.grow(&crate::aabb::Aabb::new(self.lo[axis][i], self.hi[axis][i]));
        }
        Some(Split {
            axis,
            bin,
            bins: NB,
            left,
            right,
        })
    }
}
