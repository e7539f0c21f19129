//! The suite's plots, each as SVG and PNG (plotters; PNG text from an embedded DejaVu Sans
//! Mono, so no system fonts are needed):
//!
//! - `time_vs_triangles`: GPU shadow ms against caster triangles (tessellation sweep), per
//!   method, with the limit lines (every caster triangle at the small-triangle rate; the
//!   McGuire volumes' fragments at the stencil fill rate);
//! - `time_vs_resolution`: against pixels (bench/fill), with the fill limit line;
//! - `roofline`: every row's fill fraction against its vertex fraction: the diagonal splits
//!   fill-bound from vertex-bound, 100% on an axis is the device's limit;
//! - `pareto`: speed against error on the named scenes, one panel per scene, both axes log,
//!   exact methods on a labelled floor, the Pareto front drawn;
//! - `model_fit`: each row's measured shadow time against the cost model's prediction.

use super::report::{SuiteReport, SuiteRow};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;
use umbrage::error::{Error, Result};

/// Series colours, saturated enough to read as markers and text on white (plotters'
/// `Palette99` has pale yellows and greens from its tenth colour on).
const SERIES: [(u8, u8, u8); 20] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (90, 90, 90),
    (160, 160, 20),
    (23, 160, 180),
    (0, 0, 128),
    (128, 0, 0),
    (0, 110, 110),
    (255, 0, 255),
    (0, 0, 0),
    (210, 105, 30),
    (85, 107, 47),
    (199, 21, 133),
    (70, 130, 180),
    (120, 60, 160),
];

/// The colour of series `i` (cycling through [`SERIES`]).
fn series_colour(i: usize) -> RGBAColor {
    let (r, g, b) = SERIES[i % SERIES.len()];
    RGBColor(r, g, b).to_rgba()
}

static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSansMono.ttf");
const W: u32 = 960;
const H: u32 = 600;

/// Registers the embedded font as "sans-serif" (once).
pub(crate) fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

fn err<E: std::fmt::Debug>(what: &str) -> impl Fn(E) -> Error + '_ {
    move |e| Error::io(format!("plot {what}"), std::io::Error::other(format!("{e:?}")))
}

/// Writes every plot into `dir` and returns the file names.
pub fn write_all(report: &SuiteReport, dir: &Path) -> Result<Vec<String>> {
    register_font();
    let mut out = Vec::new();
    macro_rules! emit {
        ($name:expr, $f:ident) => {{
            let p = dir.join(format!("{}.svg", $name));
            {
                let root = SVGBackend::new(&p, (W, H)).into_drawing_area();
                $f(report, root)?;
            }
            out.push(format!("{}.svg", $name));
            let mut buf = vec![0u8; (W * H * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
                $f(report, root)?;
            }
            let rgba: Vec<u8> = buf.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 255]).collect();
            umbrage_render::output::write_png(&dir.join(format!("{}.png", $name)), W, H, &rgba)?;
            out.push(format!("{}.png", $name));
        }};
    }
    emit!("time_vs_triangles", time_vs_triangles);
    emit!("time_vs_resolution", time_vs_resolution);
    emit!("roofline", roofline);
    emit!("pareto", pareto);
    emit!("model_fit", model_fit);
    Ok(out)
}

/// Methods in first-seen order.
fn methods<'a>(rows: impl Iterator<Item = &'a SuiteRow>) -> Vec<String> {
    let mut m: Vec<String> = Vec::new();
    for r in rows {
        if !m.contains(&r.method) {
            m.push(r.method.clone());
        }
    }
    m
}

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v.filter(|x| x.is_finite() && *x > 0.0).fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    if lo > hi {
        (0.1, 10.0)
    } else {
        (lo / 1.5, hi * 1.5)
    }
}

/// A log-log chart of GPU shadow ms against `x`, one line per method, plus `limits` lines.
fn sweep_chart<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    x_label: &str,
    rows: &[&SuiteRow],
    limits: &[(String, Vec<(f64, f64)>)],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err(title))?;
    let (x0, x1) = range(rows.iter().map(|r| r.x));
    let (y0, y1) = range(rows.iter().filter_map(|r| r.gpu_shadow_ms).chain(limits.iter().flat_map(|l| l.1.iter().map(|p| p.1))));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err(title))?;
    chart.configure_mesh().x_desc(x_label).y_desc("GPU shadow ms").draw().map_err(err(title))?;
    for (i, m) in methods(rows.iter().copied()).iter().enumerate() {
        let color = series_colour(i);
        let mut pts: Vec<(f64, f64)> = rows.iter().filter(|r| &r.method == m).filter_map(|r| Some((r.x, r.gpu_shadow_ms?))).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
            .map_err(err(title))?
            .label(m.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled()))).map_err(err(title))?;
    }
    for (i, (name, pts)) in limits.iter().enumerate() {
        let color = if i == 0 { BLACK.mix(0.8) } else { RED.mix(0.8) };
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(3)))
            .map_err(err(title))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(3)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(err(title))?;
    root.present().map_err(err(title))?;
    Ok(())
}

