//! Choosing the lane width at run time: [`SimdLevel`] names each path, detects what the
//! CPU offers and runs a [`LaneKernel`] on it; [`LaneDistance`] is what every field
//! implements once, generically, and gets its batch evaluation from.

use std::marker::PhantomData;

use thiserror::Error;

use super::{Avx2, Avx512, Isa, Lane, LaneVec3, Neon, Portable, Sse, Task, Wide};

/// A dispatch path: the lane type a kernel runs with, and the instruction set it is
/// compiled for. Every variant exists on every target; [`SimdLevel::available`] says which
/// this CPU can run. All of them give the same bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SimdLevel {
    /// One lane, `f32`: the scalar formulas themselves.
    Scalar,
    /// 8 lanes with no target features beyond the compilation target's.
    Portable,
    /// 4 lanes, x86 SSE4.2.
    Sse,
    /// 8 lanes, x86 AVX2.
    Avx2,
    /// 16 lanes, x86 AVX-512.
    Avx512,
    /// 4 lanes, aarch64 NEON.
    Neon,
}

/// A [`SimdLevel`] was forced that this CPU (or target) does not have.
#[derive(Clone, Copy, Debug, Error, PartialEq, Eq)]
#[error("this CPU cannot run the {0:?} lane path")]
pub struct UnavailableLevel(pub SimdLevel);

/// Code generic over its lane type, run by [`SimdLevel::dispatch`] with the level's lane
/// type. Mark `run` `#[inline(always)]`: it is compiled with the level's target features
/// only where it is inlined into the dispatching function.
pub trait LaneKernel {
    /// What the kernel returns.
    type Output;
    /// The kernel, instantiated for one lane type.
    fn run<L: Lane>(self) -> Self::Output;
}

impl SimdLevel {
    /// Every level, narrowest first.
    pub const ALL: [SimdLevel; 6] = [
        SimdLevel::Scalar,
        SimdLevel::Portable,
        SimdLevel::Sse,
        SimdLevel::Neon,
        SimdLevel::Avx2,
        SimdLevel::Avx512,
    ];

    /// The widest level this CPU offers.
    pub fn detect() -> SimdLevel {
        Self::widest_up_to(usize::MAX)
    }

    /// The widest instruction-set level this CPU offers with at most `lanes` lanes; where
    /// it has none, `Portable` if `lanes` allows its 8, else `Scalar`.
    pub fn widest_up_to(lanes: usize) -> SimdLevel {
        let best = [
            SimdLevel::Avx512,
            SimdLevel::Avx2,
            SimdLevel::Sse,
            SimdLevel::Neon,
        ];
        let fallback = if lanes >= SimdLevel::Portable.lanes() {
            SimdLevel::Portable
        } else {
            SimdLevel::Scalar
        };
        best.into_iter()
            .find(|level| level.lanes() <= lanes && level.is_available())
            .unwrap_or(fallback)
    }

    /// This level where the CPU has it, else the widest it has ([`SimdLevel::detect`]):
    /// what a stream asked to run on a level runs on.
    pub fn or_widest(self) -> SimdLevel {
        if self.is_available() {
            self
        } else {
            SimdLevel::detect()
        }
    }

    /// Every level this CPU can run, narrowest first (always `Scalar` and `Portable`).
    pub fn available() -> Vec<SimdLevel> {
        Self::ALL.into_iter().filter(|l| l.is_available()).collect()
    }

    /// Whether this CPU can run the level.
    pub fn is_available(self) -> bool {
        match self {
            SimdLevel::Scalar | SimdLevel::Portable => true,
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            SimdLevel::Sse => pulp::x86::V2::try_new().is_some(),
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            SimdLevel::Avx2 => pulp::x86::V3::try_new().is_some(),
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            SimdLevel::Avx512 => pulp::x86::V4::try_new().is_some(),
            #[cfg(target_arch = "aarch64")]
            SimdLevel::Neon => pulp::aarch64::Neon::try_new().is_some(),
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    /// The level's name on a command line: `scalar`, `portable`, `sse`, `avx2`, `avx512`,
    /// `neon`.
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Scalar => "scalar",
            SimdLevel::Portable => "portable",
            SimdLevel::Sse => "sse",
            SimdLevel::Avx2 => "avx2",
            SimdLevel::Avx512 => "avx512",
            SimdLevel::Neon => "neon",
        }
    }

    /// The level named `name` ([`SimdLevel::name`]), if any.
    pub fn from_name(name: &str) -> Option<SimdLevel> {
        Self::ALL.into_iter().find(|level| level.name() == name)
    }

