//! Rank-1 Kronecker sequences: the additive recurrence `x_i = frac(s + i a)`
//! with Roberts's generalised golden ratios.
//!
//! Roberts 2018, "The Unreasonable Effectiveness of Quasirandom Sequences"
//! (extremelearning.com.au): in `d` dimensions, `phi_d` is the positive root
//! of `x^(d+1) = x + 1` and `a_j = phi_d^-(j+1)`; `d = 2` gives "R2". The
//! random start `s` is a Cranley–Patterson rotation (Cranley and Patterson
//! 1976, "Randomization of number theoretic methods for multiple
//! integration", SIAM J. Numer. Anal. 13(6)), which makes every point
//! uniform while keeping the set's structure.

/// `phi_d`, the unique positive root of `x^(d+1) = x + 1`, by Newton's
/// method from 2 (the function is convex there, so it converges from above).
pub fn generalized_golden_ratio(d: usize) -> f64 {
    let power = d as i32 + 1;
    let mut x = 2.0f64;
    for _ in 0..64 {
        let f = x.powi(power) - x - 1.0;
        let df = f64::from(power) * x.powi(power - 1) - 1.0;
        let next = x - f / df;
        if next == x {
            break;
        }
        x = next;
    }
    x
}

/// The increments of the `d`-dimensional sequence as 64-bit binary
/// fractions, so that `s + i a` is computed exactly modulo 1 by wrapping
/// integer arithmetic (a float `i * a` would lose the low bits of the
/// fractional part as `i` grows).
pub fn increments(d: usize) -> Vec<u64> {
    let phi = generalized_golden_ratio(d);
    (1..=d)
        .map(|j| {
            let a = phi.powi(-(j as i32));
            // a in (0, 1): exact scaling by 2^64, truncation toward zero.
            (a * 18_446_744_073_709_551_616.0) as u64
        })
        .collect()
}
