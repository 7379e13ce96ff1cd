//! Metallic-roughness material parameters and their mapping to microfacet widths and F0.

use glam::{DVec3, Vec3};

/// Smallest perceptual roughness the BRDF accepts; inputs below are raised to it.
///
/// GGX at `alpha → 0` is a delta: the peak `D(n) = 1 / (π α²)` grows without bound, and the
/// isotropic form compares `1 − (n·h)²` with `α² (n·h)²`. In the f32 WGSL twin `n·h` carries a
/// rounding error near 6e-8, so `α²` must stay well above it: at this minimum `α² ≈ 4e-6` and
/// the isotropic peak is off by a few per cent at worst (the anisotropic form, fed
/// tangent-frame components, has no such cancellation). It also keeps a punctual light's
/// highlight from collapsing below a pixel.
pub const MIN_PERCEPTUAL_ROUGHNESS: f64 = 0.045;

/// `MIN_PERCEPTUAL_ROUGHNESS²`: the smallest GGX width along any tangent axis.
pub const MIN_ALPHA: f64 = MIN_PERCEPTUAL_ROUGHNESS * MIN_PERCEPTUAL_ROUGHNESS;

/// Normal-incidence reflectance of a dielectric: `((η − 1) / (η + 1))²` for `η ≈ 1.5`
/// (glass, plastics, most non-metals): the constant of Karis 2013 and of glTF 2.0's
/// metallic-roughness model.
pub const DIELECTRIC_F0: f64 = 0.04;

/// Burley 2012's anisotropy constant: `aspect = sqrt(1 − 0.9 |anisotropy|)`, so the two widths
/// differ by at most `1 / (1 − 0.9) = 10x`.
pub const ANISOTROPY_ASPECT_SCALE: f64 = 0.9;

/// A metallic-roughness material at one shading point (glTF 2.0 / Burley 2012 parameters).
///
/// Every field is clamped to its range when used; nothing here panics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Linear base colour in [0, 1]: diffuse albedo for dielectrics, F0 for metals.
    pub base_color: Vec3,
    /// Perceptual roughness in [[`MIN_PERCEPTUAL_ROUGHNESS`], 1]; `alpha` is its square.
    pub perceptual_roughness: f32,
    /// Metalness in [0, 1]: 0 dielectric (F0 = 0.04, diffuse = base colour), 1 metal
    /// (F0 = base colour, no diffuse); values in between blend linearly.
    pub metalness: f32,
    /// Anisotropy in [-1, 1]: positive stretches the highlight along the tangent `t`,
    /// negative along the bitangent `b`, 0 is isotropic.
    pub anisotropy: f32,
    /// Weight in [0, 1] of the dielectric's specular lobe (glTF's KHR_materials_specular
    /// `specularFactor`): 1 is the usual F0 = 0.04 interface, 0 a matte surface whose dielectric
    /// part is pure Lambert. Metals ignore it.
    pub specular: f32,
}

impl Material {
    /// An isotropic dielectric.
    pub fn dielectric(base_color: Vec3, perceptual_roughness: f32) -> Self {
        Self {
            base_color,
            perceptual_roughness,
            metalness: 0.0,
            anisotropy: 0.0,
            specular: 1.0,
        }
    }

    /// An isotropic metal whose F0 is `base_color`.
    pub fn metal(base_color: Vec3, perceptual_roughness: f32) -> Self {
        Self {
            base_color,
            perceptual_roughness,
            metalness: 1.0,
            anisotropy: 0.0,
            specular: 1.0,
        }
    }

    /// The same material with `anisotropy` set.
    pub fn with_anisotropy(self, anisotropy: f32) -> Self {
        Self { anisotropy, ..self }
    }

    /// The same material with the dielectric specular weight `specular` set.
    pub fn with_specular(self, specular: f32) -> Self {
        Self { specular, ..self }
    }

    fn base(&self) -> DVec3 {
        self.base_color.as_dvec3().clamp(DVec3::ZERO, DVec3::ONE)
    }

    fn metal_fraction(&self) -> f64 {
        (self.metalness as f64).clamp(0.0, 1.0)
    }

