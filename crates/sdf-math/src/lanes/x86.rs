//! The x86 levels' lane types: [`Zmm`] for AVX-512 (16 lanes in one 512-bit register) and
//! [`Ymm`] for AVX2 (8 lanes in one 256-bit register), each operation one instruction of
//! the level's full width, through pulp's safe `V4` and `V3` methods.
//!
//! Why not [`Wide`](super::Wide) there: its operations are loops over lanes that LLVM's
//! vectorizer has to turn back into vector instructions, and in large kernels it does so
//! in part with narrower pieces. `xtask codegen` found lueur's own kernels at 0.65 of
//! full width under AVX-512 and 0.77 under AVX2, and the in-loop prototype's trace
//! kernel moved between 1.04x and 1.33x lueur's speed with small edits
//! (docs/PERFORMANCE.md, "Explicit vector operations"). Here the vector is the
//! operation, so there is nothing left to split.
//!
//! The bit-identity contract ([`Lane`]) holds because only IEEE add, subtract, multiply,
//! divide and square root are used, each once per scalar operation and never fused; the
//! minima, maxima and clamps are the scalar's compares and selects, not `vminps`, whose
//! NaN and signed-zero rules are x86's own.
//!
//! # The `unsafe`, the workspace's only
//! pulp's methods need its token, which only a feature check makes safely. The check is
//! a relaxed atomic load and a branch that LLVM can neither merge nor hoist out of a
//! loop; with it in every [`Lane::splat`] and [`Lane::load`], the shipped scenes rendered
//! at 0.83-0.87x the speed (the same docs section). So [`v4`] and [`v3`] make the token
//! unchecked, and [`Lane::apart`] calls a function compiled with the token's features
//! ([`apart_v4`], [`apart_v3`]), under one invariant: a `Zmm` or `Ymm` value, and so any
//! call of their methods, exists only inside [`Avx512::within`](super::Avx512) or
//! [`Avx2::within`](super::Avx2), which run their task only after pulp's own check of
//! the same token passed. The types are private to this crate, and
//! [`SimdLevel::dispatch`](super::SimdLevel::dispatch) is the only code that names them.
//! CPU features are the machine's, not the thread's, so a value moved to another thread
//! stays valid.
//!
//! # Everything inlined, or apart
//! An operation here is an intrinsic compiled with the level's features. Code that uses
//! it out of line, in a function compiled for the baseline, cannot inline it and calls
//! it, once per operation: the union of 8 spheres evaluated 6 to 10x slower so. So kernels
//! inline what they call, as for `Wide`, and what they keep out of line goes through
//! [`Lane::apart`]. `cargo xtask codegen` fails on any such intrinsic left out of line.

use std::ops::{Add, Div, Mul, Neg, Sub};

use pulp::x86::{V3, V4};
use pulp::{b16, f32x8, f32x16, m32x8};

use super::{Lane, Task};

/// pulp's AVX-512 token. See the module notes for why it is sound.
#[inline(always)]
#[allow(unsafe_code)]
fn v4() -> V4 {
    debug_assert!(V4::is_available());
    // SAFETY: only reached from code that `Avx512::within` runs, after `V4::try_new`
    // succeeded (module notes).
    unsafe { V4::new_unchecked() }
}

/// pulp's AVX2 token. See the module notes for why it is sound.
#[inline(always)]
#[allow(unsafe_code)]
fn v3() -> V3 {
    debug_assert!(V3::is_available());
    // SAFETY: only reached from code that `Avx2::within` runs, after `V3::try_new`
    // succeeded (module notes).
    unsafe { V3::new_unchecked() }
}

/// [`Lane::apart`] for `Zmm`: out of line, with exactly pulp's `V4` features.
#[cold]
#[inline(never)]
#[target_feature(
    enable = "sse,sse2,fxsr,sse3,ssse3,sse4.1,sse4.2,popcnt,avx,avx2,bmi1,bmi2,fma,lzcnt,avx512f,avx512bw,avx512cd,avx512dq,avx512vl"
)]
fn apart_v4<T: Task>(task: T) -> T::Output {
    task.run()
}

/// [`Lane::apart`] for `Ymm`: out of line, with exactly pulp's `V3` features.
#[cold]
#[inline(never)]
#[target_feature(
    enable = "sse,sse2,fxsr,sse3,ssse3,sse4.1,sse4.2,popcnt,avx,avx2,bmi1,bmi2,fma,lzcnt"
)]
fn apart_v3<T: Task>(task: T) -> T::Output {
    task.run()
}

