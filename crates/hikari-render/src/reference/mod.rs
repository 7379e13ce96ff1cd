//! CPU twins of what several techniques share: the shared WGSL modules under
//! `shaders/common/` (octahedral mapping, phase function, reprojection), the G-buffer texel and
//! radiance clamp of the lighting passes, and the scene's textures as the twins sample them. A
//! technique's own twin is `techniques/<name>/reference.rs`; the lights' is `lights/reference.rs`.

pub mod lighting;
pub mod octahedral;
pub mod phase;
pub mod reprojection;
pub mod textures;
