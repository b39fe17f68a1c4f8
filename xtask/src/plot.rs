//! Small raster plots for the PNG figures: a scatter of 2D points and line
//! plots with linear or logarithmic axes.
//!
//! plotters' bitmap backend draws the marks (frame, grid, curves, dots)
//! into an RGB buffer; its text would need a font backend, so every label
//! is drawn afterwards with the `font8x8` glyphs of [`crate::compose`], at
//! positions plotters maps from data coordinates. No system font is read,
//! and the pixels are the same on every machine.

use anyhow::{Result, anyhow};
use image::{Rgb, RgbImage};
use plotters::prelude::*;

use crate::compose::{INK, draw_text_scaled};

/// Tick labels and legends are 8x8 glyphs at scale 1.
const GLYPH: i32 = 8;
const GRID: RGBColor = RGBColor(225, 225, 225);

/// One axis of a [`LinePlot`]: its range in data units, whether it is
/// logarithmic (then the range and ticks are data values, mapped by log10),
/// and where its ticks go with their labels.
pub struct Axis {
    pub range: (f64, f64),
    pub log: bool,
    pub ticks: Vec<(f64, String)>,
    pub title: String,
}

impl Axis {
    fn map(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    fn mapped_range(&self) -> std::ops::Range<f64> {
        self.map(self.range.0)..self.map(self.range.1)
    }

    /// `v` mapped and clamped into the axis' range (a log axis takes zero
    /// and negative values to its bottom).
    fn clamped(&self, v: f64) -> f64 {
        let r = self.mapped_range();
        let m = self.map(v);
        if m.is_nan() || m < r.start {
            r.start
        } else {
            m.min(r.end)
        }
    }
}

/// A curve of a [`LinePlot`]; `label` goes in the legend when set.
pub struct Series {
    pub label: Option<String>,
    pub points: Vec<(f64, f64)>,
    pub color: RGBColor,
    pub dashed: bool,
}

/// A line plot of `width` x `height` pixels, labels included.
pub struct LinePlot {
    pub width: u32,
    pub height: u32,
    pub x: Axis,
    pub y: Axis,
}

/// Margins around the plotting area, in pixels: room for the tick labels
/// (`y_label_chars` glyphs wide on the left), the y axis title above and
/// the x axis title below.
fn margins(y_label_chars: usize) -> (u32, u32, u32, u32) {
    let left = (GLYPH as u32) * (y_label_chars as u32 + 1) + 6;
    let right = 10;
    let top = 2 * GLYPH as u32 + 2;
    let bottom = 2 * GLYPH as u32 + 14;
    (left, right, top, bottom)
}

/// Draws `plot` with its `series`; values outside an axis' range are
/// clamped to its edge, so a curve that leaves the plot runs along it.
pub fn line_plot(plot: &LinePlot, series: &[Series]) -> Result<RgbImage> {
    let (w, h) = (plot.width, plot.height);
    let y_chars = plot.y.ticks.iter().map(|t| t.1.len()).max().unwrap_or(0);
    let (left, right, top, bottom) = margins(y_chars);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let mut labels: Vec<(i32, i32, String, Rgb<u8>)> = Vec::new();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let mut chart = ChartBuilder::on(&root)
            .margin_left(left)
            .margin_right(right)
            .margin_top(top)
            .margin_bottom(bottom)
            .build_cartesian_2d(plot.x.mapped_range(), plot.y.mapped_range())
            .map_err(|e| anyhow!("plot layout: {e}"))?;
        let (xr, yr) = (plot.x.mapped_range(), plot.y.mapped_range());
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("plot drawing: {e}");
        for (v, text) in &plot.x.ticks {
            let x = plot.x.map(*v);
            chart
                .draw_series(LineSeries::new([(x, yr.start), (x, yr.end)], GRID))
                .map_err(err)?;
            let (px, py) = chart.backend_coord(&(x, yr.start));
            let tw = GLYPH * text.len() as i32;
            labels.push((px - tw / 2, py + 5, text.clone(), INK));
        }
        for (v, text) in &plot.y.ticks {
            let y = plot.y.map(*v);
            chart
                .draw_series(LineSeries::new([(xr.start, y), (xr.end, y)], GRID))
                .map_err(err)?;
            let (px, py) = chart.backend_coord(&(xr.start, y));
            let tw = GLYPH * text.len() as i32;
            labels.push((px - tw - 5, py - GLYPH / 2, text.clone(), INK));
        }
        for s in series {
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .map(|&(x, y)| (plot.x.clamped(x), plot.y.clamped(y)))
                .collect();
            let style = s.color.stroke_width(2);
            if s.dashed {
                chart
                    .draw_series(DashedLineSeries::new(points, 6, 4, style))
                    .map_err(err)?;
            } else {
                chart
                    .draw_series(LineSeries::new(points, style))
                    .map_err(err)?;
            }
        }
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(xr.start, yr.start), (xr.end, yr.end)],
                BLACK.stroke_width(1),
            )))
            .map_err(err)?;
        // The legend, top right inside the frame: a short stroke, then the label.
        let (right_px, top_px) = chart.backend_coord(&(xr.end, yr.end));
        let legend: Vec<&Series> = series.iter().filter(|s| s.label.is_some()).collect();
        let chars = legend
            .iter()
            .filter_map(|s| s.label.as_ref())
            .map(String::len)
            .max()
            .unwrap_or(0) as i32;
        let x0 = right_px - 8 - GLYPH * chars - 24;
        for (i, s) in legend.iter().enumerate() {
            let y = top_px + 8 + i as i32 * (GLYPH + 6);
            let stroke = [(x0, y + GLYPH / 2), (x0 + 18, y + GLYPH / 2)];
            let style = s.color.stroke_width(2);
            root.draw(&PathElement::new(stroke.to_vec(), style))
                .map_err(err)?;
            let c = s.color;
            labels.push((
                x0 + 24,
                y,
                s.label.clone().unwrap_or_default(),
                Rgb([c.0, c.1, c.2]),
            ));
        }
        // The x axis title, centred below the tick labels.
        let (x_mid, bottom_px) = chart.backend_coord(&((xr.start + xr.end) / 2.0, yr.start));
        let tw = GLYPH * plot.x.title.len() as i32;
        labels.push((
            x_mid - tw / 2,
            bottom_px + GLYPH + 10,
            plot.x.title.clone(),
            INK,
        ));
        root.present().map_err(err)?;
    }
    let mut img = RgbImage::from_raw(w, h, buf).expect("buffer matches the plot's size");
    // The y axis title, top left above the tick labels' column.
    if !plot.y.title.is_empty() {
        draw_text_scaled(&mut img, 2, 0, &plot.y.title, INK, 1);
    }
    for (x, y, text, color) in labels {
        draw_text_scaled(&mut img, x.max(0) as u32, y.max(0) as u32, &text, color, 1);
    }
    Ok(img)
}