/// The sign bit of an `f32`: what `-x` flips.
const SIGN: u32 = 0x8000_0000;

/// 16 lanes of `f32` as one AVX-512 vector; its masks are AVX-512 mask registers.
#[derive(Clone, Copy)]
pub(crate) struct Zmm(f32x16);

/// 8 lanes of `f32` as one AVX2 vector; its masks are all ones or all zeros per lane,
/// what AVX2's compares write and its blends read.
#[derive(Clone, Copy)]
pub(crate) struct Ymm(f32x8);

/// The arithmetic operators, each one instruction.
macro_rules! arithmetic {
    ($lanes:ident, $token:ident, $($trait:ident $method:ident $op:ident),*) => {$(
        impl $trait for $lanes {
            type Output = $lanes;
            #[inline(always)]
            fn $method(self, rhs: $lanes) -> $lanes {
                $lanes($token().$op(self.0, rhs.0))
            }
        }
    )*};
}

arithmetic!(Zmm, v4, Add add add_f32x16, Sub sub sub_f32x16, Mul mul mul_f32x16, Div div div_f32x16);
arithmetic!(Ymm, v3, Add add add_f32x8, Sub sub sub_f32x8, Mul mul mul_f32x8, Div div div_f32x8);

impl Neg for Zmm {
    type Output = Zmm;
    /// The sign bit flipped, as the scalar `-x` does (NaNs included).
    #[inline(always)]
    fn neg(self) -> Zmm {
        let simd = v4();
        let flipped = simd.xor_u32x16(pulp::cast(self.0), simd.splat_u32x16(SIGN));
        Zmm(pulp::cast(flipped))
    }
}

impl Neg for Ymm {
    type Output = Ymm;
    /// The sign bit flipped, as the scalar `-x` does (NaNs included).
    #[inline(always)]
    fn neg(self) -> Ymm {
        let simd = v3();
        let flipped = simd.xor_u32x8(pulp::cast(self.0), simd.splat_u32x8(SIGN));
        Ymm(pulp::cast(flipped))
    }
}

/// The first `values.len()` lanes (at most `N`) from `values`, the rest 0.
#[inline(always)]
fn lanes_from<const N: usize>(values: &[f32]) -> [f32; N] {
    if let Ok(whole) = <[f32; N]>::try_from(values) {
        return whole;
    }
    let mut lanes = [0.0; N];
    for (lane, v) in lanes.iter_mut().zip(values) {
        *lane = *v;
    }
    lanes
}

/// The first `out.len()` lanes (at most `N`) of `lanes` into `out`.
#[inline(always)]
fn lanes_into<const N: usize>(lanes: [f32; N], out: &mut [f32]) {
    if let Ok(whole) = <&mut [f32; N]>::try_from(&mut *out) {
        *whole = lanes;
        return;
    }
    for (slot, v) in out.iter_mut().zip(lanes) {
        *slot = v;
    }
}

