//! What a user may tune about a frame. Each technique owns its settings struct
//! (`techniques/<name>/settings.rs`) with its ranges declared once, as data
//! ([`TechniqueSettings::fields`]), and its values for each [`Preset`]; [`Settings`] registers
//! them, one line each, under the technique's name, which is also the table's name in the
//! settings file (docs/config.example.toml).
//!
//! Settings are read as TOML: a preset gives every value, the file's tables override it key by
//! key, and `--set table.key=value` overrides both. Unknown keys, wrong types and values out of
//! range are errors that name the field and its allowed range.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

pub use crate::techniques::area_lights::settings::AreaLightsSettings;
pub use crate::techniques::clouds::settings::CloudsSettings;
pub use crate::techniques::direct_lighting::settings::DirectLightingSettings;
pub use crate::techniques::exposure::settings::ExposureSettings;
pub use crate::techniques::gi_denoiser::settings::GiDenoiserSettings;
pub use crate::techniques::haze::settings::HazeSettings;
pub use crate::techniques::irradiance_probes::settings::IrradianceProbesSettings;
pub use crate::techniques::local_tonemap::settings::LocalTonemapSettings;
pub use crate::techniques::particles::settings::ParticlesSettings;
pub use crate::techniques::ray_traced_gi::settings::RayTracedGiSettings;
pub use crate::techniques::reflection_probes::settings::ReflectionProbesSettings;
pub use crate::techniques::sky::settings::SkySettings;
pub use crate::techniques::sun_shadows::settings::SunShadowsSettings;
pub use crate::techniques::taa::settings::TaaSettings;
pub use crate::techniques::tonemap::settings::TonemapSettings;

/// Named quality levels, as game renderers offer them: each sets the resolutions, ray and
/// sample counts and update budgets of every technique. `High` is the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    Low,
    Medium,
    #[default]
    High,
    Ultra,
}

impl Preset {
    pub const ALL: [Preset; 4] = [Preset::Low, Preset::Medium, Preset::High, Preset::Ultra];

    pub fn name(self) -> &'static str {
        match self {
            Preset::Low => "low",
            Preset::Medium => "medium",
            Preset::High => "high",
            Preset::Ultra => "ultra",
        }
    }
}

impl std::fmt::Display for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Preset {
    type Err = SettingError;
    fn from_str(s: &str) -> Result<Self, SettingError> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| SettingError {
                field: "preset".into(),
                value: format!("{s:?}"),
                allowed: "low, medium, high or ultra".into(),
            })
    }
}

/// The range a numeric field must lie in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// An integer from `lo` to `hi`.
    Int { lo: i64, hi: i64 },
    /// A power of two from `lo` to `hi`.
    PowerOfTwo { lo: i64, hi: i64 },
    /// A finite number from `lo` to `hi`.
    Float { lo: f64, hi: f64 },
}

impl Range {
    pub(crate) fn describe(&self) -> String {
        match *self {
            Range::Int { lo, hi } => format!("{lo} to {hi}"),
            Range::PowerOfTwo { lo, hi } => format!("a power of two from {lo} to {hi}"),
            Range::Float { lo, hi } => format!("{lo} to {hi}"),
        }
    }

    pub(crate) fn admits(&self, v: &toml::Value) -> bool {
        match (*self, v) {
            (Range::Int { lo, hi }, toml::Value::Integer(i)) => (lo..=hi).contains(i),
            (Range::PowerOfTwo { lo, hi }, toml::Value::Integer(i)) => {
                (lo..=hi).contains(i) && (*i as u64).is_power_of_two()
            }
            (Range::Float { lo, hi }, toml::Value::Float(f)) => {
                f.is_finite() && (lo..=hi).contains(f)
            }
            (Range::Float { lo, hi }, toml::Value::Integer(i)) => (lo..=hi).contains(&(*i as f64)),
            _ => false,
        }
    }
}

/// A bounded field of a technique's settings: its key in the technique's table and its range.
/// An optional field that is absent is not checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Field {
    pub key: &'static str,
    pub range: Range,
}

