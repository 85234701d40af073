//! Line charts written as SVG and PNG: several series, optional log axes, and reference values
//! drawn as dashed horizontal lines (e.g. the full-FE value a reduced model converges to).
//!
//! A chart is plain data ([`LineChart`]); [`LineChart::write_svg`], [`LineChart::write_png`] and
//! [`LineChart::write`] (both) draw it with `plotters`. Text needs a TrueType font, read at run
//! time (no fontconfig): the file named by the environment variable `JOINTROM_FONT`, else the
//! first of [`FONT_CANDIDATES`] that exists (Debian's `fonts-dejavu-core` provides the first).
//! The font is loaded once per process. Every failure — no font, an unwritable file, a drawing
//! error, non-finite or (on a log axis) non-positive data only — is an [`Error`], never a panic.
//!
//! On a log axis points with a value ≤ 0 or non-finite cannot be drawn; they are skipped (a
//! series then shows a gap), and a chart with no drawable point at all is an error.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::{Error, FontError, ReportError};

/// Font files tried, in order, when `JOINTROM_FONT` is not set.
pub const FONT_CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// An axis range `(min, max)`.
type Range = (f64, f64);

/// The font family name the charts use (registered by [`ensure_font`]).
pub(crate) const FAMILY: &str = "sans-serif";

/// One line of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// `(x, y)` points in order.
    pub points: Vec<(f64, f64)>,
    /// Draw a small circle at every point too.
    pub markers: bool,
    /// Join the points by a line (`false`: a scatter of markers).
    pub line: bool,
    /// Palette slot of the colour; `None`: the series' position in the chart (so that one
    /// model keeps its colour across charts that show different subsets).
    pub color: Option<usize>,
}

impl Series {
    /// A series from `(x, y)` points, with markers.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            points,
            markers: true,
            line: true,
            color: None,
        }
    }

    /// A scatter: markers only, no connecting line.
    pub fn scatter(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            line: false,
            ..Series::new(label, points)
        }
    }
}

/// A reference value, drawn as a dashed horizontal line across the chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// Legend text.
    pub label: String,
    /// The y value.
    pub value: f64,
    /// Line colour (RGB); `None`: black.
    pub color: Option<[u8; 3]>,
}

impl Reference {
    /// A black reference line.
    pub fn new(label: impl Into<String>, value: f64) -> Reference {
        Reference {
            label: label.into(),
            value,
            color: None,
        }
    }
}

/// A line chart: title, axes, series and reference lines.
#[derive(Clone, Debug, PartialEq)]
pub struct LineChart {
    /// Title above the plot.
    pub title: String,
    /// x axis description.
    pub x_label: String,
    /// y axis description.
    pub y_label: String,
    /// Logarithmic x axis.
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// The lines.
    pub series: Vec<Series>,
    /// Horizontal reference lines.
    pub references: Vec<Reference>,
    /// Vertical reference lines (`value` is an x value).
    pub x_references: Vec<Reference>,
    /// Fixed y range `(min, max)`; `None`: from the data (with a margin).
    pub y_range: Option<(f64, f64)>,
    /// Image size in pixels (SVG user units).
    pub size: (u32, u32),
    /// Where the legend box goes.
    pub legend: LegendPosition,
}

/// Corner of the plot area that holds the legend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// Upper right (default).
    #[default]
    UpperRight,
    /// Upper left.
    UpperLeft,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
}

