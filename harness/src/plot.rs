//! SVG plots (plotters): every panel has axes with units and a legend beside the data.
//!
//! Readable at a glance: each series has its own colour, dash pattern and marker (see
//! [`Style`]), so that curves lying on top of each other stay visible; the legend is drawn in a
//! strip right of the plot area, never over the data; logarithmic axes are drawn as such
//! (`log_x`, `log_y`).

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::Error;

/// Line pattern of a series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dash {
    /// Continuous line.
    #[default]
    Solid,
    /// Long dashes.
    Dashed,
    /// Short dots.
    Dotted,
    /// No line: markers only (e.g. a peer code's single measurement).
    None,
}

/// Marker drawn on a series (at every point of a short series, at about 12 evenly spaced points
/// of a long one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Open circle.
    Circle,
    /// Filled square.
    Square,
    /// Open triangle.
    Triangle,
    /// Cross.
    Cross,
    /// Filled diamond.
    Diamond,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    /// Colour.
    pub color: RGBColor,
    /// Line pattern.
    pub dash: Dash,
    /// Marker, if any.
    pub marker: Option<Marker>,
    /// Line width, px.
    pub width: u32,
}

impl Style {
    /// A solid line of `color`, 2 px, no marker.
    pub const fn solid(color: RGBColor) -> Self {
        Self { color, dash: Dash::Solid, marker: None, width: 2 }
    }
    /// The same style with a dash pattern.
    pub const fn dash(self, dash: Dash) -> Self {
        Self { dash, ..self }
    }
    /// The same style with a marker.
    pub const fn marker(self, marker: Marker) -> Self {
        Self { marker: Some(marker), ..self }
    }
    /// The same style with a line width.
    pub const fn width(self, width: u32) -> Self {
        Self { width, ..self }
    }
    /// How formulation `f` is drawn in `color` where the formulations appear together: the first
    /// of [`Formulation::ALL`](crate::case::Formulation::ALL) dashed with circles on top, the
    /// second solid and wide beneath it, so that either stays visible when the two coincide.
    pub fn of_formulation(f: crate::case::Formulation, color: RGBColor) -> Self {
        [Self::solid(color).dash(Dash::Dashed).marker(Marker::Circle), Self::solid(color).width(3)][f.index()]
    }
    /// The line pattern of formulation `f` in plots without markers: the first solid, the
    /// second dashed.
    pub fn formulation_dash(f: crate::case::Formulation) -> Dash {
        [Dash::Solid, Dash::Dashed][f.index()]
    }
    /// The `i`-th of a set of distinct styles (colour, dash and marker all change with `i`), for
    /// series that have no fixed meaning.
    pub fn nth(i: usize) -> Self {
        const DASHES: [Dash; 3] = [Dash::Solid, Dash::Dashed, Dash::Dotted];
        const MARKERS: [Marker; 5] = [Marker::Circle, Marker::Square, Marker::Triangle, Marker::Cross, Marker::Diamond];
        let p = colors::PALETTE;
        Self { color: p[i % p.len()], dash: DASHES[i % 3], marker: Some(MARKERS[i % 5]), width: 2 }
    }
}

/// One curve of a panel.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// How it is drawn.
    pub style: Style,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// A series.
    pub fn new(label: impl Into<String>, style: Style, points: Vec<(f64, f64)>) -> Self {
        Self { label: label.into(), style, points }
    }
}

/// One panel: title, axis labels with units, curves.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// X axis label with unit.
    pub x_label: String,
    /// Y axis label with unit.
    pub y_label: String,
    /// Logarithmic x axis (non-positive values are dropped).
    pub log_x: bool,
    /// Logarithmic y axis (non-positive values are clipped to the smallest positive one).
    pub log_y: bool,
    /// Widen a linear x axis by 5 % each side, as the y axis is (scattered points, a root locus),
    /// instead of ending it at the data (time histories, sweeps).
    pub pad_x: bool,
    /// Curves.
    pub series: Vec<Series>,
}

