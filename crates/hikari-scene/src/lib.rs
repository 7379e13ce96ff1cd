//! hikari-scene: the scene model (meshes, materials, textures, instances, cameras, lights),
//! glTF 2.0 loading and the built-in scenes.
//!
//! # Units
//!
//! Lengths are in metres, angles of cameras in degrees (vertical field of view) and of spot
//! cones in radians. Colours are linear Rec.709. Light is photometric: the sun ([`Sun`]) in
//! lux, point and spot lights ([`Light`]) in candela (with constructors from lumens), emissive
//! surfaces ([`Material::emissive_nits`]) in nits (cd/m²).
//!
//! # Animation
//!
//! A mesh may carry a [`Deformation`] (vertex animation in object space: plants swaying,
//! wheels spinning), evaluated deterministically by [`Mesh::deformed`]. The sun and moon of a
//! date, time and place come from `hikari_math::astro` through hikari-render's sky settings.
//!
//! # Built-in scenes ([`builtin`])
//!
//! `village` (generated from a seed by [`village`]), `boxes`, `cornell`, `terrain` and
//! `cutout` ([`builtin::cutout`]: two alpha-tested quads over a ground plane, for renderer
//! tests of cut-outs in the image and in shadows).
//!
//! # Alpha
//!
//! [`Material::alpha_mode`] follows glTF's `alphaMode`: [`AlphaMode::Opaque`] (alpha ignored),
//! [`AlphaMode::Mask`] (a cut-out: covered where the base colour alpha, texture A times factor,
//! is at least the cut-off, glTF's `alphaCutoff`, default 0.5) and [`AlphaMode::Blend`], which
//! is drawn as a cut-out at 0.5 until transparency exists (the loader warns, naming the
//! material). Renderers read [`Material::alpha_cutoff`]: `None` for opaque, else the cut-off.
//! The built-in village's materials are all opaque.
//!
//! # Validation
//!
//! [`Scene::validate`] checks everything a GPU would trust blindly. [`Camera::validate`]
//! (and [`Camera::validate_projection`] with the image's aspect ratio), [`Sun::validate`] and
//! [`Light::validate`] check single objects, for renderers handed them outside a scene; every
//! error names the object and the field.
//!
//! # glTF 2.0 support ([`gltf::load`])
//!
//! Read:
//! - `.gltf` with buffers and images in external files (relative paths, `file:` URIs) or
//!   embedded as base64 `data:` URIs, and `.glb` (its BIN chunk); PNG and JPEG images, decoded
//!   to RGBA8 (16-bit and float images are reduced to 8 bits).
//! - Meshes: triangle-list primitives, one [`Mesh`] each, with POSITION, NORMAL, TANGENT,
//!   TEXCOORD_0 (float or normalised u8/u16; more with `KHR_mesh_quantization`), COLOR_0 (RGB or RGBA) and u8/u16/u32 indices;
//!   sparse accessors. Primitives without normals get flat normals (as the glTF spec asks).
//!   Missing tangents are generated from the UVs only when the material has a normal map (not
//!   MikkTSpace; see [`gltf::generate_tangents`]); otherwise they stay absent.
//! - The node hierarchy of the default scene (else the first scene), flattened into
//!   [`Instance`]s with world transforms; a mesh used by several nodes is shared.
//! - Metallic-roughness materials with all five textures (base colour, metallic-roughness,
//!   normal with scale, emissive, occlusion with strength), texture samplers' wrap modes,
//!   `doubleSided`, base colour alpha and `alphaMode` with `alphaCutoff` (see Alpha above).
//! - Perspective cameras, with their names (the camera's, else the node's, else `cameraN`),
//!   world position, view direction (-Z) and up (+Y) of the node, `yfov` and `znear`
//!   (checked, with `zfar` and `aspectRatio`, against the ranges glTF allows).
//! - `KHR_lights_punctual`: point and spot lights with their intensity in candela, as the
//!   extension defines it; the first directional light becomes the [`Sun`], its intensity
//!   taken as lux (also the extension's unit).
//! - `KHR_materials_emissive_strength`: emission in nits = `emissiveFactor` x
//!   `emissiveStrength` x [`gltf::GltfOptions::emissive_nits_per_unit`] (default 1), i.e. the
//!   product is read as cd/m², which is what that extension says to do where a physical unit
//!   is needed. Files written for display-referred viewers, where emissive 1 means "white",
//!   look dim under daylight exposure unless that option is raised.
//! - `KHR_materials_specular`: `specularFactor` becomes [`Material::specular`], the weight of
//!   a dielectric's specular reflection (0: matte). Its textures and `specularColorFactor`
//!   are not read (a warning says so).
//! - `KHR_mesh_quantization`: POSITION as (unsigned) byte or short, normalized or not; NORMAL
//!   and TANGENT as normalized byte or short (renormalised; tangent w keeps its sign);
//!   TEXCOORD_0 as any of those. Integers are dequantized with the spec's formulas; the node
//!   transform that undoes a position quantization applies as usual. Quantized types in a file
//!   that does not declare the extension, and types the extension does not allow (unsigned
//!   normals, say), are errors naming the mesh, primitive and attribute.
//! - `KHR_texture_transform` (`offset`, `rotation`, `scale`, `texCoord`) on any of a
//!   material's five textures, applied to TEXCOORD_0 at load, before tangents are generated
//!   (file tangents are re-expressed for the new UVs). A mesh has one UV set, so a material has
//!   one transform: its base colour texture's (else its first textured slot's); a slot with a
//!   different one gets a warning naming the material and slot. Malformed values are errors
//!   naming the material, slot and field. docs/gltf.md.
//!
//! Approximated, with a warning: `BLEND` materials, drawn as cut-outs at alpha 0.5.
//!
//! Ignored, with a warning in [`gltf::Loaded::warnings`] (also logged with `log::warn!`):
//! non-triangle primitives (points, lines, strips, fans), orthographic cameras, further
//! directional lights, animations, skins, morph targets, texture coordinate sets other than 0
//! (also where `KHR_texture_transform`'s `texCoord` asks for one), scenes other than the
//! default one, and any extension other than the four above listed in `extensionsUsed`. An extension in
//! `extensionsRequired` that is not supported is an error. Also ignored silently: `zfar` and
//! `aspectRatio` of cameras (the renderer uses an infinite far plane and the image's aspect
//! ratio), texture filters (the renderer chooses its own), `extras` (but a material's
//! `{"hikari": {"area_light": true}}` or `false`, read into [`Material::area_light`]; any other
//! value of that key is an error).
//!
//! A file without cameras gets one named `auto` framing the bounds of the whole scene
//! ([`Camera::framing`]), or, with nothing to frame, looking level at the horizon
//! ([`Camera::horizon`]; the file still loads, with a warning, and renders as sky only); a
//! file without any light gets [`Sun::default`] (100 000 lux).
//!
//! The interior mask (docs/irradiance-probes.md): a material's `extras`
//! `{"hikari": {"interior": w}}` ([`Material::interior`]) and the vertex attribute
//! `_HIKARI_INTERIOR` ([`Mesh::interior`], SCALAR float or normalized u8/u16), each in [0, 1]
//! (0 outdoors, 1 indoors); anything else under that key or out of range is an error.
//!
//! Malformed files give a [`gltf::GltfError`] naming the file and what is wrong, never a
//! panic: unreadable or truncated files, bad JSON, glTF validation failures (indices of
//! missing objects, unsupported required extensions), missing or short buffers and images,
//! buffer views and accessors reading out of range, attributes of the wrong type or count,
//! indices out of range, counts too large for the file (checked before anything is
//! allocated), node hierarchies with cycles or that expand past [`gltf::MAX_NODE_VISITS`]
//! nodes, undecodable images, camera and light numbers outside glTF's ranges, alpha cut-offs
//! outside [0, 1], non-finite numbers (through [`Scene::validate`]). `tests/malformed.rs` holds
//! a case for each of these.

pub mod builtin;
pub mod deformation;
pub mod gltf;
pub mod model;
pub mod particles;
pub mod shapes;
pub mod validation;
pub mod village;

pub use deformation::Deformation;
pub use model::{
    AlphaMode, Anisotropy, Camera, DEFAULT_INTERIOR, Instance, Light, LightKind, Material, Mesh,
    Scene, SceneError, Sun, Texture, TextureRef, Wrap,
};
pub use particles::{Particle, ParticleEmitter};
