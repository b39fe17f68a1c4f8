//! The radially averaged power spectrum of an image: the picture that
//! tells blue-noise error (little power at low frequencies) from white
//! noise (flat), as `lueur_pointsets::radial_power_spectrum`
//! does for point sets.
//!
//! The image's mean is removed, its 2D DFT taken separably (a plain
//! `O(N^3)` DFT: at the figures' 128x128 pixels it takes milliseconds, so
//! no FFT crate is needed), and `P(f) = |F(f)|^2 / N^2` averaged over the
//! annuli `round(|f|) = r`. With that scaling white noise of variance
//! `s^2` has `E[P(f)] = s^2` at every frequency, and the mean of `P` over
//! all frequencies is the image's variance (Parseval).

/// A radially averaged periodogram of an `N x N` image.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageSpectrum {
    /// Mean of `P(f)` over the annulus of radius `r` (in cycles per
    /// image), for `r = 1..=N/2`, at index `r - 1`.
    pub power: Vec<f64>,
    /// How many frequency vectors each annulus holds.
    pub counts: Vec<usize>,
}

impl ImageSpectrum {
    /// The radii `1..=N/2`, as plot abscissae.
    pub fn radii(&self) -> impl Iterator<Item = f64> + '_ {
        (1..=self.power.len()).map(|r| r as f64)
    }

    /// The energy (sum of `P(f)`) over the annuli `1..=max_radius`.
    pub fn energy_up_to(&self, max_radius: usize) -> f64 {
        self.power
            .iter()
            .zip(&self.counts)
            .take(max_radius)
            .map(|(&p, &c)| p * c as f64)
            .sum()
    }

    /// The mean of several spectra of same-sized images (the counts are
    /// the same for all of them).
    pub fn mean(spectra: &[ImageSpectrum]) -> ImageSpectrum {
        let first = &spectra[0];
        let n = spectra.len() as f64;
        ImageSpectrum {
            power: (0..first.power.len())
                .map(|i| spectra.iter().map(|s| s.power[i]).sum::<f64>() / n)
                .collect(),
            counts: first.counts.clone(),
        }
    }
}

/// The radially averaged power spectrum of the `size x size` image
/// `values` (row-major), its mean removed.
pub fn image_spectrum(values: &[f64], size: usize) -> ImageSpectrum {
    assert_eq!(values.len(), size * size, "a square image");
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let (re, im) = dft_2d(values.iter().map(|v| v - mean).collect(), size);
    let half = size / 2;
    let mut sums = vec![0.0; half + 1];
    let mut counts = vec![0usize; half + 1];
    let signed = |k: usize| {
        if k <= size / 2 {
            k as f64
        } else {
            k as f64 - size as f64
        }
    };
    let norm = (size * size) as f64;
    for ky in 0..size {
        for kx in 0..size {
            let radius = signed(kx).hypot(signed(ky)).round() as usize;
            if radius == 0 || radius > half {
                continue;
            }
            let at = ky * size + kx;
            sums[radius] += (re[at] * re[at] + im[at] * im[at]) / norm;
            counts[radius] += 1;
        }
    }
    ImageSpectrum {
        power: (1..=half)
            .map(|r| sums[r] / counts[r].max(1) as f64)
            .collect(),
        counts: counts[1..].to_vec(),
    }
}

