//! Discrete distributions, for choosing one light among many.

use crate::math::clamp_u;

/// A distribution over `0..len()` proportional to non-negative weights,
/// sampled by inverting its cumulative distribution (pbrt-v4 §2.3.1 and
/// §A.4, the piecewise-constant case with unit-width cells).
///
/// Invariant: the pmfs sum to 1 (to f32 rounding), an index with pmf 0 is
/// never sampled, and every sampled index has `pmf > 0`.
#[derive(Clone, Debug)]
pub struct DiscreteDistribution {
    pmf: Vec<f32>,
    /// `cdf[i]` is the probability of an index below `i`; `cdf[len] = 1`.
    cdf: Vec<f64>,
}

impl DiscreteDistribution {
    /// A distribution proportional to `weights`. `None` when `weights` is
    /// empty, all zero, or holds a negative, NaN or infinite weight.
    pub fn new(weights: &[f32]) -> Option<Self> {
        if weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        // Finite f32 weights cannot overflow an f64 sum: no NaN here.
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        if total <= 0.0 {
            return None;
        }
        // The cdf is built from the f32 pmfs themselves, so that an index
        // whose pmf rounds to 0 can never be drawn.
        let pmf: Vec<f32> = weights
            .iter()
            .map(|&w| (f64::from(w) / total) as f32)
            .collect();
        let pmf_total: f64 = pmf.iter().map(|&p| f64::from(p)).sum();
        let mut cdf = Vec::with_capacity(pmf.len() + 1);
        let mut running = 0.0;
        cdf.push(0.0);
        for &p in &pmf {
            running += f64::from(p);
            cdf.push(running / pmf_total);
        }
        // Exactly 1, so that every u < 1 finds an index.
        *cdf.last_mut()? = 1.0;
        Some(Self { pmf, cdf })
    }

    /// The uniform distribution over `n` indices; `None` for `n = 0`.
    pub fn uniform(n: usize) -> Option<Self> {
        Self::new(&vec![1.0; n])
    }

    /// Draws an index from a uniform `u` in `[0, 1)` and returns it with its
    /// pmf. Never returns an index of pmf 0. With one index, `u` is not read
    /// ([`DiscreteDistribution::reads_u`]).
    pub fn sample(&self, u: f32) -> (usize, f32) {
        // One index (a scene with one light): what the search below finds for every `u`,
        // without it; the renderer asks once or twice per path vertex.
        if let [pmf] = self.pmf[..] {
            return (0, pmf);
        }
        let u = f64::from(clamp_u(u));
        // First i with cdf[i + 1] > u; cdf[len] = 1 > u, so i < len.
        let i = self.cdf[1..].partition_point(|&c| c <= u);
        let i = i.min(self.pmf.len() - 1);
        (i, self.pmf[i])
    }

    /// Whether [`DiscreteDistribution::sample`] reads its `u`: not with one index, so a
    /// caller may leave that number undrawn.
    pub fn reads_u(&self) -> bool {
        self.pmf.len() > 1
    }

    /// Probability of index `i` (0 out of range).
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }

    /// Number of indices, zero-weight ones included.
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// Always false: an empty distribution cannot be built.
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::ONE_MINUS_EPSILON;

    /// One index: index 0 with pmf 1 for every `u`, as the search finds it (the shortcut
    /// must not change a draw).
    #[test]
    fn one_index_is_always_drawn_with_pmf_one() {
        for d in [
            DiscreteDistribution::uniform(1).unwrap(),
            DiscreteDistribution::new(&[3.5]).unwrap(),
        ] {
            for u in [0.0, 0.5, ONE_MINUS_EPSILON, 1.0, -1.0, f32::NAN] {
                assert_eq!(d.sample(u), (0, 1.0), "u = {u}");
            }
            assert_eq!(d.pmf(0), 1.0);
        }
    }

    #[test]
    fn rejects_bad_weights() {
        for weights in [
            &[][..],
            &[0.0, 0.0],
            &[1.0, -1.0],
            &[1.0, f32::NAN],
            &[1.0, f32::INFINITY],
        ] {
            assert!(DiscreteDistribution::new(weights).is_none(), "{weights:?}");
        }
        assert!(DiscreteDistribution::uniform(0).is_none());
    }

    #[test]
    fn zero_weights_are_skipped_at_the_ends_of_u() {
        let d = DiscreteDistribution::new(&[0.0, 2.0, 0.0, 0.0, 1.0, 0.0]).unwrap();
        assert_eq!(d.sample(0.0), (1, 2.0 / 3.0));
        assert_eq!(d.sample(ONE_MINUS_EPSILON), (4, 1.0 / 3.0));
        assert_eq!(d.sample(2.0 / 3.0 - 1e-6).0, 1);
        assert_eq!(d.sample(2.0 / 3.0 + 1e-6).0, 4);
        assert_eq!(d.pmf(0), 0.0);
        assert_eq!(d.pmf(99), 0.0);
        assert_eq!(d.len(), 6);
        assert!(!d.is_empty());
    }

    #[test]
    fn extreme_weight_ratio_never_returns_zero_pmf() {
        let d = DiscreteDistribution::new(&[f32::MAX, f32::MIN_POSITIVE]).unwrap();
        for u in [0.0, 0.5, ONE_MINUS_EPSILON] {
            let (_, pmf) = d.sample(u);
            assert!(pmf > 0.0);
        }
    }
}
