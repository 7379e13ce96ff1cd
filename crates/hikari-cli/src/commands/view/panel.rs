//! The panel's state and the edits it makes: the clock, settings fields clamped to their
//! declared ranges, technique switches, the preset and the debug view. No GUI here: the
//! widgets (`ui.rs`) call these, and the tests check them.

use hikari_render::Settings;
use hikari_render::settings::Range;

/// Seconds in a day.
pub const DAY_S: f64 = 86_400.0;
/// What `[` and `]` step the clock by.
pub const TIME_STEP_S: f64 = 30.0 * 60.0;
/// The clock's default rate when played: one hour every ten seconds.
pub const DEFAULT_RATE_H_PER_10S: f64 = 1.0;

/// The sky's clock and place as the panel edits them.
#[derive(Clone, Debug, PartialEq)]
pub struct Clock {
    /// Local time of day, seconds after midnight, in [0, 86400).
    pub seconds: f64,
    pub date: String,
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub utc_offset_h: f64,
    pub weather: String,
    pub playing: bool,
    /// Clock hours that pass every ten seconds while playing.
    pub rate_h_per_10s: f64,
}

impl Clock {
    /// The clock of `settings`' sky.
    pub fn of(settings: &Settings) -> Self {
        let sky = &settings.sky;
        Self {
            seconds: parse_time(&sky.time).unwrap_or(12.0 * 3600.0),
            date: sky.date.clone(),
            latitude_deg: sky.latitude_deg,
            longitude_deg: sky.longitude_deg,
            utc_offset_h: sky.utc_offset_h,
            weather: sky.weather.clone(),
            playing: false,
            rate_h_per_10s: DEFAULT_RATE_H_PER_10S,
        }
    }

    /// Steps the time by `delta` seconds, wrapping around midnight.
    pub fn step(&mut self, delta: f64) {
        self.seconds = (self.seconds + delta).rem_euclid(DAY_S);
    }

    /// Advances a playing clock by `dt` seconds of wall time; whether the time changed.
    pub fn advance(&mut self, dt: f64) -> bool {
        if !self.playing || dt.is_nan() || dt <= 0.0 || self.rate_h_per_10s == 0.0 {
            return false;
        }
        self.step(dt * self.rate_h_per_10s * 3600.0 / 10.0);
        true
    }

    /// `HH:MM` of the time.
    pub fn hh_mm(&self) -> String {
        let s = self.seconds.round() as u32 % 86_400;
        format!("{:02}:{:02}", s / 3600, s / 60 % 60)
    }
}

/// `HH:MM` or `HH:MM:SS` as seconds after midnight.
pub fn parse_time(t: &str) -> Option<f64> {
    let parts: Vec<&str> = t.trim().split(':').collect();
    if !(2..=3).contains(&parts.len()) {
        return None;
    }
    let n: Vec<u32> = parts
        .iter()
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    let (h, m, s) = (n[0], n[1], n.get(2).copied().unwrap_or(0));
    (h < 24 && m < 60 && s < 60).then(|| (h * 3600 + m * 60 + s) as f64)
}

/// The settings as a TOML table of tables.
fn table_of(settings: &Settings) -> toml::Table {
    with_table(settings, toml::Table::clone)
}

thread_local! {
    /// The last settings serialised and their table: the panel reads every field every frame,
    /// and the settings change only when someone edits them.
    static TABLE: std::cell::RefCell<Option<(Settings, toml::Table)>> =
        const { std::cell::RefCell::new(None) };
}

/// `f` of the settings as a TOML table of tables, serialised once per change of `settings`.
fn with_table<R>(settings: &Settings, f: impl FnOnce(&toml::Table) -> R) -> R {
    TABLE.with_borrow_mut(|cache| {
        if cache.as_ref().is_none_or(|(s, _)| s != settings) {
            let table = match toml::Value::try_from(settings) {
                Ok(toml::Value::Table(t)) => t,
                _ => toml::Table::new(),
            };
            *cache = Some((settings.clone(), table));
        }
        f(&cache.as_ref().expect("filled above").1)
    })
}

/// Settings from an edited table, checked.
fn from_table(t: toml::Table) -> Result<Settings, String> {
    let s: Settings = toml::Value::Table(t)
        .try_into()
        .map_err(|e: toml::de::Error| e.message().trim().to_string())?;
    s.validate().map_err(|e| e.to_string())?;
    Ok(s)
}

/// The value of `table.key` (absent: an optional field that is not set).
pub fn field_value(settings: &Settings, field: &str) -> Option<toml::Value> {
    let (table, key) = field.split_once('.')?;
    with_table(settings, |t| t.get(table)?.get(key).cloned())
}