/// The unnormalized 2D DFT `F(k) = sum_x f(x) exp(-2 pi i k . x / N)` of a
/// real `size x size` image: rows, then columns.
fn dft_2d(values: Vec<f64>, size: usize) -> (Vec<f64>, Vec<f64>) {
    // exp(-2 pi i m / N) for m = 0..N; index products are taken mod N.
    let twiddle: Vec<(f64, f64)> = (0..size)
        .map(|m| {
            let (s, c) = (-2.0 * std::f64::consts::PI * m as f64 / size as f64).sin_cos();
            (c, s)
        })
        .collect();
    let dft_1d = |re_in: &[f64], im_in: &[f64], re_out: &mut [f64], im_out: &mut [f64]| {
        for k in 0..size {
            let (mut sr, mut si) = (0.0, 0.0);
            for x in 0..size {
                let (c, s) = twiddle[(k * x) % size];
                sr += re_in[x] * c - im_in[x] * s;
                si += re_in[x] * s + im_in[x] * c;
            }
            re_out[k] = sr;
            im_out[k] = si;
        }
    };
    let zeros = vec![0.0; size];
    let (mut re, mut im) = (vec![0.0; size * size], vec![0.0; size * size]);
    for y in 0..size {
        let row = y * size..(y + 1) * size;
        let (r, i) = (&mut re[row.clone()], &mut im[row.clone()]);
        dft_1d(&values[row], &zeros, r, i);
    }
    let (mut col_re, mut col_im) = (vec![0.0; size], vec![0.0; size]);
    let (mut out_re, mut out_im) = (vec![0.0; size], vec![0.0; size]);
    for x in 0..size {
        for y in 0..size {
            col_re[y] = re[y * size + x];
            col_im[y] = im[y * size + x];
        }
        dft_1d(&col_re, &col_im, &mut out_re, &mut out_im);
        for y in 0..size {
            re[y * size + x] = out_re[y];
            im[y * size + x] = out_im[y];
        }
    }
    (re, im)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed pseudo-random image in [-0.5, 0.5) (splitmix64).
    fn noise(size: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..size * size)
            .map(|_| {
                state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
                let mut z = state;
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                z ^= z >> 31;
                (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn a_constant_image_has_no_power() {
        let s = image_spectrum(&vec![3.0; 16 * 16], 16);
        assert_eq!(s.power.len(), 8);
        assert!(s.power.iter().all(|&p| p.abs() < 1e-20), "{s:?}");
    }

    #[test]
    fn a_cosine_has_power_only_at_its_frequency() {
        let size = 32;
        let img: Vec<f64> = (0..size * size)
            .map(|i| (2.0 * std::f64::consts::PI * 5.0 * (i % size) as f64 / size as f64).cos())
            .collect();
        let s = image_spectrum(&img, size);
        for (r, &p) in s.power.iter().enumerate() {
            if r + 1 == 5 {
                assert!(p > 1.0, "{s:?}");
            } else {
                assert!(p < 1e-18, "radius {}: {p}", r + 1);
            }
        }
    }

    #[test]
    fn white_noise_is_flat_at_its_variance() {
        let size = 64;
        let spectra: Vec<ImageSpectrum> = (0..8)
            .map(|seed| image_spectrum(&noise(size, seed), size))
            .collect();
        let s = ImageSpectrum::mean(&spectra);
        // Uniform on [-0.5, 0.5): variance 1/12; the low and high halves
        // agree with it, and with each other, within a few percent.
        let half = s.power.len() / 2;
        let band = |from: usize, to: usize| {
            let e: f64 = (from..to).map(|i| s.power[i] * s.counts[i] as f64).sum();
            e / s.counts[from..to].iter().sum::<usize>() as f64
        };
        let (low, high) = (band(0, half), band(half, s.power.len()));
        assert!((low * 12.0 - 1.0).abs() < 0.1, "{low}");
        assert!((high * 12.0 - 1.0).abs() < 0.05, "{high}");
    }

    #[test]
    fn the_dft_keeps_energy() {
        // Parseval: sum |F|^2 = N^2 sum |f|^2 for the unnormalized DFT.
        let size = 16;
        let img = noise(size, 3);
        let (re, im) = dft_2d(img.clone(), size);
        let freq: f64 = re.iter().zip(&im).map(|(r, i)| r * r + i * i).sum();
        let space: f64 = img.iter().map(|v| v * v).sum();
        assert!((freq / (size * size) as f64 - space).abs() < 1e-9 * space);
    }
}
