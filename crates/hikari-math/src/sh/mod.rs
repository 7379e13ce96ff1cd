//! Real spherical harmonics up to band 2 (L1: 4 coefficients, L2: 9).
//!
//! # Convention (one convention everywhere, the WGSL twin `hikari::sh` matches it)
//!
//! Orthonormal real SH over the unit sphere, `∫ Y_i Y_j dω = δ_ij`, flat index `i = l(l+1) + m`,
//! **no Condon-Shortley phase** (every band-1 basis function is a positive multiple of a
//! coordinate), for a unit direction `(x, y, z)`:
//!
//! | i | (l, m) | Y_i                           |
//! |---|--------|-------------------------------|
//! | 0 | (0, 0) | `1 / (2√π)`                   |
//! | 1 | (1,-1) | `√3 / (2√π) · y`              |
//! | 2 | (1, 0) | `√3 / (2√π) · z`              |
//! | 3 | (1, 1) | `√3 / (2√π) · x`              |
//! | 4 | (2,-2) | `√15 / (2√π) · x y`           |
//! | 5 | (2,-1) | `√15 / (2√π) · y z`           |
//! | 6 | (2, 0) | `√5 / (4√π) · (3 z² − 1)`     |
//! | 7 | (2, 1) | `√15 / (2√π) · x z`           |
//! | 8 | (2, 2) | `√15 / (4√π) · (x² − y²)`     |
//!
//! This is the convention of the Metro Exodus encoding (`L1_1 = 0.488603 · dir.y`, ...). The
//! axes are whatever the caller's world axes are; the basis does not assume an "up".
//! Coefficients of a function `f` are `c_i = ∫ f Y_i dω` (radiance in, radiance coefficients out).

pub mod basis;
pub mod dering;
pub mod product;
pub mod project;
pub mod rotate;
pub mod window;
pub mod ycocg;
pub mod zonal;

use core::fmt::Debug;
use core::ops::{Add, Mul, Sub};
use glam::Vec3;

/// What an SH coefficient can be: a scalar (`f32`) or an RGB triple (`Vec3`).
pub trait ShCoeff:
    Copy
    + Default
    + Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<f32, Output = Self>
    + Mul<Self, Output = Self>
{
    /// Number of scalar channels.
    const CHANNELS: usize;
    /// Channel `k` as a scalar.
    fn channel(self, k: usize) -> f32;
    /// The same scalar in every channel.
    fn splat(v: f32) -> Self;
    /// Builds a coefficient from its first `CHANNELS` channels.
    fn from_channels(v: [f64; 3]) -> Self;
}

impl ShCoeff for f32 {
    const CHANNELS: usize = 1;
    fn channel(self, _k: usize) -> f32 {
        self
    }
    fn splat(v: f32) -> Self {
        v
    }
    fn from_channels(v: [f64; 3]) -> Self {
        v[0] as f32
    }
}

impl ShCoeff for Vec3 {
    const CHANNELS: usize = 3;
    fn channel(self, k: usize) -> f32 {
        self[k]
    }
    fn splat(v: f32) -> Self {
        Vec3::splat(v)
    }
    fn from_channels(v: [f64; 3]) -> Self {
        glam::DVec3::from_array(v).as_vec3()
    }
}

/// SH coefficients of order `N` (1, 4 or 9 coefficients) with coefficient type `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sh<T, const N: usize> {
    /// Coefficients in the order documented in [the module docs](self).
    pub coeffs: [T; N],
}

/// Band-0..1 scalar SH (4 coefficients).
pub type ShL1 = Sh<f32, 4>;
/// Band-0..2 scalar SH (9 coefficients).
pub type ShL2 = Sh<f32, 9>;
/// Band-0..1 RGB SH.
pub type ShL1Rgb = Sh<Vec3, 4>;
/// Band-0..2 RGB SH.
pub type ShL2Rgb = Sh<Vec3, 9>;

impl<T: ShCoeff, const N: usize> Default for Sh<T, N> {
    fn default() -> Self {
        Self::zero()
    }
}

impl<T: ShCoeff, const N: usize> Sh<T, N> {
    const VALID: () = assert!(
        N == 1 || N == 4 || N == 9,
        "SH order must have 1, 4 or 9 coefficients"
    );

    /// Wraps coefficients.
    pub const fn new(coeffs: [T; N]) -> Self {
        Self { coeffs }
    }

    /// All coefficients zero.
    pub fn zero() -> Self {
        #[allow(clippy::let_unit_value)]
        let _ = Self::VALID;
        Self {
            coeffs: [T::default(); N],
        }
    }

    /// Highest band held (0, 1 or 2).
    pub const fn max_band() -> usize {
        match N {
            1 => 0,
            4 => 1,
            _ => 2,
        }
    }