fn time_vs_triangles<DB: DrawingBackend>(r: &SuiteReport, root: DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let rows: Vec<&SuiteRow> = r.rows.iter().filter(|x| x.sweep == "tessellation").collect();
    let tri = r.limits.small_tri_mtri_s * 1e6;
    let fill = r.limits.stencil_fill_gfrag_s * 1e9;
    let mut xs: Vec<f64> = rows.iter().map(|x| x.x).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let vertex_line: Vec<(f64, f64)> = xs.iter().map(|&x| (x, x / tri * 1e3)).collect();
    let fill_line: Vec<(f64, f64)> = rows
        .iter()
        .filter(|x| x.method == "mcguire")
        .filter_map(|x| Some((x.x, x.stencil_fragments? as f64 / fill * 1e3)))
        .filter(|p| p.1 > 0.0)
        .collect();
    let title = format!("Shadow time vs caster triangles ({})", r.device);
    let limits = vec![
        (format!("every caster triangle at {:.1} Mtri/s", r.limits.small_tri_mtri_s), vertex_line),
        (format!("mcguire fragments at {:.2} Gfrag/s", r.limits.stencil_fill_gfrag_s), fill_line),
    ];
    sweep_chart(root, &title, "caster triangles", &rows, &limits)
}

fn time_vs_resolution<DB: DrawingBackend>(r: &SuiteReport, root: DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let rows: Vec<&SuiteRow> = r.rows.iter().filter(|x| x.sweep == "resolution").collect();
    let fill = r.limits.stencil_fill_gfrag_s * 1e9;
    let mut fill_line: Vec<(f64, f64)> = rows
        .iter()
        .filter(|x| x.method == "mcguire")
        .filter_map(|x| Some((x.x, x.stencil_fragments? as f64 / fill * 1e3)))
        .filter(|p| p.1 > 0.0)
        .collect();
    fill_line.sort_by(|a, b| a.0.total_cmp(&b.0));
    let title = format!("Shadow time vs resolution, bench/fill ({})", r.device);
    let limits = vec![(format!("mcguire fragments at {:.2} Gfrag/s", r.limits.stencil_fill_gfrag_s), fill_line)];
    sweep_chart(root, &title, "pixels", &rows, &limits)
}

