//! What can go wrong in a bake: bad options, or a scene the BVH cannot be built from.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum BakeError {
    #[error("bake option `{option}` is {value}: {why}")]
    BadOption {
        option: &'static str,
        value: String,
        why: &'static str,
    },
    #[error("the scene cannot be baked: {0}")]
    Scene(String),
    #[error("building the scene's BVH failed: {0}")]
    Bvh(#[from] hikari_bvh::BvhError),
    #[error("probe volume `{name}`: {why}")]
    BadVolume { name: String, why: &'static str },
    #[error("reflection probe `{name}`: {why}")]
    BadReflectionProbe { name: String, why: &'static str },
    #[error("{}: {what}", path.display())]
    Gltf {
        path: std::path::PathBuf,
        what: String,
    },
    #[error("tetrahedralising probe volume `{volume}`: {source}")]
    Tetrahedralize {
        volume: String,
        source: crate::delaunay::DelaunayError,
    },
    /// The transport tracer (the GPU's) failed; the message says what and where.
    #[error("the {tracer} tracer failed: {message}")]
    Tracer { tracer: String, message: String },
    #[error("the bake was cancelled")]
    Cancelled,
    /// Reading or writing the bake file or its checkpoint (the message names the file).
    #[error("{0}")]
    File(String),
}