/// Colours used consistently across all plots (colour-blind-safe where it matters: the two
/// formulations are blue and vermilion).
pub mod colors {
    use plotters::style::RGBColor;
    /// ANCF.
    pub const ANCF: RGBColor = RGBColor(0, 114, 178);
    /// GEBF.
    pub const GEBF: RGBColor = RGBColor(213, 94, 0);
    /// The colour of formulation `f`.
    pub fn of(f: crate::case::Formulation) -> RGBColor {
        [ANCF, GEBF][f.index()]
    }
    /// External references, in order.
    pub const REFS: [RGBColor; 4] =
        [RGBColor(30, 30, 30), RGBColor(0, 158, 115), RGBColor(204, 121, 167), RGBColor(120, 120, 120)];
    /// Extra curves.
    pub const EXTRA: [RGBColor; 4] =
        [RGBColor(86, 180, 233), RGBColor(230, 159, 0), RGBColor(140, 86, 75), RGBColor(148, 103, 189)];
    /// Distinct colours for series without a fixed meaning.
    pub const PALETTE: [RGBColor; 8] = [
        RGBColor(0, 114, 178),
        RGBColor(213, 94, 0),
        RGBColor(0, 158, 115),
        RGBColor(204, 121, 167),
        RGBColor(30, 30, 30),
        RGBColor(230, 159, 0),
        RGBColor(86, 180, 233),
        RGBColor(140, 86, 75),
    ];
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

/// Range of a log axis: positive values, widened to whole factors.
fn log_range(it: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = finite_range(it.filter(|v| *v > 0.0)).unwrap_or((1e-12, 1.0));
    (lo.max(hi * 1e-14) / 1.5, hi * 1.5)
}

/// Indices of the points of a series of `n` points that carry a marker: all of a short series,
/// about 12 of a long one, shifted by `phase` (the series' index) so that markers of coincident
/// curves do not hide each other.
fn marker_indices(n: usize, phase: usize) -> impl Iterator<Item = usize> {
    let step = if n <= 30 { 1 } else { n / 12 };
    let offset = if step == 1 { 0 } else { (phase * step / 5) % step };
    (offset..n).step_by(step.max(1))
}

fn shape(style: &Style) -> ShapeStyle {
    ShapeStyle { color: style.color.to_rgba(), filled: false, stroke_width: style.width }
}

/// Draw markers `m` of `color` at the points `$pts` with `$draw(iterator of elements)`.
macro_rules! draw_markers {
    ($m:expr, $color:expr, $pts:expr, $draw:expr) => {{
        let line = ShapeStyle { color: $color.to_rgba(), filled: false, stroke_width: 2 };
        let fill = $color.filled();
        let r = 4;
        match $m {
            Marker::Circle => $draw($pts.map(|c| EmptyElement::at(c) + Circle::new((0, 0), r, line))),
            Marker::Square => $draw($pts.map(|c| EmptyElement::at(c) + Rectangle::new([(-r, -r), (r, r)], fill))),
            Marker::Triangle => $draw($pts.map(|c| {
                EmptyElement::at(c) + PathElement::new(vec![(0, -r - 1), (r + 1, r), (-r - 1, r), (0, -r - 1)], line)
            })),
            Marker::Cross => $draw($pts.map(|c| {
                EmptyElement::at(c)
                    + PathElement::new(vec![(-r, -r), (r, r)], line)
                    + PathElement::new(vec![(-r, r), (r, -r)], line)
            })),
            Marker::Diamond => $draw($pts.map(|c| {
                EmptyElement::at(c) + Polygon::new(vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)], fill)
            })),
        }
    }};
}

/// Draw every series of `p` into a built chart; `fix` maps a point to the drawn point (None: drop).
macro_rules! draw_series {
    ($c:expr, $p:expr, $fix:expr) => {{
        for (k, s) in $p.series.iter().enumerate() {
            let pts: Vec<(f64, f64)> = s.points.iter().filter_map(|&q| $fix(q)).collect();
            let st = shape(&s.style);
            match s.style.dash {
                Dash::Solid => {
                    $c.draw_series(LineSeries::new(pts.iter().copied(), st)).map_err(|e| e.to_string())?;
                }
                Dash::Dashed => {
                    $c.draw_series(DashedLineSeries::new(pts.iter().copied(), 10, 6, st)).map_err(|e| e.to_string())?;
                }
                Dash::Dotted => {
                    $c.draw_series(DashedLineSeries::new(pts.iter().copied(), 2, 5, st)).map_err(|e| e.to_string())?;
                }
                Dash::None => {}
            }
            if let Some(m) = s.style.marker {
                let at = marker_indices(pts.len(), k).map(|i| pts[i]);
                draw_markers!(m, s.style.color, at, |els| $c.draw_series(els).map(|_| ()).map_err(|e| e.to_string()))?;
            }
        }
    }};
}

fn sci(v: f64) -> String {
    format!("{v:.0e}")
}

