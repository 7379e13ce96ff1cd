//! `--config FILE`: a TOML file with what to render and the frame's settings (see
//! docs/config.example.toml). Command-line flags win over the file, the file over the preset.
//! The settings tables follow hikari-render's settings structs by themselves: a technique that
//! registers its settings is readable here, and by `--set`, with no change to this file.

use std::path::Path;

use anyhow::Context;
use serde::Deserialize;

use hikari_render::{Preset, Settings};

/// What the file says besides the technique tables.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Head {
    scene: Option<String>,
    camera: Option<String>,
    /// "HH:MM".
    time: Option<String>,
    width: Option<u32>,
    height: Option<u32>,
}

/// The file: what to render, and the renderer's settings.
#[derive(Debug, Default)]
pub struct ConfigFile {
    pub scene: Option<String>,
    pub camera: Option<String>,
    pub time: Option<String>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// The technique tables and `preset`, as written (validated when the file was read).
    tables: toml::Table,
}

const HEAD_KEYS: [&str; 5] = ["scene", "camera", "time", "width", "height"];

impl ConfigFile {
    /// Whether the file names a preset.
    pub fn has_preset(&self) -> bool {
        self.tables.contains_key("preset")
    }

    /// The settings the file gives: its preset (default `high`) and its tables.
    #[cfg(test)]
    pub fn settings(&self) -> Settings {
        self.settings_with(None, &[]).expect("validated when read")
    }

    /// The settings with a preset from the command line (which wins over the file's) and
    /// `--set table.key=value` overrides (which win over everything).
    pub fn settings_with(
        &self,
        preset: Option<Preset>,
        overrides: &[(String, String)],
    ) -> anyhow::Result<Settings> {
        Ok(Settings::from_toml(preset, self.tables.clone(), overrides)?)
    }
}

/// Reads and validates `path`; errors name the file, and the field with its allowed range.
pub fn load(path: &Path) -> anyhow::Result<ConfigFile> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read config file {}", path.display()))?;
    parse(&text).with_context(|| format!("config file {}", path.display()))
}

pub fn parse(text: &str) -> anyhow::Result<ConfigFile> {
    let mut tables: toml::Table = text.parse().map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut head = toml::Table::new();
    for k in HEAD_KEYS {
        if let Some(v) = tables.remove(k) {
            head.insert(k.into(), v);
        }
    }
    let head: Head = toml::Value::Table(head)
        .try_into()
        .map_err(|e: toml::de::Error| anyhow::anyhow!("{}", e.message().trim()))?;
    Settings::from_toml(None, tables.clone(), &[])?;
    Ok(ConfigFile {
        scene: head.scene,
        camera: head.camera,
        time: head.time,
        width: head.width,
        height: head.height,
        tables,
    })
}

