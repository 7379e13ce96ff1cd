//! Blue-noise dither arrays by void-and-cluster (Ulichney 1993), on a torus so they tile.
//!
//! Energy of a pixel = Σ over points of a Gaussian of the toroidal distance (σ = 1.5 px, the
//! paper's value). The algorithm ranks every pixel: initial pattern by relaxing a random 10 %
//! set (move the tightest cluster to the largest void until stable), then ranks below the
//! initial count by removing tightest clusters, above it by filling largest voids.
//!
//! Cost is O(n²) per array with an incremental energy table; 64 x 64 takes well under a second
//! in release builds. `hikari-math/examples/make_blue_noise.rs` writes the 64 x 64 x 64 set.

use super::SplitMix64;
use crate::MathError;

/// Gaussian width of the energy filter, pixels (Ulichney 1993).
pub const SIGMA: f64 = 1.5;

struct Field {
    w: usize,
    h: usize,
    lut: Vec<f64>, // energy contribution by toroidal (dx, dy)
    energy: Vec<f64>,
    on: Vec<bool>,
}

impl Field {
    fn new(w: usize, h: usize) -> Self {
        let mut lut = vec![0.0; w * h];
        for dy in 0..h {
            for dx in 0..w {
                let x = dx.min(w - dx) as f64;
                let y = dy.min(h - dy) as f64;
                lut[dy * w + dx] = (-(x * x + y * y) / (2.0 * SIGMA * SIGMA)).exp();
            }
        }
        Self {
            w,
            h,
            lut,
            energy: vec![0.0; w * h],
            on: vec![false; w * h],
        }
    }

    fn toggle(&mut self, p: usize, on: bool) {
        self.on[p] = on;
        let sign = if on { 1.0 } else { -1.0 };
        let (px, py) = (p % self.w, p / self.w);
        for y in 0..self.h {
            let dy = (y + self.h - py) % self.h;
            for x in 0..self.w {
                let dx = (x + self.w - px) % self.w;
                self.energy[y * self.w + x] += sign * self.lut[dy * self.w + dx];
            }
        }
    }

    fn tightest_cluster(&self) -> usize {
        let mut best = (f64::NEG_INFINITY, 0);
        for (i, e) in self.energy.iter().enumerate() {
            if self.on[i] && *e > best.0 {
                best = (*e, i);
            }
        }
        best.1
    }

    fn largest_void(&self) -> usize {
        let mut best = (f64::INFINITY, 0);
        for (i, e) in self.energy.iter().enumerate() {
            if !self.on[i] && *e < best.0 {
                best = (*e, i);
            }
        }
        best.1
    }
}

/// A `w x h` dither array: every rank `0 .. w·h` exactly once, row-major. Thresholding at rank
/// `k` gives `k` well-spread points at every `k`. `w, h` in `4 ..= 256`.
pub fn void_and_cluster(w: usize, h: usize, seed: u64) -> Result<Vec<u32>, MathError> {
    for (name, v) in [("width", w), ("height", h)] {
        if !(4..=256).contains(&v) {
            return Err(MathError::OutOfRange {
                name,
                value: v as f64,
                allowed: "4 ..= 256",
            });
        }
    }
    let n = w * h;
    let mut f = Field::new(w, h);
    let mut rng = SplitMix64(seed);
    let initial = (n / 10).max(1);
    let mut placed = 0;
    while placed < initial {
        let p = (rng.next_u64() % n as u64) as usize;
        if !f.on[p] {
            f.toggle(p, true);
            placed += 1;
        }
    }
    // Relax the initial pattern: move the tightest cluster to the largest void until the move
    // would put the point back where it came from.
    for _ in 0..4 * n {
        let c = f.tightest_cluster();
        f.toggle(c, false);
        let v = f.largest_void();
        f.toggle(v, true);
        if v == c {
            break;
        }
    }
    let prototype = f.on.clone();
    let mut rank = vec![0u32; n];
    // Phase 1: ranks initial-1 .. 0 by removing tightest clusters.
    for r in (0..initial).rev() {
        let c = f.tightest_cluster();
        f.toggle(c, false);
        rank[c] = r as u32;
    }
    // Restore the prototype, then phase 2/3: fill largest voids for the remaining ranks.
    for (p, on) in prototype.iter().enumerate() {
        if *on {
            f.toggle(p, true);
        }
    }
    for r in initial..n {
        let v = f.largest_void();
        f.toggle(v, true);
        rank[v] = r as u32;
    }
    Ok(rank)
}

/// `slices` independent `size x size` arrays (seeds `seed + k`), e.g. 64 x 64 x 64 for one
/// array per frame of a 64-frame cycle, ranks scaled to `u8` (`rank · 256 / size²`).
pub fn blue_noise_slices(size: usize, slices: usize, seed: u64) -> Result<Vec<Vec<u8>>, MathError> {
    (0..slices as u64)
        .map(|k| {
            let r = void_and_cluster(size, size, seed.wrapping_add(k))?;
            let n = (size * size) as u64;
            Ok(r.into_iter().map(|v| (v as u64 * 256 / n) as u8).collect())
        })
        .collect()
}

/// Edge length of the committed blue-noise arrays.
pub const BLUE_NOISE_SIZE: usize = 64;
/// Number of committed slices (one per frame of a 64-frame cycle).
pub const BLUE_NOISE_SLICES: usize = 64;
/// Seed of slice 0 (slice k uses `BLUE_NOISE_SEED + k`).
pub const BLUE_NOISE_SEED: u64 = 0x6869_6B61_7269; // "hikari"

/// The committed 64 x 64 x 64 set made by `examples/make_blue_noise.rs` with
/// [`blue_noise_slices`]`(64, 64, BLUE_NOISE_SEED)`: u8 ranks, slice-major then row-major.
pub static BLUE_NOISE_64X64X64: &[u8; 64 * 64 * 64] =
    include_bytes!("../../data/blue_noise_64x64x64.bin");

/// Slice `k` (wrapped modulo 64) of the committed set, row-major 64 x 64.
pub fn blue_noise_slice(k: usize) -> &'static [u8] {
    let n = BLUE_NOISE_SIZE * BLUE_NOISE_SIZE;
    let k = k % BLUE_NOISE_SLICES;
    &BLUE_NOISE_64X64X64[k * n..(k + 1) * n]
}
