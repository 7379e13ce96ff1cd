//! One folder per technique: its passes (`mod.rs`), its WGSL, its CPU twin (`reference.rs`)
//! and its settings (`settings.rs`), under one name. The technique `sun_shadows` labels its
//! passes `sun_shadows.*`, names its dumps `sun_shadows.*`, and is tested in
//! `tests/render/sun_shadows.rs`.

/// The techniques in the order `frame.rs` records them. A technique may use what one before
/// it publishes, never one after it (`tests/render/layering.rs`); the debug view runs on the
/// frame's output.
pub const FRAME_ORDER: [&str; 17] = [
    "gbuffer",
    "clouds",
    "sky",
    "irradiance_probes",
    "reflection_probes",
    "sun_shadows",
    "ray_traced_gi",
    "gi_denoiser",
    "area_lights",
    "direct_lighting",
    "haze",
    "particles",
    "taa",
    "exposure",
    "local_tonemap",
    "tonemap",
    "debug_view",
];

pub mod area_lights;
pub mod clouds;
pub mod debug_view;
pub mod direct_lighting;
pub mod exposure;
pub mod gbuffer;
pub mod gi_denoiser;
pub mod haze;
pub mod irradiance_probes;
pub mod local_tonemap;
pub mod particles;
pub mod ray_traced_gi;
pub mod reflection_probes;
pub mod sky;
pub mod sun_shadows;
pub mod taa;
pub mod tonemap;