impl LineChart {
    /// An empty chart, linear axes, 960 × 600, legend upper right.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> LineChart {
        LineChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            series: Vec::new(),
            references: Vec::new(),
            x_references: Vec::new(),
            y_range: None,
            size: (960, 600),
            legend: LegendPosition::UpperRight,
        }
    }

    /// Writes `<stem>.svg` and `<stem>.png`; returns both paths.
    pub fn write(&self, stem: &Path) -> Result<[PathBuf; 2], Error> {
        let svg = stem.with_extension("svg");
        let png = stem.with_extension("png");
        self.write_svg(&svg)?;
        self.write_png(&png)?;
        Ok([svg, png])
    }

    /// Writes the chart as SVG.
    pub fn write_svg(&self, path: &Path) -> Result<(), Error> {
        ensure_font()?;
        crate::files::write_atomic_with(path, |tmp| {
            let root = SVGBackend::new(tmp, self.size).into_drawing_area();
            self.draw(root).map_err(|e| chart_error(path, e))
        })
    }

    /// Writes the chart as PNG (the format follows the extension; use `.png`).
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        ensure_font()?;
        crate::files::write_atomic_with(path, |tmp| {
            let root = BitMapBackend::new(tmp, self.size).into_drawing_area();
            self.draw(root).map_err(|e| chart_error(path, e))
        })
    }

    /// A point that can be drawn: finite, positive on a log axis, and inside a fixed y range
    /// (a series leaving the range is cut there rather than drawn across the frame).
    fn drawable(&self, x: f64, y: f64) -> bool {
        x.is_finite()
            && y.is_finite()
            && (!self.x_log || x > 0.0)
            && (!self.y_log || y > 0.0)
            && self.y_range.is_none_or(|(lo, hi)| (lo..=hi).contains(&y))
    }

    /// Data ranges over the drawable points and references, with a margin.
    fn ranges(&self) -> Result<(Range, Range), String> {
        let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
        let mut yr = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &self.series {
            for &(x, y) in &s.points {
                if self.drawable(x, y) {
                    xr = (xr.0.min(x), xr.1.max(x));
                    yr = (yr.0.min(y), yr.1.max(y));
                }
            }
        }
        if xr.0 > xr.1 {
            return Err(format!(
                "chart \"{}\" has no drawable point (all empty, non-finite{})",
                self.title,
                if self.x_log || self.y_log {
                    " or ≤ 0 on a log axis"
                } else {
                    ""
                }
            ));
        }
        for r in &self.references {
            if r.value.is_finite() && (!self.y_log || r.value > 0.0) {
                yr = (yr.0.min(r.value), yr.1.max(r.value));
            }
        }
        for r in &self.x_references {
            if r.value.is_finite() && (!self.x_log || r.value > 0.0) {
                xr = (xr.0.min(r.value), xr.1.max(r.value));
            }
        }
        if let Some((lo, hi)) = self.y_range {
            if !(lo < hi && lo.is_finite() && hi.is_finite() && (!self.y_log || lo > 0.0)) {
                return Err(format!(
                    "chart \"{}\": invalid y range ({lo}, {hi})",
                    self.title
                ));
            }
            yr = (lo, hi);
        } else {
            yr = pad(yr, self.y_log);
        }
        Ok((pad_x(xr, self.x_log), yr))
    }

    fn draw<DB>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        let ((x0, x1), (y0, y1)) = self.ranges()?;
        match (self.x_log, self.y_log) {
            (false, false) => self.draw_in(root, x0..x1, y0..y1, (y0, y1)),
            (false, true) => self.draw_in(root, x0..x1, (y0..y1).log_scale(), (y0, y1)),
            (true, false) => self.draw_in(root, (x0..x1).log_scale(), y0..y1, (y0, y1)),
            (true, true) => {
                self.draw_in(root, (x0..x1).log_scale(), (y0..y1).log_scale(), (y0, y1))
            }
        }
    }

    fn draw_in<DB, XS, YS>(
        &self,
        root: DrawingArea<DB, Shift>,
        xs: XS,
        ys: YS,
        (ylo, yhi): (f64, f64),
    ) -> Result<(), String>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
        XS: AsRangedCoord<Value = f64>,
        YS: AsRangedCoord<Value = f64>,
        XS::CoordDescType: ValueFormatter<f64>,
        YS::CoordDescType: ValueFormatter<f64>,
    {
        let err = |e: &dyn std::fmt::Display| e.to_string();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (xmin, xmax) = xs_bounds(&self.series, self.x_log);
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, (FAMILY, 22))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(xs, ys)
            .map_err(|e| err(&e))?;
        let x_fmt = |v: &f64| tick(*v, self.x_log, xmin.abs().max(xmax.abs()));
        let y_fmt = |v: &f64| tick(*v, self.y_log, ylo.abs().max(yhi.abs()));
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style((FAMILY, 14))
            .axis_desc_style((FAMILY, 16))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, s) in self.series.iter().enumerate() {
            let color = palette(s.color.unwrap_or(k));
            // Runs of drawable points: a point that cannot be drawn breaks the line.
            let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for &(x, y) in &s.points {
                if self.drawable(x, y) {
                    runs.last_mut().expect("runs is never empty").push((x, y));
                } else if !runs.last().expect("runs is never empty").is_empty() {
                    runs.push(Vec::new());
                }
            }
            for (i, run) in runs.iter().enumerate() {
                let width = if s.line { 2 } else { 0 };
                let drawn = chart
                    .draw_series(LineSeries::new(
                        run.iter().copied().filter(|_| s.line),
                        color.stroke_width(width),
                    ))
                    .map_err(|e| err(&e))?;
                if i == 0 && !s.line {
                    drawn
                        .label(s.label.as_str())
                        .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
                } else if i == 0 {
                    drawn.label(s.label.as_str()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                }
                if s.markers {
                    chart
                        .draw_series(
                            run.iter().map(|&p| {
                                Circle::new(p, if s.line { 3 } else { 5 }, color.filled())
                            }),
                        )
                        .map_err(|e| err(&e))?;
                }
            }
        }
        for r in &self.references {
            if !(r.value.is_finite() && (!self.y_log || r.value > 0.0)) {
                continue;
            }
            let [r_, g_, b_] = r.color.unwrap_or([0, 0, 0]);
            let style = RGBColor(r_, g_, b_).stroke_width(if r.color.is_some() { 2 } else { 1 });
            chart
                .draw_series(DashedLineSeries::new(
                    [(xmin, r.value), (xmax, r.value)],
                    8,
                    5,
                    style,
                ))
                .map_err(|e| err(&e))?
                .label(r.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
        for r in &self.x_references {
            if !(r.value.is_finite() && (!self.x_log || r.value > 0.0)) {
                continue;
            }
            let [r_, g_, b_] = r.color.unwrap_or([0, 0, 0]);
            let style = RGBColor(r_, g_, b_).stroke_width(if r.color.is_some() { 2 } else { 1 });
            chart
                .draw_series(DashedLineSeries::new(
                    [(r.value, ylo), (r.value, yhi)],
                    8,
                    5,
                    style,
                ))
                .map_err(|e| err(&e))?
                .label(r.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x + 10, y - 6), (x + 10, y + 6)], style)
                });
        }
        if !self.series.is_empty() || !self.references.is_empty() {
            chart
                .configure_series_labels()
                .label_font((FAMILY, 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(match self.legend {
                    LegendPosition::UpperRight => SeriesLabelPosition::UpperRight,
                    LegendPosition::UpperLeft => SeriesLabelPosition::UpperLeft,
                    LegendPosition::LowerLeft => SeriesLabelPosition::LowerLeft,
                    LegendPosition::LowerRight => SeriesLabelPosition::LowerRight,
                })
                .draw()
                .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
        Ok(())
    }
}

/// Registers the chart font once per process (see the module docs); later calls return the
/// first call's outcome.
pub fn ensure_font() -> Result<(), Error> {
    static LOADED: OnceLock<Result<(), FontError>> = OnceLock::new();
    Ok(LOADED
        .get_or_init(load_font)
        .clone()
        .map_err(ReportError::Font)?)
}

fn load_font() -> Result<(), FontError> {
    let path = match std::env::var_os("JOINTROM_FONT") {
        Some(p) => PathBuf::from(p),
        None => FONT_CANDIDATES
            .iter()
            .map(PathBuf::from)
            .find(|p| p.is_file())
            .ok_or(FontError::Missing {
                candidates: FONT_CANDIDATES,
            })?,
    };
    let bytes = std::fs::read(&path).map_err(|e| FontError::Unreadable {
        file: path.clone(),
        reason: e.to_string(),
    })?;
    // plotters keeps fonts for the whole process; the bytes are leaked once (OnceLock).
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font(FAMILY, FontStyle::Normal, bytes)
        .map_err(|_| FontError::Invalid { file: path.clone() })
}

pub(crate) fn chart_error(path: &Path, reason: String) -> Error {
    crate::files::write_err(
        path,
        "write",
        std::io::Error::other(format!("cannot draw chart: {reason}")),
    )
}

fn xs_bounds(series: &[Series], log: bool) -> (f64, f64) {
    let mut r = (f64::INFINITY, f64::NEG_INFINITY);
    for s in series {
        for &(x, _) in &s.points {
            if x.is_finite() && (!log || x > 0.0) {
                r = (r.0.min(x), r.1.max(x));
            }
        }
    }
    if r.0 <= r.1 {
        r
    } else {
        (0.0, 1.0)
    }
}

/// A y range with a margin: 5 % of the span on a linear axis, a quarter decade on a log axis.
fn pad((lo, hi): (f64, f64), log: bool) -> (f64, f64) {
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        let m = if b > a { 0.25 } else { 0.5 };
        (10f64.powf(a - m), 10f64.powf(b + m))
    } else if hi > lo {
        let m = 0.05 * (hi - lo);
        (lo - m, hi + m)
    } else {
        let m = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        (lo - m, hi + m)
    }
}

/// An x range with a small margin (none below a linear zero start).
fn pad_x((lo, hi): (f64, f64), log: bool) -> (f64, f64) {
    if log {
        pad((lo, hi), true)
    } else if hi > lo {
        let m = 0.02 * (hi - lo);
        (if lo == 0.0 { 0.0 } else { lo - m }, hi + m)
    } else {
        (lo - 0.5, hi + 0.5)
    }
}

/// A tick label; on a linear axis whose values reach `scale`, a value within round-off of zero
/// (`-2.2e-16`) is written `0`.
fn tick(v: f64, log: bool, scale: f64) -> String {
    let v = if !log && v.abs() <= 1e-9 * scale {
        0.0
    } else {
        v
    };
    if log {
        format!("{v:.0e}")
    } else if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-3) {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

/// The colour of the `k`-th series of a chart (RGB), for references drawn in a series' colour.
pub(crate) fn series_color(k: usize) -> [u8; 3] {
    let RGBColor(r, g, b) = palette(k);
    [r, g, b]
}

/// Distinct line colours (Tableau 10), cycling.
fn palette(k: usize) -> RGBColor {
    const C: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    let (r, g, b) = C[k % C.len()];
    RGBColor(r, g, b)
}
