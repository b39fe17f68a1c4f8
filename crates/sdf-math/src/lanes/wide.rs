//! [`Wide`]: `N` lanes of `f32`, each operation the `f32` one applied lane by lane, in a
//! loop the compiler turns into vector instructions of the instruction set `I`.
//!
//! Writing each lane's operation as the scalar one, rather than as intrinsics, is what
//! makes the bit-identity contract hold by construction: the vector unit's add, multiply,
//! divide, square root, compare and blend round exactly as the scalar unit does, and the
//! compiler never fuses a multiply and an add on its own. The instruction set comes from
//! where the code runs: [`SimdLevel::dispatch`](super::SimdLevel::dispatch) enters a
//! function compiled with `I`'s target features (through `pulp`, safely), and what is
//! inlined into it runs with them.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Lane, SimdLevel, Task};

/// An instruction set a [`Wide`] vector is compiled for.
pub trait Isa: Copy + fmt::Debug + 'static {
    /// The dispatch level it is.
    const LEVEL: SimdLevel;
    /// Runs `task` in a function compiled with this instruction set's target features, or
    /// as plain code where the CPU lacks them (the results are the same either way).
    fn within<T: Task>(task: T) -> T::Output;
}

/// No target features beyond the compilation target's own (SSE2 on x86_64, NEON on
/// aarch64, scalar code elsewhere).
#[derive(Clone, Copy, Debug)]
pub struct Portable;

/// x86 up to SSE4.2 (pulp's `V2`), 4 lanes.
#[derive(Clone, Copy, Debug)]
pub struct Sse;

/// x86 AVX2 (pulp's `V3`), 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct Avx2;

/// x86 AVX-512 F/BW/CD/DQ/VL (pulp's `V4`), 16 lanes.
#[derive(Clone, Copy, Debug)]
pub struct Avx512;

/// aarch64 NEON (pulp's `Neon`), 4 lanes.
#[derive(Clone, Copy, Debug)]
pub struct Neon;

impl Isa for Portable {
    const LEVEL: SimdLevel = SimdLevel::Portable;
    #[inline(always)]
    fn within<T: Task>(task: T) -> T::Output {
        task.run()
    }
}

/// A [`Task`] as pulp's `NullaryFnOnce`, whose `call` pulp inlines into its
/// target-feature function.
#[cfg_attr(
    not(any(target_arch = "x86", target_arch = "x86_64", target_arch = "aarch64")),
    allow(dead_code)
)]
struct Pulp<T>(T);

impl<T: Task> pulp::NullaryFnOnce for Pulp<T> {
    type Output = T::Output;
    #[inline(always)]
    fn call(self) -> T::Output {
        self.0.run()
    }
}

/// One `Isa` per pulp token: `within` enters the token's target-feature context.
macro_rules! pulp_isa {
    ($isa:ident, $level:ident, $arch:meta, $token:path) => {
        impl Isa for $isa {
            const LEVEL: SimdLevel = SimdLevel::$level;
            #[inline(always)]
            fn within<T: Task>(task: T) -> T::Output {
                #[cfg($arch)]
                {
                    if let Some(token) = <$token>::try_new() {
                        return token.vectorize(Pulp(task));
                    }
                }
                task.run()
            }
        }
    };
}

pulp_isa!(
    Sse,
    Sse,
    any(target_arch = "x86", target_arch = "x86_64"),
    pulp::x86::V2
);
pulp_isa!(
    Avx2,
    Avx2,
    any(target_arch = "x86", target_arch = "x86_64"),
    pulp::x86::V3
);
pulp_isa!(
    Avx512,
    Avx512,
    any(target_arch = "x86", target_arch = "x86_64"),
    pulp::x86::V4
);
pulp_isa!(Neon, Neon, target_arch = "aarch64", pulp::aarch64::Neon);

/// `N` lanes of `f32` compiled for the instruction set `I`.
#[derive(Clone, Copy)]
pub struct Wide<const N: usize, I> {
    lanes: [f32; N],
    isa: PhantomData<I>,
}

impl<const N: usize, I> Wide<N, I> {
    /// From the lanes' values.
    #[inline(always)]
    pub fn from_array(lanes: [f32; N]) -> Self {
        Self {
            lanes,
            isa: PhantomData,
        }
    }

