//! The rendering stack's one error type. Every variant names what went wrong and where, so the
//! CLI can print it as is. The engine raises the GPU, shader and graph kinds; the renderer
//! above it fills the settings and scene kinds with its own error values.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum RenderError {
    #[error(
        "no GPU adapter found for backends {backends:?}.\n\
         hikari needs a Vulkan, Metal, DX12 or GL driver. On a machine without a GPU, install the \
         CPU Vulkan driver: `sudo apt-get install mesa-vulkan-drivers` (Debian/Ubuntu), then run \
         with WGPU_BACKEND=vulkan. In a hikari checkout, `./x setup` does this for you."
    )]
    NoAdapter { backends: wgpu::Backends },

    #[error(
        "WGPU_ADAPTER_NAME={wanted:?} matches no adapter; adapters found: {}",
        if seen.is_empty() { "none".to_string() } else { seen.join("; ") }
    )]
    AdapterNotFound { wanted: String, seen: Vec<String> },

    #[error("could not create the GPU device: {0}")]
    Device(String),

    #[error("shader {path}: {message}")]
    Shader { path: String, message: String },

    #[error("pass `{pass}`: {message}")]
    Pass { pass: String, message: String },

    #[error("frame graph: {0}")]
    Graph(String),

    /// A setting outside its range, of the wrong type or unknown.
    #[error("settings: {0}")]
    Settings(Box<dyn std::error::Error + Send + Sync>),

    /// A setting whose value is well formed but unusable: a LUT file that does not read.
    #[error("settings: `{field}`: {message}")]
    Setting { field: String, message: String },

    /// The scene, a camera or a light handed to the renderer is not valid.
    #[error("{what}: {source}")]
    Scene {
        what: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },

    #[error("{what} of {requested} exceeds this GPU's limit of {limit}")]
    Limit {
        what: String,
        requested: u64,
        limit: u64,
    },

    #[error("GPU error during {during}: {message}")]
    Gpu { during: String, message: String },

    /// The GPU ran out of memory: the last change asked for more than it has.
    #[error("the GPU ran out of memory during {during}: {message}")]
    OutOfMemory { during: String, message: String },

    /// The device is gone (a driver reset, a removed GPU, a timeout): nothing more renders
    /// on it.
    #[error(
        "the GPU device was lost during {during} ({reason}); nothing more can render on it: \
         restart hikari (a driver reset or a GPU timeout causes this)"
    )]
    DeviceLost { during: String, reason: String },

    #[error("writing {path}: {message}")]
    Output { path: String, message: String },

    #[error("reading {path}: {message}")]
    Input { path: String, message: String },
}

pub type Result<T, E = RenderError> = std::result::Result<T, E>;