/// The number `v` brought into `range`: rounded to an integer, or to the nearest power of two,
/// or clamped; as the TOML value the field takes.
pub fn clamp_to(range: Range, v: f64) -> toml::Value {
    match range {
        Range::Int { lo, hi } => {
            let v = if v.is_finite() { v.round() as i64 } else { lo };
            toml::Value::Integer(v.clamp(lo, hi))
        }
        Range::PowerOfTwo { lo, hi } => {
            let v = if v.is_finite() { v.max(1.0) } else { lo as f64 };
            let p = 2f64.powf(v.log2().round()) as i64;
            let lo_p = (lo.max(1) as u64).next_power_of_two() as i64;
            let hi_p = if (hi as u64).is_power_of_two() {
                hi
            } else {
                ((hi as u64).next_power_of_two() / 2) as i64
            };
            toml::Value::Integer(p.clamp(lo_p, hi_p))
        }
        Range::Float { lo, hi } => {
            let v = if v.is_finite() { v } else { lo };
            toml::Value::Float(v.clamp(lo, hi))
        }
    }
}

/// The settings with `table.key` set to `v` brought into `range`; an error (the old settings
/// kept) when the whole does not validate.
pub fn with_field(
    settings: &Settings,
    field: &str,
    range: Range,
    v: f64,
) -> Result<Settings, String> {
    set_value(settings, field, clamp_to(range, v))
}

/// The settings with `table.key` set to `value` as it is.
pub fn set_value(settings: &Settings, field: &str, value: toml::Value) -> Result<Settings, String> {
    let (table, key) = field
        .split_once('.')
        .ok_or_else(|| format!("`{field}` is not table.key"))?;
    let mut t = table_of(settings);
    let tab = t
        .get_mut(table)
        .and_then(|v| v.as_table_mut())
        .ok_or_else(|| format!("no settings table `{table}`"))?;
    tab.insert(key.to_string(), value);
    from_table(t)
}

/// The settings with technique `table` switched on or off.
pub fn with_switch(settings: &Settings, table: &str, on: bool) -> Result<Settings, String> {
    set_value(
        settings,
        &format!("{table}.enabled"),
        toml::Value::Boolean(on),
    )
}

/// Each technique's `enabled` switch, `(technique, on)`, from the cached table.
pub fn switches(settings: &Settings) -> Vec<(String, bool)> {
    with_table(settings, |t| {
        t.iter()
            .filter_map(|(table, v)| {
                let on = v.as_table()?.get("enabled")?.as_bool()?;
                Some((table.clone(), on))
            })
            .collect()
    })
}

/// Every on/off field other than the techniques' switches, as `table.key`.
pub fn bool_fields(settings: &Settings) -> Vec<(String, bool)> {
    with_table(settings, |t| {
        let mut out = Vec::new();
        for (table, values) in t {
            let Some(values) = values.as_table() else {
                continue;
            };
            for (key, v) in values {
                if let (Some(b), false) = (v.as_bool(), key == "enabled") {
                    out.push((format!("{table}.{key}"), b));
                }
            }
        }
        out
    })
}

/// `preset`'s settings with the sky (clock, place, weather, sun and sky switches) kept: a
/// preset changes quality, not the time of day.
pub fn with_preset(settings: &Settings, preset: hikari_render::Preset) -> Settings {
    Settings {
        sky: settings.sky.clone(),
        ..Settings::preset(preset)
    }
}

