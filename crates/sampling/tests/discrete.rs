use lueur_sampling::{DiscreteDistribution, ONE_MINUS_EPSILON};
use lueur_stats::chi_square_test;
use proptest::prelude::*;

use crate::common::{N_SAMPLES, Uniforms, assert_fits, proptest_config};

#[test]
fn frequencies_match_pmf_with_zero_weights() {
    let weights = [1.0, 0.0, 3.0, 0.5, 0.0, 10.0, 2.0, 1e-3];
    let d = DiscreteDistribution::new(&weights).unwrap();
    let mut observed = vec![0.0; weights.len()];
    let mut u = Uniforms::new(50);
    for _ in 0..N_SAMPLES {
        let (i, pmf) = d.sample(u.next_1d());
        assert_eq!(pmf, d.pmf(i));
        observed[i] += 1.0;
    }
    let expected: Vec<f64> = (0..weights.len())
        .map(|i| f64::from(d.pmf(i)) * N_SAMPLES as f64)
        .collect();
    // Zero-weight indices have expected count 0: one draw of them fails.
    assert_fits(
        "discrete distribution",
        chi_square_test(&observed, &expected),
    );
}

#[test]
fn uniform_distribution() {
    let d = DiscreteDistribution::uniform(7).unwrap();
    assert_eq!(d.len(), 7);
    for i in 0..7 {
        assert!((d.pmf(i) - 1.0 / 7.0).abs() < 1e-7);
    }
    assert_eq!(d.sample(0.0).0, 0);
    assert_eq!(d.sample(ONE_MINUS_EPSILON).0, 6);
    assert_eq!(d.sample(3.5 / 7.0).0, 3);
}

proptest! {
    #![proptest_config(proptest_config(500))]

    #[test]
    fn pmf_sums_to_one_and_samples_have_weight(
        weights in prop::collection::vec(
            prop_oneof![Just(0.0f32), 1e-6f32..1e6],
            1..40,
        ),
        u in prop_oneof![Just(0.0f32), Just(ONE_MINUS_EPSILON), 0.0f32..1.0],
    ) {
        match DiscreteDistribution::new(&weights) {
            None => prop_assert!(weights.iter().all(|&w| w == 0.0)),
            Some(d) => {
                let total: f64 = (0..d.len()).map(|i| f64::from(d.pmf(i))).sum();
                prop_assert!((total - 1.0).abs() < 1e-5, "sum {}", total);
                let (i, pmf) = d.sample(u);
                prop_assert!(i < weights.len() && weights[i] > 0.0 && pmf > 0.0);
                prop_assert_eq!(pmf, d.pmf(i));
            }
        }
    }
}
