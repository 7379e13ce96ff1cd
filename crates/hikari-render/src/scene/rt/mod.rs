//! One scene BVH for every ray traced in a frame (ray-traced GI and AO, area-light and
//! punctual shadows): BLAS per mesh, refitted for deforming meshes under a throttling budget,
//! and the TLAS rebuilt every frame over the instances kept around the camera
//! (docs/ray-traced-gi.md, "The BVH follows the frame").

pub mod frame_bvh;
pub mod gpu;
pub mod settings;

pub use frame_bvh::{FrameBvh, FrameBvhStats, FrameTlases, kept_instances};
pub use gpu::{SceneRt, SceneRtBuffers};
pub use settings::SceneRtSettings;