    /// How many lanes the level's lane type holds.
    pub fn lanes(self) -> usize {
        match self {
            SimdLevel::Scalar => 1,
            SimdLevel::Sse | SimdLevel::Neon => 4,
            SimdLevel::Portable | SimdLevel::Avx2 => 8,
            SimdLevel::Avx512 => 16,
        }
    }

    /// Runs `kernel` with this level's lane type, inside a function compiled for its
    /// instruction set.
    #[inline]
    pub fn dispatch<K: LaneKernel>(self, kernel: K) -> Result<K::Output, UnavailableLevel> {
        let output = match self {
            SimdLevel::Scalar => Some(kernel.run::<f32>()),
            SimdLevel::Portable => {
                Portable::within(Run::<K, Wide<8, Portable>>(kernel, PhantomData))
            }
            SimdLevel::Sse => Sse::within(Run::<K, Wide<4, Sse>>(kernel, PhantomData)),
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx2 => Avx2::within(Run::<K, super::x86::Ymm>(kernel, PhantomData)),
            #[cfg(not(target_arch = "x86_64"))]
            SimdLevel::Avx2 => Avx2::within(Run::<K, Wide<8, Avx2>>(kernel, PhantomData)),
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx512 => Avx512::within(Run::<K, super::x86::Zmm>(kernel, PhantomData)),
            #[cfg(not(target_arch = "x86_64"))]
            SimdLevel::Avx512 => Avx512::within(Run::<K, Wide<16, Avx512>>(kernel, PhantomData)),
            SimdLevel::Neon => Neon::within(Run::<K, Wide<4, Neon>>(kernel, PhantomData)),
        };
        output.ok_or(UnavailableLevel(self))
    }
}

/// A kernel instantiated for the lane type `L`, as a [`Task`].
struct Run<K, L>(K, PhantomData<L>);

impl<K: LaneKernel, L: Lane> Task for Run<K, L> {
    type Output = K::Output;
    #[inline(always)]
    fn run(self) -> K::Output {
        self.0.run::<L>()
    }
}

/// A distance field written once over any [`Lane`] type: [`Primitive`](crate::Primitive),
/// [`Sdf`](crate::Sdf) and [`PreparedSdf`](crate::PreparedSdf). The scalar `distance` of
/// each is this at `f32`, so every lane of a batch equals it bit for bit.
pub trait LaneDistance {
    /// The signed distance (or bound) at each lane's point.
    fn distance_lanes<L: Lane>(&self, p: LaneVec3<L>) -> L;

    /// `out[i] = distance((xs[i], ys[i], zs[i]))` on the widest path this CPU has: whole
    /// lanes, then a tail in one partly filled vector.
    ///
    /// # Panics
    /// If the four slices differ in length.
    fn distance_batch(&self, xs: &[f32], ys: &[f32], zs: &[f32], out: &mut [f32]) {
        let level = SimdLevel::detect();
        // `detect` only returns levels the CPU has.
        let _ = self.distance_batch_at(level, xs, ys, zs, out);
    }

    /// [`LaneDistance::distance_batch`] on a forced path; the same bits on every path.
    ///
    /// # Panics
    /// If the four slices differ in length.
    fn distance_batch_at(
        &self,
        level: SimdLevel,
        xs: &[f32],
        ys: &[f32],
        zs: &[f32],
        out: &mut [f32],
    ) -> Result<(), UnavailableLevel> {
        let n = out.len();
        assert!(
            xs.len() == n && ys.len() == n && zs.len() == n,
            "distance_batch: {} x, {} y, {} z for {n} outputs",
            xs.len(),
            ys.len(),
            zs.len()
        );
        level.dispatch(Batch {
            field: self,
            xs,
            ys,
            zs,
            out,
        })
    }
}

/// The kernel behind [`LaneDistance::distance_batch_at`].
struct Batch<'a, F: ?Sized> {
    field: &'a F,
    xs: &'a [f32],
    ys: &'a [f32],
    zs: &'a [f32],
    out: &'a mut [f32],
}

impl<F: LaneDistance + ?Sized> LaneKernel for Batch<'_, F> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let chunks = self.out.chunks_mut(L::LANES);
        let points = self
            .xs
            .chunks(L::LANES)
            .zip(self.ys.chunks(L::LANES))
            .zip(self.zs.chunks(L::LANES));
        for (out, ((x, y), z)) in chunks.zip(points) {
            let p = LaneVec3::new(L::load(x), L::load(y), L::load(z));
            self.field.distance_lanes(p).store(out);
        }
    }
}
