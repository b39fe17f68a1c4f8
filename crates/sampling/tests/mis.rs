use lueur_sampling::{balance_heuristic, power_heuristic};
use proptest::prelude::*;

use crate::common::proptest_config;

/// A pdf: zero, infinite, or anything from 1e-30 to 1e30.
fn pdf() -> impl Strategy<Value = f32> {
    prop_oneof![
        Just(0.0f32),
        Just(f32::INFINITY),
        (-30.0f32..30.0).prop_map(|e| 10f32.powf(e)),
    ]
}

proptest! {
    #![proptest_config(proptest_config(2000))]

    #[test]
    fn weights_partition_unity(nf in 1u32..5, f in pdf(), ng in 1u32..5, g in pdf()) {
        let (nf, ng) = (nf as f32, ng as f32);
        for heuristic in [balance_heuristic, power_heuristic] {
            let wf = heuristic(nf, f, ng, g);
            let wg = heuristic(ng, g, nf, f);
            prop_assert!((0.0..=1.0).contains(&wf) && (0.0..=1.0).contains(&wg), "{} {}", wf, wg);
            if f == 0.0 && g == 0.0 {
                prop_assert_eq!((wf, wg), (0.0, 0.0));
            } else {
                prop_assert!((wf + wg - 1.0).abs() < 1e-6, "{} + {}", wf, wg);
            }
        }
    }
}

#[test]
fn nan_inputs_give_no_weight_not_nan() {
    for heuristic in [balance_heuristic, power_heuristic] {
        assert_eq!(heuristic(1.0, f32::NAN, 1.0, f32::NAN), 0.0);
        assert_eq!(heuristic(1.0, f32::NAN, 1.0, 2.0), 0.0);
        assert_eq!(heuristic(1.0, 2.0, 1.0, f32::NAN), 1.0);
        assert_eq!(heuristic(0.0, 2.0, 1.0, 1.0), 0.0);
    }
}
