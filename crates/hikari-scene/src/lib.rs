//! hikari-scene: the scene model (meshes, materials, instances, cameras, the sun) and the
//! built-in scenes. Lights are in physical units: the sun in lux, emission in nits.
//!
//! This is the first cut that the engine skeleton needs; glTF loading and the procedural
//! village come with the scenes issue.

pub mod builtin;
pub mod model;
pub mod shapes;

pub use model::{Camera, Instance, Material, Mesh, Scene, SceneError, Sun};
