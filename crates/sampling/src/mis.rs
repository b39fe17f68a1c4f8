//! Multiple importance sampling weights (Veach 1997, "Robust Monte Carlo
//! Methods for Light Transport Simulation", PhD thesis, §9.2; pbrt-v4 §2.2.3).

/// `n * pdf` with NaN, negative and zero inputs mapped to 0 ("no weight").
/// May be infinite.
#[inline]
fn effective_density(n: f32, pdf: f32) -> f32 {
    if n > 0.0 && pdf > 0.0 { n * pdf } else { 0.0 }
}

/// `f^beta / (f^beta + g^beta)` for `f, g >= 0` computed through the ratio of
/// the smaller to the larger, so that it neither overflows (pbrt-v4's
/// `PowerHeuristic` squares the densities) nor divides infinity by infinity.
#[inline]
fn ratio_weight(f: f32, g: f32, beta: i32) -> f32 {
    if g <= f {
        1.0 / (1.0 + (g / f).powi(beta))
    } else {
        let r = (f / g).powi(beta);
        r / (1.0 + r)
    }
}

fn heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32, beta: i32) -> f32 {
    let f = effective_density(nf, f_pdf);
    let g = effective_density(ng, g_pdf);
    if f == 0.0 {
        return 0.0;
    }
    if f.is_infinite() && g.is_infinite() {
        // Both strategies have a Dirac-like density here: weigh by sample
        // counts alone, which keeps the two weights summing to 1.
        let w = ratio_weight(nf, ng, beta);
        return if w.is_finite() { w } else { 0.5 };
    }
    ratio_weight(f, g, beta)
}

/// Veach's balance heuristic (1997, Eq. 9.8): the weight of a sample from
/// strategy `f` (taken `nf` times, density `f_pdf`) against strategy `g`:
/// `nf f_pdf / (nf f_pdf + ng g_pdf)`.
///
/// Returns 0 when `nf f_pdf` is 0 (so also when both pdfs are 0), 1 when only
/// `f_pdf` is infinite, and a value in `[0, 1]` for any input; never NaN.
/// `balance_heuristic(nf, f, ng, g) + balance_heuristic(ng, g, nf, f) = 1`
/// whenever either density is positive.
pub fn balance_heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32) -> f32 {
    heuristic(nf, f_pdf, ng, g_pdf, 1)
}

/// Veach's power heuristic with exponent 2 (1997, Eq. 9.13):
/// `(nf f_pdf)^2 / ((nf f_pdf)^2 + (ng g_pdf)^2)`, with the same guarantees as
/// [`balance_heuristic`], and no overflow for densities above `1.8e19`.
pub fn power_heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32) -> f32 {
    heuristic(nf, f_pdf, ng, g_pdf, 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        let close = |a: f32, b: f32| (a - b).abs() < 1e-6;
        assert!(close(balance_heuristic(1.0, 3.0, 1.0, 1.0), 0.75));
        assert!(close(power_heuristic(1.0, 3.0, 1.0, 1.0), 0.9));
        assert_eq!(balance_heuristic(2.0, 1.0, 1.0, 2.0), 0.5);
        assert_eq!(power_heuristic(1.0, 1e30, 1.0, 1e30), 0.5);
        assert_eq!(power_heuristic(1.0, f32::INFINITY, 1.0, 1.0), 1.0);
        assert_eq!(power_heuristic(1.0, 1.0, 1.0, f32::INFINITY), 0.0);
        assert!(close(
            balance_heuristic(1.0, f32::INFINITY, 3.0, f32::INFINITY),
            0.25
        ));
        assert_eq!(balance_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
        assert_eq!(power_heuristic(1.0, f32::NAN, 1.0, 1.0), 0.0);
        assert_eq!(power_heuristic(1.0, 1.0, 1.0, f32::NAN), 1.0);
    }
}
