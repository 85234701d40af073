//! Heat maps written as SVG and PNG: a grid of coloured cells with a short text in each, row
//! labels on the left, multi-line column headers on top and a colour key below.
//!
//! A heat map is plain data ([`HeatMap`]): the caller decides every cell's colour (categorical,
//! e.g. a solver status, or from a continuous value through [`sequential`]) and text.
//! [`HeatMap::write`] draws it with `plotters` in pixel coordinates, with the font of
//! [`crate::report::chart`] ([`crate::report::chart::ensure_font`]). Every failure — no font, an unwritable file,
//! a drawing error, a ragged grid — is an [`Error`], never a panic.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::{Error, ReportError};
use crate::report::chart::ensure_font;

/// The font family registered by [`crate::report::chart::ensure_font`].
const FAMILY: &str = "sans-serif";

/// One cell: fill colour (RGB) and a short text drawn in it (may be empty).
#[derive(Clone, Debug, PartialEq)]
pub struct HeatCell {
    /// Fill colour.
    pub color: [u8; 3],
    /// Text in the cell (keep it to ~10 characters).
    pub text: String,
}

/// A heat map: `cells[row][col]`.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatMap {
    /// Title above the grid.
    pub title: String,
    /// One label per row.
    pub row_labels: Vec<String>,
    /// One header per column, as lines drawn top to bottom.
    pub col_labels: Vec<Vec<String>>,
    /// The grid, row-major.
    pub cells: Vec<Vec<HeatCell>>,
    /// Colour key below the grid: `(text, colour)`.
    pub legend: Vec<(String, [u8; 3])>,
    /// Cell size in pixels.
    pub cell_size: (u32, u32),
    /// Width of the row-label column, pixels.
    pub row_label_width: u32,
}

impl HeatMap {
    /// Checks the grid's shape.
    fn check(&self) -> Result<(), ReportError> {
        if self.cells.len() != self.row_labels.len() {
            return Err(ReportError::HeatMapRows {
                title: self.title.clone(),
                rows: self.cells.len(),
                labels: self.row_labels.len(),
            });
        }
        if let Some((i, r)) = self
            .cells
            .iter()
            .enumerate()
            .find(|(_, r)| r.len() != self.col_labels.len())
        {
            return Err(ReportError::HeatMapRow {
                title: self.title.clone(),
                row: i,
                cells: r.len(),
                labels: self.col_labels.len(),
            });
        }
        if self.cell_size.0 == 0 || self.cell_size.1 == 0 {
            return Err(ReportError::HeatMapCellSize {
                title: self.title.clone(),
            });
        }
        Ok(())
    }

    fn header_lines(&self) -> usize {
        self.col_labels.iter().map(Vec::len).max().unwrap_or(0)
    }

    /// Image size in pixels.
    pub fn size(&self) -> (u32, u32) {
        let (cw, ch) = self.cell_size;
        let cols = self.col_labels.len() as u32;
        let rows = self.row_labels.len() as u32;
        let legend_rows = self.legend.len().div_ceil(4) as u32;
        let w = 20 + self.row_label_width + cols * cw + 20;
        let h = 50 + 18 * self.header_lines() as u32 + 10 + rows * ch + 20 + legend_rows * 24 + 10;
        (w.max(400), h)
    }

    /// Writes `<stem>.svg` and `<stem>.png`; returns both paths.
    pub fn write(&self, stem: &Path) -> Result<[PathBuf; 2], Error> {
        let svg = stem.with_extension("svg");
        let png = stem.with_extension("png");
        ensure_font()?;
        self.check()?;
        let size = self.size();
        crate::files::write_atomic_with(&svg, |tmp| {
            self.draw(SVGBackend::new(tmp, size).into_drawing_area())
                .map_err(|e| draw_error(&svg, e))
        })?;
        crate::files::write_atomic_with(&png, |tmp| {
            self.draw(BitMapBackend::new(tmp, size).into_drawing_area())
                .map_err(|e| draw_error(&png, e))
        })?;
        Ok([svg, png])
    }