/// The [`Lane`] methods both types write alike: over their token (`$token`), the
/// function their work apart runs in (`$apart`) and pulp's name for each operation on
/// their vector.
macro_rules! shared {
    (
        $lanes:ident, $n:literal, $token:ident, $apart:ident,
        $splat:ident, $sqrt:ident, $abs:ident, $lt:ident, $gt:ident, $ge:ident,
        $is_nan:ident, $select:ident
    ) => {
        const LANES: usize = $n;

        #[inline(always)]
        #[allow(unsafe_code)]
        fn apart<T: Task>(task: T) -> T::Output {
            // SAFETY: as for the token: a value of this type exists, so the CPU has the
            // token's features, which are exactly the function's.
            unsafe { $apart(task) }
        }

        #[inline(always)]
        fn splat(value: f32) -> $lanes {
            $lanes($token().$splat(value))
        }

        #[inline(always)]
        fn sqrt(self) -> $lanes {
            $lanes($token().$sqrt(self.0))
        }

        #[inline(always)]
        fn abs(self) -> $lanes {
            $lanes($token().$abs(self.0))
        }

        #[inline(always)]
        fn lt(self, other: $lanes) -> Self::Mask {
            $token().$lt(self.0, other.0)
        }

        #[inline(always)]
        fn gt(self, other: $lanes) -> Self::Mask {
            $token().$gt(self.0, other.0)
        }

        #[inline(always)]
        fn ge(self, other: $lanes) -> Self::Mask {
            $token().$ge(self.0, other.0)
        }

        #[inline(always)]
        fn is_nan(self) -> Self::Mask {
            $token().$is_nan(self.0)
        }

        #[inline(always)]
        fn select(mask: Self::Mask, if_true: $lanes, if_false: $lanes) -> $lanes {
            $lanes($token().$select(mask, if_true.0, if_false.0))
        }

        #[inline(always)]
        fn load(values: &[f32]) -> $lanes {
            $lanes(pulp::cast(lanes_from::<$n>(values)))
        }

        #[inline(always)]
        fn store(self, out: &mut [f32]) {
            lanes_into::<$n>(pulp::cast(self.0), out)
        }

        /// `other` where `self` is NaN or `other < self`, as the scalar's.
        #[inline(always)]
        fn min(self, other: $lanes) -> $lanes {
            let take = Self::or(self.is_nan(), other.lt(self));
            Self::select(take, other, self)
        }

        /// `other` where `self` is NaN or `other > self`, as the scalar's.
        #[inline(always)]
        fn max(self, other: $lanes) -> $lanes {
            let take = Self::or(self.is_nan(), other.gt(self));
            Self::select(take, other, self)
        }

        #[inline(always)]
        fn min_cmp(self, other: $lanes) -> $lanes {
            Self::select(self.lt(other), self, other)
        }

        #[inline(always)]
        fn max_cmp(self, other: $lanes) -> $lanes {
            Self::select(self.gt(other), self, other)
        }

        #[inline(always)]
        fn clamp(self, lo: f32, hi: f32) -> $lanes {
            let (lo, hi) = (Self::splat(lo), Self::splat(hi));
            let x = Self::select(self.lt(lo), lo, self);
            Self::select(x.gt(hi), hi, x)
        }
    };
}

impl Lane for Zmm {
    type Mask = b16;
    shared!(
        Zmm,
        16,
        v4,
        apart_v4,
        splat_f32x16,
        sqrt_f32x16,
        abs_f32x16,
        cmp_lt_f32x16,
        cmp_gt_f32x16,
        cmp_ge_f32x16,
        is_nan_f32x16,
        select_f32x16
    );

    #[inline(always)]
    fn assemble(values: &[f32]) -> Zmm {
        let v = lanes_from::<16>(values);
        Zmm(pulp::cast(v4().avx512f._mm512_setr_ps(
            v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13],
            v[14], v[15],
        )))
    }

    #[inline(always)]
    fn and(a: b16, b: b16) -> b16 {
        b16(a.0 & b.0)
    }

    #[inline(always)]
    fn or(a: b16, b: b16) -> b16 {
        b16(a.0 | b.0)
    }

    #[inline(always)]
    fn not(mask: b16) -> b16 {
        b16(!mask.0)
    }

    #[inline(always)]
    fn any(mask: b16) -> bool {
        mask.0 != 0
    }

    #[inline(always)]
    fn bits(mask: b16) -> u32 {
        u32::from(mask.0)
    }
}

impl Lane for Ymm {
    type Mask = m32x8;
    shared!(
        Ymm,
        8,
        v3,
        apart_v3,
        splat_f32x8,
        sqrt_f32x8,
        abs_f32x8,
        cmp_lt_f32x8,
        cmp_gt_f32x8,
        cmp_ge_f32x8,
        is_nan_f32x8,
        select_f32x8
    );

    #[inline(always)]
    fn assemble(values: &[f32]) -> Ymm {
        let v = lanes_from::<8>(values);
        Ymm(pulp::cast(v3().avx._mm256_setr_ps(
            v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7],
        )))
    }

    #[inline(always)]
    fn and(a: m32x8, b: m32x8) -> m32x8 {
        v3().and_m32x8(a, b)
    }

    #[inline(always)]
    fn or(a: m32x8, b: m32x8) -> m32x8 {
        v3().or_m32x8(a, b)
    }

    #[inline(always)]
    fn not(mask: m32x8) -> m32x8 {
        v3().not_m32x8(mask)
    }

    #[inline(always)]
    fn any(mask: m32x8) -> bool {
        Self::bits(mask) != 0
    }

    /// `vmovmskps`: each lane's sign bit, which a compare sets with the rest of the lane.
    #[inline(always)]
    fn bits(mask: m32x8) -> u32 {
        v3().avx._mm256_movemask_ps(pulp::cast(mask)) as u32
    }
}