    /// The lanes' values.
    #[inline(always)]
    pub fn to_array(self) -> [f32; N] {
        self.lanes
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        let mut out = self.lanes;
        for lane in &mut out {
            *lane = f(*lane);
        }
        Self::from_array(out)
    }

    #[inline(always)]
    fn zip(self, rhs: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        let mut out = self.lanes;
        for (lane, r) in out.iter_mut().zip(rhs.lanes) {
            *lane = f(*lane, r);
        }
        Self::from_array(out)
    }

    #[inline(always)]
    fn test(self, rhs: Self, f: impl Fn(f32, f32) -> bool) -> [bool; N] {
        let mut out = [false; N];
        for ((m, a), b) in out.iter_mut().zip(self.lanes).zip(rhs.lanes) {
            *m = f(a, b);
        }
        out
    }
}

impl<const N: usize, I> fmt::Debug for Wide<N, I> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("Wide").field(&self.lanes).finish()
    }
}

/// The arithmetic operators, each the `f32` operator per lane.
macro_rules! lanewise {
    ($($trait:ident $method:ident $op:tt),*) => {$(
        impl<const N: usize, I> $trait for Wide<N, I> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                self.zip(rhs, |a, b| a $op b)
            }
        }
    )*};
}

lanewise!(Add add +, Sub sub -, Mul mul *, Div div /);

impl<const N: usize, I> Neg for Wide<N, I> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl<const N: usize, I: Isa> Lane for Wide<N, I> {
    type Mask = [bool; N];
    const LANES: usize = N;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        Self::from_array([value; N])
    }

    #[inline(always)]
    fn load(values: &[f32]) -> Self {
        if let Ok(whole) = <[f32; N]>::try_from(values) {
            return Self::from_array(whole);
        }
        let mut lanes = [0.0; N];
        for (lane, v) in lanes.iter_mut().zip(values) {
            *lane = *v;
        }
        Self::from_array(lanes)
    }

    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        if let Ok(whole) = <&mut [f32; N]>::try_from(&mut *out) {
            *whole = self.lanes;
            return;
        }
        for (slot, v) in out.iter_mut().zip(self.lanes) {
            *slot = v;
        }
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(<f32 as Lane>::sqrt)
    }

    #[inline(always)]
    fn abs(self) -> Self {
        self.map(<f32 as Lane>::abs)
    }

    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, <f32 as Lane>::min)
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, <f32 as Lane>::max)
    }

    #[inline(always)]
    fn min_cmp(self, other: Self) -> Self {
        self.zip(other, <f32 as Lane>::min_cmp)
    }

    #[inline(always)]
    fn max_cmp(self, other: Self) -> Self {
        self.zip(other, <f32 as Lane>::max_cmp)
    }

    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        self.map(|a| <f32 as Lane>::clamp(a, lo, hi))
    }

    #[inline(always)]
    fn lt(self, other: Self) -> [bool; N] {
        self.test(other, <f32 as Lane>::lt)
    }

    #[inline(always)]
    fn gt(self, other: Self) -> [bool; N] {
        self.test(other, <f32 as Lane>::gt)
    }

    #[inline(always)]
    fn ge(self, other: Self) -> [bool; N] {
        self.test(other, <f32 as Lane>::ge)
    }

    #[inline(always)]
    fn is_nan(self) -> [bool; N] {
        self.test(self, |a, _| a.is_nan())
    }

    #[inline(always)]
    fn and(a: [bool; N], b: [bool; N]) -> [bool; N] {
        let mut out = a;
        for (m, b) in out.iter_mut().zip(b) {
            *m &= b;
        }
        out
    }

    #[inline(always)]
    fn or(a: [bool; N], b: [bool; N]) -> [bool; N] {
        let mut out = a;
        for (m, b) in out.iter_mut().zip(b) {
            *m |= b;
        }
        out
    }

    #[inline(always)]
    fn not(mask: [bool; N]) -> [bool; N] {
        let mut out = mask;
        for m in &mut out {
            *m = !*m;
        }
        out
    }

    #[inline(always)]
    fn any(mask: [bool; N]) -> bool {
        mask.iter().any(|&m| m)
    }

    #[inline(always)]
    fn select(mask: [bool; N], if_true: Self, if_false: Self) -> Self {
        let mut out = if_false.lanes;
        for ((lane, t), m) in out.iter_mut().zip(if_true.lanes).zip(mask) {
            *lane = <f32 as Lane>::select(m, t, *lane);
        }
        Self::from_array(out)
    }
}
