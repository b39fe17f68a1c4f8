//! lueur-stats: the goodness-of-fit machinery that checks that a sampler's
//! samples follow the pdf it reports. Pearson's chi-square test with pooling
//! of sparse bins ([`chi_square_test`], whose outcome is the primary type,
//! [`ChiSquareTest`]), its p-value through the regularised incomplete gamma
//! function, and equal-solid-angle binning of directions
//! ([`DirectionBins`]), as Mitsuba's `chi2` module and pbrt-v4's
//! `bsdfs_test.cpp` do.
//!
//! What it is not: part of the renderer. It is a dev-only helper
//! (`publish = false`, used only in `[dev-dependencies]`), shared by every
//! crate whose tests owe the same check (warps and lights in
//! `lueur-sampling`, strategies in `lueur-integrator`); no renderer crate
//! depends on it. Its unit tests hold it to closed forms; `statrs` would give the gamma functions but not the pooling nor
//! the direction bins, and is not in the dependency tree.
//!
//! ```
//! use lueur_stats::{DirectionBins, chi_square_test};
//! use glam::Vec3;
//!
//! // Counts that match their expectation are accepted...
//! let fit = chi_square_test(&[98.0, 103.0, 99.0], &[100.0, 100.0, 100.0]);
//! assert!(fit.accepts(0.01));
//! // ...counts far from it are not.
//! assert!(!chi_square_test(&[150.0, 50.0, 100.0], &[100.0, 100.0, 100.0]).accepts(0.01));
//!
//! // Equal-solid-angle bins over the hemisphere around +z.
//! let bins = DirectionBins::new(Vec3::Z, 0.0, 4, 8);
//! assert_eq!(bins.len(), 32);
//! assert!(bins.bin(Vec3::new(0.0, 0.0, 1.0)).is_some());
//! assert!(bins.bin(Vec3::new(0.0, 0.0, -1.0)).is_none());
//! ```

#![deny(missing_docs)]

use std::f64::consts::TAU;

use glam::{DVec3, Vec3};

use lueur_sampling::Frame;

/// Natural log of the gamma function for `x > 0`, by the Lanczos
/// approximation with `g = 7`, 9 coefficients (Numerical Recipes, 3rd ed.,
/// §6.1); relative error near `1e-15`. The reflection formula covers
/// `x < 0.5`.
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin().abs()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    0.5 * TAU.ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised lower incomplete gamma function `P(a, x) = gamma(a, x) /
/// Gamma(a)` for `a > 0`, `x >= 0`: the series for `x < a + 1`, else `1 - Q`
/// from the continued fraction (Numerical Recipes, 3rd ed., §6.2).
pub fn regularized_gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x < a + 1.0 {
        gamma_series(a, x)
    } else {
        1.0 - gamma_continued_fraction(a, x)
    }
}

/// Regularised upper incomplete gamma function `Q(a, x) = 1 - P(a, x)`,
/// computed directly in the tail so that small p-values keep their digits.
pub fn regularized_gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        1.0
    } else if x < a + 1.0 {
        1.0 - gamma_series(a, x)
    } else {
        gamma_continued_fraction(a, x)
    }
}

/// `P(a, x)` by its power series.
fn gamma_series(a: f64, x: f64) -> f64 {
    let mut ap = a;
    let mut term = 1.0 / a;
    let mut sum = term;
    for _ in 0..10_000 {
        ap += 1.0;
        term *= x / ap;
        sum += term;
        if term.abs() < sum.abs() * 1e-16 {
            break;
        }
    }
    sum * (-x + a * x.ln() - ln_gamma(a)).exp()
}

/// `Q(a, x)` by its continued fraction, evaluated with the modified Lentz
/// method.
fn gamma_continued_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..10_000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + an / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x + a * x.ln() - ln_gamma(a)).exp() * h
}

/// Upper-tail probability of the chi-square distribution with `dof` degrees
/// of freedom: `Q(dof / 2, statistic / 2)`.
pub fn chi_square_p_value(statistic: f64, dof: f64) -> f64 {
    regularized_gamma_q(dof / 2.0, statistic / 2.0)
}

