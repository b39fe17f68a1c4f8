//! The independent kind's generator for a vector of paths at once: [`PcgLanes`].

use crate::sampler::{PCG_MULTIPLIER, fraction_to_f32};

/// `N` generators of [`SamplerKind::Independent`](crate::SamplerKind::Independent), one per
/// lane, each `rand_pcg`'s `Pcg32` (PCG XSH RR 64/32) kept as its state and increment,
/// stepped together: a loop over the lanes that a caller compiled for a SIMD level turns
/// into vector instructions (a 64-bit multiply per lane), where a path's own
/// [`Sampler`](crate::Sampler) steps one generator at a time. Lane `i` gives the numbers
/// of the sampler whose [`Sampler::independent_generator`](crate::Sampler::independent_generator)
/// it was set from, in order, bit for bit.
///
/// Why here and not `rand_pcg`: it steps one generator; this is its LCG step and XSH RR
/// output written again over arrays, held to it by the tests below.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgLanes<const N: usize> {
    /// Each lane's LCG state.
    pub state: [u64; N],
    /// Each lane's increment (odd).
    pub increment: [u64; N],
}

impl<const N: usize> PcgLanes<N> {
    /// Generators that all stand at state 0, increment 1 (a placeholder, until each lane
    /// is set from a sampler).
    pub const UNSET: PcgLanes<N> = PcgLanes {
        state: [0; N],
        increment: [1; N],
    };

    /// Lane `lane`'s generator, from a sampler's
    /// [`independent_generator`](crate::Sampler::independent_generator).
    #[inline]
    pub fn set(&mut self, lane: usize, (state, increment): (u64, u64)) {
        self.state[lane] = state;
        self.increment[lane] = increment;
    }

    /// Each lane's next number, as [`Sampler::next_1d`](crate::Sampler::next_1d) draws it
    /// for the independent kind: the top 24 bits of the generator's next output.
    #[inline(always)]
    pub fn next_1d(&mut self) -> [f32; N] {
        let mut out = [0.0; N];
        for ((value, state), &increment) in out.iter_mut().zip(&mut self.state).zip(&self.increment)
        {
            let old = *state;
            *state = old.wrapping_mul(PCG_MULTIPLIER).wrapping_add(increment);
            // XSH RR: the xorshifted high bits, rotated by the top five.
            let rotation = (old >> 59) as u32;
            let shifted = (((old >> 18) ^ old) >> 27) as u32;
            *value = fraction_to_f32(shifted.rotate_right(rotation));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Sampler, SamplerKind};

    /// Every lane, set from a sampler of its own pixel and sample, draws that sampler's
    /// numbers, bit for bit, over a path's worth of dimensions; and a dimension skipped
    /// by stepping is the one the sampler reaches by starting there.
    #[test]
    fn each_lane_draws_its_sampler_s_numbers() {
        const N: usize = 16;
        let mut lanes = PcgLanes::<N>::UNSET;
        let mut samplers: Vec<Sampler> = (0..N)
            .map(|i| {
                let mut s = Sampler::for_render(SamplerKind::Independent, 7, [64, 64], 64, 1);
                let pixel = [(i * 5) as u32 % 64, (i * 11) as u32 % 64];
                s.start_pixel_sample(pixel, (i * 3) as u32 % 64, 2);
                s
            })
            .collect();
        for (i, s) in samplers.iter().enumerate() {
            lanes.set(i, s.independent_generator().expect("independent"));
        }
        let starts = samplers.clone();
        for _ in 0..100 {
            let drawn = lanes.next_1d();
            for (s, &x) in samplers.iter_mut().zip(&drawn) {
                assert_eq!(s.next_1d().to_bits(), x.to_bits());
            }
        }
        // Dimension 2 + 100 of each sample, reached from its start.
        let next = lanes.next_1d();
        for ((mut s, drawn), i) in starts.into_iter().zip(next).zip(0..) {
            let pixel = [(i * 5) as u32 % 64, (i * 11) as u32 % 64];
            s.start_pixel_sample(pixel, (i * 3) as u32 % 64, 102);
            assert_eq!(s.next_1d().to_bits(), drawn.to_bits());
        }
    }

    #[test]
    fn only_the_independent_kind_has_a_generator() {
        for kind in SamplerKind::ALL {
            let s = Sampler::for_render(*kind, 1, [8, 8], 16, 1);
            assert_eq!(
                s.independent_generator().is_some(),
                *kind == SamplerKind::Independent
            );
        }
    }
}
