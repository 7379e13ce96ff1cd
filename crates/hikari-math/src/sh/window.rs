//! Windowing (per-band attenuation) to reduce ringing.
//!
//! All windows return factors for bands 0, 1, 2, to be applied with [`super::Sh::scale_bands`].

/// Hanning window of width `w` (bands ≥ `w` vanish): `(1 + cos(π l / w)) / 2`
/// (Sloan, "Stupid Spherical Harmonics Tricks", 2008). `w` must be > 0; non-positive or
/// non-finite `w` returns the identity window.
pub fn hanning(w: f32) -> [f32; 3] {
    band_factors(|l| {
        if !valid_width(w) {
            1.0
        } else if l >= w {
            0.0
        } else {
            0.5 * (1.0 + (std::f32::consts::PI * l / w).cos())
        }
    })
}

/// Lanczos (sinc) window of width `w`: `sin(π l / w) / (π l / w)`, zero for bands ≥ `w`
/// (Sloan 2008). Non-positive or non-finite `w` returns the identity window.
pub fn lanczos(w: f32) -> [f32; 3] {
    band_factors(|l| {
        if !valid_width(w) || l == 0.0 {
            1.0
        } else if l >= w {
            0.0
        } else {
            let x = std::f32::consts::PI * l / w;
            x.sin() / x
        }
    })
}

/// The window of Sloan 2017, "Deringing Spherical Harmonics": minimising
/// `‖f − g‖² + λ ‖Δg‖²` over band-limited `g` gives `1 / (1 + λ l² (l + 1)²)`, since the
/// spherical Laplacian has eigenvalue `−l(l + 1)` on band `l`. `λ ≥ 0`; negative or NaN `λ`
/// is treated as 0 and `λ = ∞` keeps only band 0.
pub fn sloan2017(lambda: f32) -> [f32; 3] {
    let lambda = if lambda > 0.0 { lambda } else { 0.0 };
    band_factors(|l| {
        let e = l * l * (l + 1.0) * (l + 1.0);
        if e == 0.0 {
            1.0
        } else {
            1.0 / (1.0 + lambda * e)
        }
    })
}

fn valid_width(w: f32) -> bool {
    w.is_finite() && w > 0.0
}

fn band_factors(f: impl Fn(f32) -> f32) -> [f32; 3] {
    [f(0.0), f(1.0), f(2.0)]
}