    /// Value of the represented function in unit direction `dir`.
    pub fn eval(&self, dir: Vec3) -> T {
        let y = basis::eval_l2(dir);
        let mut acc = T::default();
        for i in 0..N {
            acc = acc + self.coeffs[i] * y[i];
        }
        acc
    }

    /// `self * s`.
    pub fn scale(&self, s: f32) -> Self {
        Self {
            coeffs: self.coeffs.map(|c| c * s),
        }
    }

    /// Linear interpolation `self + (other - self) * t`.
    pub fn lerp(&self, other: &Self, t: f32) -> Self {
        let mut out = *self;
        for i in 0..N {
            out.coeffs[i] = self.coeffs[i] + (other.coeffs[i] - self.coeffs[i]) * t;
        }
        out
    }

    /// Multiplies each band `l` by `factors[l]` (windowing, zonal convolution).
    pub fn scale_bands(&self, factors: [f32; 3]) -> Self {
        let mut out = *self;
        for (i, c) in out.coeffs.iter_mut().enumerate() {
            *c = *c * factors[basis::band_of(i)];
        }
        out
    }

    /// Adds `weight * Y(dir)`: accumulating one sample (Monte Carlo projection without the
    /// normalisation, which the caller applies).
    pub fn add_sample(&mut self, dir: Vec3, weight: T) {
        let y = basis::eval_l2(dir);
        for i in 0..N {
            self.coeffs[i] = self.coeffs[i] + weight * y[i];
        }
    }

    /// Projection of a delta (Dirac) function of integral `weight` in unit direction `dir`:
    /// `c_i = weight · Y_i(dir)`.
    pub fn delta(dir: Vec3, weight: T) -> Self {
        let mut s = Self::zero();
        s.add_sample(dir, weight);
        s
    }

    /// The band-1 vector `(c_3, c_1, c_2)` rearranged as `(x, y, z)` per channel; zero for L0.
    pub fn linear_vector(&self) -> [T; 3] {
        if N < 4 {
            return [T::default(); 3];
        }
        [self.coeffs[3], self.coeffs[1], self.coeffs[2]]
    }

    /// One scalar channel of a multi-channel SH.
    pub fn channel(&self, k: usize) -> Sh<f32, N> {
        Sh {
            coeffs: self.coeffs.map(|c| c.channel(k)),
        }
    }
}

impl<T: ShCoeff, const N: usize> Add for Sh<T, N> {
    type Output = Self;
    fn add(mut self, rhs: Self) -> Self {
        for i in 0..N {
            self.coeffs[i] = self.coeffs[i] + rhs.coeffs[i];
        }
        self
    }
}

impl<T: ShCoeff, const N: usize> Sub for Sh<T, N> {
    type Output = Self;
    fn sub(mut self, rhs: Self) -> Self {
        for i in 0..N {
            self.coeffs[i] = self.coeffs[i] - rhs.coeffs[i];
        }
        self
    }
}

impl<T: ShCoeff, const N: usize> Mul<f32> for Sh<T, N> {
    type Output = Self;
    fn mul(self, s: f32) -> Self {
        self.scale(s)
    }
}

impl<T: ShCoeff> Sh<T, 4> {
    /// Extends to L2 with zero band-2 coefficients.
    pub fn to_l2(&self) -> Sh<T, 9> {
        let mut c = [T::default(); 9];
        c[..4].copy_from_slice(&self.coeffs);
        Sh { coeffs: c }
    }
}

impl<T: ShCoeff> Sh<T, 9> {
    /// Drops band 2 (the L2 function's best L1 approximation, since the basis is orthonormal).
    pub fn to_l1(&self) -> Sh<T, 4> {
        Sh {
            coeffs: [
                self.coeffs[0],
                self.coeffs[1],
                self.coeffs[2],
                self.coeffs[3],
            ],
        }
    }
}

impl<const N: usize> Sh<Vec3, N> {
    /// Builds an RGB SH from three scalar ones.
    pub fn from_channels(r: &Sh<f32, N>, g: &Sh<f32, N>, b: &Sh<f32, N>) -> Self {
        let mut c = [Vec3::ZERO; N];
        for i in 0..N {
            c[i] = Vec3::new(r.coeffs[i], g.coeffs[i], b.coeffs[i]);
        }
        Sh { coeffs: c }
    }

    /// Weighted sum of the channels, e.g. luminance with Rec.709 weights.
    pub fn dot_channels(&self, w: Vec3) -> Sh<f32, N> {
        Sh {
            coeffs: self.coeffs.map(|c| c.dot(w)),
        }
    }
}
