//! Smith masking-shadowing for GGX (Smith 1967; Walter et al. 2007; Heitz 2014,
//! "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2)).
//!
//! We use the height-correlated form `G2 = 1 / (1 + Λ(v) + Λ(l))` rather than the separable
//! `G1(v) G1(l)`: Heitz 2014 shows the separable form double-counts occlusion that high
//! microfacets escape in both directions, so it darkens rough surfaces. Directions are unit
//! vectors in the tangent frame `(t·w, b·w, n·w)` or given by their cosine `n·w`.

use glam::DVec3;

/// Smith `Λ(w) = (−1 + sqrt(1 + α² tan²θ)) / 2` for isotropic GGX, from the cosine
/// `n_dot_w = cos θ`; dimensionless, +∞ at grazing (`n_dot_w ≤ 0`).
pub fn smith_lambda(n_dot_w: f64, alpha: f64) -> f64 {
    if n_dot_w <= 0.0 {
        return f64::INFINITY;
    }
    let c2 = n_dot_w * n_dot_w;
    let tan2 = (1.0 - n_dot_w) * (1.0 + n_dot_w) / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Anisotropic `Λ(w)`: as [`smith_lambda`] with the projected width
/// `α(φ)² = α_x² cos²φ + α_y² sin²φ` (Heitz 2014), i.e.
/// `α² tan²θ = ((α_x w_x)² + (α_y w_y)²) / w_z²`.
pub fn smith_lambda_aniso(w_local: DVec3, alpha_x: f64, alpha_y: f64) -> f64 {
    if w_local.z <= 0.0 {
        return f64::INFINITY;
    }
    let a2tan2 =
        ((alpha_x * w_local.x).powi(2) + (alpha_y * w_local.y).powi(2)) / (w_local.z * w_local.z);
    0.5 * ((1.0 + a2tan2).sqrt() - 1.0)
}

/// Smith masking `G1(w) = 1 / (1 + Λ(w))`, in [0, 1], for a microfacet that faces `w`
/// (the `χ⁺(w·h)` factor is the caller's).
pub fn smith_g1(n_dot_w: f64, alpha: f64) -> f64 {
    1.0 / (1.0 + smith_lambda(n_dot_w, alpha))
}

/// Anisotropic [`smith_g1`].
pub fn smith_g1_aniso(w_local: DVec3, alpha_x: f64, alpha_y: f64) -> f64 {
    1.0 / (1.0 + smith_lambda_aniso(w_local, alpha_x, alpha_y))
}

/// Height-correlated masking-shadowing `G2(v, l) = 1 / (1 + Λ(v) + Λ(l))` (Heitz 2014), in
/// [0, 1]; 0 if either direction is at or below the horizon.
pub fn smith_g2_height_correlated(n_dot_v: f64, n_dot_l: f64, alpha: f64) -> f64 {
    1.0 / (1.0 + smith_lambda(n_dot_v, alpha) + smith_lambda(n_dot_l, alpha))
}

/// Anisotropic [`smith_g2_height_correlated`].
pub fn smith_g2_height_correlated_aniso(
    v_local: DVec3,
    l_local: DVec3,
    alpha_x: f64,
    alpha_y: f64,
) -> f64 {
    1.0 / (1.0
        + smith_lambda_aniso(v_local, alpha_x, alpha_y)
        + smith_lambda_aniso(l_local, alpha_x, alpha_y))
}

/// Visibility `V = G2 / (4 (n·l)(n·v))` with the height-correlated `G2`, dimensionless (the specular
/// BRDF is `D · V · F`).
///
/// Multiplying `1 + Λ(v) + Λ(l)` out by `4 (n·v)(n·l)` gives
/// `V = 1 / (2 ((n·l) sqrt((n·v)² + α² (1 − (n·v)²)) + (n·v) sqrt((n·l)² + α² (1 − (n·l)²))))`,
/// which stays finite at grazing angles where `G2 → 0` and `1 / (n·v) → ∞` (limit `1 / (2 α n·l)`
/// as `n·v → 0`). 0 if either cosine is ≤ 0.
pub fn visibility(n_dot_v: f64, n_dot_l: f64, alpha: f64) -> f64 {
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let lv = n_dot_l * (n_dot_v * n_dot_v + a2 * (1.0 - n_dot_v) * (1.0 + n_dot_v)).sqrt();
    let vl = n_dot_v * (n_dot_l * n_dot_l + a2 * (1.0 - n_dot_l) * (1.0 + n_dot_l)).sqrt();
    0.5 / (lv + vl)
}

/// Anisotropic [`visibility`]: `(n·w)² + α² tan²θ (n·w)²` becomes
/// `|(α_x w_x, α_y w_y, w_z)|²`.
pub fn visibility_aniso(v_local: DVec3, l_local: DVec3, alpha_x: f64, alpha_y: f64) -> f64 {
    if v_local.z <= 0.0 || l_local.z <= 0.0 {
        return 0.0;
    }
    let stretch = DVec3::new(alpha_x, alpha_y, 1.0);
    let lv = l_local.z * (v_local * stretch).length();
    let vl = v_local.z * (l_local * stretch).length();
    0.5 / (lv + vl)
}