fn roofline<DB: DrawingBackend>(r: &SuiteReport, root: DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let title = format!("Each pass against the limits: fill vs vertex fraction ({})", r.device);
    root.fill(&WHITE).map_err(err(&title))?;
    let rows: Vec<&SuiteRow> =
        r.rows.iter().filter(|x| x.fill_fraction.is_some_and(|f| f > 0.0) && x.vertex_fraction.is_some_and(|f| f > 0.0)).collect();
    let (a0, a1) = range(rows.iter().flat_map(|x| [x.fill_fraction.unwrap_or(1.0), x.vertex_fraction.unwrap_or(1.0)]).chain([1.0]));
    let mut chart = ChartBuilder::on(&root)
        .caption(&title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((a0..a1).log_scale(), (a0..a1).log_scale())
        .map_err(err(&title))?;
    chart
        .configure_mesh()
        .x_desc("fill fraction (model's fill terms / time)")
        .y_desc("vertex fraction (model's vertex terms / time)")
        .draw()
        .map_err(err(&title))?;
    chart.draw_series(LineSeries::new(vec![(a0, a0), (a1, a1)], BLACK.stroke_width(1))).map_err(err(&title))?.label("fill = vertex");
    chart
        .draw_series(LineSeries::new(vec![(1.0, a0), (1.0, a1)], RED.mix(0.6).stroke_width(2)))
        .map_err(err(&title))?
        .label("limit (100%)");
    chart.draw_series(LineSeries::new(vec![(a0, 1.0), (a1, 1.0)], RED.mix(0.6).stroke_width(2))).map_err(err(&title))?;
    let sweeps =
        ["scenes", "resolution", "tessellation", "lights", "light_distance", "casters"].into_iter().chain(super::sweeps::ONE_FACTOR);
    for (i, sweep) in sweeps.chain(["caps", "ablation"]).enumerate() {
        let color = series_colour(i);
        let pts: Vec<(f64, f64)> =
            rows.iter().filter(|x| x.sweep == sweep).filter_map(|x| Some((x.fill_fraction?, x.vertex_fraction?))).collect();
        if pts.is_empty() {
            continue;
        }
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(err(&title))?
            .label(sweep)
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(err(&title))?;
    root.present().map_err(err(&title))?;
    Ok(())
}

/// One label for rows of one technique read two ways: `shadowmap-512 (taps, gather)` for
/// `shadowmap-512` and `shadowmap-512-gather`; other names joined by commas.
fn join_variants(names: &[String]) -> String {
    match names {
        [a, b] | [b, a] if super::classic::taps_label_of(b) == Some(a.as_str()) => format!("{a} (taps, gather)"),
        _ => names.join(", "),
    }
}

fn pareto<DB: DrawingBackend>(r: &SuiteReport, root: DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let title = format!("Speed against error, named scenes ({})", r.device);
    root.fill(&WHITE).map_err(err(&title))?;
    let rows: Vec<&SuiteRow> =
        r.rows.iter().filter(|x| x.sweep == "scenes" && x.error_fraction.is_some() && x.gpu_shadow_ms.is_some()).collect();
    // Error on a log axis; exact methods (no mismatched pixel) sit on a labelled floor a
    // decade below the smallest error measured.
    let smallest = rows.iter().filter_map(|x| x.error_fraction).filter(|e| *e > 0.0).fold(f64::INFINITY, f64::min) * 100.0;
    let floor = if smallest.is_finite() { smallest / 10.0 } else { 1e-4 };
    let e_max = rows.iter().filter_map(|x| x.error_fraction).fold(0.0f64, f64::max) * 100.0;
    let (y0, y1) = (floor / 3.0, (e_max.max(floor * 10.0)) * 3.0);
    let (x0, x1) = range(rows.iter().filter_map(|x| x.gpu_shadow_ms));
    let mut scenes: Vec<&str> = Vec::new();
    for x in &rows {
        if !scenes.contains(&x.scene.as_str()) {
            scenes.push(&x.scene);
        }
    }
    let (top, body) = root.split_vertically(30);
    top.titled(&title, ("sans-serif", 18)).map_err(err(&title))?;
    // One panel per scene, stacked: each plot as wide as the image less its exact-method list.
    let areas = body.split_evenly((scenes.len().max(1), 1));
    let all_methods = methods(rows.iter().copied());
    for (panel, scene) in areas.iter().zip(scenes) {
        // The plot, and to its right a column listing the exact methods (which share the
        // floor), so the list never covers a point or its label.
        let (pw, _) = panel.dim_in_pixel();
        let (area, list) = panel.split_horizontally(pw.saturating_sub(190));
        let mut chart = ChartBuilder::on(&area)
            .caption(format!("{scene} (green: the Pareto front)"), ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(65)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(err(&title))?;
        chart
            .configure_mesh()
            .x_desc("GPU shadow ms (log)")
            .y_desc("error, % of pixels (log)")
            .y_label_formatter(&|v| if *v <= floor * 1.0001 { "exact".into() } else { format!("{v:.0e}") })
            .draw()
            .map_err(err(&title))?;
        chart.draw_series(LineSeries::new(vec![(x0, floor), (x1, floor)], BLACK.mix(0.4).stroke_width(1))).map_err(err(&title))?;
        chart
            .draw_series(std::iter::once(Text::new("exact: 0 mismatched pixels", (x0 * 1.05, floor * 0.6), ("sans-serif", 11).into_font())))
            .map_err(err(&title))?;
        let mut pts: Vec<(f64, f64, String, usize)> = rows
            .iter()
            .filter(|x| x.scene == scene)
            .filter_map(|x| {
                let e = x.error_fraction? * 100.0;
                let i = all_methods.iter().position(|m| m == &x.method).unwrap_or(0);
                Some((x.gpu_shadow_ms?, if e > 0.0 { e.max(floor) } else { floor }, x.method.clone(), i))
            })
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        // The front: each point no other point is both faster and more exact than.
        let mut front: Vec<(f64, f64)> = Vec::new();
        for p in &pts {
            if front.last().is_none_or(|l| p.1 < l.1) {
                if let Some(l) = front.last().copied() {
                    front.push((p.0, l.1));
                }
                front.push((p.0, p.1));
            }
        }
        if let Some(l) = front.last().copied() {
            front.push((x1, l.1));
        }
        chart.draw_series(LineSeries::new(front, RGBColor(40, 120, 40).stroke_width(2))).map_err(err(&title))?;
        // Inexact points are labelled where they sit, one label for the points of equal error
        // (the shadow map read with taps and with gathers: the same comparisons), at the
        // fastest; the exact ones are listed fastest first beside the plot, each with its
        // marker colour.
        let mut exact = Vec::new();
        let mut labelled: Vec<(f64, Vec<String>, f64)> = Vec::new();
        for (t, e, m, i) in &pts {
            let color = series_colour(*i);
            let marker = EmptyElement::at((*t, *e)) + Circle::new((0, 0), 4, color.filled());
            chart.draw_series(std::iter::once(marker)).map_err(err(&title))?;
            if *e <= floor {
                exact.push((format!("{m}  {t:.2} ms"), color));
            } else if let Some(g) = labelled.iter_mut().find(|g| (g.0 - e).abs() <= 1e-9 * e) {
                g.1.push(m.clone());
            } else {
                labelled.push((*e, vec![m.clone()], *t));
            }
        }
        for (e, names, t) in labelled {
            // Right of the point, or left of it in the plot's right third (inside the plot).
            let right_third = (t / x0).ln() > 0.67 * (x1 / x0).ln();
            let font = TextStyle::from(("sans-serif", 11).into_font());
            let (style, dx) = if right_third { (font.pos(Pos::new(HPos::Right, VPos::Top)), -5) } else { (font, 5) };
            let label = Text::new(join_variants(&names), (dx, -14), style);
            chart.draw_series(std::iter::once(EmptyElement::at((t, e)) + label)).map_err(err(&title))?;
        }
        if !exact.is_empty() {
            let (_, h) = list.dim_in_pixel();
            let (x, y0) = (4, h as i32 / 2 - 10 * exact.len() as i32);
            list.draw(&Text::new("exact, fastest first:", (x, y0 - 16), ("sans-serif", 12).into_font())).map_err(err(&title))?;
            for (k, (line, color)) in exact.iter().enumerate() {
                let y = y0 + 15 * k as i32;
                list.draw(&Circle::new((x + 4, y + 6), 4, color.filled())).map_err(err(&title))?;
                list.draw(&Text::new(line.clone(), (x + 14, y), ("sans-serif", 11).into_font())).map_err(err(&title))?;
            }
        }
    }
    root.present().map_err(err(&title))?;
    Ok(())
}

/// The cost model: each row's measured GPU shadow ms against the model's prediction (log-log),
/// the diagonal and the ±30 % band.
fn model_fit<DB: DrawingBackend>(r: &SuiteReport, root: DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let m = &r.model;
    let title = format!(
        "Cost model: measured vs predicted ({}; held-out median {:.0}%, {:.0}% within 30%)",
        r.device,
        m.median_rel_error * 100.0,
        m.within_30_percent * 100.0
    );
    root.fill(&WHITE).map_err(err(&title))?;
    let rows: Vec<&SuiteRow> = r.rows.iter().filter(|x| x.predicted_shadow_ms.is_some() && x.gpu_shadow_ms.is_some()).collect();
    let (a0, a1) = range(rows.iter().flat_map(|x| [x.gpu_shadow_ms.unwrap_or(1.0), x.predicted_shadow_ms.unwrap_or(1.0)]));
    let mut chart = ChartBuilder::on(&root)
        .caption(&title, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((a0..a1).log_scale(), (a0..a1).log_scale())
        .map_err(err(&title))?;
    chart.configure_mesh().x_desc("predicted GPU shadow ms").y_desc("measured GPU shadow ms").draw().map_err(err(&title))?;
    chart.draw_series(LineSeries::new(vec![(a0, a0), (a1, a1)], BLACK.stroke_width(1))).map_err(err(&title))?.label("measured = predicted");
    // The ±30 % band, clipped to the chart.
    let band = [vec![(a0, a0 * 1.3), (a1 / 1.3, a1)], vec![(a0 * 1.3, a0), (a1, a1 / 1.3)]];
    for line in band {
        chart.draw_series(LineSeries::new(line, BLACK.mix(0.3).stroke_width(1))).map_err(err(&title))?;
    }
    for (i, m) in methods(rows.iter().copied()).iter().enumerate() {
        let color = series_colour(i);
        let pts: Vec<(f64, f64)> =
            rows.iter().filter(|x| &x.method == m).filter_map(|x| Some((x.predicted_shadow_ms?, x.gpu_shadow_ms?))).collect();
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(err(&title))?
            .label(m.as_str())
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(("sans-serif", 11))
        .draw()
        .map_err(err(&title))?;
    root.present().map_err(err(&title))?;
    Ok(())
}
