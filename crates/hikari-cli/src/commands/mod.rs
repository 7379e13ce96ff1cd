//! One module per command. A command module may use the shared modules (`args`,
//! `scene_source`, `report`, `config`, `still`) but never another command module: what two commands
//! share moves into a shared module (`tests/command_modules.rs` checks this).

pub mod bake;
pub mod bc6h;
pub mod bench_frame;
pub mod bench_overhead;
pub mod bench_probes;
pub mod bench_rays;
pub mod bench_soak;
pub mod compare;
pub mod constants;
pub mod info;
pub mod lut;
pub mod probes;
pub mod render;
pub mod sky;
pub mod timelapse;
pub mod view;
