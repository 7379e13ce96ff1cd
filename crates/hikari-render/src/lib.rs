//! hikari-render: the renderer on the engine crate `hikari-gpu` (GPU context, frame graph,
//! pipelines, shader system, re-exported here so a user needs one crate). The scene's GPU side
//! (`scene/`: upload, textures, BVH and its trace, the compute rasteriser), one folder per
//! technique under `techniques/` (passes, WGSL, CPU twin, settings), and `frame.rs`, where one
//! frame reads top to bottom.

pub mod bc6h;
pub mod brdf_tables;
pub mod checks;
pub mod error;
pub mod frame;
pub mod frame_context;
pub mod layout;
pub mod lights;
pub mod output;
pub mod probe_bake_gpu;
pub mod reference;
pub mod renderer;
pub mod scene;
pub mod settings;
pub mod shader;
pub mod steady_light;
pub mod techniques;
pub mod view;

pub use error::{RenderError, Result};
pub use frame_context::{FrameContext, FrameSettings, HistoryReset, SunSource};
pub use hikari_gpu::{ContextOptions, GpuContext, context, faults, graph, pipeline};
pub use renderer::{Display, DisplayedFrame, RenderedFrame, Renderer};
pub use settings::{Preset, Settings};
pub use wgpu;
