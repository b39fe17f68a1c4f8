//! `--crop-window` and `--pixel-bounds`: render part of the image, as
//! pbrt-v4's `--cropwindow` and `--pixelbounds`. The pixels rendered are
//! those of the whole image (same sampler keys, same camera rays), so a
//! crop is bit-identical to the same pixels of the full render.

use lueur_integrator::PixelBounds;

use crate::BadInput;

/// The pixels to render of a `width` x `height` image: `crop` (fractions
/// `x0 x1 y0 y1` of the image, pbrt-v4's crop window: pixel bounds from the
/// ceilings of the fractions times the resolution, row 0 at the top), or
/// `pixels` (pixel bounds `x0 x1 y0 y1`, ends excluded), or `None` for the
/// whole image.
pub fn bounds(
    crop: Option<&[f64]>,
    pixels: Option<&[u32]>,
    width: u32,
    height: u32,
) -> Result<Option<PixelBounds>, BadInput> {
    let bounds = match (crop, pixels) {
        (Some(c), _) => {
            let ok = c.len() == 4
                && c.iter().all(|v| (0.0..=1.0).contains(v))
                && c[0] < c[1]
                && c[2] < c[3];
            if !ok {
                return Err(BadInput(format!(
                    "--crop-window {}: expected X0 X1 Y0 Y1, fractions of the image with \
                     0 <= X0 < X1 <= 1 and 0 <= Y0 < Y1 <= 1",
                    join(c)
                )));
            }
            let at = |f: f64, side: u32| (f * f64::from(side)).ceil() as u32;
            let b = PixelBounds {
                x0: at(c[0], width),
                x1: at(c[1], width),
                y0: at(c[2], height),
                y1: at(c[3], height),
            };
            if b.width() == 0 || b.height() == 0 {
                return Err(BadInput(format!(
                    "--crop-window {} holds no pixel of the {width}x{height} image",
                    join(c)
                )));
            }
            b
        }
        (None, Some(p)) => {
            let ok = p.len() == 4 && p[0] < p[1] && p[1] <= width && p[2] < p[3] && p[3] <= height;
            if !ok {
                return Err(BadInput(format!(
                    "--pixel-bounds {}: expected X0 X1 Y0 Y1 with X0 < X1 <= {width} and \
                     Y0 < Y1 <= {height} (the image's size; ends excluded)",
                    join(p)
                )));
            }
            PixelBounds {
                x0: p[0],
                x1: p[1],
                y0: p[2],
                y1: p[3],
            }
        }
        (None, None) => return Ok(None),
    };
    Ok((bounds != PixelBounds::whole(width, height)).then_some(bounds))
}

fn join<T: std::fmt::Display>(v: &[T]) -> String {
    v.iter().map(T::to_string).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crop_window_takes_the_ceilings_as_pbrt_v4_does() {
        let b = bounds(Some(&[0.25, 0.75, 0.1, 0.5]), None, 10, 10)
            .unwrap()
            .unwrap();
        assert_eq!((b.x0, b.x1, b.y0, b.y1), (3, 8, 1, 5));
        assert_eq!(
            bounds(Some(&[0.0, 1.0, 0.0, 1.0]), None, 10, 10).unwrap(),
            None
        );
        assert!(bounds(Some(&[0.5, 0.5, 0.0, 1.0]), None, 10, 10).is_err());
        assert!(bounds(Some(&[0.0, 0.01, 0.0, 1.0]), None, 10, 10).is_ok());
        assert!(bounds(Some(&[0.0, 1.5, 0.0, 1.0]), None, 10, 10).is_err());
        assert!(bounds(None, Some(&[0, 11, 0, 10]), 10, 10).is_err());
        let b = bounds(None, Some(&[2, 5, 0, 1]), 10, 10).unwrap().unwrap();
        assert_eq!((b.width(), b.height()), (3, 1));
    }
}
