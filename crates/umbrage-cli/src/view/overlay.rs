//! The egui overlay: what the frame did (fps, frame time, GPU ms per pass, shadow triangles
//! by case, bytes sent, light–caster pairs kept and replanned), the settings and the control mode, and the same controls as widgets;
//! the right-click menu of control modes. Drawn by egui-ash-renderer straight into the
//! swapchain image after the blit of the renderer's output.

use super::controls::Mode;
use glam::Vec3;
use std::collections::HashMap;
use umbrage_render::{Counter, RenderTechnique, Stats, View};

/// Lights whose GPU times the overlay lists one by one (the rest are counted).
const PER_LIGHT_SHOWN: usize = 8;

/// What the overlay shows.
pub struct Shown<'a> {
    /// Frames per second over the last second.
    pub fps: f64,
    /// CPU wall time of the last frame, ms.
    pub frame_ms: f64,
    /// The last finished frame's stats.
    pub stats: Option<&'a Stats>,
    /// The technique list `M` cycles, and the current one's index.
    pub techniques: &'a [RenderTechnique],
    /// Index into `techniques`.
    pub technique: usize,
    /// The counter.
    pub counter: Counter,
    /// The view.
    pub view: View,
    /// The control mode.
    pub mode: Mode,
    /// The selected caster's name.
    pub caster: &'a str,
    /// The selected light's index and position (as drawn).
    pub light: Option<(usize, Vec3)>,
    /// The scene's time, s, and whether it is paused.
    pub time: f64,
    /// Animation paused.
    pub paused: bool,
    /// Fallbacks and refusals to tell the user (present mode, format, techniques refused).
    pub notes: &'a [String],
    /// Present mode and surface format in use.
    pub present: String,
}

/// What the user changed through the overlay's widgets this frame.
#[derive(Default, Debug)]
pub struct Changes {
    /// A new technique index.
    pub technique: Option<usize>,
    /// A new counter.
    pub counter: Option<Counter>,
    /// A new view.
    pub view: Option<View>,
    /// A new control mode (widgets or the right-click menu).
    pub mode: Option<Mode>,
    /// The selected light's new position (sliders).
    pub light_position: Option<Vec3>,
}

/// Shadow triangles summed per McGuire case over every light and caster.
pub fn triangles_by_case(stats: &Stats) -> Vec<(String, u64)> {
    let mut by: HashMap<String, u64> = HashMap::new();
    for l in &stats.lights {
        for c in &l.casters {
            *by.entry(c.case.name().to_string()).or_default() += c.triangles.total();
        }
    }
    let mut v: Vec<_> = by.into_iter().collect();
    v.sort();
    v
}

/// The light–caster pairs the frame drew, how many were drawn from plans kept across frames
/// and how many planned again (`PassSettings::keep`; `--no-keep`: every one planned), and the
/// kept lists' bytes and evictions.
pub fn pairs_line(stats: &Stats) -> String {
    let t = &stats.totals;
    format!(
        "pairs {}: kept {}, replanned {}  (kept lists {:.1} KiB, {} evicted)",
        t.pairs_total,
        t.pairs_kept,
        t.pairs_replanned,
        t.kept_bytes as f64 / 1024.0,
        t.kept_evictions
    )
}

/// Builds the overlay's widgets; `menu_at`: where the right-click menu is open (window
/// points), cleared when it closes.
pub fn ui(ctx: &egui::Context, s: &Shown, menu_at: &mut Option<egui::Pos2>) -> Changes {
    let mut ch = Changes::default();
    egui::Window::new("umbrage").default_pos([8.0, 8.0]).resizable(false).show(ctx, |ui| {
        ui.label(format!("{:.1} fps  {:.2} ms/frame  t = {:.2} s{}", s.fps, s.frame_ms, s.time, if s.paused { " (paused)" } else { "" }));
        if let Some(st) = s.stats {
            ui.label(pairs_line(st));
            match &st.gpu_ms {
                Some(g) => {
                    ui.label(format!(
                        "GPU ms: depth {:.2}  shadow {:.2}  illuminate {:.2}  frame {:.2}",
                        g.depth, g.shadow, g.illuminate, g.frame
                    ));
                    // The first lights only: a level's hundred lights would fill the window.
                    let per: Vec<String> =
                        g.per_light.iter().take(PER_LIGHT_SHOWN).map(|l| format!("{:.2}+{:.2}", l.shadow, l.illuminate)).collect();
                    let more = match g.per_light.len().saturating_sub(PER_LIGHT_SHOWN) {
                        0 => String::new(),
                        n => format!("  (+{n} more)"),
                    };
                    ui.label(format!("  per light (shadow+illuminate): {}{more}", per.join("  ")));
                }
                None => {
                    ui.label("GPU ms: no timestamps on this device");
                }
            }
            let cases: Vec<String> = triangles_by_case(st).iter().map(|(c, n)| format!("{c} {n}")).collect();
            ui.label(format!("shadow triangles {}: {}", st.totals.triangles.total(), cases.join(", ")));
            ui.label(format!("bytes sent {}  (index {}, vertex {})", st.totals.bytes_sent, st.totals.index_bytes, st.totals.vertex_bytes));
            for w in &st.warnings {
                ui.colored_label(egui::Color32::YELLOW, w);
            }
        }
        ui.label(format!(
            "{} / {} / {}  mode {}  present {}",
            s.techniques.get(s.technique).map(|t| t.name()).unwrap_or("?"),
            s.counter.name(),
            s.view.name(),
            s.mode.name(),
            s.present
        ));
        for n in s.notes {
            ui.colored_label(egui::Color32::YELLOW, n);
        }
        egui::CollapsingHeader::new("controls").default_open(false).show(ui, |ui| controls(ui, s, &mut ch));
    });
    menu(ctx, menu_at, &mut ch);
    ch
}

