//! One folder per technique: its passes (`mod.rs`), its WGSL, its CPU twin (`reference.rs`)
//! and its settings (`settings.rs`), under one name. The technique `sun_shadows` labels its
//! passes `sun_shadows.*`, names its dumps `sun_shadows.*`, and is tested in
//! `tests/render/sun_shadows.rs`.

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
