//! 30-bit Morton codes of instance centres and the radix sort that orders instances by them:
//! the TLAS builder's only sort. Along a Morton curve, instances close in the order are close in
//! space, so the builder can split contiguous ranges of the order instead of partitioning.

use crate::aabb::Aabb;
use glam::Vec3A;

/// Cells per axis of the Morton grid (10 bits per axis).
const CELLS: f32 = 1024.0;

/// Spreads the low 10 bits of `v` so that bit `k` lands on bit `3k`.
const fn spread10(v: u32) -> u32 {
    let mut x = v & 0x3FF;
    x = (x | (x << 16)) & 0x0300_00FF;
    x = (x | (x << 8)) & 0x0300_F00F;
    x = (x | (x << 4)) & 0x030C_30C3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// [`spread10`] of every 10-bit value (4 KiB): one load per axis instead of a chain of twelve
/// shifts and masks.
static SPREAD: [u32; 1024] = {
    let mut t = [0u32; 1024];
    let mut i = 0;
    while i < 1024 {
        t[i] = spread10(i as u32);
        i += 1;
    }
    t
};

/// Morton code of grid cell `q` (each coordinate below 1024): x in the highest bit of every
/// triple, then y, then z.
#[inline]
pub(crate) fn code(q: [u32; 3]) -> u32 {
    let s = |v: u32| SPREAD[(v & 0x3FF) as usize];
    s(q[0]) << 2 | s(q[1]) << 1 | s(q[2])
}

/// Maps centres into the Morton grid. The grid is a cube over the centres' box (cells of equal
/// size on every axis), so that the curve's first splits cut the longest axis, as a spatial
/// median split would; a flat scene (a village: hundreds of metres wide, tens high) leaves the
/// short axis's high bits zero instead of stretching it.
pub(crate) struct Grid {
    origin: Vec3A,
    scale: f32,
}

impl Grid {
    pub(crate) fn new(centres: &Aabb) -> Grid {
        let ext = centres.extent().max_element();
        // Just below `CELLS` so the largest centre lands in the last cell. An infinite extent
        // (centres near +-f32::MAX) or a single point gives 0: every code is 0, and the build
        // still works from the boxes alone.
        let scale = if ext > 0.0 && ext.is_finite() {
            CELLS * (1.0 - 1e-6) / ext
        } else {
            0.0
        };
        Grid {
            origin: centres.min,
            scale,
        }
    }

    #[inline]
    pub(crate) fn code(&self, centre: Vec3A) -> u32 {
        // `max` first: it maps NaN (an infinite centre times a zero scale) to 0.
        let q = ((centre - self.origin) * self.scale)
            .max(Vec3A::ZERO)
            .min(Vec3A::splat(CELLS - 1.0));
        code(cells(q))
    }
}

/// Truncates three lanes known to lie in `[0, CELLS)`: one packed conversion on x86_64 instead
/// of three saturating scalar casts.
#[cfg(target_arch = "x86_64")]
#[inline]
fn cells(v: Vec3A) -> [u32; 3] {
    use std::arch::x86_64::{_mm_cvttps_epi32, _mm_storeu_si128};
    let mut out = [0u32; 4];
    // SAFETY: SSE2 is part of the x86_64 baseline; `out` is 16 writable bytes and the store is
    // the unaligned variant.
    unsafe { _mm_storeu_si128(out.as_mut_ptr().cast(), _mm_cvttps_epi32(v.into())) };
    [out[0], out[1], out[2]]
}

#[cfg(not(target_arch = "x86_64"))]
#[inline]
fn cells(v: Vec3A) -> [u32; 3] {
    [v.x as u32, v.y as u32, v.z as u32]
}

/// Sorts `keys` (Morton code in the high 32 bits, anything in the low ones) by code, stable, so
/// keys with equal codes keep their order. `scratch` is resized as needed.
pub(crate) fn sort_by_code(keys: &mut Vec<u64>, scratch: &mut Vec<u64>) {
    let n = keys.len();
    if n <= SMALL_SORT {
        // The low half is the position in the input, so an unstable sort of whole keys is the
        // stable sort by code; below a few hundred keys it beats clearing the histograms.
        keys.sort_unstable();
        return;
    }
    // Least significant digit first, 8 bits per pass, all four histograms in one read.
    let mut hist = [[0u32; 256]; 4];
    for &k in keys.iter() {
        let c = (k >> 32) as u32;
        for (d, h) in hist.iter_mut().enumerate() {
            h[((c >> (8 * d)) & 0xFF) as usize] += 1;
        }
    }
    scratch.resize(n, 0);
    let first = (keys[0] >> 32) as u32;
    for (d, h) in hist.iter_mut().enumerate() {
        // Every key has the same digit: the pass would not move anything.
        if h[((first >> (8 * d)) & 0xFF) as usize] as usize == n {
            continue;
        }
        let mut sum = 0u32;
        for c in h.iter_mut() {
            let count = *c;
            *c = sum;
            sum += count;
        }
        for &k in keys.iter() {
            let digit = (((k >> 32) as u32 >> (8 * d)) & 0xFF) as usize;
            scratch[h[digit] as usize] = k;
            h[digit] += 1;
        }
        std::mem::swap(keys, scratch);
    }
}

/// Inputs up to this size are sorted by comparison.
const SMALL_SORT: usize = 256;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn codes_interleave_the_bits_of_the_three_axes() {
        // Reference: bit k of x goes to bit 3k + 2, of y to 3k + 1, of z to 3k.
        let mut rng = SplitMix64::new(1);
        for _ in 0..10_000 {
            let q = [0; 3].map(|_| rng.below(1024) as u32);
            let mut want = 0u32;
            for k in 0..10 {
                want |= ((q[0] >> k) & 1) << (3 * k + 2);
                want |= ((q[1] >> k) & 1) << (3 * k + 1);
                want |= ((q[2] >> k) & 1) << (3 * k);
            }
            assert_eq!(code(q), want, "{q:?}");
        }
    }

    #[test]
    fn radix_sort_is_a_stable_sort_by_code() {
        let mut rng = SplitMix64::new(2);
        for &n in &[0usize, 1, 2, 255, 256, 257, 1000, 5000] {
            for spread in [1u64, 7, 1 << 30] {
                // Few distinct codes (many ties), or codes sharing their high digits.
                let keys: Vec<u64> = (0..n)
                    .map(|i| ((rng.next_u64() % spread) << 32) | i as u64)
                    .collect();
                let mut want = keys.clone();
                want.sort_by_key(|k| k >> 32);
                let mut got = keys.clone();
                sort_by_code(&mut got, &mut Vec::new());
                assert_eq!(got, want, "{n} keys, {spread} codes");
            }
        }
    }

    #[test]
    fn grid_codes_stay_in_range_for_extreme_centres() {
        let b = Aabb::new(Vec3A::splat(-3e38), Vec3A::splat(3e38));
        let g = Grid::new(&b);
        for c in [Vec3A::splat(-3e38), Vec3A::ZERO, Vec3A::splat(3e38)] {
            assert!(g.code(c) < 1 << 30);
        }
        let one = Grid::new(&Aabb::new(Vec3A::ONE, Vec3A::ONE));
        assert_eq!(one.code(Vec3A::ONE), 0);
    }
}
