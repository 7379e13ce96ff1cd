//! The panel's widgets. They edit a [`Model`] (copies of what the renderer holds); the app
//! applies what changed after the pass, so that a change reaches the renderer through its
//! setters, validated, and nothing is edited twice.

use std::time::Instant;

use egui::{Color32, RichText};
use hikari_render::settings::Range;
use hikari_render::{Preset, Settings};

use super::keys::KEY_TABLE;
use super::panel::{self, Clock};
use super::stats::Stats;

/// What the panel shows and edits.
pub struct Model<'a> {
    pub picture: Option<(egui::TextureId, [u32; 2])>,
    pub show_panel: bool,
    pub scene: &'a str,
    pub adapter: &'a str,
    pub cameras: Vec<String>,
    /// A camera picked (its index), to jump to.
    pub jump: Option<usize>,
    pub speed: f32,
    pub sun: &'a str,
    pub clock: Clock,
    pub settings: Settings,
    pub preset: Option<Preset>,
    pub view: Option<String>,
    pub names: &'a [String],
    pub stats: &'a mut Stats,
    pub now: Instant,
    pub message: Option<(&'a str, bool)>,
    pub screenshot: bool,
}

/// The whole window: the frame as the background, the panel over it, a message at the bottom.
pub fn draw(ui: &mut egui::Ui, m: &mut Model) {
    let ctx = ui.ctx().clone();
    let screen = ctx.content_rect();
    if let Some((id, _)) = m.picture {
        ctx.layer_painter(egui::LayerId::background()).image(
            id,
            screen,
            egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            Color32::WHITE,
        );
    }
    if m.show_panel {
        egui::Panel::left("hikari.panel")
            .resizable(true)
            .default_size(300.0)
            .frame(egui::Frame::side_top_panel(&ctx.global_style()).multiply_with_opacity(0.92))
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| panel_contents(ui, m));
            });
    }
    if let Some((text, error)) = m.message {
        egui::Area::new(egui::Id::unique("hikari.message"))
            .anchor(egui::Align2::RIGHT_BOTTOM, egui::vec2(-8.0, -8.0))
            .show(&ctx, |ui| {
                egui::Frame::popup(&ctx.global_style()).show(ui, |ui| {
                    let color = if error {
                        Color32::from_rgb(255, 110, 100)
                    } else {
                        Color32::LIGHT_GRAY
                    };
                    ui.label(RichText::new(text).color(color));
                });
            });
    }
}

