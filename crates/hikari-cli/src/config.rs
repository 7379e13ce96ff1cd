//! `--config FILE`: a TOML file with the frame's settings (see docs/config.example.toml). Command-line
//! flags win over the file, the file over the defaults.

use std::path::Path;

use anyhow::Context;
use serde::Deserialize;

use hikari_render::Settings;
use hikari_render::settings::{ExposureSettings, LightingSettings, ShadowSettings};

/// The file: what to render, and the renderer's settings.
#[derive(Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ConfigFile {
    pub scene: Option<String>,
    pub camera: Option<String>,
    /// "HH:MM".
    pub time: Option<String>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    // Spelled out rather than flattened from `Settings`: serde's flatten would lose the
    // position of type errors and could not refuse unknown keys.
    pub shadows: ShadowSettings,
    pub lighting: LightingSettings,
    pub exposure: ExposureSettings,
}

impl ConfigFile {
    pub fn settings(&self) -> Settings {
        Settings {
            shadows: self.shadows.clone(),
            lighting: self.lighting.clone(),
            exposure: self.exposure.clone(),
        }
    }
}

/// Reads and validates `path`; errors name the file, and the field with its allowed range.
pub fn load(path: &Path) -> anyhow::Result<ConfigFile> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read config file {}", path.display()))?;
    parse(&text).with_context(|| format!("config file {}", path.display()))
}

pub fn parse(text: &str) -> anyhow::Result<ConfigFile> {
    let file: ConfigFile = toml::from_str(text).map_err(|e| anyhow::anyhow!("{e}"))?;
    file.settings().validate()?;
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_example_parses_to_the_defaults_it_states() {
        let f = parse(include_str!("../../../docs/config.example.toml")).unwrap();
        assert_eq!(f.settings(), Settings::default());
        assert_eq!(f.scene.as_deref(), Some("village"));
    }

    #[test]
    fn an_out_of_range_value_names_the_field_and_the_range() {
        let e = parse("[shadows]\ncascades = 7\n").unwrap_err();
        let msg = format!("{e:#}");
        assert!(
            msg.contains("shadows.cascades") && msg.contains("1 to 4"),
            "{msg}"
        );
        let e = parse("[shadows]\nresolution = 1000\n").unwrap_err();
        assert!(format!("{e:#}").contains("power of two"), "{e:#}");
        let e = parse("[exposure]\nev100 = 99.0\n").unwrap_err();
        assert!(format!("{e:#}").contains("exposure.ev100"), "{e:#}");
    }

    #[test]
    fn unknown_fields_and_wrong_types_are_errors_that_name_them() {
        let e = parse("[shadows]\ncascade = 2\n").unwrap_err();
        assert!(format!("{e:#}").contains("cascade"), "{e:#}");
        let e = parse("[lighting]\nsun = \"yes\"\n").unwrap_err();
        assert!(format!("{e:#}").contains("sun"), "{e:#}");
        assert!(parse("width = -3\n").is_err());
    }
}
