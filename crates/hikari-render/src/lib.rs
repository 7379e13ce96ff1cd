//! hikari-render: the wgpu side of hikari. The GPU context, the frame graph, the shader system,
//! the compute rasteriser (`raster/`), one folder per technique under `techniques/` (passes,
//! WGSL, CPU twin, settings), and `frame.rs`, where one frame reads top to bottom.

pub mod brdf_tables;
pub mod bvh_trace;
pub mod checks;
pub mod context;
pub mod error;
pub mod frame;
pub mod frame_context;
pub mod graph;
pub mod layout;
pub mod output;
pub mod pipeline;
pub mod probe_bake_gpu;
pub mod raster;
pub mod reference;
pub mod renderer;
pub mod scene_bvh;
pub mod scene_gpu;
pub mod scene_rt;
pub mod scene_textures;
pub mod settings;
pub mod shader;
pub mod techniques;
pub mod view;

pub use context::{ContextOptions, GpuContext};
pub use error::{RenderError, Result};
pub use frame_context::{FrameContext, FrameSettings, HistoryReset, SunSource};
pub use renderer::{Display, DisplayedFrame, RenderedFrame, Renderer};
pub use settings::{Preset, Settings};
pub use wgpu;
