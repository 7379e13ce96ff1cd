//! One module per technique; each owns its pipelines and adds its passes to a frame.

pub mod bvh_trace;
pub mod direct_lighting;
pub mod gbuffer;
pub mod graph_check;
pub mod math_check;
pub mod placeholder_tonemap;
pub mod raster;
pub mod sun_shadows;
