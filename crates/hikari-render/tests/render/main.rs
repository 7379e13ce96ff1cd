//! hikari-render's tests in one binary (one link of wgpu and naga instead of one a file):
//! a module a technique or engine part, named as the technique (`sky` tests
//! `techniques/sky`), plus the whole frame (`frame`, `live`, `snapshots`). Shared helpers are
//! in `common`. Run one module with `cargo test -p hikari-render --test render sky::`.

mod alpha;
mod area_lights;
mod atmosphere_gpu;
mod bc6h;
mod bvh_alpha;
mod bvh_trace;
mod clouds;
mod common;
mod debug_view;
mod direct_lighting;
mod exposure;
mod faults;
mod frame;
mod gbuffer;
mod gi_denoiser;
mod gi_robustness;
mod gi_validation;
mod graph;
mod haze;
mod instance_albedo;
mod irradiance_probes;
mod irradiance_probes_leak;
mod layering;
mod live;
mod local_tonemap;
mod math_twins;
mod particles;
mod probe_bake_gpu;
mod raster;
mod ray_traced_gi;
mod reflection_probes;
mod scene_rt;
mod settings;
mod shaders;
mod sky;
mod snapshots;
mod struct_layout;
mod sun_shadows;
mod taa;
mod tonemap;
