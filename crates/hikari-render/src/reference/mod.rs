//! CPU twins of the shared WGSL modules under `shaders/common/`. A technique's own twin is
//! `techniques/<name>/reference.rs`.

pub mod octahedral;
