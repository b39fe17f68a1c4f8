//! The PNG plot of `lueur points`: two dimensions of a point set as dots in
//! a framed unit square, with ticks at quarters, their values and the
//! dimensions' names, drawn with an 8x8 bitmap font (no system fonts, the
//! same image everywhere).

use std::path::Path;

use anyhow::Result;
use image::{GrayImage, Luma};
use lueur_pointsets::PointSet;

/// Side of the PNG, in pixels.
pub const PLOT_SIZE: u32 = 512;
/// Where the unit square lies: its left and top edges, and its side.
const LEFT: u32 = 56;
const TOP: u32 = 24;
const SIDE: u32 = 432;
/// Grey of the frame, ticks and text; the dots are black.
const INK: Luma<u8> = Luma([96]);
const DOT: Luma<u8> = Luma([0]);

/// Plots dimensions `i` (across) and `j` (up) of `points` to `path`.
pub fn write_png(path: &Path, points: &PointSet, i: usize, j: usize) -> Result<()> {
    let mut img = GrayImage::from_pixel(PLOT_SIZE, PLOT_SIZE, Luma([255]));
    let (right, bottom) = (LEFT + SIDE, TOP + SIDE);
    for t in 0..=SIDE {
        for (x, y) in [
            (LEFT - 1, TOP + t),
            (right + 1, TOP + t),
            (LEFT + t, TOP - 1),
            (LEFT + t, bottom + 1),
        ] {
            img.put_pixel(x, y, INK);
        }
    }
    for (k, label) in ["0", "0.25", "0.5", "0.75", "1"].iter().enumerate() {
        let at = SIDE * k as u32 / 4;
        for d in 2..7 {
            img.put_pixel(LEFT + at, bottom + d, INK);
            img.put_pixel(LEFT - d, bottom - at, INK);
        }
        let w = 8 * label.len() as u32;
        text(&mut img, LEFT + at - w / 2, bottom + 10, label);
        text(&mut img, LEFT - 10 - w, bottom - at - 4, label);
    }
    let across = format!("dimension {i}");
    text(
        &mut img,
        LEFT + SIDE / 2 - 4 * across.len() as u32,
        bottom + 26,
        &across,
    );
    text(&mut img, 4, 6, &format!("dimension {j}"));
    text(
        &mut img,
        right - 8 * 10,
        6,
        &format!("n = {}", points.len()),
    );
    for p in points.points() {
        // Coordinates are in [0, 1), so the dot's centre is in the square.
        let cx = i64::from(LEFT) + (p[i] * f64::from(SIDE)) as i64;
        let cy = i64::from(bottom) - 1 - (p[j] * f64::from(SIDE)) as i64;
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (x, y) = (cx + dx, cy + dy);
                if (i64::from(LEFT)..i64::from(right)).contains(&x)
                    && (i64::from(TOP)..i64::from(bottom)).contains(&y)
                {
                    img.put_pixel(x as u32, y as u32, DOT);
                }
            }
        }
    }
    img.save_with_format(path, image::ImageFormat::Png)?;
    Ok(())
}

/// Draws `s` with its top-left corner at (x, y), clipped to the image.
fn text(img: &mut GrayImage, x: u32, y: u32, s: &str) {
    use font8x8::UnicodeFonts;
    for (k, c) in s.chars().enumerate() {
        let Some(glyph) = font8x8::BASIC_FONTS.get(c) else {
            continue;
        };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                let (px, py) = (x + 8 * k as u32 + col, y + row as u32);
                if bits >> col & 1 == 1 && px < img.width() && py < img.height() {
                    img.put_pixel(px, py, INK);
                }
            }
        }
    }
}
