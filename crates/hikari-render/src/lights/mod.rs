//! Lights, below every technique that lights with them: the scene's polygonal lights and their
//! GPU records (`polygon`, `tables`), the world grid of lights by reach that GI hits and the
//! haze pick from (`grid`), the point and spot lights' cut-off policy (`cutoff`), the shared
//! WGSL of polygonal lights (`area_polygon.wgsl`, `hikari::area_polygon`) and the CPU twin of
//! all of it (`reference`). Direct lighting, area lights, GI hits, the haze and the reflection
//! probes use this module; none of them imports another for its lights.

pub mod cutoff;
pub mod grid;
pub mod polygon;
pub mod reference;
pub mod tables;

pub use cutoff::{LIGHT_CUTOFF_FRACTION, LIGHT_CUTOFF_LUX, light_cutoff_lux};
pub use polygon::{AreaLightGpu, AreaTriangleGpu, PolygonLights};
pub use tables::{AreaLightScene, shadow_casters};

/// The format of every lit radiance image (nits): the lighting passes' outputs and inputs.
pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
