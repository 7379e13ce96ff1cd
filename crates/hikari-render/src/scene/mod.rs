//! The scene's GPU side, below every technique: the upload of meshes, materials and lights
//! (`upload`), their textures (`textures`), the scene BVH (`bvh`) and its per-frame top level
//! with the trace that walks it (`rt`, `bvh_trace`), and the compute rasteriser (`raster`).

pub mod bvh;
pub mod bvh_trace;
pub mod raster;
pub mod rt;
pub mod textures;
pub mod upload;