/// The settings and the selected light as widgets.
fn controls(ui: &mut egui::Ui, s: &Shown, ch: &mut Changes) {
    {
        let name = |t: &RenderTechnique| t.name().to_string();
        let mut t = s.technique;
        egui::ComboBox::from_label("method (M)").selected_text(s.techniques.get(t).map(name).unwrap_or_default()).show_ui(ui, |ui| {
            for (i, tech) in s.techniques.iter().enumerate() {
                ui.selectable_value(&mut t, i, name(tech));
            }
        });
        if t != s.technique {
            ch.technique = Some(t);
        }
        let mut c = s.counter;
        egui::ComboBox::from_label("counter (C)").selected_text(c.name()).show_ui(ui, |ui| {
            for v in [Counter::Stencil, Counter::Float] {
                ui.selectable_value(&mut c, v, v.name());
            }
        });
        if c != s.counter {
            ch.counter = Some(c);
        }
        let mut v = s.view;
        egui::ComboBox::from_label("view (V)").selected_text(v.name()).show_ui(ui, |ui| {
            for x in [View::Shaded, View::Volumes, View::Stencil] {
                ui.selectable_value(&mut v, x, x.name());
            }
        });
        if v != s.view {
            ch.view = Some(v);
        }
        let mut m = s.mode;
        ui.horizontal(|ui| {
            ui.label("mode (1/2/3, right-click):");
            for x in [Mode::Scene, Mode::Model, Mode::Light] {
                ui.selectable_value(&mut m, x, x.name());
            }
        });
        if m != s.mode {
            ch.mode = Some(m);
        }
        ui.label(format!("caster (Tab in model mode): {}", s.caster));
        if let Some((i, p)) = s.light {
            ui.label(format!("light {i} (Tab in light mode)"));
            let mut q = p;
            for (axis, v) in ["x", "y", "z"].iter().zip(q.as_mut()) {
                ui.add(egui::Slider::new(v, -20.0..=20.0).text(*axis));
            }
            if q != p {
                ch.light_position = Some(q);
            }
        }
        ui.label("drag: turn, Ctrl: move X/Y, Shift: move Z, wheel: zoom");
        ui.label("Space: pause, P/F12: screenshot, H: hide, Esc: quit");
    }
}

/// Only the right-click menu (the overlay is hidden).
pub fn menu_only(ctx: &egui::Context, menu_at: &mut Option<egui::Pos2>) -> Changes {
    let mut ch = Changes::default();
    menu(ctx, menu_at, &mut ch);
    ch
}

/// The right-click menu of control modes, open at `menu_at`.
fn menu(ctx: &egui::Context, menu_at: &mut Option<egui::Pos2>, ch: &mut Changes) {
    if let Some(at) = *menu_at {
        let mut close = false;
        egui::Area::new(egui::Id::new("umbrage-mode-menu")).fixed_pos(at).order(egui::Order::Foreground).show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                for x in [Mode::Scene, Mode::Model, Mode::Light] {
                    if ui.button(format!("{} mode", x.name())).clicked() {
                        ch.mode = Some(x);
                        close = true;
                    }
                }
            });
        });
        if close || (ctx.input(|i| i.pointer.any_click()) && !ctx.is_pointer_over_egui()) {
            *menu_at = None;
        }
    }
}