/// What each technique's settings struct provides.
pub trait TechniqueSettings:
    Clone + Default + PartialEq + Serialize + DeserializeOwned + std::fmt::Debug
{
    /// Every bounded field, with its range, declared once.
    fn fields() -> &'static [Field];

    /// The values of a preset; `Preset::High` gives `Default::default()`.
    fn preset(p: Preset) -> Self;

    /// Checks every field of [`Self::fields`]; `table` names the technique in errors.
    fn check_fields(&self, table: &str) -> Result<(), SettingError> {
        let value = toml::Value::try_from(self).map_err(|e| SettingError {
            field: table.into(),
            value: "?".into(),
            allowed: format!("a value TOML can hold ({e})"),
        })?;
        for f in Self::fields() {
            let Some(v) = value.get(f.key) else { continue };
            if !f.range.admits(v) {
                return Err(SettingError {
                    field: format!("{table}.{}", f.key),
                    value: v.to_string(),
                    allowed: f.range.describe(),
                });
            }
        }
        Ok(())
    }

    /// Checks the settings: the ranges of [`Self::fields`] (a technique with rules that a range
    /// cannot say adds them after `check_fields`).
    fn validate(&self, table: &str) -> Result<(), SettingError> {
        self.check_fields(table)
    }
}

/// A setting outside its allowed range, of the wrong type, or unknown.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{field}` is {value}; allowed: {allowed}")]
pub struct SettingError {
    pub field: String,
    pub value: String,
    pub allowed: String,
}

/// Registers each technique's settings under its name: one line a technique.
macro_rules! register_settings {
    ($($name:ident: $ty:ty),* $(,)?) => {
        /// Every tunable of the frame, one table per technique.
        #[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct Settings {
            $(pub $name: $ty,)*
        }

        impl Settings {
            /// Every technique's values for `preset`.
            pub fn preset(preset: Preset) -> Self {
                Self { $($name: <$ty as TechniqueSettings>::preset(preset),)* }
            }

            /// Checks every technique's fields; the error names the first field out of range.
            pub fn validate(&self) -> Result<(), SettingError> {
                $(self.$name.validate(stringify!($name))?;)*
                Ok(())
            }

            /// Each technique's `enabled` switch, `(technique, on)`, in registration order
            /// (techniques without one are left out).
            pub fn switches(&self) -> Vec<(&'static str, bool)> {
                let mut out = Vec::new();
                $(if let Ok(toml::Value::Table(t)) = toml::Value::try_from(&self.$name)
                    && let Some(toml::Value::Boolean(on)) = t.get("enabled")
                {
                    out.push((stringify!($name), *on));
                })*
                out
            }

            /// The names of the settings tables, in registration order.
            pub fn tables() -> &'static [&'static str] {
                &[$(stringify!($name),)*]
            }

            /// Reads each technique's table of `merged` on its own, so that a key the
            /// technique does not have is named with its table and the keys it does have.
            fn check_keys(merged: &toml::Table) -> Result<(), SettingError> {
                $(if let Some(t) = merged.get(stringify!($name))
                    && let Err(e) = t.clone().try_into::<$ty>()
                    && let Some(err) = unknown_key(stringify!($name), e.message())
                {
                    return Err(err);
                })*
                Ok(())
            }

            /// The first `table.key` of `merged` that its technique cannot read on its own
            /// (serde's message names no key), with what serde expected.
            fn unreadable(merged: &toml::Table) -> Option<SettingError> {
                $(for (key, v) in merged
                    .get(stringify!($name))
                    .and_then(|t| t.as_table())
                    .into_iter()
                    .flatten()
                {
                    let alone = toml::Table::from_iter([(key.clone(), v.clone())]);
                    if let Err(e) = toml::Value::Table(alone).try_into::<$ty>() {
                        let m = e.message().trim();
                        return Some(SettingError {
                            field: format!("{}.{key}", stringify!($name)),
                            value: v.to_string(),
                            allowed: m.split_once("expected ").map_or(m, |(_, x)| x).to_string(),
                        });
                    }
                })*
                None
            }

            /// Every bounded field as `table.key` with its range, for documentation and tests.
            pub fn fields() -> Vec<(String, Range)> {
                let mut out = Vec::new();
                $(for f in <$ty as TechniqueSettings>::fields() {
                    out.push((format!("{}.{}", stringify!($name), f.key), f.range));
                })*
                out
            }
        }
    };
}

register_settings! {
    sun_shadows: SunShadowsSettings,
    direct_lighting: DirectLightingSettings,
    exposure: ExposureSettings,
    local_tonemap: LocalTonemapSettings,
    sky: SkySettings,
    clouds: CloudsSettings,
    taa: TaaSettings,
    gi_denoiser: GiDenoiserSettings,
    area_lights: AreaLightsSettings,
    haze: HazeSettings,
    particles: ParticlesSettings,
    irradiance_probes: IrradianceProbesSettings,
    reflection_probes: ReflectionProbesSettings,
    ray_traced_gi: RayTracedGiSettings,
    tonemap: TonemapSettings,
    scene_rt: crate::scene::rt::SceneRtSettings,
}

