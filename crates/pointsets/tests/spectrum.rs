//! The radially averaged power spectrum: flat for independent points,
//! low at low frequencies for jittered and Poisson-disk points (blue noise).

use lueur_pointsets::{PointSetKind, RadialSpectrum, generate, radial_power_spectrum};

/// The spectrum of `n` points of `kind`, averaged over `seeds` seeds.
fn mean_spectrum(kind: PointSetKind, n: usize, half_size: usize, seeds: u64) -> RadialSpectrum {
    let mut total = vec![0.0; half_size];
    let mut radii = Vec::new();
    for seed in 0..seeds {
        let s = radial_power_spectrum(&generate(kind, n, 2, seed).unwrap(), half_size).unwrap();
        for (t, p) in total.iter_mut().zip(&s.power) {
            *t += p / seeds as f64;
        }
        radii = s.radii;
    }
    RadialSpectrum {
        radii,
        power: total,
    }
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// `E[P(f)] = 1` at every nonzero integer frequency for independent
/// points. Radii 5..=32 hold about 3000 frequencies, 4 seeds: the mean's
/// standard error is about 1%, so 10% is a wide margin.
#[test]
fn independent_points_have_a_flat_spectrum() {
    let s = mean_spectrum(PointSetKind::Independent, 1024, 32, 4);
    let m = mean(&s.power[4..]);
    eprintln!("independent: mean power over radii 5..32 = {m:.3}");
    assert!((m - 1.0).abs() < 0.1, "{:?}", s.power);
}

/// Jittered and Poisson-disk points are blue: little power below the
/// frequency of their spacing, `sqrt(n) = 32` cycles per unit. For a
/// jittered grid, `E[P(f)] = 1 - |sinc|^2` of the cell, about 0.58 at
/// `|f| = sqrt(n)/2`: each radius up to `sqrt(n)/4` and the mean up to
/// `sqrt(n)/2` are below 0.5.
#[test]
fn jittered_and_poisson_disk_points_are_blue() {
    let n = 1024;
    let half = 16; // sqrt(n) / 2
    for kind in [PointSetKind::Stratified, PointSetKind::PoissonDisk] {
        let s = mean_spectrum(kind, n, 40, 4);
        eprintln!("{kind}: {:.2?}", s.power);
        assert!(
            s.power[..half / 2].iter().all(|&p| p < 0.5),
            "{kind}: {:?}",
            &s.power[..half / 2]
        );
        let low = mean(&s.power[..half]);
        assert!(low < 0.5, "{kind}: mean low-frequency power {low}");
    }
}
