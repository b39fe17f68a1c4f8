//! The radially averaged power spectrum of a 2D point set: the usual
//! picture of blue noise (Ulichney 1987, "Digital Halftoning"; for point
//! sets, Lagae and Dutré 2008, "A comparison of methods for generating
//! Poisson disk distributions", Computer Graphics Forum 27(1); UTK's
//! `RadialSpectrum`).
//!
//! The periodogram `P(f) = |sum_j exp(-2 pi i f . x_j)|^2 / n` is taken at
//! integer frequency vectors, where the torus is periodic and independent
//! uniform points have `E[P(f)] = 1` exactly for every `f != 0`: power below
//! 1 at low frequencies is what "blue" means, and spikes are regular
//! structure (a grid's lattice peaks).

use super::{PointSet, PointSetError};

/// A radially averaged periodogram.
#[derive(Clone, Debug, PartialEq)]
pub struct RadialSpectrum {
    /// The annuli's radii `1, 2, ..., K` (in cycles per unit length).
    pub radii: Vec<f64>,
    /// The mean of `P(f)` over the integer vectors `f` with
    /// `round(|f|) = radius`.
    pub power: Vec<f64>,
}

/// The radially averaged power spectrum of `points` (2D) over the integer
/// frequencies in `[-half_size, half_size]^2`, averaged over annuli of
/// integer radius `1..=half_size` (each annulus lies inside the square).
/// The zero frequency, where `P = n`, is left out.
///
/// `O(n K^2)`: each point's phasors along x and y are built by complex
/// multiplication (one `sin`/`cos` pair per point and axis) and combined
/// separably. For an empty set every power is 0.
///
/// Errors with [`PointSetError::UnsupportedDimensions`] unless `dim == 2`.
pub fn radial_power_spectrum(
    points: &PointSet,
    half_size: usize,
) -> Result<RadialSpectrum, PointSetError> {
    if points.dim() != 2 {
        return Err(PointSetError::UnsupportedDimensions {
            what: "the radial power spectrum",
            dim: points.dim(),
            supported: "2",
        });
    }
    let k = half_size as i64;
    let side = 2 * half_size + 1;
    // Real and imaginary parts of sum_j exp(-2 pi i f . x_j), f = (fx, fy),
    // stored at [(fy + K) * side + (fx + K)].
    let mut re = vec![0.0; side * side];
    let mut im = vec![0.0; side * side];
    let (mut ax, mut ay) = (vec![(0.0, 0.0); side], vec![(0.0, 0.0); side]);
    let phasors = |t: f64, out: &mut [(f64, f64)]| {
        // exp(-2 pi i f t) for f = -K..=K, from exp(-2 pi i t) by
        // repeated multiplication: accurate to ~K ulps, far below the noise.
        let (s, c) = (-2.0 * std::f64::consts::PI * t).sin_cos();
        out[half_size] = (1.0, 0.0);
        for f in 1..=half_size {
            let (pr, pi) = out[half_size + f - 1];
            let next = (pr * c - pi * s, pr * s + pi * c);
            out[half_size + f] = next;
            out[half_size - f] = (next.0, -next.1);
        }
    };
    for p in points.points() {
        phasors(p[0], &mut ax);
        phasors(p[1], &mut ay);
        for (row, &(yr, yi)) in ay.iter().enumerate() {
            let (re_row, im_row) = (
                &mut re[row * side..(row + 1) * side],
                &mut im[row * side..(row + 1) * side],
            );
            for ((r, i), &(xr, xi)) in re_row.iter_mut().zip(im_row.iter_mut()).zip(&ax) {
                *r += xr * yr - xi * yi;
                *i += xr * yi + xi * yr;
            }
        }
    }
    let n = points.len().max(1) as f64;
    let mut sums = vec![0.0; half_size + 1];
    let mut counts = vec![0usize; half_size + 1];
    for fy in -k..=k {
        for fx in -k..=k {
            let radius = ((fx * fx + fy * fy) as f64).sqrt().round() as usize;
            if radius == 0 || radius > half_size {
                continue;
            }
            let at = ((fy + k) as usize) * side + (fx + k) as usize;
            sums[radius] += (re[at] * re[at] + im[at] * im[at]) / n;
            counts[radius] += 1;
        }
    }
    Ok(RadialSpectrum {
        radii: (1..=half_size).map(|r| r as f64).collect(),
        power: (1..=half_size)
            .map(|r| sums[r] / counts[r].max(1) as f64)
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_single_point_has_unit_power_everywhere() {
        let p = PointSet::new(2, vec![0.3, 0.7]).unwrap();
        let s = radial_power_spectrum(&p, 8).unwrap();
        assert_eq!(s.radii.len(), 8);
        assert!(s.power.iter().all(|&v| (v - 1.0).abs() < 1e-9), "{s:?}");
    }

    #[test]
    fn a_regular_grid_has_peaks_at_its_lattice() {
        // 8x8 cell centres: P = n at multiples of 8 along the axes, 0 at
        // every other nonzero frequency below 8.
        let data: Vec<f64> = (0..64)
            .flat_map(|i| [((i % 8) as f64 + 0.5) / 8.0, ((i / 8) as f64 + 0.5) / 8.0])
            .collect();
        let s = radial_power_spectrum(&PointSet::new(2, data).unwrap(), 8).unwrap();
        assert!(s.power[..7].iter().all(|&v| v < 1e-9), "{s:?}");
        assert!(s.power[7] > 1.0, "{s:?}");
    }

    #[test]
    fn three_dimensional_sets_are_refused() {
        let p = PointSet::new(3, vec![0.1, 0.2, 0.3]).unwrap();
        assert!(radial_power_spectrum(&p, 4).is_err());
    }
}
