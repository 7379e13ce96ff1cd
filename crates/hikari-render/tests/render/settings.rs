//! Settings as a user writes them: every bounded field of every technique (`Settings::fields`)
//! at both ends of its range is accepted, just outside either end or non-finite is refused
//! with an error naming the field, from every preset, through the settings file's tables and
//! through `--set` overrides alike; and the presets themselves are valid and ordered.

use hikari_render::settings::{Range, SettingError};
use hikari_render::{Preset, Settings};

/// A TOML literal for `v` that TOML reads back as a float (with a point or exponent).
fn float_literal(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{v:?}")
    }
}

/// In-range values (ends of the range) and refused values (just outside, not a power of two
/// where one is needed, non-finite), as TOML literals.
fn cases(range: Range) -> (Vec<String>, Vec<String>) {
    let non_finite = ["nan", "inf", "-inf"].map(String::from);
    match range {
        Range::Int { lo, hi } => (
            vec![lo.to_string(), hi.to_string()],
            [(lo - 1).to_string(), (hi + 1).to_string()]
                .into_iter()
                .chain(non_finite)
                .collect(),
        ),
        Range::PowerOfTwo { lo, hi } => (
            vec![lo.to_string(), hi.to_string()],
            [
                (lo / 2).to_string(),
                (hi * 2).to_string(),
                // Inside the bounds, but not a power of two.
                (lo + 1).to_string(),
                (hi - 1).to_string(),
            ]
            .into_iter()
            .chain(non_finite)
            .collect(),
        ),
        Range::Float { lo, hi } => {
            // Outside by a thousandth of the range: far more than f32 rounding of the value
            // (the fields are f32), so "just outside" stays outside after parsing.
            let step = (hi - lo) * 1e-3;
            (
                vec![float_literal(lo), float_literal(hi)],
                [float_literal(lo - step), float_literal(hi + step)]
                    .into_iter()
                    .chain(non_finite)
                    .collect(),
            )
        }
    }
}

fn range_bounds(range: Range) -> (String, String) {
    match range {
        Range::Int { lo, hi } | Range::PowerOfTwo { lo, hi } => (lo.to_string(), hi.to_string()),
        Range::Float { lo, hi } => (lo.to_string(), hi.to_string()),
    }
}

/// Settings from `preset` with `field` (`table.key`) set to `value` in the settings file's
/// table, and the same through a `--set` override; both must agree.
fn read(preset: Preset, field: &str, value: &str) -> Result<Settings, SettingError> {
    let (table, key) = field.split_once('.').unwrap();
    let text = format!("[{table}]\n{key} = {value}\n");
    let doc: toml::Table = text
        .parse()
        .unwrap_or_else(|e| panic!("test TOML {text:?}: {e}"));
    let from_file = Settings::from_toml(Some(preset), doc, &[]);
    let from_set = Settings::from_toml(
        Some(preset),
        toml::Table::new(),
        &[(field.to_string(), value.to_string())],
    );
    assert_eq!(
        from_file, from_set,
        "{preset}: {field} = {value} from a file and from --set differ"
    );
    from_file
}

/// The value of `field` in `settings`, as TOML holds it.
fn value_of(settings: &Settings, field: &str) -> toml::Value {
    let doc: toml::Table = settings.to_toml().parse().unwrap();
    let (table, key) = field.split_once('.').unwrap();
    doc[table][key].clone()
}

#[test]
fn every_field_accepts_its_range_and_refuses_what_lies_outside() {
    let fields = Settings::fields();
    // The check below must have fields to check: the shadow maps' alone have seven.
    assert!(fields.len() >= 8, "only {} bounded fields", fields.len());
    let mut failures = Vec::new();
    for preset in Preset::ALL {
        for (field, range) in &fields {
            let (accepted, refused) = cases(*range);
            for v in &accepted {
                match read(preset, field, v) {
                    Ok(s) => {
                        // Accepted and kept: the field holds the value written.
                        let got = value_of(&s, field);
                        let want: f64 = v.parse().unwrap();
                        let got = got
                            .as_float()
                            .or_else(|| got.as_integer().map(|i| i as f64));
                        if got != Some(want) {
                            failures.push(format!(
                                "{preset}: {field} = {v} accepted but reads {got:?}"
                            ));
                        }
                    }
                    Err(e) => failures.push(format!("{preset}: {field} = {v} refused: {e}")),
                }
            }
            for v in &refused {
                match read(preset, field, v) {
                    Ok(_) => failures.push(format!("{preset}: {field} = {v} accepted")),
                    Err(e) => {
                        let text = e.to_string();
                        let (lo, hi) = range_bounds(*range);
                        if !text.contains(field.as_str()) {
                            failures.push(format!(
                                "{preset}: {field} = {v}: the error does not name the field: \
                                 {text}"
                            ));
                        } else if !(text.contains(&lo) && text.contains(&hi)) {
                            failures.push(format!(
                                "{preset}: {field} = {v}: the error does not give the range \
                                 {lo} to {hi}: {text}"
                            ));
                        }
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn every_preset_is_valid() {
    for preset in Preset::ALL {
        let s = Settings::preset(preset);
        s.validate()
            .unwrap_or_else(|e| panic!("preset {preset} is out of range: {e}"));
        // And a preset read through TOML is the preset.
        let read = Settings::from_toml(Some(preset), toml::Table::new(), &[]).unwrap();
        assert_eq!(read, s, "preset {preset} read through TOML");
    }
    assert_eq!(Settings::preset(Preset::High), Settings::default());
}

#[test]
fn higher_presets_never_lower_resolutions_counts_or_distances() {
    // Fields that buy quality with more texels, cascades or reach: low <= medium <= high <=
    // ultra. Named here so a new field of that kind has to be added on purpose.
    let ordered = [
        "sun_shadows.resolution",
        "sun_shadows.cascades",
        "sun_shadows.max_distance_m",
    ];
    let fields = Settings::fields();
    for field in ordered {
        assert!(
            fields.iter().any(|(f, _)| f == field),
            "{field} is no longer a bounded field"
        );
        let values: Vec<f64> = Preset::ALL
            .iter()
            .map(|&p| {
                let v = value_of(&Settings::preset(p), field);
                v.as_float()
                    .or_else(|| v.as_integer().map(|i| i as f64))
                    .unwrap_or_else(|| panic!("{p}: {field} is {v}"))
            })
            .collect();
        assert!(
            values.windows(2).all(|w| w[0] <= w[1]),
            "{field} by preset (low, medium, high, ultra): {values:?}"
        );
    }
    // And ultra is more than low somewhere, or the presets are one preset.
    assert_ne!(
        Settings::preset(Preset::Low),
        Settings::preset(Preset::Ultra)
    );
}
