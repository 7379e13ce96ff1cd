//! Low-discrepancy sequences: van der Corput / Hammersley and Sobol.

use super::sobol_data::{DIMS, POLY, VINIT};
use crate::MathError;
use glam::Vec2;

/// Base-2 radical inverse of `i` (van der Corput), in [0, 1).
pub fn radical_inverse_base2(i: u32) -> f32 {
    (i.reverse_bits() as f64 / 4_294_967_296.0) as f32
}

/// Point `i` of the `n`-point Hammersley set: `((i + 0.5) / n, φ₂(i))`. The half-sample
/// offset centres the first coordinate in its stratum.
pub fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(
        ((i as f64 + 0.5) / n.max(1) as f64) as f32,
        radical_inverse_base2(i),
    )
}

/// Sobol sequence (Joe & Kuo 2008 direction numbers, first [`DIMS`] dimensions), 32-bit.
#[derive(Clone, Debug)]
pub struct Sobol {
    /// `v[d][j]`: direction number j of dimension d, scaled to 32 bits.
    v: Vec<[u32; 32]>,
}

impl Sobol {
    /// Sobol generator for `dims` dimensions (1 ..= 64).
    pub fn new(dims: usize) -> Result<Self, MathError> {
        if dims == 0 || dims > DIMS {
            return Err(MathError::OutOfRange {
                name: "Sobol dimensions",
                value: dims as f64,
                allowed: "1 ..= 64",
            });
        }
        let mut v = vec![[0u32; 32]; dims];
        for (d, vd) in v.iter_mut().enumerate() {
            if d == 0 {
                for (j, x) in vd.iter_mut().enumerate() {
                    *x = 1 << (31 - j);
                }
                continue;
            }
            let p = POLY[d];
            let s = 31 - p.leading_zeros() as usize; // degree
            let mut m = [0u32; 32];
            m[..s].copy_from_slice(&VINIT[d][..s]);
            // m_j = 2 a_1 m_(j-1) ^ 4 a_2 m_(j-2) ^ ... ^ 2^s m_(j-s) ^ m_(j-s)
            for j in s..32 {
                let mut x = m[j - s] ^ (m[j - s] << s);
                for k in 1..s {
                    if (p >> (s - k)) & 1 == 1 {
                        x ^= m[j - k] << k;
                    }
                }
                m[j] = x;
            }
            for j in 0..32 {
                vd[j] = m[j] << (31 - j);
            }
        }
        Ok(Self { v })
    }

    /// Number of dimensions.
    pub fn dims(&self) -> usize {
        self.v.len()
    }

    /// Coordinate `dim` of point `index`, in Gray-code order (the order of Joe & Kuo's and
    /// scipy's generators: point `index` uses the bits of `index ^ (index >> 1)`).
    pub fn sample_u32(&self, index: u32, dim: usize) -> u32 {
        let g = index ^ (index >> 1);
        let mut x = 0u32;
        let vd = &self.v[dim.min(self.v.len() - 1)];
        let mut bits = g;
        let mut j = 0;
        while bits != 0 {
            if bits & 1 == 1 {
                x ^= vd[j];
            }
            bits >>= 1;
            j += 1;
        }
        x
    }

    /// As [`Sobol::sample_u32`], in [0, 1).
    pub fn sample(&self, index: u32, dim: usize) -> f64 {
        self.sample_u32(index, dim) as f64 / 4_294_967_296.0
    }
}

/// The `i`-th point of the Halton sequence in `base` (the radical inverse of `i`), in [0, 1).
pub fn halton(mut i: u32, base: u32) -> f32 {
    let inv = 1.0 / base as f64;
    let (mut f, mut r) = (1.0f64, 0.0f64);
    while i > 0 {
        f *= inv;
        r += f * (i % base) as f64;
        i /= base;
    }
    r as f32
}

#[cfg(test)]
mod halton_tests {
    use super::halton;

    #[test]
    fn halton_is_the_radical_inverse() {
        // By definition: the digits of i in the base, mirrored about the radix point.
        assert_eq!(halton(0, 2), 0.0);
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(6, 2), 0.375); // 110 -> 0.011
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(5, 3) - 7.0 / 9.0).abs() < 1e-7); // 12 -> 0.21
    }
}
