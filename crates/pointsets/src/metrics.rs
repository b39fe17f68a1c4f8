//! Uniformity measures of point sets: L2 discrepancies in closed form and
//! the exact star discrepancy in 2D.
//!
//! All four return the discrepancy itself, not its square. For comparison
//! with `scipy.stats.qmc.discrepancy` (SciPy 1.7+): its `'L2-star'` is the
//! square root (as here), while its `'CD'` and `'WD'` return the *squares*
//! of [`centered_l2_discrepancy`] and [`wraparound_l2_discrepancy`].

use super::{PointSet, PointSetError};

/// The L2-star discrepancy: the L2 norm over anchored boxes `[0, a)` of the
/// local discrepancy `vol([0, a)) - #{x_i in [0, a)} / n`.
///
/// Warnock 1972, "Computational investigations of low-discrepancy point
/// sets", in Zaremba (ed.), Applications of Number Theory to Numerical
/// Analysis:
/// `D^2 = 3^-d - 2^(1-d)/n sum_i prod_k (1 - x_ik^2)
///        + 1/n^2 sum_i sum_j prod_k (1 - max(x_ik, x_jk))`.
/// `O(n^2 d)`. For an empty set, `3^(-d/2)`.
pub fn l2_star_discrepancy(points: &PointSet) -> f64 {
    let (n, d) = (points.len() as f64, points.dim() as i32);
    let single: f64 = points
        .points()
        .map(|x| x.iter().map(|&v| 1.0 - v * v).product::<f64>())
        .sum();
    let pairs = pair_sum(points, |a, b| 1.0 - a.max(b));
    let square = if points.is_empty() {
        3f64.powi(-d)
    } else {
        3f64.powi(-d) - 2f64.powi(1 - d) / n * single + pairs / (n * n)
    };
    square.max(0.0).sqrt()
}

/// The centered L2 discrepancy, which is invariant under reflections
/// `x_k -> 1 - x_k` of any coordinate (boxes anchored at the nearest corner
/// rather than at the origin).
///
/// Hickernell 1998, "A generalized discrepancy and quadrature error bound",
/// Math. Comp. 67(221), eq. (5.1c):
/// `CD^2 = (13/12)^d - 2/n sum_i prod_k (1 + |z_ik|/2 - z_ik^2/2)
///   + 1/n^2 sum_ij prod_k (1 + |z_ik|/2 + |z_jk|/2 - |x_ik - x_jk|/2)`,
/// `z = x - 1/2`. `O(n^2 d)`.
pub fn centered_l2_discrepancy(points: &PointSet) -> f64 {
    let (n, d) = (points.len() as f64, points.dim() as i32);
    let base = (13.0f64 / 12.0).powi(d);
    if points.is_empty() {
        return base.sqrt();
    }
    let single: f64 = points
        .points()
        .map(|x| {
            x.iter()
                .map(|&v| {
                    let z = (v - 0.5).abs();
                    1.0 + 0.5 * z - 0.5 * z * z
                })
                .product::<f64>()
        })
        .sum();
    let pairs = pair_sum(points, |a, b| {
        1.0 + 0.5 * (a - 0.5).abs() + 0.5 * (b - 0.5).abs() - 0.5 * (a - b).abs()
    });
    (base - 2.0 / n * single + pairs / (n * n)).max(0.0).sqrt()
}

/// The wrap-around L2 discrepancy: boxes may wrap around the unit torus, so
/// it does not favour any corner and is invariant under shifts modulo 1
/// (a Cranley–Patterson rotation leaves it unchanged).
///
/// Hickernell 1998 (as above), eq. (5.1d):
/// `WD^2 = -(4/3)^d + 1/n^2 sum_ij prod_k (3/2 - |x_ik - x_jk| (1 - |x_ik - x_jk|))`.
/// `O(n^2 d)`.
pub fn wraparound_l2_discrepancy(points: &PointSet) -> f64 {
    let (n, d) = (points.len() as f64, points.dim() as i32);
    if points.is_empty() {
        return 0.0;
    }
    let pairs = pair_sum(points, |a, b| {
        let t = (a - b).abs();
        1.5 - t * (1.0 - t)
    });
    (pairs / (n * n) - (4.0f64 / 3.0).powi(d)).max(0.0).sqrt()
}

/// `sum_i sum_j prod_k f(x_ik, x_jk)` for a symmetric `f`: the diagonal
/// once, the off-diagonal pairs twice.
fn pair_sum(points: &PointSet, f: impl Fn(f64, f64) -> f64) -> f64 {
    let term = |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).map(|(&u, &v)| f(u, v)).product() };
    let mut total = 0.0;
    for i in 0..points.len() {
        let a = points.point(i);
        let mut row = 0.0;
        for j in 0..i {
            row += term(a, points.point(j));
        }
        total += 2.0 * row + term(a, a);
    }
    total
}

/// The exact star discrepancy of a 2D point set: the supremum over anchored
/// boxes `[0, a) x [0, b)` of `|ab - #{points inside} / n|`.
///
/// The supremum is reached at a corner `(a, b)` on the grid of the points'
/// coordinates (and 1), with the box either open or closed (Niederreiter
/// 1972, "Discrepancy and convex programming", Ann. Mat. Pura Appl. 93;
/// Bundschuh and Zhu 1993, "A method for exact calculation of the
/// discrepancy of low-dimensional finite point sets", Abh. Math. Sem. Univ.
/// Hamburg 63): `D* = max over the grid of max(ab - A_open / n,
/// A_closed / n - ab)`. This visits the whole grid: `O(n^2 log n)`, fine
/// for `n` up to a few thousand. An empty set has `D* = 1`.
///
/// Errors with [`PointSetError::UnsupportedDimensions`] unless `dim == 2`.
pub fn star_discrepancy_2d(points: &PointSet) -> Result<f64, PointSetError> {
    if points.dim() != 2 {
        return Err(PointSetError::UnsupportedDimensions {
            what: "the exact star discrepancy",
            dim: points.dim(),
            supported: "2",
        });
    }
    let n = points.len();
    if n == 0 {
        return Ok(1.0);
    }
    let mut by_x: Vec<[f64; 2]> = points.points().map(|p| [p[0], p[1]]).collect();
    by_x.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut b_values: Vec<f64> = by_x.iter().map(|p| p[1]).collect();
    b_values.push(1.0);
    b_values.sort_by(f64::total_cmp);
    b_values.dedup();

    let inv_n = 1.0 / n as f64;
    let mut worst = 0.0f64;
    // `below` holds, sorted, the y of every point with x < a (then <= a).
    let mut below: Vec<f64> = Vec::with_capacity(n);
    let mut next = 0;
    let mut a_values: Vec<f64> = by_x.iter().map(|p| p[0]).collect();
    a_values.push(1.0);
    a_values.dedup();
    for &a in &a_values {
        // Open in x: points with x < a are in `below` now.
        for &b in &b_values {
            let open = below.partition_point(|&y| y < b) as f64;
            worst = worst.max(a * b - open * inv_n);
        }
        while next < n && by_x[next][0] <= a {
            let y = by_x[next][1];
            let at = below.partition_point(|&v| v <= y);
            below.insert(at, y);
            next += 1;
        }
        for &b in &b_values {
            let closed = below.partition_point(|&y| y <= b) as f64;
            worst = worst.max(closed * inv_n - a * b);
        }
    }
    Ok(worst)
}
