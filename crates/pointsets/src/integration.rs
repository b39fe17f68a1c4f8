//! Integration-error analysis as UTK runs it (Perrier, Coeurjolly et al.,
//! "Sequences with low-discrepancy blue-noise 2-D projections", Eurographics
//! 2018, and the UTK toolkit's `IntegrationTest`): integrate random 2D
//! integrands of known integral with a point set, average the squared error
//! over independent randomizations (a fresh point-set seed and a fresh
//! integrand each time), and fit the convergence rate of that mean squared
//! error in `n`.
//!
//! Families follow UTK's `Integrands/Gaussians.hpp` and `Heaviside.hpp`,
//! restricted to what has a closed form here:
//! - [`IntegrandFamily::Gaussian`]: an isotropic Gaussian
//!   `exp(-|x - mu|^2 / (2 s^2))`, `mu` uniform in the unit square and the
//!   variance `s^2` uniform in `[0.01, 1]` (UTK's defaults `smin = 0.01`,
//!   `smax = 1`, which are variances); UTK also rotates an anisotropic
//!   covariance, which has no separable closed form, so the width is
//!   isotropic here and the integral is a product of two `erf` differences.
//! - [`IntegrandFamily::Heaviside`]: UTK's half-plane indicator
//!   `[n . (x - p) > 0]`, with `n` a uniform direction and `p` uniform in the
//!   unit square; its integral is the area of a convex polygon (the square
//!   clipped by the half-plane).
//! - [`IntegrandFamily::Disk`]: the indicator of a disk lying inside the
//!   square (radius uniform in `[0.05, 0.45]`, centre uniform where the disk
//!   fits), whose integral is `pi r^2`; a discontinuity along a curve rather
//!   than a line.
//!
//! Expected rates (Pilleboue, Singh et al. 2015, "Variance analysis for
//! Monte Carlo integration", ACM TOG 34(4)): independent points give
//! `O(n^-1)` for every integrand; jittered points `O(n^-2)` for smooth
//! integrands in 2D and `O(n^-1.5)` for discontinuities along curves;
//! Owen-scrambled nets `O(n^-3 log n)` for smooth ones (Owen 1997,
//! "Scrambled net variance for integrals of smooth functions", Ann. Stat.
//! 25(4)) and `O(n^-1.5)` for discontinuities.

use std::f64::consts::{FRAC_1_SQRT_2, PI};
use std::fmt;

use super::hash::{hash2, hash3, u64_to_unit};
use super::{PointSet, PointSetError, PointSetKind, generate};

/// A family of random 2D integrands over `[0, 1)^2`, each member with a
/// closed-form integral.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntegrandFamily {
    /// Smooth: isotropic Gaussians of random centre and width.
    Gaussian,
    /// Discontinuous along a line: random half-plane indicators.
    Heaviside,
    /// Discontinuous along a circle: random disk indicators inside the
    /// square.
    Disk,
}

impl IntegrandFamily {
    /// Every family, in a stable order.
    pub const ALL: &'static [IntegrandFamily] = &[
        IntegrandFamily::Gaussian,
        IntegrandFamily::Heaviside,
        IntegrandFamily::Disk,
    ];

    /// The lowercase name used on command lines.
    pub fn name(&self) -> &'static str {
        match self {
            IntegrandFamily::Gaussian => "gaussian",
            IntegrandFamily::Heaviside => "heaviside",
            IntegrandFamily::Disk => "disk",
        }
    }

    /// The family called `s` (ASCII case-insensitive), if any.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|f| f.name().eq_ignore_ascii_case(s))
    }
}

