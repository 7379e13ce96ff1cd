//! hikari's shaders: shared modules under `shaders/`, each technique's own beside its code under
//! `src/`, all embedded at build time (see `build.rs`); the engine's shader system composes them.
//! Set `HIKARI_SHADER_DIR` to the hikari-render crate folder to read them from disk instead
//! while editing.

pub use hikari_gpu::shader::*;

use crate::error::{RenderError, Result};

mod embedded {
    include!(concat!(env!("OUT_DIR"), "/shader_files.rs"));
}

/// Every shader file of the crate, embedded or read from the crate folder `HIKARI_SHADER_DIR`
/// names.
pub fn shader_files() -> Result<Vec<ShaderFile>> {
    let from_disk = std::env::var_os("HIKARI_SHADER_DIR");
    embedded::SHADER_FILES
        .iter()
        .map(|(key, rel, text)| {
            let source = match &from_disk {
                Some(dir) => {
                    let full = std::path::Path::new(dir).join(rel);
                    std::fs::read_to_string(&full).map_err(|e| RenderError::Shader {
                        path: full.display().to_string(),
                        message: e.to_string(),
                    })?
                }
                None => text.to_string(),
            };
            Ok(ShaderFile::new(key.to_string(), source))
        })
        .collect()
}

/// A shader library over every shader of the crate.
pub fn library(capabilities: naga::valid::Capabilities) -> Result<ShaderLibrary> {
    ShaderLibrary::new(shader_files()?, capabilities)
}
