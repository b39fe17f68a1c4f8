//! [`Wide`]: `N` lanes of `f32`, each operation the `f32` one applied lane by lane, in a
//! loop the compiler turns into vector instructions of the instruction set `I`: the lane
//! type of the portable, SSE and NEON levels. AVX2 and AVX-512 on x86-64 have lane types
//! whose operations are instructions themselves (`x86.rs`), because LLVM turned these
//! loops into a mix of widths there.
//!
//! Writing each lane's operation as the scalar one makes the bit-identity contract hold
//! by construction: the vector unit's add, multiply, divide, square root, compare and
//! blend round exactly as the scalar unit does, and the compiler never fuses a multiply
//! and an add on its own. The instruction set comes from where the code runs:
//! [`SimdLevel::dispatch`](super::SimdLevel::dispatch) enters a function compiled with
//! `I`'s target features (through `pulp`, safely), and what is inlined into it runs with
//! them.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::{Lane, SimdLevel, Task};

/// An instruction set a [`Wide`] vector is compiled for.
pub trait Isa: Copy + fmt::Debug + 'static {
    /// The dispatch level it is.
    const LEVEL: SimdLevel;
    /// How a vector of `N` lanes under this instruction set holds one boolean per lane:
    /// the form its compares produce and its blends read, so that a mask never has to be
    /// converted between the two (AVX2 converting `bool`s at every select cost a fifth of
    /// a render).
    type Mask<const N: usize>: LaneMask<N>;
    /// Runs `task` in a function compiled with this instruction set's target features;
    /// `None`, without running it, where the CPU lacks them. No plain-code copy of the task
    /// is kept for that case: every kernel is inlined whole into each copy, so a copy per
    /// level that never runs would cost build time (about half of each kernel's
    /// optimisation) and nothing else.
    fn within<T: Task>(task: T) -> Option<T::Output>;
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
    type Mask<const N: usize> = BitMask<N>;
    #[inline(always)]
    fn within<T: Task>(task: T) -> Option<T::Output> {
        Some(task.run())
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
    ($isa:ident, $level:ident, $mask:ident, $arch:meta, $token:path) => {
        impl Isa for $isa {
            const LEVEL: SimdLevel = SimdLevel::$level;
            type Mask<const N: usize> = $mask<N>;
            #[inline(always)]
            fn within<T: Task>(task: T) -> Option<T::Output> {
                #[cfg($arch)]
                {
                    if let Some(token) = <$token>::try_new() {
                        return Some(token.vectorize(Pulp(task)));
                    }
                }
                #[cfg(not($arch))]
                let _ = task;
                None
            }
        }
    };
}

pulp_isa!(
    Sse,
    Sse,
    BitMask,
    any(target_arch = "x86", target_arch = "x86_64"),
    pulp::x86::V2
);
pulp_isa!(
    Avx2,
    Avx2,
    BitMask,
    any(target_arch = "x86", target_arch = "x86_64"),
    pulp::x86::V3
);
pulp_isa!(
    Avx512,
    Avx512,
    BitMask,
    any(target_arch = "x86", target_arch = "x86_64"),
    pulp::x86::V4
);
pulp_isa!(
    Neon,
    Neon,
    BitMask,
    target_arch = "aarch64",
    pulp::aarch64::Neon
);

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
}

/// One boolean per lane of an `N`-lane vector, in the form an instruction set's compares
/// and blends use ([`Isa::Mask`]). Every form gives the same lanes: a mask is only ever
/// made by a compare and read by a select or [`LaneMask::any`].
pub trait LaneMask<const N: usize>: Copy {
    /// `f(a, b)` per lane.
    fn test(a: [f32; N], b: [f32; N], f: impl Fn(f32, f32) -> bool) -> Self;
    /// Both, per lane.
    fn and(self, other: Self) -> Self;
    /// Either, per lane.
    fn or(self, other: Self) -> Self;
    /// The negation, per lane.
    fn not(self) -> Self;
    /// Whether any lane is set.
    fn any(self) -> bool;
    /// Lane `i` in bit `i`.
    fn bits(self) -> u32;
    /// `if self { if_true } else { if_false }`, per lane.
    fn select(self, if_true: [f32; N], if_false: [f32; N]) -> [f32; N];
}

/// One lane of a [`Mask`]: how a form holds a boolean, tests it and selects by it.
pub trait MaskLane:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// The lane holding `b`.
    fn from_bool(b: bool) -> Self;
    /// 1 where set, 0 elsewhere.
    fn bit(self) -> u32;
    /// `if self { if_true } else { if_false }`.
    fn select(self, if_true: f32, if_false: f32) -> f32;
    /// Whether any of `lanes` is set, in the reduction this form compiles best to.
    fn any<const N: usize>(lanes: [Self; N]) -> bool;
    /// Lane `i` of `lanes` in bit `i`.
    #[inline(always)]
    fn bits<const N: usize>(lanes: [Self; N]) -> u32 {
        bits_from(&lanes, 0)
    }
}

/// `lanes[i]` in bit `first + i`, one lane at a time.
#[inline(always)]
fn bits_from<T: MaskLane>(lanes: &[T], first: usize) -> u32 {
    (lanes.iter().enumerate()).fold(0, |acc, (i, &m)| acc | (m.bit() << (first + i)))
}