impl fmt::Display for IntegrandFamily {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One integrand over `[0, 1)^2` with a known integral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrand {
    /// `exp(-|x - centre|^2 / (2 sigma^2))`.
    Gaussian {
        /// The peak.
        centre: [f64; 2],
        /// The standard deviation, in both axes.
        sigma: f64,
    },
    /// `1` where `normal . x > offset`, else `0`.
    HalfPlane {
        /// A unit vector pointing into the half-plane.
        normal: [f64; 2],
        /// `normal . p` for a point `p` on the boundary line.
        offset: f64,
    },
    /// `1` where `|x - centre| < radius`, else `0`; the disk lies inside
    /// the unit square.
    Disk {
        /// The centre.
        centre: [f64; 2],
        /// The radius.
        radius: f64,
    },
}

impl Integrand {
    /// A member of `family` drawn from `seed` (a pure function of both, so
    /// a seed names an integrand).
    pub fn random(family: IntegrandFamily, seed: u64) -> Self {
        let u = |k: u64| u64_to_unit(hash2(seed, k));
        match family {
            IntegrandFamily::Gaussian => Integrand::Gaussian {
                centre: [u(0), u(1)],
                // UTK draws the variance, not the deviation, in [0.01, 1].
                sigma: (0.01 + 0.99 * u(2)).sqrt(),
            },
            IntegrandFamily::Heaviside => {
                // A uniform direction (UTK normalises a Gaussian vector,
                // which is the same in 2D) through a uniform point.
                let angle = 2.0 * PI * u(0);
                let normal = [angle.cos(), angle.sin()];
                let p = [u(1), u(2)];
                Integrand::HalfPlane {
                    normal,
                    offset: normal[0] * p[0] + normal[1] * p[1],
                }
            }
            IntegrandFamily::Disk => {
                let radius = 0.05 + 0.4 * u(0);
                let span = 1.0 - 2.0 * radius;
                Integrand::Disk {
                    centre: [radius + span * u(1), radius + span * u(2)],
                    radius,
                }
            }
        }
    }

