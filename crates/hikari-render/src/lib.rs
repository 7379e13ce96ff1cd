//! hikari-render: the wgpu side of hikari. The GPU context, the frame graph, the shader system,
//! one module per technique under `passes/` with its CPU twin under `reference/`, and
//! `frame.rs`, where one frame reads top to bottom.

pub mod context;
pub mod error;
pub mod frame;
pub mod graph;
pub mod layout;
pub mod output;
pub mod passes;
pub mod pipeline;
pub mod reference;
pub mod renderer;
pub mod scene_bvh;
pub mod scene_gpu;
pub mod scene_textures;
pub mod settings;
pub mod shader;
pub mod view;

pub use context::{ContextOptions, GpuContext};
pub use error::{RenderError, Result};
pub use frame::FrameSettings;
pub use renderer::{RenderedFrame, Renderer};
pub use settings::Settings;
pub use wgpu;
