//! CPU twins of the GPU passes, named as the passes are. Tests hold each pass to its twin.

pub mod direct_lighting;
pub mod gbuffer;
pub mod octahedral;
pub mod placeholder_tonemap;
pub mod sun_shadows;
