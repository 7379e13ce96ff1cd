//! hikari-gpu: the engine under hikari's renderer, which knows no technique. The GPU context
//! (`context`), the frame graph with its resources, history and timings (`graph`), compute and
//! raster pipelines (`pipeline`), the device's after-the-fact errors and loss (`faults`), WGSL composition and validation (`shader`), the checks that
//! hold Rust mirrors of WGSL structs and constants to naga's reflection (`layout`), and the one
//! error type (`error`).

pub mod context;
pub mod error;
pub mod faults;
pub mod graph;
pub mod layout;
pub mod pipeline;
pub mod shader;

pub use context::{ContextOptions, GpuContext};
pub use error::{RenderError, Result};
pub use wgpu;
