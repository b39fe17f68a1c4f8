//! Multiple importance sampling weights (Veach 1997, "Robust Monte Carlo
//! Methods for Light Transport Simulation", PhD thesis, §9.2; pbrt-v4 §2.2.3).

use lueur_sdf_math::Lane;

/// `n * pdf` with NaN, negative and zero inputs mapped to 0 ("no weight").
/// May be infinite.
#[inline(always)]
fn effective_density<L: Lane>(n: L, pdf: L) -> L {
    let zero = L::splat(0.0);
    L::select(L::and(n.gt(zero), pdf.gt(zero)), n * pdf, zero)
}

/// `x^beta` for the heuristics' exponents, by multiplication: the bits of `powi`.
#[inline(always)]
fn power<L: Lane>(x: L, beta: u32) -> L {
    debug_assert!(beta >= 1, "the heuristics' exponents are 1 and 2");
    (1..beta).fold(x, |r, _| r * x)
}

/// `f^beta / (f^beta + g^beta)` for `f, g >= 0` computed through the ratio of
/// the smaller to the larger, so that it neither overflows (pbrt-v4's
/// `PowerHeuristic` squares the densities) nor divides infinity by infinity: with `r`
/// that ratio to the power `beta`, `1 / (1 + r)` where `g <= f`, else `r / (1 + r)`. Two
/// divisions, whichever side a lane is on.
#[inline(always)]
fn ratio_weight<L: Lane>(f: L, g: L, beta: u32) -> L {
    // `g <= f`, false where either is NaN.
    let g_le_f = f.ge(g);
    let (smaller, larger) = (L::select(g_le_f, g, f), L::select(g_le_f, f, g));
    let r = power(smaller / larger, beta);
    L::select(g_le_f, L::splat(1.0), r) / (L::splat(1.0) + r)
}

/// The heuristic of exponent `beta`, per lane: each lane's weight is the one its inputs
/// give alone.
#[inline(always)]
fn heuristic<L: Lane>(nf: L, f_pdf: L, ng: L, g_pdf: L, beta: u32) -> L {
    let f = effective_density(nf, f_pdf);
    // `f` is 0 or more: not above 0 is 0. (At one lane, the divisions are skipped.)
    let weighs = f.gt(L::splat(0.0));
    if !L::any(weighs) {
        return L::splat(0.0);
    }
    let g = effective_density(ng, g_pdf);
    let infinite = |x: L| x.gt(L::splat(f32::MAX));
    // Both strategies have a Dirac-like density here: weigh by sample counts alone,
    // which keeps the two weights summing to 1.
    let dirac = L::and(infinite(f), infinite(g));
    let w = if L::any(dirac) {
        let w = ratio_weight(L::select(dirac, nf, f), L::select(dirac, ng, g), beta);
        L::select(L::and(dirac, L::not(w.finite())), L::splat(0.5), w)
    } else {
        ratio_weight(f, g, beta)
    };
    L::select(weighs, w, L::splat(0.0))
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
    power_heuristic_lanes(nf, f_pdf, ng, g_pdf)
}

/// [`power_heuristic`] per lane, its one definition: each lane's weight is the bits
/// [`power_heuristic`] gives for that lane's inputs.
#[inline(always)]
pub fn power_heuristic_lanes<L: Lane>(nf: L, f_pdf: L, ng: L, g_pdf: L) -> L {
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