/// Width of the legend strip for the longest label of `panels` (the same for every panel of a
/// file, so that their x axes line up).
fn legend_width(panels: &[Panel]) -> i32 {
    let longest = panels.iter().flat_map(|p| &p.series).map(|s| s.label.chars().count()).max().unwrap_or(0);
    if longest == 0 { 0 } else { (longest as i32 * 7 + 52).clamp(90, 330) }
}

/// Tick labels of a linear axis spanning `lo..hi`: enough decimals to tell neighbouring ticks
/// apart, scientific notation for values that are all tiny or huge.
fn tick_format(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let big = lo.abs().max(hi.abs());
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let sci = !(1e-3..1e6).contains(&big);
    let decimals = ((-(span / 8.0).log10()).ceil().max(0.0) as usize).min(8);
    move |v: &f64| {
        if *v == 0.0 {
            "0".to_string()
        } else if sci {
            format!("{v:.1e}")
        } else {
            format!("{v:.decimals$}")
        }
    }
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel, legend_w: i32) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    // The legend gets its own strip right of the plot.
    let (w, _) = area.dim_in_pixel();
    let (plot, legend) = area.split_horizontally((w as i32 - legend_w).max(200));
    let xs = p.series.iter().flat_map(|s| s.points.iter().map(|q| q.0));
    let ys = p.series.iter().flat_map(|s| s.points.iter().map(|q| q.1));
    let mut chart = ChartBuilder::on(&plot);
    chart.caption(&p.title, ("sans-serif", 18)).margin(8).x_label_area_size(40).y_label_area_size(80);
    let label_style = ("sans-serif", 14);
    match (p.log_x, p.log_y) {
        (false, false) => {
            let (x0, x1) = finite_range(xs)
                .map(|(a, b)| {
                    if p.pad_x {
                        pad(a, b)
                    } else if b > a {
                        (a, b)
                    } else {
                        (a, a + 1.0)
                    }
                })
                .unwrap_or((0.0, 1.0));
            let (lo, hi) = finite_range(ys).map(|(a, b)| pad(a, b)).unwrap_or((-1.0, 1.0));
            let mut c = chart.build_cartesian_2d(x0..x1, lo..hi).map_err(|e| e.to_string())?;
            c.configure_mesh()
                .x_desc(&p.x_label)
                .y_desc(&p.y_label)
                .label_style(label_style)
                .x_label_formatter(&tick_format(x0, x1))
                .y_label_formatter(&tick_format(lo, hi))
                .draw()
                .map_err(|e| e.to_string())?;
            draw_series!(c, p, |q: (f64, f64)| (q.0.is_finite() && q.1.is_finite()).then_some(q));
        }
        (false, true) => {
            let (x0, x1) =
                finite_range(xs).map(|(a, b)| if b > a { (a, b) } else { (a, a + 1.0) }).unwrap_or((0.0, 1.0));
            let (lo, hi) = log_range(ys);
            let mut c = chart.build_cartesian_2d(x0..x1, (lo..hi).log_scale()).map_err(|e| e.to_string())?;
            c.configure_mesh()
                .x_desc(&p.x_label)
                .y_desc(&p.y_label)
                .label_style(label_style)
                .x_label_formatter(&tick_format(x0, x1))
                .y_label_formatter(&|v| sci(*v))
                .draw()
                .map_err(|e| e.to_string())?;
            draw_series!(c, p, |q: (f64, f64)| (q.0.is_finite() && q.1.is_finite()).then_some((q.0, q.1.max(lo))));
        }
        (true, ly) => {
            let (x0, x1) = log_range(xs);
            let (lo, hi) =
                if ly { log_range(ys) } else { finite_range(ys).map(|(a, b)| pad(a, b)).unwrap_or((-1.0, 1.0)) };
            if ly {
                let mut c =
                    chart.build_cartesian_2d((x0..x1).log_scale(), (lo..hi).log_scale()).map_err(|e| e.to_string())?;
                c.configure_mesh()
                    .x_desc(&p.x_label)
                    .y_desc(&p.y_label)
                    .label_style(label_style)
                    .x_label_formatter(&|v| sci(*v))
                    .y_label_formatter(&|v| sci(*v))
                    .draw()
                    .map_err(|e| e.to_string())?;
                draw_series!(c, p, |q: (f64, f64)| (q.0 > 0.0 && q.0.is_finite() && q.1.is_finite())
                    .then_some((q.0, q.1.max(lo))));
            } else {
                let mut c = chart.build_cartesian_2d((x0..x1).log_scale(), lo..hi).map_err(|e| e.to_string())?;
                c.configure_mesh()
                    .x_desc(&p.x_label)
                    .y_desc(&p.y_label)
                    .label_style(label_style)
                    .x_label_formatter(&|v| sci(*v))
                    .y_label_formatter(&tick_format(lo, hi))
                    .draw()
                    .map_err(|e| e.to_string())?;
                draw_series!(c, p, |q: (f64, f64)| (q.0 > 0.0 && q.0.is_finite() && q.1.is_finite()).then_some(q));
            }
        }
    }
    draw_legend(&legend, p)
}

