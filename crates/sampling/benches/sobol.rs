//! Owen-scrambled Sobol' of lueur against the `sobol_burley` crate (Burley
//! 2020's reference implementation in Rust), sample by sample as a renderer
//! asks for them: `cargo bench -p lueur-sampling`. A plain timing loop, the
//! best of several runs, so that no benchmark harness is needed.

use std::hint::black_box;
use std::time::Instant;

use lueur_pointsets::sobol_owen_u32;
use lueur_sampling::{Sampler, SamplerKind};

/// Nanoseconds per call of `f` over `2^16` indices and 4 dimensions, best of
/// `runs` runs.
fn time(runs: usize, mut f: impl FnMut(u32, u32) -> f32) -> f64 {
    let calls = (1u32 << 16) * 4;
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            let mut acc = 0.0f32;
            for i in 0..1u32 << 16 {
                for d in 0..4 {
                    acc += f(black_box(i), black_box(d));
                }
            }
            black_box(acc);
            start.elapsed().as_secs_f64() * 1e9 / f64::from(calls)
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let runs = 20;
    let seed = 0x1234_5678;
    let ours = time(runs, |i, d| {
        (sobol_owen_u32(i, d as usize, seed) >> 8) as f32 * (1.0 / 16_777_216.0)
    });
    let burley = time(runs, |i, d| sobol_burley::sample(i, d, seed));
    let burley_4d = time(runs, |i, d| {
        // One 4D call serves 4 dimensions: charge a quarter per dimension.
        if d == 0 {
            sobol_burley::sample_4d(i, 0, seed).iter().sum()
        } else {
            0.0
        }
    });
    let mut sampler = Sampler::for_image(SamplerKind::SobolOwen, 1, [256, 256], 1 << 16);
    let renderer = time(runs, |i, d| {
        sampler.start_pixel_sample([7, 9], i, d);
        sampler.next_1d()
    });
    let mut zsobol = Sampler::for_image(SamplerKind::ZSobol, 1, [256, 256], 1 << 16);
    let renderer_z = time(runs, |i, d| {
        zsobol.start_pixel_sample([7, 9], i, d);
        zsobol.next_1d()
    });
    println!("ns per 1D value (2^16 indices x 4 dimensions, best of {runs}):");
    println!("  lueur sobol_owen_u32          {ours:6.2}");
    println!("  sobol_burley::sample          {burley:6.2}");
    println!("  sobol_burley::sample_4d (/4)  {burley_4d:6.2}");
    println!("  lueur Sampler sobol-owen      {renderer:6.2}");
    println!("  lueur Sampler zsobol          {renderer_z:6.2}");
}
