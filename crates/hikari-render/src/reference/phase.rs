//! CPU twin of `hikari::phase` (`shaders/common/phase.wgsl`), which the haze, the clouds and
//! the particles share.

/// Henyey-Greenstein phase function, per steradian (`hikari::phase::hg_phase`); `cos_theta`
/// between the light's direction of travel and the scattered direction (1: straight on).
pub fn hg_phase(cos_theta: f32, g: f32) -> f32 {
    hikari_atmosphere::phase::henyey_greenstein(f64::from(cos_theta), f64::from(g)) as f32
}
