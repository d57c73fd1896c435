//! SVG plots (plotters): every panel has axes with units and a legend.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Error;

/// One curve of a panel.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Colour.
    pub color: RGBColor,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
}

/// One panel: title, axis labels with units, curves.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// X axis label with unit.
    pub x_label: String,
    /// Y axis label with unit.
    pub y_label: String,
    /// Logarithmic y axis (non-positive values are clipped to the smallest positive one).
    pub log_y: bool,
    /// Legend in the lower right corner instead of the upper right (for curves that end high).
    pub legend_lower_right: bool,
    /// Curves.
    pub series: Vec<Series>,
}

/// Colours used consistently across all plots.
pub mod colors {
    use plotters::style::RGBColor;
    /// ANCF.
    pub const ANCF: RGBColor = RGBColor(31, 119, 180);
    /// GEBF.
    pub const GEBF: RGBColor = RGBColor(214, 39, 40);
    /// External references, in order.
    pub const REFS: [RGBColor; 4] =
        [RGBColor(40, 40, 40), RGBColor(44, 160, 44), RGBColor(148, 103, 189), RGBColor(255, 127, 14)];
    /// Extra curves.
    pub const EXTRA: [RGBColor; 4] =
        [RGBColor(23, 190, 207), RGBColor(188, 189, 34), RGBColor(140, 86, 75), RGBColor(227, 119, 194)];
}

fn finite_range(it: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) =
        it.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    (lo <= hi).then_some((lo, hi))
}

fn pad(lo: f64, hi: f64) -> (f64, f64) {
    if hi - lo < 1e-12 * (1.0 + lo.abs().max(hi.abs())) {
        let d = if lo == 0.0 { 1e-3 } else { 0.05 * lo.abs() };
        (lo - d, hi + d)
    } else {
        let d = 0.05 * (hi - lo);
        (lo - d, hi + d)
    }
}

fn legend_position(p: &Panel) -> SeriesLabelPosition {
    if p.legend_lower_right { SeriesLabelPosition::LowerRight } else { SeriesLabelPosition::UpperRight }
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let xs = finite_range(p.series.iter().flat_map(|s| s.points.iter().map(|q| q.0)));
    let (x0, x1) = xs.map(|(a, b)| if b > a { (a, b) } else { (a, a + 1.0) }).unwrap_or((0.0, 1.0));
    let mut chart = ChartBuilder::on(area);
    chart.caption(&p.title, ("sans-serif", 18)).margin(8).x_label_area_size(40).y_label_area_size(78);
    let label_style = ("sans-serif", 14);
    if p.log_y {
        let ys = finite_range(p.series.iter().flat_map(|s| s.points.iter().map(|q| q.1).filter(|v| *v > 0.0)));
        let (lo, hi) = ys.unwrap_or((1e-12, 1.0));
        let (lo, hi) = (lo.max(hi * 1e-14) / 2.0, hi * 2.0);
        let mut c = chart.build_cartesian_2d(x0..x1, (lo..hi).log_scale()).map_err(|e| e.to_string())?;
        c.configure_mesh()
            .x_desc(&p.x_label)
            .y_desc(&p.y_label)
            .label_style(label_style)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for s in &p.series {
            let color = s.color;
            c.draw_series(LineSeries::new(s.points.iter().map(|&(x, y)| (x, y.max(lo))), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(&s.label)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2)));
        }
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(label_style)
            .position(legend_position(p))
            .draw()
            .map_err(|e| e.to_string())?;
    } else {
        let ys = finite_range(p.series.iter().flat_map(|s| s.points.iter().map(|q| q.1)));
        let (lo, hi) = ys.map(|(a, b)| pad(a, b)).unwrap_or((-1.0, 1.0));
        let mut c = chart.build_cartesian_2d(x0..x1, lo..hi).map_err(|e| e.to_string())?;
        c.configure_mesh()
            .x_desc(&p.x_label)
            .y_desc(&p.y_label)
            .label_style(label_style)
            .draw()
            .map_err(|e| e.to_string())?;
        for s in &p.series {
            let color = s.color;
            c.draw_series(LineSeries::new(s.points.iter().copied().filter(|q| q.1.is_finite()), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(&s.label)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2)));
        }
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(label_style)
            .position(legend_position(p))
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Draw panels stacked vertically (or in `cols` columns) into one SVG file.
pub fn panels_svg(path: &Path, panels: &[Panel], cols: usize, panel_size: (u32, u32)) -> Result<(), Error> {
    let err = |msg: String| Error::Plot { file: path.display().to_string(), msg };
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(|e| err(e.to_string()))?;
    }
    let cols = cols.max(1);
    let rows = panels.len().div_ceil(cols).max(1);
    let size = (panel_size.0 * cols as u32, panel_size.1 * rows as u32);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let areas = root.split_evenly((rows, cols));
    for (p, a) in panels.iter().zip(areas.iter()) {
        draw_panel(a, p).map_err(&err)?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_svg_with_labels_and_legend() {
        let dir = std::env::temp_dir().join(format!("harness-plot-{}", std::process::id()));
        let path = dir.join("t.svg");
        let panel = |log_y| Panel {
            title: "tip Z".into(),
            x_label: "t [s]".into(),
            y_label: "Z [m]".into(),
            log_y,
            legend_lower_right: log_y,
            series: vec![Series {
                label: "ANCF".into(),
                color: colors::ANCF,
                points: (0..50).map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin().abs() + 1e-3)).collect(),
            }],
        };
        panels_svg(&path, &[panel(false), panel(true)], 1, (600, 300)).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("t [s]") && svg.contains("Z [m]") && svg.contains("ANCF"));
        std::fs::remove_dir_all(dir).ok();
    }
}