impl Settings {
    /// Reads settings from TOML tables (one a technique): a preset gives every value (`preset`,
    /// else the table's `preset = "..."` key, else `High`), `table` overrides it key by key,
    /// `overrides` (`("sun_shadows.resolution", "4096")`, values in TOML syntax) override both.
    /// Then validates.
    pub fn from_toml(
        preset: Option<Preset>,
        mut table: toml::Table,
        overrides: &[(String, String)],
    ) -> Result<Self, SettingError> {
        let in_table = match table.remove("preset") {
            None => None,
            Some(toml::Value::String(s)) => Some(s.parse::<Preset>()?),
            Some(v) => {
                return Err(SettingError {
                    field: "preset".into(),
                    value: v.to_string(),
                    allowed: "\"low\", \"medium\", \"high\" or \"ultra\"".into(),
                });
            }
        };
        let preset = preset.or(in_table).unwrap_or_default();
        let base = toml::Value::try_from(Self::preset(preset)).map_err(|e| SettingError {
            field: "settings".into(),
            value: "?".into(),
            allowed: e.to_string(),
        })?;
        let mut merged = match base.clone() {
            toml::Value::Table(t) => t,
            _ => unreachable!("a struct serialises to a table"),
        };
        merge(&mut merged, table);
        for (key, value) in overrides {
            set_path(&mut merged, &base, key, value)?;
        }
        // A table no technique has (a typo in the file or in `--set`), named with the
        // nearest one.
        for (name, v) in &merged {
            if !Self::tables().contains(&name.as_str()) {
                return Err(unknown_table(name));
            }
            if !v.is_table() {
                return Err(SettingError {
                    field: name.clone(),
                    value: v.to_string(),
                    allowed: format!("a table of settings, `[{name}]`"),
                });
            }
        }
        // Ranges first: a value of the wrong kind (`nan` for a count) would otherwise fail in
        // serde, whose error does not name the field.
        for (field, range) in Self::fields() {
            let (table, key) = field.split_once('.').unwrap_or(("", &field));
            if let Some(v) = merged.get(table).and_then(|t| t.get(key))
                && !range.admits(v)
            {
                return Err(SettingError {
                    field,
                    value: v.to_string(),
                    allowed: range.describe(),
                });
            }
        }
        Self::check_keys(&merged)?;
        // A value of the wrong type: name the first field whose TOML type differs from the
        // preset's (serde's own message names no field).
        let reference = base_types(&Self::preset(preset));
        let settings: Settings =
            toml::Value::Table(merged.clone())
                .try_into()
                .map_err(|e: toml::de::Error| {
                    wrong_type(&merged, &reference)
                        .or_else(|| Self::unreadable(&merged))
                        .unwrap_or_else(|| SettingError {
                            field: "settings".into(),
                            value: "not readable".into(),
                            allowed: e.message().trim().to_string(),
                        })
                })?;
        settings.validate()?;
        Ok(settings)
    }

    /// The settings as a TOML document, as the settings file spells them.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }
}

/// The preset's settings as a TOML table, whose value types the file's must match.
fn base_types(preset: &Settings) -> toml::Table {
    match toml::Value::try_from(preset) {
        Ok(toml::Value::Table(t)) => t,
        _ => toml::Table::new(),
    }
}

/// The first `table.key` of `merged` whose value has another TOML type than the reference's
/// (integers are accepted where floats are expected).
fn wrong_type(merged: &toml::Table, reference: &toml::Table) -> Option<SettingError> {
    for (table, values) in merged {
        let (Some(values), Some(want)) = (
            values.as_table(),
            reference.get(table).and_then(|t| t.as_table()),
        ) else {
            continue;
        };
        for (key, v) in values {
            let Some(w) = want.get(key) else { continue };
            let same = std::mem::discriminant(v) == std::mem::discriminant(w)
                || (v.is_integer() && w.is_float());
            if !same {
                return Some(SettingError {
                    field: format!("{table}.{key}"),
                    value: v.to_string(),
                    allowed: format!("a {} like {w}", w.type_str()),
                });
            }
        }
    }
    None
}