/// The legend in its own strip: a sample of each series' line and marker, then its label.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let y0 = 40;
    for (k, s) in p.series.iter().enumerate() {
        let y = y0 + 22 * k as i32;
        let (x0, x1) = (4, 34);
        let st = shape(&s.style);
        match s.style.dash {
            Dash::Solid => area.draw(&PathElement::new(vec![(x0, y), (x1, y)], st)).map_err(e)?,
            Dash::Dashed => area.draw(&DashedPathElement::new(vec![(x0, y), (x1, y)], 8, 4, st)).map_err(e)?,
            Dash::Dotted => area.draw(&DashedPathElement::new(vec![(x0, y), (x1, y)], 2, 4, st)).map_err(e)?,
            Dash::None => {}
        }
        if let Some(m) = s.style.marker {
            let at = std::iter::once(((x0 + x1) / 2, y));
            draw_markers!(m, s.style.color, at, |els: _| -> Result<(), String> {
                for el in els {
                    area.draw(&el).map_err(e)?;
                }
                Ok(())
            })?;
        }
        area.draw(&Text::new(s.label.clone(), (x1 + 6, y - 7), ("sans-serif", 13).into_font().color(&BLACK)))
            .map_err(e)?;
    }
    Ok(())
}

/// Draw panels stacked vertically (or in `cols` columns) into one SVG file, written atomically
/// (a temporary file renamed over `path`).
pub fn panels_svg(path: &Path, panels: &[Panel], cols: usize, panel_size: (u32, u32)) -> Result<(), Error> {
    let err = |msg: String| Error::Plot { file: path.display().to_string(), msg };
    let cols = cols.max(1);
    let rows = panels.len().div_ceil(cols).max(1);
    let size = (panel_size.0 * cols as u32, panel_size.1 * rows as u32);
    // Drawn to a temporary file beside the target and renamed over it once complete.
    let file = crate::atomic::TempFile::new(path)?;
    let tmp = file.path().to_path_buf();
    let root = SVGBackend::new(&tmp, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let areas = root.split_evenly((rows, cols));
    let legend_w = legend_width(panels);
    for (p, a) in panels.iter().zip(areas.iter()) {
        draw_panel(a, p, legend_w).map_err(&err)?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_svg_with_labels_and_legend_in_every_axis_kind() {
        let dir = std::env::temp_dir().join(format!("harness-plot-{}", std::process::id()));
        let path = dir.join("t.svg");
        let panel = |log_x, log_y| Panel {
            title: "tip Z".into(),
            x_label: "t [s]".into(),
            y_label: "Z [m]".into(),
            log_x,
            log_y,
            pad_x: false,
            series: (0..3)
                .map(|k| {
                    Series::new(
                        format!("series {k}"),
                        Style::nth(k),
                        (1..50).map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin().abs() + 1e-3)).collect(),
                    )
                })
                .collect(),
        };
        let panels = [panel(false, false), panel(false, true), panel(true, true), panel(true, false)];
        panels_svg(&path, &panels, 2, (600, 300)).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("t [s]") && svg.contains("Z [m]") && svg.contains("series 2"));
        // Dashed series are drawn as many short segments; dotted ones too.
        assert!(svg.matches("<polyline").count() > 3 * 4);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn markers_cover_short_series_and_sample_long_ones() {
        assert_eq!(marker_indices(5, 3).count(), 5);
        let long: Vec<usize> = marker_indices(2000, 0).collect();
        assert!((12..=14).contains(&long.len()), "{}", long.len());
        // Another series' markers sit elsewhere.
        assert_ne!(marker_indices(2000, 1).next(), Some(0));
    }

    #[test]
    fn tick_labels_tell_neighbours_apart() {
        let f = tick_format(-4e-5, 1e-5);
        assert_eq!(f(&-3e-5), "-3.0e-5");
        let g = tick_format(-200.0, 60.0);
        assert_eq!(g(&-150.0), "-150");
        let h = tick_format(0.0, 2.0);
        assert_eq!(h(&0.4), "0.4");
        assert_eq!(h(&0.0), "0");
    }
}