fn panel_contents(ui: &mut egui::Ui, m: &mut Model) {
    ui.heading("hikari");
    ui.label(format!("{} — {}", m.scene, m.adapter));
    numbers(ui, m);
    egui::CollapsingHeader::new("Camera")
        .default_open(true)
        .show(ui, |ui| {
            ui.add(
                egui::Slider::new(&mut m.speed, 0.05..=500.0)
                    .logarithmic(true)
                    .text("speed m/s"),
            );
            for (i, name) in m.cameras.iter().enumerate() {
                let key = if i < 9 {
                    format!("{} ", i + 1)
                } else {
                    String::new()
                };
                if ui.button(format!("{key}{name}")).clicked() {
                    m.jump = Some(i);
                }
            }
        });
    egui::CollapsingHeader::new("Clock and place")
        .default_open(true)
        .show(ui, |ui| clock(ui, m));
    egui::CollapsingHeader::new("Techniques")
        .default_open(true)
        .show(ui, |ui| techniques(ui, m));
    egui::CollapsingHeader::new("Debug view")
        .default_open(false)
        .show(ui, |ui| {
            let current = m.view.clone().unwrap_or_else(|| "final image".into());
            egui::ComboBox::from_id_salt("hikari.view")
                .selected_text(current)
                .height(400.0)
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut m.view, None, "final image");
                    for n in m.names {
                        ui.selectable_value(&mut m.view, Some(n.clone()), n);
                    }
                });
        });
    egui::CollapsingHeader::new("Settings")
        .default_open(false)
        .show(ui, |ui| settings(ui, m));
    egui::CollapsingHeader::new("Keys")
        .default_open(false)
        .show(ui, |ui| {
            egui::Grid::new("hikari.keys").striped(true).show(ui, |ui| {
                for (k, what) in KEY_TABLE {
                    ui.label(RichText::new(*k).strong());
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
    if ui.button("Screenshot (F12)").clicked() {
        m.screenshot = true;
    }
}

fn clock(ui: &mut egui::Ui, m: &mut Model) {
    let c = &mut m.clock;
    ui.label(format!("light: {}", m.sun));
    let mut hours = c.seconds / 3600.0;
    let label = c.hh_mm();
    if ui
        .add(
            egui::Slider::new(&mut hours, 0.0..=24.0)
                .text(label)
                .show_value(false),
        )
        .changed()
    {
        c.seconds = (hours * 3600.0).clamp(0.0, panel::DAY_S - 1.0);
    }
    ui.horizontal(|ui| {
        ui.label("date");
        ui.add(egui::TextEdit::singleline(&mut c.date).desired_width(90.0));
    });
    ui.add(
        egui::DragValue::new(&mut c.latitude_deg)
            .range(-90.0..=90.0)
            .speed(0.1)
            .prefix("lat "),
    );
    ui.add(
        egui::DragValue::new(&mut c.longitude_deg)
            .range(-180.0..=180.0)
            .speed(0.1)
            .prefix("lon "),
    );
    ui.add(
        egui::DragValue::new(&mut c.utc_offset_h)
            .range(-14.0..=14.0)
            .speed(0.25)
            .prefix("UTC offset h "),
    );
    egui::ComboBox::from_label("weather")
        .selected_text(c.weather.clone())
        .show_ui(ui, |ui| {
            for w in ["clear", "hazy", "overcast"] {
                ui.selectable_value(&mut c.weather, w.to_string(), w);
            }
        });
    ui.horizontal(|ui| {
        ui.checkbox(&mut c.playing, "play (P)");
        ui.add(
            egui::DragValue::new(&mut c.rate_h_per_10s)
                .range(-24.0..=24.0)
                .speed(0.05)
                .suffix(" h / 10 s"),
        );
    });
}

fn techniques(ui: &mut egui::Ui, m: &mut Model) {
    let mut preset = m.preset;
    egui::ComboBox::from_label("preset")
        .selected_text(preset.map_or("custom".to_string(), |p| p.to_string()))
        .show_ui(ui, |ui| {
            for p in Preset::ALL {
                ui.selectable_value(&mut preset, Some(p), p.name());
            }
        });
    if preset != m.preset
        && let Some(p) = preset
    {
        m.settings = panel::with_preset(&m.settings, p);
        m.preset = preset;
    }
    for (table, on) in panel::switches(&m.settings) {
        let mut now = on;
        let label = if table == "ray_traced_gi" {
            "ray_traced_gi (T)".to_string()
        } else {
            table.to_string()
        };
        if ui.checkbox(&mut now, label).changed()
            && let Ok(s) = panel::with_switch(&m.settings, &table, now)
        {
            m.settings = s;
        }
    }
}

fn settings(ui: &mut egui::Ui, m: &mut Model) {
    let fields = Settings::fields();
    let bools = panel::bool_fields(&m.settings);
    let mut tables: Vec<&str> = fields
        .iter()
        .map(|(f, _)| f.split('.').next().unwrap_or(""))
        .chain(bools.iter().map(|(f, _)| f.split('.').next().unwrap_or("")))
        .collect();
    tables.dedup();
    tables.sort();
    tables.dedup();
    for table in tables {
        egui::CollapsingHeader::new(table).show(ui, |ui| {
            for (field, on) in bools
                .iter()
                .filter(|(f, _)| f.starts_with(&format!("{table}.")))
            {
                let mut now = *on;
                let key = field.split_once('.').map_or(field.as_str(), |(_, k)| k);
                if ui.checkbox(&mut now, key).changed()
                    && let Ok(s) = panel::set_value(&m.settings, field, toml::Value::Boolean(now))
                {
                    m.settings = s;
                }
            }
            for (field, range) in fields
                .iter()
                .filter(|(f, _)| f.starts_with(&format!("{table}.")))
            {
                let key = field.split_once('.').map_or(field.as_str(), |(_, k)| k);
                number(ui, m, field, key, *range);
            }
        });
    }
}

/// One bounded field: a widget that cannot leave the declared range.
fn number(ui: &mut egui::Ui, m: &mut Model, field: &str, key: &str, range: Range) {
    let Some(value) = panel::field_value(&m.settings, field) else {
        ui.label(format!("{key}: (unset)"));
        return;
    };
    let Some(v) = value.as_float().or(value.as_integer().map(|i| i as f64)) else {
        return;
    };
    let mut x = v;
    let changed = ui
        .horizontal(|ui| {
            let r = match range {
                Range::Int { lo, hi } => {
                    let mut i = v as i64;
                    let r = ui.add(egui::DragValue::new(&mut i).range(lo..=hi).speed(0.1));
                    x = i as f64;
                    r.changed()
                }
                Range::PowerOfTwo { lo, hi } => {
                    let mut i = v as i64;
                    let mut changed = false;
                    egui::ComboBox::from_id_salt(field)
                        .selected_text(i.to_string())
                        .width(70.0)
                        .show_ui(ui, |ui| {
                            let mut p = 1i64;
                            while p <= hi {
                                if p >= lo {
                                    changed |=
                                        ui.selectable_value(&mut i, p, p.to_string()).changed();
                                }
                                p *= 2;
                            }
                        });
                    x = i as f64;
                    changed
                }
                Range::Float { lo, hi } => {
                    let speed = ((hi - lo) / 500.0).clamp(1e-4, 10.0);
                    ui.add(egui::DragValue::new(&mut x).range(lo..=hi).speed(speed))
                        .changed()
                }
            };
            ui.label(key).on_hover_text(format!("{field}: {range:?}"));
            r
        })
        .inner;
    if changed && x != v {
        match panel::with_field(&m.settings, field, range, x) {
            Ok(s) => m.settings = s,
            Err(e) => log::warn!("{field}: {e}"),
        }
    }
}

fn numbers(ui: &mut egui::Ui, m: &mut Model) {
    let fps = m.stats.fps(m.now);
    let last = m.stats.frames().last().copied();
    ui.label(format!(
        "{fps:.1} fps   frame {:.1} ms   CPU {:.2} ms   GPU {}",
        last.map_or(0.0, |f| f.frame_ms),
        last.map_or(0.0, |f| f.cpu_ms),
        m.stats
            .frames()
            .filter_map(|f| f.gpu_ms)
            .last()
            .map_or("-".into(), |g| format!("{g:.2} ms")),
    ));
    if let Some(us) = m.stats.ui_cpu_us() {
        ui.label(format!(
            "viewer's own CPU (egui + paint): {:.3} ms",
            us / 1000.0
        ));
    }
    match m.stats.rays {
        Some(r) => ui.label(format!(
            "GI: {:.2} rays a pixel, {:.0} % resolved by the pre-trace",
            r.rays_per_pixel,
            r.pretrace_share * 100.0
        )),
        None => ui.label("GI: off"),
    };
    graph(ui, m.stats);
    egui::CollapsingHeader::new("GPU time per pass (median, last second)")
        .default_open(false)
        .show(ui, |ui| {
            egui::Grid::new("hikari.passes")
                .striped(true)
                .show(ui, |ui| {
                    for g in m.stats.table(m.now) {
                        ui.label(RichText::new(&g.technique).strong());
                        ui.label(RichText::new(format!("{:.3}", g.total_ms)).strong());
                        ui.end_row();
                        for (name, ms) in &g.passes {
                            ui.label(format!("  {name}"));
                            ui.label(format!("{ms:.3}"));
                            ui.end_row();
                        }
                    }
                });
        });
}

/// Frame times, oldest to newest: CPU (orange line), GPU (green dots, the timed frames).
fn graph(ui: &mut egui::Ui, stats: &Stats) {
    let (rect, _) = ui.allocate_exact_size(
        egui::vec2(ui.available_width().min(280.0), 50.0),
        egui::Sense::hover(),
    );
    let p = ui.painter_at(rect);
    p.rect_filled(rect, 2.0, Color32::from_black_alpha(120));
    let frames: Vec<_> = stats.frames().collect();
    let top = frames
        .iter()
        .flat_map(|f| [f.cpu_ms, f.gpu_ms.unwrap_or(0.0)])
        .fold(1.0f64, f64::max);
    let n = super::stats::GRAPH_FRAMES as f32;
    let at = |i: usize, ms: f64| {
        egui::pos2(
            rect.left() + rect.width() * (i as f32 + (n - frames.len() as f32)) / n,
            rect.bottom() - rect.height() * (ms / top) as f32,
        )
    };
    let cpu: Vec<egui::Pos2> = frames
        .iter()
        .enumerate()
        .map(|(i, f)| at(i, f.cpu_ms))
        .collect();
    p.add(egui::Shape::line(
        cpu,
        egui::Stroke::new(1.0, Color32::from_rgb(255, 170, 60)),
    ));
    for (i, f) in frames.iter().enumerate() {
        if let Some(g) = f.gpu_ms {
            p.circle_filled(at(i, g), 1.5, Color32::from_rgb(90, 220, 120));
        }
    }
    p.text(
        rect.left_top() + egui::vec2(3.0, 1.0),
        egui::Align2::LEFT_TOP,
        format!("{top:.1} ms  CPU / GPU"),
        egui::FontId::monospace(9.0),
        Color32::GRAY,
    );
}

/// The start-up screen: what is loading and for how long.
pub fn loading(ui: &mut egui::Ui, scene: &str, stage: &str, seconds: f64) {
    egui::CentralPanel::default().show(ui, |ui| {
        ui.vertical_centered(|ui| {
            ui.add_space(ui.available_height() * 0.35);
            ui.heading(format!("hikari: loading {scene}"));
            ui.label(format!("{stage} ({seconds:.0} s)"));
            ui.add(egui::Spinner::new());
        });
    });
}
