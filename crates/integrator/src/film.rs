//! The film: per-pixel running statistics of the sample estimates.

use glam::Vec3;

/// Running mean and variance of one pixel's estimates (Welford 1962), per
/// RGB channel. Welford's update stays accurate where the naive
/// sum-of-squares formula cancels catastrophically at high spp.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    /// Number of finite estimates added.
    pub n: u32,
    /// Mean of the estimates.
    pub mean: Vec3,
    /// Sum of squared deviations from the mean.
    pub m2: Vec3,
}

impl PixelStats {
    /// Adds one estimate. The caller has checked that it is finite.
    #[inline]
    pub fn add(&mut self, x: Vec3) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f32;
        self.m2 += delta * (x - self.mean);
    }

    /// Unbiased sample variance of one estimate (zero below two samples).
    pub fn sample_variance(&self) -> Vec3 {
        if self.n < 2 {
            Vec3::ZERO
        } else {
            self.m2 / (self.n - 1) as f32
        }
    }

    /// Variance of the pixel mean: the squared standard error of the pixel.
    pub fn variance_of_mean(&self) -> Vec3 {
        if self.n < 2 {
            Vec3::ZERO
        } else {
            self.sample_variance() / self.n as f32
        }
    }
}

/// An image of per-pixel statistics, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// Sample indices `0..spp` have been added to every pixel (less any
    /// NaN or infinite sample, dropped and counted by the render).
    spp: u32,
    pixels: Vec<PixelStats>,
}

impl Film {
    /// An empty film.
    pub fn new(width: u32, height: u32) -> Film {
        Film {
            width,
            height,
            spp: 0,
            pixels: vec![PixelStats::default(); width as usize * height as usize],
        }
    }

    /// Samples per pixel rendered so far: every pixel has seen sample
    /// indices `0..spp`, so a film is always a whole number of samples per
    /// pixel, however its render was cut into passes.
    pub fn spp(&self) -> u32 {
        self.spp
    }

    /// A film from saved statistics (a checkpoint): `pixels` row-major,
    /// `width * height` of them, each holding at most `spp` samples.
    /// `None` if the parts do not fit together.
    pub fn from_parts(width: u32, height: u32, spp: u32, pixels: Vec<PixelStats>) -> Option<Film> {
        let fits = pixels.len() == width as usize * height as usize
            && pixels.iter().all(|p| {
                p.n <= spp && p.mean.is_finite() && p.m2.is_finite() && p.m2.min_element() >= 0.0
            });
        fits.then_some(Film {
            width,
            height,
            spp,
            pixels,
        })
    }

    pub(crate) fn set_spp(&mut self, spp: u32) {
        self.spp = spp;
    }

    /// Relative standard error of the image: the RMS over pixels and
    /// channels of each pixel's standard error, divided by the image's mean
    /// radiance. What `--target-error` stops on; infinite before 2 spp.
    pub fn relative_error(&self) -> f64 {
        let (mean, _) = self.image_mean();
        if self.spp < 2 || !(mean > 0.0) {
            return f64::INFINITY;
        }
        let n = 3.0 * self.pixels.len() as f64;
        let var: f64 = self
            .pixels
            .iter()
            .map(|p| p.variance_of_mean().element_sum() as f64)
            .sum::<f64>()
            / n;
        var.sqrt() / mean
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Statistics of pixel (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> &PixelStats {
        &self.pixels[(y * self.width + x) as usize]
    }

    /// All pixels, row-major.
    pub fn pixels(&self) -> &[PixelStats] {
        &self.pixels
    }

    pub(crate) fn pixels_mut(&mut self) -> &mut [PixelStats] {
        &mut self.pixels
    }

    /// Mean radiance of every pixel, row-major.
    pub fn mean_image(&self) -> Vec<Vec3> {
        self.pixels.iter().map(|p| p.mean).collect()
    }

    /// Variance of the mean of every pixel, row-major.
    pub fn variance_image(&self) -> Vec<Vec3> {
        self.pixels.iter().map(|p| p.variance_of_mean()).collect()
    }

    /// The mean image as 8-bit sRGB (IEC 61966-2-1), clamped, after scaling
    /// by `2^exposure`: what a PNG shows.
    pub fn srgb8(&self, exposure: f32) -> Vec<u8> {
        let gain = exposure.exp2();
        let encode = |linear: f32| {
            let c = (linear * gain).clamp(0.0, 1.0);
            let v = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (v * 255.0 + 0.5) as u8
        };
        self.pixels
            .iter()
            .flat_map(|p| [encode(p.mean.x), encode(p.mean.y), encode(p.mean.z)])
            .collect()
    }

    /// Mean over pixels and channels of the per-sample variance: the noise
    /// of one sample, the figure the strategies are compared on.
    pub fn mean_sample_variance(&self) -> f64 {
        let sum: f64 = self
            .pixels
            .iter()
            .map(|p| p.sample_variance().element_sum() as f64)
            .sum();
        sum / (3.0 * self.pixels.len() as f64)
    }

    /// Mean of the image over pixels and channels, with its standard error
    /// (pixels are independent, so the variances of their means add).
    pub fn image_mean(&self) -> (f64, f64) {
        let n = 3.0 * self.pixels.len() as f64;
        let mean: f64 = self
            .pixels
            .iter()
            .map(|p| p.mean.element_sum() as f64)
            .sum::<f64>()
            / n;
        let var: f64 = self
            .pixels
            .iter()
            .map(|p| p.variance_of_mean().element_sum() as f64)
            .sum::<f64>()
            / (n * n);
        (mean, var.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_matches_two_pass() {
        let xs = [1.0f32, 4.0, 2.5, 10.0, -3.0, 0.25];
        let mut s = PixelStats::default();
        for &x in &xs {
            s.add(Vec3::splat(x));
        }
        let mean = xs.iter().sum::<f32>() / xs.len() as f32;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / (xs.len() - 1) as f32;
        assert!((s.mean.x - mean).abs() < 1e-5);
        assert!((s.sample_variance().x - var).abs() < 1e-4);
        assert!((s.variance_of_mean().y - var / xs.len() as f32).abs() < 1e-4);
    }

    #[test]
    fn one_sample_has_no_variance() {
        let mut s = PixelStats::default();
        s.add(Vec3::ONE);
        assert_eq!(s.variance_of_mean(), Vec3::ZERO);
    }
}