/// All ones or all zeros per lane: what SSE, AVX2 and NEON compares write and their
/// blends (or `and`, `andnot`, `or`) read. A select moves each lane's bits unchanged, as
/// the scalar select does. `Wide`'s AVX-512 takes this form too, LLVM moving it to and
/// from the mask registers where an instruction needs them: on the Intel Xeon measured,
/// its 16 lanes rendered at 1.09-1.15x AVX2's speed with it, and at 0.92-0.99x with a
/// `bool` per lane (docs/PERFORMANCE.md, "Sixteen lanes with bit masks"). On x86-64 the
/// AVX-512 level runs `x86.rs`'s `Zmm` instead, whose masks are the mask registers.
impl MaskLane for u32 {
    #[inline(always)]
    fn from_bool(b: bool) -> u32 {
        if b { u32::MAX } else { 0 }
    }

    #[inline(always)]
    fn bit(self) -> u32 {
        self >> 31
    }

    #[inline(always)]
    fn select(self, if_true: f32, if_false: f32) -> f32 {
        f32::from_bits((if_true.to_bits() & self) | (if_false.to_bits() & !self))
    }

    #[inline(always)]
    fn any<const N: usize>(lanes: [u32; N]) -> bool {
        // A reduction without an early exit, which vectorizes to one test.
        lanes.iter().fold(0, |acc, &m| acc | m) != 0
    }

    /// On x86-64, `movmskps` per 4 lanes: LLVM does not recognise the shift-and-or
    /// reduction as one, and built the bits in some thirty shuffles and compares.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn bits<const N: usize>(lanes: [u32; N]) -> u32 {
        // SSE is part of the x86-64 baseline, so the check is a constant.
        let Some(sse) = pulp::core_arch::x86::Sse::try_new() else {
            return bits_from(&lanes, 0);
        };
        let mut bits = 0;
        let mut chunks = lanes.chunks_exact(4);
        for (k, c) in chunks.by_ref().enumerate() {
            let v = sse._mm_setr_ps(
                f32::from_bits(c[0]),
                f32::from_bits(c[1]),
                f32::from_bits(c[2]),
                f32::from_bits(c[3]),
            );
            bits |= (sse._mm_movemask_ps(v) as u32) << (4 * k);
        }
        bits | bits_from(chunks.remainder(), N - chunks.remainder().len())
    }
}

/// `N` lanes of a [`MaskLane`] form, each operation lane by lane.
#[derive(Clone, Copy, Debug)]
pub struct Mask<T, const N: usize>([T; N]);

/// The mask form of every level.
pub type BitMask<const N: usize> = Mask<u32, N>;

impl<T: MaskLane, const N: usize> LaneMask<N> for Mask<T, N> {
    #[inline(always)]
    fn test(a: [f32; N], b: [f32; N], f: impl Fn(f32, f32) -> bool) -> Self {
        let mut out = [T::from_bool(false); N];
        for ((m, a), b) in out.iter_mut().zip(a).zip(b) {
            *m = T::from_bool(f(a, b));
        }
        Mask(out)
    }

    #[inline(always)]
    fn and(self, other: Self) -> Self {
        let mut out = self.0;
        for (m, b) in out.iter_mut().zip(other.0) {
            *m = *m & b;
        }
        Mask(out)
    }

    #[inline(always)]
    fn or(self, other: Self) -> Self {
        let mut out = self.0;
        for (m, b) in out.iter_mut().zip(other.0) {
            *m = *m | b;
        }
        Mask(out)
    }

    #[inline(always)]
    fn not(self) -> Self {
        let mut out = self.0;
        for m in &mut out {
            *m = !*m;
        }
        Mask(out)
    }

    #[inline(always)]
    fn any(self) -> bool {
        T::any(self.0)
    }

    #[inline(always)]
    fn bits(self) -> u32 {
        T::bits(self.0)
    }

    #[inline(always)]
    fn select(self, if_true: [f32; N], if_false: [f32; N]) -> [f32; N] {
        let mut out = if_false;
        for ((lane, t), m) in out.iter_mut().zip(if_true).zip(self.0) {
            *lane = m.select(t, *lane);
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
    type Mask = I::Mask<N>;
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
    fn lt(self, other: Self) -> Self::Mask {
        LaneMask::test(self.lanes, other.lanes, <f32 as Lane>::lt)
    }

    #[inline(always)]
    fn gt(self, other: Self) -> Self::Mask {
        LaneMask::test(self.lanes, other.lanes, <f32 as Lane>::gt)
    }

    #[inline(always)]
    fn ge(self, other: Self) -> Self::Mask {
        LaneMask::test(self.lanes, other.lanes, <f32 as Lane>::ge)
    }

    #[inline(always)]
    fn is_nan(self) -> Self::Mask {
        LaneMask::test(self.lanes, self.lanes, |a, _| a.is_nan())
    }

    #[inline(always)]
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask {
        a.and(b)
    }

    #[inline(always)]
    fn or(a: Self::Mask, b: Self::Mask) -> Self::Mask {
        a.or(b)
    }

    #[inline(always)]
    fn not(mask: Self::Mask) -> Self::Mask {
        mask.not()
    }

    #[inline(always)]
    fn any(mask: Self::Mask) -> bool {
        mask.any()
    }

    #[inline(always)]
    fn bits(mask: Self::Mask) -> u32 {
        mask.bits()
    }

    #[inline(always)]
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self {
        Self::from_array(mask.select(if_true.lanes, if_false.lanes))
    }
}