    fn draw<DB>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        let err = |e: &dyn std::fmt::Display| e.to_string();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (cw, ch) = (self.cell_size.0 as i32, self.cell_size.1 as i32);
        let x0 = 20 + self.row_label_width as i32;
        let y_title = 12;
        let header_top = 50;
        let y0 = header_top + 18 * self.header_lines() as i32 + 10;
        let title_style = TextStyle::from((FAMILY, 20).into_font()).color(&BLACK);
        root.draw(&Text::new(self.title.clone(), (20, y_title), title_style))
            .map_err(|e| err(&e))?;
        let centered = |size: i32| {
            TextStyle::from((FAMILY, size).into_font())
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Center))
        };
        for (c, lines) in self.col_labels.iter().enumerate() {
            for (k, line) in lines.iter().enumerate() {
                let p = (x0 + c as i32 * cw + cw / 2, header_top + 18 * k as i32 + 9);
                root.draw(&Text::new(line.clone(), p, centered(12)))
                    .map_err(|e| err(&e))?;
            }
        }
        let left = TextStyle::from((FAMILY, 13).into_font())
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Center));
        for (r, label) in self.row_labels.iter().enumerate() {
            let p = (20, y0 + r as i32 * ch + ch / 2);
            root.draw(&Text::new(label.clone(), p, left.clone()))
                .map_err(|e| err(&e))?;
        }
        for (r, row) in self.cells.iter().enumerate() {
            for (c, cell) in row.iter().enumerate() {
                let (x, y) = (x0 + c as i32 * cw, y0 + r as i32 * ch);
                let [cr, cg, cb] = cell.color;
                root.draw(&Rectangle::new(
                    [(x, y), (x + cw, y + ch)],
                    RGBColor(cr, cg, cb).filled(),
                ))
                .map_err(|e| err(&e))?;
                root.draw(&Rectangle::new(
                    [(x, y), (x + cw, y + ch)],
                    RGBColor(255, 255, 255).stroke_width(1),
                ))
                .map_err(|e| err(&e))?;
                if !cell.text.is_empty() {
                    let fg = if luminance(cell.color) < 0.5 {
                        WHITE
                    } else {
                        BLACK
                    };
                    let style = TextStyle::from((FAMILY, 11).into_font())
                        .color(&fg)
                        .pos(Pos::new(HPos::Center, VPos::Center));
                    root.draw(&Text::new(
                        cell.text.clone(),
                        (x + cw / 2, y + ch / 2),
                        style,
                    ))
                    .map_err(|e| err(&e))?;
                }
            }
        }
        let ly = y0 + self.row_labels.len() as i32 * ch + 20;
        for (k, (text, color)) in self.legend.iter().enumerate() {
            let (col, row) = ((k % 4) as i32, (k / 4) as i32);
            let (x, y) = (20 + col * 220, ly + row * 24);
            let [cr, cg, cb] = *color;
            root.draw(&Rectangle::new(
                [(x, y), (x + 16, y + 16)],
                RGBColor(cr, cg, cb).filled(),
            ))
            .map_err(|e| err(&e))?;
            root.draw(&Text::new(
                text.clone(),
                (x + 22, y + 8),
                TextStyle::from((FAMILY, 12).into_font())
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
        Ok(())
    }
}

/// Relative luminance (0 black … 1 white) of an sRGB colour, to pick the text colour.
fn luminance([r, g, b]: [u8; 3]) -> f64 {
    (0.2126 * r as f64 + 0.7152 * g as f64 + 0.0722 * b as f64) / 255.0
}

/// A sequential colour scale (viridis, linearly interpolated between 5 stops): `x` in [0, 1]
/// (clamped; NaN gives light grey).
pub fn sequential(x: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    if x.is_nan() {
        return [220, 220, 220];
    }
    let x = x.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    std::array::from_fn(|c| (STOPS[i][c] * (1.0 - f) + STOPS[i + 1][c] * f).round() as u8)
}

fn draw_error(path: &Path, reason: String) -> Error {
    crate::files::write_err(
        path,
        "write",
        std::io::Error::other(format!("cannot draw heat map: {reason}")),
    )
}