/// Bins whose expected count is below this are pooled together.
pub const MIN_EXPECTED_COUNT: f64 = 5.0;

/// Outcome of [`chi_square_test`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquareTest {
    /// Pearson's statistic `sum (observed - expected)^2 / expected`.
    pub statistic: f64,
    /// Degrees of freedom: cells after pooling, minus one.
    pub dof: usize,
    /// Probability of a statistic at least this large if the samples follow
    /// the expected distribution; 0 when `impossible_samples > 0`.
    pub p_value: f64,
    /// How many sparse bins were merged into pooled cells.
    pub pooled_bins: usize,
    /// Samples observed in bins whose expected count is exactly 0: proof that
    /// the sampler leaves the pdf's support.
    pub impossible_samples: f64,
}

impl ChiSquareTest {
    /// True when the fit is not rejected at level `significance`.
    pub fn accepts(&self, significance: f64) -> bool {
        self.p_value >= significance
    }
}

/// Pearson's chi-square goodness-of-fit test of `observed` counts against
/// `expected` counts (same length). Bins are sorted by expected count and
/// those below [`MIN_EXPECTED_COUNT`] are pooled, smallest first, into cells
/// of at least that count (as Mitsuba's `ChiSquareTest` does); a remainder
/// joins the last pooled cell, or the smallest regular cell.
pub fn chi_square_test(observed: &[f64], expected: &[f64]) -> ChiSquareTest {
    assert_eq!(observed.len(), expected.len(), "one expected count per bin");
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut impossible = 0.0;
    let mut cells: Vec<(f64, f64)> = Vec::new();
    let mut pooled_cells = 0;
    let mut pooled_bins = 0;
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    for &i in &order {
        let (obs, exp) = (observed[i], expected[i]);
        if exp <= 0.0 {
            impossible += obs;
        } else if exp < MIN_EXPECTED_COUNT {
            pool_obs += obs;
            pool_exp += exp;
            pooled_bins += 1;
            if pool_exp >= MIN_EXPECTED_COUNT {
                cells.push((pool_obs, pool_exp));
                pooled_cells += 1;
                pool_obs = 0.0;
                pool_exp = 0.0;
            }
        } else {
            cells.push((obs, exp));
        }
    }
    if pool_exp > 0.0 {
        // Sorted order: pooled cells come first, so the last pooled cell is at
        // pooled_cells - 1, and otherwise cell 0 is the smallest regular one.
        match cells.get_mut(pooled_cells.max(1) - 1) {
            Some(cell) => {
                cell.0 += pool_obs;
                cell.1 += pool_exp;
            }
            None => cells.push((pool_obs, pool_exp)),
        }
    }
    let statistic: f64 = cells.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = cells.len().saturating_sub(1);
    let p_value = if impossible > 0.0 {
        0.0
    } else if dof == 0 {
        1.0
    } else {
        chi_square_p_value(statistic, dof as f64)
    };
    ChiSquareTest {
        statistic,
        dof,
        p_value,
        pooled_bins,
        impossible_samples: impossible,
    }
}

/// Equal-solid-angle bins over the spherical band `z_min <= cos(theta) <=
/// z_max` around `axis` (a cap when `z_max = 1`): `n_z` bins uniform in
/// `z = cos(theta)` times `n_phi` bins uniform in azimuth. With `z_min = -1`
/// a cap covers the whole sphere. Since `d omega = dz dphi`, the midpoint
/// rule on a sub-grid in `(z, phi)` integrates a pdf over each bin without a
/// Jacobian.
#[derive(Clone, Copy, Debug)]
pub struct DirectionBins {
    frame: Frame,
    z_min: f64,
    z_max: f64,
    n_z: usize,
    n_phi: usize,
}

