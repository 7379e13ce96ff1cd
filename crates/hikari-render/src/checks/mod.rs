//! Kernels that exist to test and measure the engine itself, not to light a frame: the frame
//! graph's checks and overhead benchmark, and the WGSL math twins.

pub mod graph_check;
pub mod math_check;