/// `points` (2D, in the unit square) as dots in a framed `size` x `size`
/// square, `(0, 0)` at the bottom left.
pub fn scatter(size: u32, points: &[[f64; 2]]) -> Result<RgbImage> {
    let mut buf = vec![255u8; (size * size * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (size, size)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("scatter drawing: {e}");
        let mut chart = ChartBuilder::on(&root)
            .margin(3)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(|e| anyhow!("scatter layout: {e}"))?;
        chart
            .draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p[0], p[1]), 1, INK_COLOR.filled())),
            )
            .map_err(err)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(0.0, 0.0), (1.0, 1.0)],
                BLACK.stroke_width(1),
            )))
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(RgbImage::from_raw(size, size, buf).expect("buffer matches the plot's size"))
}

const INK_COLOR: RGBColor = RGBColor(INK.0[0], INK.0[1], INK.0[2]);

/// Ticks of a log axis at the powers of ten from `10^lo` to `10^hi`,
/// labelled `1e-2`, `0.1`, `1`, `10`, `1e2`...
pub fn decade_ticks(lo: i32, hi: i32) -> Vec<(f64, String)> {
    (lo..=hi)
        .map(|e| {
            let label = match e {
                -1 => "0.1".to_owned(),
                0 => "1".to_owned(),
                1 => "10".to_owned(),
                _ => format!("1e{e}"),
            };
            (10f64.powi(e), label)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_clamp_zero_to_their_floor() {
        let axis = Axis {
            range: (0.01, 100.0),
            log: true,
            ticks: decade_ticks(-2, 2),
            title: String::new(),
        };
        assert_eq!(axis.clamped(0.0), -2.0);
        assert_eq!(axis.clamped(1e9), 2.0);
        assert!((axis.clamped(1.0)).abs() < 1e-12);
        assert_eq!(axis.ticks[1].1, "0.1");
    }

    #[test]
    fn plots_have_the_asked_size_and_some_ink() {
        let plot = LinePlot {
            width: 200,
            height: 150,
            x: Axis {
                range: (0.0, 1.0),
                log: false,
                ticks: vec![(0.0, "0".into()), (1.0, "1".into())],
                title: "x".into(),
            },
            y: Axis {
                range: (0.1, 10.0),
                log: true,
                ticks: decade_ticks(-1, 1),
                title: "y".into(),
            },
        };
        let img = line_plot(
            &plot,
            &[Series {
                label: Some("a".into()),
                points: vec![(0.0, 0.1), (1.0, 10.0)],
                color: RED,
                dashed: false,
            }],
        )
        .unwrap();
        assert_eq!(img.dimensions(), (200, 150));
        assert!(img.pixels().any(|p| p.0 == [255, 0, 0]));
        let dots = scatter(64, &[[0.5, 0.5]]).unwrap();
        assert_eq!(dots.dimensions(), (64, 64));
    }
}