    /// The dielectric specular weight clamped to [0, 1] (NaN: 1, the glTF default).
    pub fn specular_weight(&self) -> f64 {
        let s = self.specular as f64;
        if s.is_nan() { 1.0 } else { s.clamp(0.0, 1.0) }
    }

    /// Normal-incidence Fresnel reflectance per channel: `lerp(0.04 s, base_color, metalness)`
    /// with `s` the [`Material::specular_weight`].
    pub fn f0(&self) -> DVec3 {
        let m = self.metal_fraction();
        DVec3::splat(DIELECTRIC_F0 * self.specular_weight() * (1.0 - m)) + self.base() * m
    }

    /// Grazing-incidence Fresnel reflectance: `lerp(s, 1, metalness)`. The specular lobe's
    /// Fresnel is `F0 + (F90 − F0)(1 − cos θ)⁵`, which is `s` times the dielectric's Schlick
    /// Fresnel blended with the metal's.
    pub fn f90(&self) -> f64 {
        let m = self.metal_fraction();
        self.specular_weight() * (1.0 - m) + m
    }

    /// Albedo of the diffuse lobe before its Fresnel weights: `base_color · (1 − metalness)`.
    pub fn diffuse_albedo(&self) -> DVec3 {
        self.base() * (1.0 - self.metal_fraction())
    }

    /// Isotropic GGX width `alpha` (anisotropy ignored).
    pub fn alpha(&self) -> f64 {
        alpha_from_perceptual(self.perceptual_roughness as f64)
    }

    /// GGX widths `(alpha_x, alpha_y)` along `t` and `b`, see [`anisotropic_alphas`].
    pub fn alphas(&self) -> (f64, f64) {
        anisotropic_alphas(self.perceptual_roughness as f64, self.anisotropy as f64)
    }
}

/// `lerp(DIELECTRIC_F0, base_color, metalness)` per channel (Karis 2013).
pub fn f0_from_metalness(base_color: DVec3, metalness: f64) -> DVec3 {
    DVec3::splat(DIELECTRIC_F0).lerp(base_color, metalness)
}

/// `((η − 1) / (η + 1))²`: normal-incidence reflectance of an interface between air and a
/// dielectric of refractive index `η` (Fresnel equations at θ = 0).
pub fn f0_from_ior(ior: f64) -> f64 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

/// GGX width `alpha = r²` for perceptual roughness `r` clamped to
/// [[`MIN_PERCEPTUAL_ROUGHNESS`], 1] (Burley 2012, Karis 2013): squaring makes the slider
/// perceptually linear.
pub fn alpha_from_perceptual(perceptual_roughness: f64) -> f64 {
    let r = perceptual_roughness.clamp(MIN_PERCEPTUAL_ROUGHNESS, 1.0);
    r * r
}

/// GGX widths `(alpha_x, alpha_y)` along the tangent and bitangent.
///
/// Burley 2012 (section 5.4, "anisotropic" in [0, 1]) maps
/// `aspect = sqrt(1 − 0.9 · anisotropic)`, `alpha_x = r² / aspect`, `alpha_y = r² · aspect`.
/// We extend it to [-1, 1] by symmetry: the magnitude gives the aspect and the sign says
/// which axis is the long one, so `anisotropy → −anisotropy` swaps the two widths, which is
/// the same as turning the tangent frame by 90°. The product `alpha_x · alpha_y = r⁴` is kept,
/// so the peak `D(n) = 1 / (π alpha_x alpha_y)` does not change with anisotropy. Each width is
/// then raised to [`MIN_ALPHA`]; widths above 1 (at most `sqrt(10)`) are valid GGX and kept.
pub fn anisotropic_alphas(perceptual_roughness: f64, anisotropy: f64) -> (f64, f64) {
    let alpha = alpha_from_perceptual(perceptual_roughness);
    let a = anisotropy.clamp(-1.0, 1.0);
    let aspect = (1.0 - ANISOTROPY_ASPECT_SCALE * a.abs()).sqrt();
    let (long, short) = (alpha / aspect, alpha * aspect);
    let (ax, ay) = if a >= 0.0 {
        (long, short)
    } else {
        (short, long)
    };
    (ax.max(MIN_ALPHA), ay.max(MIN_ALPHA))
}
