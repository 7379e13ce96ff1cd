//! The cut-off policy of point and spot lights, one for every pass that lights with them: the
//! frame context computes the frame's cut-off once ([`crate::FrameContext::light_cutoff_lux`]).

/// A punctual light is cut off where its illuminance falls below this fraction of the frame's
/// metered illuminance (or [`LIGHT_CUTOFF_LUX`], whichever is larger): in daylight a lantern's
/// light a few metres away is far below what the exposure can show.
pub const LIGHT_CUTOFF_FRACTION: f32 = 1e-4;

/// The least cut-off illuminance: a hundredth of a lux is far below moonlight, so the cut is
/// invisible at any exposure that shows the scene.
pub const LIGHT_CUTOFF_LUX: f32 = 0.01;

/// Lux below which a point or spot light is cut off in a frame metered at `metered_lux`.
pub fn light_cutoff_lux(metered_lux: f32) -> f32 {
    (metered_lux * LIGHT_CUTOFF_FRACTION).max(LIGHT_CUTOFF_LUX)
}
