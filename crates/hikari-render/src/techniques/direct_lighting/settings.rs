//! Which direct lights the deferred lighting adds.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, TechniqueSettings};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DirectLightingSettings {
    pub sun: bool,
    /// Point and spot lights.
    pub punctual: bool,
    pub emissive: bool,
    /// The placeholder sky and ambient light that the atmosphere and probe issues replace.
    pub placeholder_ambient: bool,
}

impl Default for DirectLightingSettings {
    fn default() -> Self {
        Self {
            sun: true,
            punctual: true,
            emissive: true,
            placeholder_ambient: true,
        }
    }
}

impl TechniqueSettings for DirectLightingSettings {
    fn fields() -> &'static [Field] {
        &[]
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }
}
