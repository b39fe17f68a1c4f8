//! Labelled image grids and false-colour error maps for the figures.
//!
//! Text is drawn with the `font8x8` bitmap font (public-domain glyphs, no
//! system fonts, so figures are identical on every machine); colour scales
//! come from `colorous` (d3's perceptually uniform gradients).

use font8x8::UnicodeFonts;
use image::{Rgb, RgbImage};

pub const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
pub const INK: Rgb<u8> = Rgb([20, 20, 20]);
/// Glyphs are 8x8, drawn at this integer scale.
const TEXT_SCALE: u32 = 2;
const PAD: u32 = 6;
const LABEL_HEIGHT: u32 = 8 * TEXT_SCALE + 2 * PAD;

/// Draws `text` with its top-left corner at (x, y); characters outside
/// Basic Latin are skipped.
pub fn draw_text(img: &mut RgbImage, x: u32, y: u32, text: &str, color: Rgb<u8>) {
    draw_text_scaled(img, x, y, text, color, TEXT_SCALE);
}

/// [`draw_text`] with the glyphs drawn at `scale` (1: 8x8 pixels), for
/// tick labels where the default size does not fit.
pub fn draw_text_scaled(
    img: &mut RgbImage,
    x: u32,
    y: u32,
    text: &str,
    color: Rgb<u8>,
    scale: u32,
) {
    let mut cx = x;
    for ch in text.chars() {
        if let Some(glyph) = font8x8::BASIC_FONTS.get(ch) {
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8u32 {
                    // font8x8 stores the leftmost pixel in the lowest bit.
                    if bits >> col & 1 == 1 {
                        for dy in 0..scale {
                            for dx in 0..scale {
                                let (px, py) = (cx + col * scale + dx, y + row as u32 * scale + dy);
                                if px < img.width() && py < img.height() {
                                    img.put_pixel(px, py, color);
                                }
                            }
                        }
                    }
                }
            }
        }
        cx += 8 * scale;
    }
}

/// Width in pixels of `text` as [`draw_text`] draws it.
pub fn text_width(text: &str) -> u32 {
    text.chars().count() as u32 * 8 * TEXT_SCALE
}

/// A grid of images, each with its label above it, rows of equal length,
/// all cells the size of the largest image, and an optional title.
pub fn grid(title: Option<&str>, rows: &[Vec<(String, RgbImage)>]) -> RgbImage {
    let cols = rows.iter().map(Vec::len).max().unwrap_or(0) as u32;
    let cell_w = rows
        .iter()
        .flatten()
        .map(|(_, i)| i.width())
        .max()
        .unwrap_or(0);
    let cell_h = rows
        .iter()
        .flatten()
        .map(|(_, i)| i.height())
        .max()
        .unwrap_or(0);
    let label_w = rows
        .iter()
        .flatten()
        .map(|(l, _)| text_width(l))
        .max()
        .unwrap_or(0);
    let cell_w = cell_w.max(label_w);
    let title_h = if title.is_some() { LABEL_HEIGHT } else { 0 };
    let title_w = title.map_or(0, |t| text_width(t) + 2 * PAD);
    let width = (cols * (cell_w + PAD) + PAD).max(title_w);
    let height = title_h + rows.len() as u32 * (cell_h + LABEL_HEIGHT) + PAD;
    let mut out = RgbImage::from_pixel(width, height, BACKGROUND);
    if let Some(t) = title {
        draw_text(&mut out, PAD, PAD, t, INK);
    }
    for (r, row) in rows.iter().enumerate() {
        let y0 = title_h + r as u32 * (cell_h + LABEL_HEIGHT);
        for (c, (label, img)) in row.iter().enumerate() {
            let x0 = PAD + c as u32 * (cell_w + PAD);
            draw_text(&mut out, x0, y0 + PAD, label, INK);
            image::imageops::replace(&mut out, img, i64::from(x0), i64::from(y0 + LABEL_HEIGHT));
        }
    }
    out
}

/// Maps `t` in [0, 1] to the colour scale of error maps (viridis).
pub fn error_color(t: f64) -> Rgb<u8> {
    let c = colorous::VIRIDIS.eval_continuous(t.clamp(0.0, 1.0));
    Rgb([c.r, c.g, c.b])
}

/// An error map: `values` (row-major, one per pixel) divided by `full_scale`
/// and coloured; values above it saturate.
pub fn error_map(width: u32, height: u32, values: &[f64], full_scale: f64) -> RgbImage {
    RgbImage::from_fn(width, height, |x, y| {
        error_color(values[(y * width + x) as usize] / full_scale)
    })
}

/// Maps `t` in [-1, 1] to the diverging scale of signed error maps
/// (d3's RdBu: negative red, zero white, positive blue).
pub fn signed_error_color(t: f64) -> Rgb<u8> {
    let c = colorous::RED_BLUE.eval_continuous(0.5 + 0.5 * t.clamp(-1.0, 1.0));
    Rgb([c.r, c.g, c.b])
}

/// A signed error map: `values` (row-major) divided by `full_scale` and
/// coloured by [`signed_error_color`]; values beyond +-1 saturate.
pub fn signed_error_map(width: u32, height: u32, values: &[f64], full_scale: f64) -> RgbImage {
    RgbImage::from_fn(width, height, |x, y| {
        signed_error_color(values[(y * width + x) as usize] / full_scale)
    })
}

/// A horizontal colour bar of `width` pixels with its end labels.
pub fn color_bar(width: u32, low: &str, high: &str) -> RgbImage {
    color_bar_with(width, low, high, error_color)
}

/// A colour bar of the signed scale, from -1 (left) to 1 (right).
pub fn signed_color_bar(width: u32, low: &str, high: &str) -> RgbImage {
    color_bar_with(width, low, high, |t| signed_error_color(2.0 * t - 1.0))
}

/// A horizontal bar of `color(t)`, `t` from 0 at the left to 1 at the
/// right, with its end labels below.
fn color_bar_with(width: u32, low: &str, high: &str, color: impl Fn(f64) -> Rgb<u8>) -> RgbImage {
    let bar_h = 14;
    let mut img = RgbImage::from_pixel(width, bar_h + LABEL_HEIGHT, BACKGROUND);
    for x in 0..width {
        let c = color(f64::from(x) / f64::from(width.max(2) - 1));
        for y in 0..bar_h {
            img.put_pixel(x, y, c);
        }
    }
    draw_text(&mut img, 0, bar_h + PAD, low, INK);
    let hw = text_width(high);
    draw_text(&mut img, width.saturating_sub(hw), bar_h + PAD, high, INK);
    img
}

/// `img` enlarged `factor` times, each pixel a square block (no
/// smoothing, so per-pixel noise stays visible as it is).
pub fn enlarge(img: &RgbImage, factor: u32) -> RgbImage {
    image::imageops::resize(
        img,
        img.width() * factor,
        img.height() * factor,
        image::imageops::FilterType::Nearest,
    )
}

/// Stacks images vertically, left-aligned, on the background colour.
pub fn stack(images: &[RgbImage]) -> RgbImage {
    let width = images.iter().map(RgbImage::width).max().unwrap_or(0);
    let height = images.iter().map(RgbImage::height).sum();
    let mut out = RgbImage::from_pixel(width, height, BACKGROUND);
    let mut y = 0;
    for img in images {
        image::imageops::replace(&mut out, img, 0, i64::from(y));
        y += img.height();
    }
    out
}