/// Parses `table.key=value` as `--set` (and `compare`'s `--a`, `--b`) takes it; clap's error
/// names the flag.
pub fn parse_override(s: &str) -> anyhow::Result<(String, String)> {
    let (k, v) = s
        .split_once('=')
        .with_context(|| format!("{s:?}: expected table.key=value"))?;
    Ok((k.trim().to_string(), v.trim().to_string()))
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

    /// The example names every key of every technique's settings, so a new setting cannot be
    /// left out of it.
    #[test]
    fn the_documented_example_names_every_setting() {
        let example: toml::Table = include_str!("../../../docs/config.example.toml")
            .parse()
            .unwrap();
        let defaults = toml::Value::try_from(Settings::default()).unwrap();
        for (table, keys) in defaults.as_table().unwrap() {
            let in_example = example
                .get(table)
                .and_then(|t| t.as_table())
                .unwrap_or_else(|| panic!("docs/config.example.toml lacks [{table}]"));
            for key in keys.as_table().unwrap().keys() {
                assert!(
                    in_example.contains_key(key),
                    "docs/config.example.toml lacks {table}.{key}"
                );
            }
        }
        // Optional keys (absent from the defaults) are written commented out in the example.
        let text = include_str!("../../../docs/config.example.toml");
        for (field, _) in Settings::fields() {
            let key = field.rsplit('.').next().unwrap();
            assert!(
                text.contains(&format!("{key} =")),
                "docs/config.example.toml does not mention {field}"
            );
        }
    }

    /// A number as the example's comments write them: `0.5`, `-10`, `1e-4`, `2^30`.
    fn comment_number(s: &str) -> Option<f64> {
        match s.split_once('^') {
            Some((b, e)) => Some(b.parse::<f64>().ok()?.powf(e.parse().ok()?)),
            None => s.parse().ok(),
        }
    }

    /// The first `LO to HI` in a comment, with whether "power of two" comes before it.
    fn comment_range(comment: &str) -> Option<(f64, f64, bool)> {
        let words: Vec<&str> = comment.split_whitespace().collect();
        let trim = |w: &str| {
            w.trim_end_matches([':', ',', ';', ')'])
                .trim_start_matches('(')
                .to_string()
        };
        for i in 1..words.len().saturating_sub(1) {
            if words[i] != "to" {
                continue;
            }
            if let (Some(lo), Some(hi)) = (
                comment_number(&trim(words[i - 1])),
                comment_number(&trim(words[i + 1])),
            ) {
                let power = words[..i].join(" ").contains("power of two");
                return Some((lo, hi, power));
            }
        }
        None
    }

    /// Every setting's line in the example states in its comment the range the settings
    /// declare (`Settings::fields`), as `LO to HI` ("a power of two from LO to HI" for powers
    /// of two), and no comment states a range for a setting that declares none; an optional
    /// setting written commented out has an example value inside its range; the scene comment
    /// names every built-in scene; no comment points at work that is done ("until the ...
    /// issue", "placeholder ... until").
    #[test]
    fn the_examples_comments_state_the_declared_ranges() {
        let text = include_str!("../../../docs/config.example.toml");
        let declared: std::collections::HashMap<String, hikari_render::settings::Range> =
            Settings::fields().into_iter().collect();
        let mut table = String::new();
        let mut failures = Vec::new();
        let mut checked = 0;
        for line in text.lines() {
            let l = line.trim();
            if let Some(rest) = l.strip_prefix('[') {
                table = rest.split(']').next().unwrap_or_default().to_string();
                continue;
            }
            // A commented-out setting: `# key = value  # comment`.
            let (commented, l) = match l.strip_prefix("# ") {
                Some(rest) if rest.contains(" = ") => (true, rest),
                _ => (false, l),
            };
            let Some((key, rest)) = l.split_once(" = ") else {
                continue;
            };
            let key = key.trim();
            if key.contains(' ') || key.starts_with('#') {
                continue;
            }
            let (value, comment) = match rest.split_once('#') {
                Some((v, c)) => (v.trim(), c.trim()),
                None => (rest.trim(), ""),
            };
            if table.is_empty() {
                if key == "scene" {
                    for name in hikari_scene::builtin::NAMES {
                        if !comment.contains(name) {
                            failures.push(format!("the scene comment lacks `{name}`"));
                        }
                    }
                }
                continue;
            }
            let field = format!("{table}.{key}");
            let stated = comment_range(comment);
            match (declared.get(&field), stated) {
                (Some(range), Some((lo, hi, power))) => {
                    checked += 1;
                    use hikari_render::settings::Range;
                    let (want_lo, want_hi, want_power) = match *range {
                        Range::Int { lo, hi } => (lo as f64, hi as f64, false),
                        Range::PowerOfTwo { lo, hi } => (lo as f64, hi as f64, true),
                        Range::Float { lo, hi } => (lo, hi, false),
                    };
                    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(1.0);
                    if !close(lo, want_lo) || !close(hi, want_hi) || power != want_power {
                        failures.push(format!(
                            "{field}: the comment says {lo} to {hi}{}, the settings {range:?}",
                            if power { " (a power of two)" } else { "" },
                        ));
                    }
                    if commented {
                        let v = comment_number(value).unwrap_or(f64::NAN);
                        if !(want_lo..=want_hi).contains(&v) {
                            failures.push(format!("{field}: the example {value} is outside"));
                        }
                    }
                }
                (Some(range), None) => failures.push(format!(
                    "{field}: the comment does not state its range, {range:?}"
                )),
                // The sky's date is checked by its own validation, not a declared range.
                (None, Some((1900.0, 2100.0, false))) if field == "sky.date" => {
                    for (date, ok) in [
                        ("1899-12-31", false),
                        ("1900-01-01", true),
                        ("2100-12-31", true),
                        ("2101-01-01", false),
                    ] {
                        let set = [("sky.date".to_string(), format!("\"{date}\""))];
                        if Settings::from_toml(None, toml::Table::new(), &set).is_ok() != ok {
                            failures.push(format!("sky.date {date}: not as the comment says"));
                        }
                    }
                }
                (None, Some((lo, hi, _))) => failures.push(format!(
                    "{field}: the comment states {lo} to {hi}, a range the settings do not declare"
                )),
                (None, None) => {}
            }
        }
        // Work the comments once waited for is done; the GI's hits shadow point lights.
        for line in text.lines() {
            let gi_unshadowed = line.starts_with("punctual = ") && line.contains("unshadowed");
            if line.contains("until the") || line.contains("issue") || gi_unshadowed {
                failures.push(format!("stale comment: {line}"));
            }
        }
        assert!(checked >= 100, "only {checked} ranges checked");
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    #[test]
    fn an_out_of_range_value_names_the_field_and_the_range() {
        let e = parse("[sun_shadows]\ncascades = 7\n").unwrap_err();
        let msg = format!("{e:#}");
        assert!(
            msg.contains("sun_shadows.cascades") && msg.contains("1 to 4"),
            "{msg}"
        );
        let e = parse("[sun_shadows]\nresolution = 1000\n").unwrap_err();
        assert!(format!("{e:#}").contains("power of two"), "{e:#}");
        let e = parse("[exposure]\nev100 = 99.0\n").unwrap_err();
        assert!(format!("{e:#}").contains("exposure.ev100"), "{e:#}");
    }

    #[test]
    fn unknown_fields_and_wrong_types_are_errors_that_name_them() {
        let e = parse("[sun_shadows]\ncascade = 2\n").unwrap_err();
        assert!(format!("{e:#}").contains("cascade"), "{e:#}");
        let e = parse("[direct_lighting]\nsun = \"yes\"\n").unwrap_err();
        assert!(
            format!("{e:#}").contains("direct_lighting.sun")
                && format!("{e:#}").contains("boolean"),
            "{e:#}"
        );
        let e = parse("[sky]\nweather = 3\n").unwrap_err();
        assert!(format!("{e:#}").contains("sky.weather"), "{e:#}");
        // An integer where a float is expected is fine.
        assert!(parse("[sun_shadows]\nmax_distance_m = 100\n").is_ok());
        assert!(parse("width = -3\n").is_err());
        let e = parse("[shadows]\ncascades = 2\n").unwrap_err();
        assert!(format!("{e:#}").contains("shadows"), "{e:#}");
    }

    #[test]
    fn the_preset_sets_values_the_file_and_overrides_win_over() {
        let f = parse("preset = \"low\"\n[sun_shadows]\ncascades = 3\n").unwrap();
        let s = f.settings();
        assert_eq!(
            s.sun_shadows.resolution,
            Settings::preset(Preset::Low).sun_shadows.resolution
        );
        assert_eq!(s.sun_shadows.cascades, 3, "the file wins over the preset");
        let s = f
            .settings_with(
                Some(Preset::Ultra),
                &[("sun_shadows.cascades".into(), "2".into())],
            )
            .unwrap();
        assert_eq!(
            s.sun_shadows.resolution, 4096,
            "the command line's preset wins"
        );
        assert_eq!(s.sun_shadows.cascades, 2, "--set wins over all");
        assert!(parse("preset = \"extreme\"\n").is_err());
    }
}