/// The debug view after `current` in `names` (`None`: the final image); after the last one,
/// the final image again.
pub fn next_view(names: &[String], current: Option<&str>) -> Option<String> {
    match current.and_then(|c| names.iter().position(|n| n == c)) {
        None => names.first().cloned(),
        Some(i) => names.get(i + 1).cloned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clock_steps_and_plays_around_midnight() {
        let mut c = Clock::of(&Settings::default());
        assert_eq!(c.hh_mm(), "12:00");
        c.step(TIME_STEP_S);
        assert_eq!(c.hh_mm(), "12:30");
        c.seconds = 23.75 * 3600.0;
        c.step(TIME_STEP_S);
        assert_eq!(c.hh_mm(), "00:15");
        c.step(-TIME_STEP_S);
        assert_eq!(c.hh_mm(), "23:45");
        assert!(!c.advance(10.0), "a stopped clock does not move");
        c.playing = true;
        c.seconds = 6.0 * 3600.0;
        assert!(c.advance(10.0));
        assert_eq!(c.hh_mm(), "07:00", "one hour every ten seconds by default");
        c.rate_h_per_10s = 2.0;
        c.advance(5.0);
        assert_eq!(c.hh_mm(), "08:00");
        assert_eq!(parse_time("7:05"), Some(7.0 * 3600.0 + 300.0));
        assert_eq!(parse_time("23:59:59"), Some(86_399.0));
        assert_eq!(parse_time("24:00"), None);
        assert_eq!(parse_time("noon"), None);
    }

    #[test]
    fn fields_are_clamped_to_their_declared_ranges() {
        let s = Settings::default();
        for (field, range) in Settings::fields() {
            let Some(v) = field_value(&s, &field) else {
                continue;
            };
            // Every field takes values far outside its range as its nearest limit.
            for far in [-1e12, 1e12] {
                let edited = with_field(&s, &field, range, far)
                    .unwrap_or_else(|e| panic!("{field} = {far}: {e}"));
                let got = field_value(&edited, &field).unwrap();
                let (lo, hi) = match range {
                    Range::Int { lo, hi } | Range::PowerOfTwo { lo, hi } => (lo as f64, hi as f64),
                    Range::Float { lo, hi } => (lo, hi),
                };
                let g = got
                    .as_float()
                    .or(got.as_integer().map(|i| i as f64))
                    .unwrap();
                assert!((lo..=hi).contains(&g), "{field}: {g} outside {lo}..{hi}");
            }
            assert_eq!(v.type_str(), field_value(&s, &field).unwrap().type_str());
        }
        let r = Range::PowerOfTwo { lo: 256, hi: 4096 };
        assert_eq!(clamp_to(r, 1000.0), toml::Value::Integer(1024));
        assert_eq!(clamp_to(r, 3.0), toml::Value::Integer(256));
        assert_eq!(clamp_to(r, f64::NAN), toml::Value::Integer(256));
        let r = Range::Int { lo: 1, hi: 8 };
        assert_eq!(clamp_to(r, 3.6), toml::Value::Integer(4));
        let r = Range::Float { lo: 0.0, hi: 1.0 };
        assert_eq!(clamp_to(r, f64::INFINITY), toml::Value::Float(0.0));
    }

    #[test]
    fn an_edit_changes_its_field_only_and_a_bad_one_keeps_the_settings() {
        let s = Settings::default();
        let (field, range) = Settings::fields()
            .into_iter()
            .find(|(f, _)| f == "taa.jitter_samples")
            .expect("taa.jitter_samples is a field");
        let edited = with_field(&s, &field, range, 4.0).unwrap();
        assert_eq!(edited.taa.jitter_samples, 4);
        assert_eq!(
            Settings {
                taa: s.taa.clone(),
                ..edited.clone()
            },
            s
        );
        assert!(set_value(&s, "taa.jitter_samples", toml::Value::String("x".into())).is_err());
        assert!(set_value(&s, "nope.x", toml::Value::Integer(1)).is_err());
        assert!(set_value(&s, "taa.no_such_key", toml::Value::Integer(1)).is_err());
    }

    #[test]
    fn switches_presets_and_booleans() {
        let s = Settings::default();
        for (table, on) in s.switches() {
            let flipped = with_switch(&s, table, !on).unwrap();
            let now = flipped.switches();
            assert!(now.contains(&(table, !on)), "{table}");
        }
        assert!(
            bool_fields(&s)
                .iter()
                .all(|(f, _)| !f.ends_with(".enabled")),
            "switches are listed apart"
        );
        let mut moved = s.clone();
        moved.sky.time = "06:30".into();
        let low = with_preset(&moved, hikari_render::Preset::Low);
        assert_eq!(low.sky.time, "06:30");
        assert_eq!(
            low.taa,
            Settings::preset(hikari_render::Preset::Low).taa,
            "the preset's quality"
        );
    }

    #[test]
    fn v_cycles_through_the_views_and_back_to_the_final_image() {
        let names: Vec<String> = ["gbuffer.normal", "gbuffer.depth"]
            .map(String::from)
            .to_vec();
        let a = next_view(&names, None);
        assert_eq!(a.as_deref(), Some("gbuffer.normal"));
        let b = next_view(&names, a.as_deref());
        assert_eq!(b.as_deref(), Some("gbuffer.depth"));
        assert_eq!(next_view(&names, b.as_deref()), None);
        assert_eq!(
            next_view(&names, Some("gone")).as_deref(),
            Some("gbuffer.normal")
        );
        assert_eq!(next_view(&[], None), None);
    }
}
