//! The rendering stack's error type lives in the engine (`hikari_gpu::error`); the renderer's
//! own error values become its settings and scene kinds here.

pub use hikari_gpu::error::{RenderError, Result};

impl From<crate::settings::SettingError> for RenderError {
    fn from(e: crate::settings::SettingError) -> Self {
        RenderError::Settings(Box::new(e))
    }
}
