//! Reading a film out: the images and the figures computed from its
//! pixels' estimates (mean, error, sRGB), which never copy the film.

use glam::Vec3;

use super::Film;

impl Film {
    /// Relative standard error of the image: the RMS over pixels and
    /// channels of each pixel's standard error, divided by the image's mean
    /// radiance. What `--target-error` stops on; infinite before 2 spp, and
    /// before every replicate has a sample.
    pub fn relative_error(&self) -> f64 {
        let (mean, _) = self.image_mean();
        if self.spp() < 2.max(self.replicates()) || !(mean > 0.0) {
            return f64::INFINITY;
        }
        let n = 3.0 * self.pixels().len() as f64;
        let var: f64 = self
            .pixels()
            .map(|p| p.variance_of_mean().element_sum() as f64)
            .sum::<f64>()
            / n;
        var.sqrt() / mean
    }

    /// Mean radiance of every pixel, row-major.
    pub fn mean_image(&self) -> Vec<Vec3> {
        self.pixels().map(|p| p.mean).collect()
    }

    /// Variance of the mean of every pixel, row-major.
    pub fn variance_image(&self) -> Vec<Vec3> {
        self.pixels().map(|p| p.variance_of_mean()).collect()
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
        self.pixels()
            .flat_map(|p| [encode(p.mean.x), encode(p.mean.y), encode(p.mean.z)])
            .collect()
    }

    /// Mean over pixels and channels of the per-sample variance: the noise
    /// of one sample, the figure the strategies are compared on.
    pub fn mean_sample_variance(&self) -> f64 {
        let sum: f64 = self
            .pixels()
            .map(|p| p.sample_variance().element_sum() as f64)
            .sum();
        sum / (3.0 * self.pixels().len() as f64)
    }

    /// Mean of the image over pixels and channels, with its standard error
    /// (pixels are independent, so the variances of their channel
    /// averages add; the channels of one pixel are not, see
    /// [`crate::PixelEstimate::variance_of_average`]).
    pub fn image_mean(&self) -> (f64, f64) {
        let pixels = self.pixels().len() as f64;
        let mean: f64 = self
            .pixels()
            .map(|p| p.mean.element_sum() as f64)
            .sum::<f64>()
            / (3.0 * pixels);
        let var: f64 = self
            .pixels()
            .map(|p| f64::from(p.variance_of_average()))
            .sum::<f64>()
            / (pixels * pixels);
        (mean, var.sqrt())
    }
}