impl DirectionBins {
    /// Bins over the cap of directions within `acos(z_min)` of the unit
    /// vector `axis`.
    pub fn new(axis: Vec3, z_min: f64, n_z: usize, n_phi: usize) -> Self {
        Self::band(axis, z_min, 1.0, n_z, n_phi)
    }

    /// Bins over the band `z_min <= cos(theta) <= z_max` around `axis`: a
    /// thin band resolves a light seen at grazing angles far better than a
    /// cap, whose rows are coarse in angle near the pole.
    pub fn band(axis: Vec3, z_min: f64, z_max: f64, n_z: usize, n_phi: usize) -> Self {
        assert!(n_z > 0 && n_phi > 0 && -1.0 <= z_min && z_min < z_max && z_max <= 1.0);
        Self {
            frame: Frame::from_normal(axis.normalize()),
            z_min,
            z_max,
            n_z,
            n_phi,
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.n_z * self.n_phi
    }

    /// Always false: there is at least one bin.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The bin of direction `w`, or `None` outside the band (or non-finite).
    /// A direction a hair outside the band (by `1e-6 + 1e-5 (z_max - z_min)`
    /// in `z`, the f32 rounding of a sample on a support boundary that
    /// coincides with the band's edge) counts in the nearest row.
    pub fn bin(&self, w: Vec3) -> Option<usize> {
        let f = &self.frame;
        let w = w.as_dvec3();
        let local = DVec3::new(
            w.dot(f.s.as_dvec3()),
            w.dot(f.t.as_dvec3()),
            w.dot(f.n.as_dvec3()),
        );
        let length = local.length();
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let z = local.z / length;
        let height = self.z_max - self.z_min;
        let slack = 1e-6 + 1e-5 * height;
        if z < self.z_min - slack || z > self.z_max + slack {
            return None;
        }
        let iz =
            (((z - self.z_min).max(0.0) / height * self.n_z as f64) as usize).min(self.n_z - 1);
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let iphi = ((phi / TAU * self.n_phi as f64) as usize).min(self.n_phi - 1);
        Some(iz * self.n_phi + iphi)
    }

    /// `n_samples` times the integral of `pdf` over each bin, by the midpoint
    /// rule on a `sub x sub` grid per bin.
    pub fn expected_counts(
        &self,
        pdf: impl Fn(Vec3) -> f32,
        n_samples: f64,
        sub: usize,
    ) -> Vec<f64> {
        let dz = (self.z_max - self.z_min) / (self.n_z * sub) as f64;
        let dphi = TAU / (self.n_phi * sub) as f64;
        let mut counts = vec![0.0; self.len()];
        for iz in 0..self.n_z {
            for iphi in 0..self.n_phi {
                let mut sum = 0.0;
                for jz in 0..sub {
                    let z = self.z_min + ((iz * sub + jz) as f64 + 0.5) * dz;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for jphi in 0..sub {
                        let phi = ((iphi * sub + jphi) as f64 + 0.5) * dphi;
                        let local = DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3();
                        sum += f64::from(pdf(self.frame.to_world(local)));
                    }
                }
                counts[iz * self.n_phi + iphi] = sum * dz * dphi * n_samples;
            }
        }
        counts
    }

    /// Histogram of `directions`; those outside the band are counted in the
    /// returned second value.
    pub fn histogram(&self, directions: impl IntoIterator<Item = Vec3>) -> (Vec<f64>, f64) {
        let mut counts = vec![0.0; self.len()];
        let mut outside = 0.0;
        for w in directions {
            match self.bin(w) {
                Some(i) => counts[i] += 1.0,
                None => outside += 1.0,
            }
        }
        (counts, outside)
    }

    /// Chi-square test of `directions` against `pdf` (integrated with a
    /// `sub x sub` grid per bin). Directions outside the band count as
    /// impossible samples: choose a band that contains the pdf's support.
    pub fn test(
        &self,
        directions: impl IntoIterator<Item = Vec3>,
        pdf: impl Fn(Vec3) -> f32,
        sub: usize,
    ) -> ChiSquareTest {
        let (mut observed, outside) = self.histogram(directions);
        let n: f64 = observed.iter().sum::<f64>() + outside;
        let mut expected = self.expected_counts(pdf, n, sub);
        observed.push(outside);
        expected.push(0.0);
        chi_square_test(&observed, &expected)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    #[test]
    fn ln_gamma_known_values() {
        // Gamma(n) = (n - 1)!, Gamma(1/2) = sqrt(pi), Gamma(0.1) from tables.
        for (x, expected) in [
            (1.0, 0.0f64),
            (2.0, 0.0),
            (5.0, 24f64.ln()),
            (10.0, 362_880f64.ln()),
            (0.5, std::f64::consts::PI.sqrt().ln()),
            (0.1, 9.513_507_698_668_732f64.ln()),
            (100.5, 361.435_540_467_777_6),
        ] {
            assert!(
                (ln_gamma(x) - expected).abs() < 1e-12 * expected.abs().max(1.0),
                "lnGamma({x})"
            );
        }
    }

    #[test]
    fn incomplete_gamma_known_values() {
        // P(1, x) = 1 - exp(-x); Q(1/2, x) = erfc(sqrt x), erfc(1) = 0.157299...
        for x in [0.01, 0.5, 1.0, 2.0, 7.5, 30.0] {
            assert!(close(regularized_gamma_p(1.0, x), 1.0 - (-x).exp(), 1e-13));
            assert!(close(regularized_gamma_q(1.0, x), (-x).exp(), 1e-12));
        }
        assert!(close(
            regularized_gamma_q(0.5, 1.0),
            0.157_299_207_050_285_13,
            1e-12
        ));
        assert_eq!(regularized_gamma_p(3.0, 0.0), 0.0);
        assert_eq!(regularized_gamma_q(3.0, 0.0), 1.0);
    }

    #[test]
    fn chi_square_critical_values() {
        // Upper 5% and 1% points (Abramowitz & Stegun 26.8); the tail
        // probabilities were evaluated with mpmath at 30 digits.
        for (statistic, dof, p) in [
            (3.841_458_820_694_124, 1.0, 0.05),
            (6.634_896_601_021_214, 1.0, 0.01),
            (18.307_038_053_275_146, 10.0, 0.05),
            (23.209_251_158_954_356, 10.0, 0.01),
            (124.342_113_404_867_4, 100.0, 0.049_999_999_994_551_01),
            (1_106.969_249_741_703, 1000.0, 0.009_999_857_736_378_296),
        ] {
            let got = chi_square_p_value(statistic, dof);
            assert!(
                close(got, p, 1e-9),
                "chi2({statistic}, {dof}) = {got}, want {p}"
            );
        }
    }

    #[test]
    fn pooling_and_impossible_bins() {
        let t = chi_square_test(&[10.0, 2.0, 2.0, 1.0, 0.0], &[10.0, 1.5, 1.5, 2.0, 0.0]);
        assert_eq!(t.impossible_samples, 0.0);
        assert_eq!(t.pooled_bins, 3);
        assert_eq!(t.dof, 1);
        assert!(t.statistic < 1e-12);
        let t = chi_square_test(&[10.0, 1.0], &[11.0, 0.0]);
        assert_eq!(t.impossible_samples, 1.0);
        assert_eq!(t.p_value, 0.0);
    }

    #[test]
    fn bins_cover_the_cap_with_equal_solid_angle() {
        let bins = DirectionBins::new(Vec3::new(0.3, -0.2, 0.9), -1.0, 8, 16);
        let counts = bins.expected_counts(|_| 1.0, 1.0, 2);
        for c in &counts {
            assert!(close(*c, 4.0 * std::f64::consts::PI / 128.0, 1e-12));
        }
        assert_eq!(
            bins.bin(Vec3::new(0.3, -0.2, 0.9).normalize())
                .map(|i| i / 16),
            Some(7)
        );
        assert_eq!(bins.bin(Vec3::NAN), None);
    }
}
