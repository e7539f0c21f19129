//! The curves' plots: CPU per frame against lights and against casters, planned every frame
//! and kept, both axes logarithmic (SVG).

use super::curves::CurvePoint;
use super::FrameCostReport;
use plotters::prelude::*;
use std::path::Path;
use umbrage::error::{Error, Result};

fn err<E: std::fmt::Debug>(what: &str) -> impl Fn(E) -> Error + '_ {
    move |e| Error::io(format!("plot {what}"), std::io::Error::other(format!("{e:?}")))
}

/// A series' value at a point.
type Value = fn(&CurvePoint) -> f64;

const W: u32 = 800;
const H: u32 = 480;

/// Writes `lights.svg` and `casters.svg` into `dir`, and each as PNG.
pub fn write(r: &FrameCostReport, dir: &Path) -> Result<()> {
    super::super::plots::register_font();
    let lights =
        ("CPU per frame against lights (bench/level's casters)", "lights", &r.lights_curve[..], (|p| p.lights) as fn(&CurvePoint) -> usize);
    let casters =
        ("CPU per frame against casters (levels of rooms)", "casters", &r.casters_curve[..], (|p| p.casters) as fn(&CurvePoint) -> usize);
    for (name, (title, x_label, points, x)) in [("lights", lights), ("casters", casters)] {
        curve(SVGBackend::new(&dir.join(format!("{name}.svg")), (W, H)).into_drawing_area(), title, x_label, points, x)?;
        let mut buf = vec![0u8; (W * H * 3) as usize];
        curve(BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area(), title, x_label, points, x)?;
        let rgba: Vec<u8> = buf.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 255]).collect();
        umbrage_render::output::write_png(&dir.join(format!("{name}.png")), W, H, &rgba)?;
    }
    Ok(())
}

fn curve<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    x_label: &str,
    points: &[CurvePoint],
    x: fn(&CurvePoint) -> usize,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err(title))?;
    let xs: Vec<f64> = points.iter().map(|p| x(p) as f64).collect();
    let ys = points.iter().flat_map(|p| [p.off_ms, p.kept_ms]).filter(|v| *v > 0.0);
    let (x0, x1) = xs.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let (y0, y1) = ys.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if !(x0 < x1 && y0 <= y1) {
        return Err(Error::input(format!("plot {title}"), "a curve needs at least two points"));
    }
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), (y0 * 0.5..y1 * 2.0).log_scale())
        .map_err(err(title))?;
    chart
        .configure_mesh()
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v}"))
        .x_desc(x_label)
        .y_desc("ms a frame (wall clock of prepare)")
        .draw()
        .map_err(err(title))?;
    let series: [(&str, RGBColor, Value); 2] =
        [("planned every frame (--no-keep)", RGBColor(214, 39, 40), |p| p.off_ms), ("kept", RGBColor(31, 119, 180), |p| p.kept_ms)];
    for (name, colour, y) in series {
        let pts: Vec<(f64, f64)> = points.iter().map(|p| (x(p) as f64, y(p))).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
            .map_err(err(title))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled()))).map_err(err(title))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(err(title))?;
    root.present().map_err(err(title))?;
    Ok(())
}