    /// The integrand at `x`.
    #[inline]
    pub fn eval(&self, x: [f64; 2]) -> f64 {
        match *self {
            Integrand::Gaussian { centre, sigma } => {
                let (dx, dy) = (x[0] - centre[0], x[1] - centre[1]);
                (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp()
            }
            Integrand::HalfPlane { normal, offset } => {
                f64::from(u8::from(normal[0] * x[0] + normal[1] * x[1] > offset))
            }
            Integrand::Disk { centre, radius } => {
                let (dx, dy) = (x[0] - centre[0], x[1] - centre[1]);
                f64::from(u8::from(dx * dx + dy * dy < radius * radius))
            }
        }
    }

    /// The exact integral over the unit square.
    pub fn integral(&self) -> f64 {
        match *self {
            Integrand::Gaussian { centre, sigma } => {
                // Separable: prod_k int_0^1 exp(-(t - c)^2 / 2s^2) dt
                //   = prod_k s sqrt(pi/2) (erf((1 - c)/(s sqrt2)) + erf(c/(s sqrt2))).
                let axis = |c: f64| {
                    let k = FRAC_1_SQRT_2 / sigma;
                    sigma * (PI / 2.0).sqrt() * (libm::erf((1.0 - c) * k) + libm::erf(c * k))
                };
                axis(centre[0]) * axis(centre[1])
            }
            Integrand::HalfPlane { normal, offset } => half_plane_area(normal, offset),
            Integrand::Disk { radius, .. } => PI * radius * radius,
        }
    }
}

/// Area of `{x in [0, 1]^2 : normal . x > offset}`: the unit square clipped
/// by the half-plane (Sutherland and Hodgman 1974, "Reentrant polygon
/// clipping", CACM 17(1)), then the shoelace formula. Exact up to rounding;
/// UTK uses the equivalent inclusion–exclusion over the cube's vertices.
fn half_plane_area(normal: [f64; 2], offset: f64) -> f64 {
    let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let side = |p: [f64; 2]| normal[0] * p[0] + normal[1] * p[1] - offset;
    let mut clipped: Vec<[f64; 2]> = Vec::with_capacity(5);
    for k in 0..4 {
        let (a, b) = (square[k], square[(k + 1) % 4]);
        let (sa, sb) = (side(a), side(b));
        if sa > 0.0 {
            clipped.push(a);
        }
        if (sa > 0.0) != (sb > 0.0) {
            let t = sa / (sa - sb);
            clipped.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    let mut twice_area = 0.0;
    for k in 0..clipped.len() {
        let (a, b) = (clipped[k], clipped[(k + 1) % clipped.len()]);
        twice_area += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * twice_area.abs()
}

/// The estimate `1/n sum f(x_i)` over the first two coordinates of each
/// point (0 for an empty set).
pub fn integrate(integrand: &Integrand, points: &PointSet) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let sum: f64 = points
        .points()
        .map(|p| integrand.eval([p[0], p.get(1).copied().unwrap_or(0.0)]))
        .sum();
    sum / points.len() as f64
}

/// The seeds of randomization `r`: one for the point set, one for the
/// integrand. They do not depend on `n`, so that a convergence curve sees
/// the same integrands at every `n` (common random numbers: the spread of
/// the integrand family then cancels out of the slope).
fn randomization_seeds(seed: u64, r: usize) -> (u64, u64) {
    (
        hash3(seed, r as u64, 0x706f_696e_7473),
        hash3(seed, r as u64, 0x0066_756e_6374),
    )
}

/// The mean squared error of integrating members of `family` with `n`
/// points of `kind` (2D), over `randomizations` independent pairs of a
/// point-set seed and an integrand, all derived from `seed`.
///
/// Errors where `kind` cannot make `n` points in 2D.
pub fn integration_mse(
    kind: PointSetKind,
    family: IntegrandFamily,
    n: usize,
    randomizations: usize,
    seed: u64,
) -> Result<f64, PointSetError> {
    if randomizations == 0 {
        return Ok(0.0);
    }
    let mut total = 0.0;
    for r in 0..randomizations {
        let (point_seed, integrand_seed) = randomization_seeds(seed, r);
        let points = generate(kind, n, 2, point_seed)?;
        let integrand = Integrand::random(family, integrand_seed);
        let error = integrate(&integrand, &points) - integrand.integral();
        total += error * error;
    }
    Ok(total / randomizations as f64)
}

/// A convergence curve: the mean squared error at each `n` and the fitted
/// rate.
#[derive(Clone, Debug, PartialEq)]
pub struct Convergence {
    /// The point counts, as given.
    pub ns: Vec<usize>,
    /// [`integration_mse`] at each of them.
    pub mse: Vec<f64>,
    /// The least-squares slope of `log2(mse)` against `log2(n)`: about -1
    /// for independent points, -2 for jittered ones on smooth integrands.
    /// NaN with fewer than two distinct `n`, or with a zero MSE.
    pub slope: f64,
}

/// [`integration_mse`] at every `n` of `ns` (the same seed, hence the same
/// integrands, at each), and the fitted log-log slope.
pub fn convergence_slope(
    kind: PointSetKind,
    family: IntegrandFamily,
    ns: &[usize],
    randomizations: usize,
    seed: u64,
) -> Result<Convergence, PointSetError> {
    let mse = ns
        .iter()
        .map(|&n| integration_mse(kind, family, n, randomizations, seed))
        .collect::<Result<Vec<f64>, _>>()?;
    let xs: Vec<f64> = ns.iter().map(|&n| (n as f64).log2()).collect();
    let ys: Vec<f64> = mse.iter().map(|&e| e.log2()).collect();
    Ok(Convergence {
        ns: ns.to_vec(),
        slope: least_squares_slope(&xs, &ys),
        mse,
    })
}

/// The slope of the least-squares line through `(xs[i], ys[i])`; NaN when
/// the `xs` are all equal or a value is not finite.
pub fn least_squares_slope(xs: &[f64], ys: &[f64]) -> f64 {
    let n = xs.len().min(ys.len()) as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    if sxx > 0.0 { sxy / sxx } else { f64::NAN }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Midpoint rule on a fine grid, to check the closed forms.
    fn brute_force(integrand: &Integrand) -> f64 {
        let m = 2000;
        let mut sum = 0.0;
        for i in 0..m {
            for j in 0..m {
                let x = [(i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64];
                sum += integrand.eval(x);
            }
        }
        sum / (m * m) as f64
    }

    #[test]
    fn closed_forms_match_quadrature() {
        for &family in IntegrandFamily::ALL {
            for seed in 0..4 {
                let f = Integrand::random(family, seed);
                let (exact, quad) = (f.integral(), brute_force(&f));
                // Smooth: the midpoint rule is far below 1e-6; indicators:
                // a boundary of length <= 3 crossing cells of area 2.5e-7.
                assert!(
                    (exact - quad).abs() < 1e-4,
                    "{family} {f:?}: {exact} {quad}"
                );
            }
        }
    }

    #[test]
    fn half_plane_areas() {
        let s = FRAC_1_SQRT_2;
        for (normal, offset, area) in [
            ([1.0, 0.0], 0.25, 0.75),
            ([-1.0, 0.0], -0.25, 0.25),
            ([0.0, 1.0], 2.0, 0.0),
            ([0.0, 1.0], -1.0, 1.0),
            ([s, s], s, 0.5),
            ([s, s], 0.5 * s, 0.875),
        ] {
            let a = half_plane_area(normal, offset);
            assert!((a - area).abs() < 1e-12, "{normal:?} {offset}: {a}");
        }
    }

    #[test]
    fn slope_of_a_power_law() {
        let xs = [4.0, 5.0, 6.0, 7.0];
        let ys: Vec<f64> = xs.iter().map(|x| 3.0 - 1.5 * x).collect();
        assert!((least_squares_slope(&xs, &ys) + 1.5).abs() < 1e-12);
        assert!(least_squares_slope(&[1.0, 1.0], &[2.0, 3.0]).is_nan());
    }
}