/// Copies `over` into `base`, table by table, key by key.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (k, v) in over {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// Sets `table.key` (dotted) to `value`, parsed as a TOML value. `reference` (the preset's
/// settings) gives the type the key expects, for the error when `value` is not TOML, and lets
/// a string setting take a bare word (`--set sky.weather=hazy`).
fn set_path(
    root: &mut toml::Table,
    reference: &toml::Value,
    key: &str,
    value: &str,
) -> Result<(), SettingError> {
    let err = |allowed: String| SettingError {
        field: key.into(),
        value: format!("{value:?}"),
        allowed,
    };
    let parts: Vec<&str> = key.split('.').collect();
    let (last, tables) = parts.split_last().ok_or_else(|| err("table.key".into()))?;
    if let Some(table) = tables.first()
        && !Settings::tables().contains(table)
    {
        return Err(unknown_table(table));
    }
    if tables.is_empty() {
        return Err(err(format!(
            "a setting as table.key, e.g. `taa.enabled`; the tables are {}",
            Settings::tables().join(", ")
        )));
    }
    let expected = parts.iter().try_fold(reference, |v, p| v.get(p));
    let v = match format!("v = {value}").parse::<toml::Table>() {
        Ok(parsed) => parsed
            .get("v")
            .cloned()
            .ok_or_else(|| err("a value".into()))?,
        Err(_) => match expected {
            // A bare word where a string is expected: the string.
            Some(toml::Value::String(_)) => toml::Value::String(value.to_string()),
            Some(w) => return Err(err(expected_kind(w))),
            None => {
                return Err(err(
                    "a TOML value: a number, true or false, or a \"string\"".into(),
                ));
            }
        },
    };
    let mut t = root;
    for p in tables {
        t = match t
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(Default::default()))
        {
            toml::Value::Table(t) => t,
            _ => return Err(err(format!("`{p}` is a value, not a table"))),
        };
    }
    t.insert(last.to_string(), v);
    Ok(())
}

/// What a value of the type of `example` is, for an error: "a boolean, true or false".
fn expected_kind(example: &toml::Value) -> String {
    match example {
        toml::Value::Boolean(_) => "a boolean, true or false".into(),
        toml::Value::Integer(_) => format!("an integer, like {example}"),
        toml::Value::Float(_) => format!("a number, like {example}"),
        toml::Value::String(_) => format!("a string, like {example}"),
        _ => format!("a {}, like {example}", example.type_str()),
    }
}

/// The error for a table that no technique registers, with the nearest name if one is near.
fn unknown_table(name: &str) -> SettingError {
    let tables = Settings::tables();
    SettingError {
        field: name.into(),
        value: "not a settings table".into(),
        allowed: format!("{}{}", tables.join(", "), did_you_mean(name, tables)),
    }
}

/// The error for serde's "unknown field `x`, expected one of `a`, `b`" in `table`: the key
/// as `table.x`, the keys there are and the nearest one. `None` for any other message.
fn unknown_key(table: &str, message: &str) -> Option<SettingError> {
    let rest = message.trim().strip_prefix("unknown field `")?;
    let (key, rest) = rest.split_once('`')?;
    let keys: Vec<&str> = rest
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|k| !k.is_empty())
        .collect();
    Some(SettingError {
        field: format!("{table}.{key}"),
        value: format!("not a setting of `{table}`"),
        allowed: if keys.is_empty() {
            format!("`{table}` has no settings")
        } else {
            format!("{}{}", keys.join(", "), did_you_mean(key, &keys))
        },
    })
}

/// " (did you mean `x`?)" when one of `names` is within a third of `name`'s length in edits
/// (at least one edit), else "".
fn did_you_mean(name: &str, names: &[&str]) -> String {
    let limit = (name.chars().count() / 3).max(1);
    names
        .iter()
        .map(|n| (edit_distance(name, n), *n))
        .filter(|(d, _)| *d <= limit)
        .min()
        .map_or(String::new(), |(_, n)| format!(" (did you mean `{n}`?)"))
}

/// Levenshtein distance in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_insertions_deletions_and_substitutions() {
        assert_eq!(edit_distance("village", "village"), 0);
        assert_eq!(edit_distance("vilage", "village"), 1);
        assert_eq!(edit_distance("cascade", "cascades"), 1);
        assert_eq!(edit_distance("taa", "haze"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(
            did_you_mean("cascade", &["resolution", "cascades"]),
            " (did you mean `cascades`?)"
        );
        assert_eq!(did_you_mean("nonexistent", &["taa", "haze"]), "");
    }
}
