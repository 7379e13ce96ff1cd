//! Exposure of the placeholder tonemap.

use serde::{Deserialize, Serialize};

use crate::settings::{Field, Preset, Range, TechniqueSettings};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExposureSettings {
    /// Exposure value at ISO 100; absent: metered from the sun.
    pub ev100: Option<f32>,
}

impl TechniqueSettings for ExposureSettings {
    fn fields() -> &'static [Field] {
        &[Field {
            key: "ev100",
            range: Range::Float {
                lo: -10.0,
                hi: 30.0,
            },
        }]
    }

    fn preset(_: Preset) -> Self {
        Self::default()
    }
}
