//! The number type the distance formulas are written over: [`Lane`] is `f32` for the
//! scalar tracer and a vector of `f32` lanes for a SIMD tracer ([`Wide`], N lanes under
//! one instruction set, or on x86-64 one AVX2 or AVX-512 register, `x86.rs`), so that
//! each primitive and operator has one definition that all of them evaluate.
//!
//! The contract every implementation meets: **each lane's result is, bit for bit, what
//! `f32` gives for that lane's inputs**. That is why the trait has two kinds of minimum
//! and maximum (Rust's NaN-ignoring [`f32::min`] and glam's comparison, which the vector
//! methods use), each written as one comparison and select on every side, and why there is
//! no fused multiply-add: with only IEEE add, subtract, multiply, divide and square root,
//! and the same order of operations, a vector unit rounds exactly as the scalar one does.

mod dispatch;
mod vec;
mod wide;
#[cfg(target_arch = "x86_64")]
mod x86;

use std::ops::{Add, Div, Mul, Neg, Sub};

pub use dispatch::{LaneDistance, LaneKernel, SimdLevel, UnavailableLevel};
pub(crate) use vec::LaneVec2;
pub use vec::LaneVec3;
pub use wide::{Avx2, Avx512, BitMask, Isa, LaneMask, Mask, MaskLane, Neon, Portable, Sse, Wide};

/// A number type with `LANES` independent `f32` lanes: `f32` itself, or a [`Wide`] vector.
///
/// Contract: every operation acts on each lane alone and gives, bit for bit, what the
/// `f32` implementation gives for that lane (see the module notes).
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// One boolean per lane.
    type Mask: Copy;
    /// How many `f32` lanes a value holds.
    const LANES: usize;

    /// Every lane set to `value`.
    fn splat(value: f32) -> Self;
    /// The first `values.len()` lanes from `values` (at most [`Lane::LANES`]), the rest 0.
    fn load(values: &[f32]) -> Self;
    /// The first `out.len()` lanes (at most [`Lane::LANES`]) into `out`.
    fn store(self, out: &mut [f32]);
    /// [`Lane::load`] of values just written one lane at a time: built in registers
    /// where a whole-vector load would wait for those single stores (a failed store
    /// forward). The same lanes as `load`.
    #[inline(always)]
    fn assemble(values: &[f32]) -> Self {
        Self::load(values)
    }

    /// Square root, correctly rounded.
    fn sqrt(self) -> Self;
    /// Absolute value (clears the sign bit).
    fn abs(self) -> Self;
    /// [`f32::min`]: the other operand where one is NaN.
    fn min(self, other: Self) -> Self;
    /// [`f32::max`]: the other operand where one is NaN.
    fn max(self, other: Self) -> Self;
    /// glam's minimum, `if self < other { self } else { other }` (a NaN `self` loses).
    fn min_cmp(self, other: Self) -> Self;
    /// glam's maximum, `if self > other { self } else { other }` (a NaN `self` loses).
    fn max_cmp(self, other: Self) -> Self;
    /// [`f32::clamp`] to `[lo, hi]` (NaN stays NaN).
    fn clamp(self, lo: f32, hi: f32) -> Self;

    /// `self < other`, per lane.
    fn lt(self, other: Self) -> Self::Mask;
    /// `self > other`, per lane.
    fn gt(self, other: Self) -> Self::Mask;
    /// `self >= other`, per lane.
    fn ge(self, other: Self) -> Self::Mask;
    /// `self.is_nan()`, per lane.
    fn is_nan(self) -> Self::Mask;
    /// Both masks, per lane.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Either mask, per lane.
    fn or(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// The mask negated, per lane.
    fn not(mask: Self::Mask) -> Self::Mask;
    /// Whether any lane of `mask` is set.
    fn any(mask: Self::Mask) -> bool;
    /// The mask as bits, lane `i` in bit `i` (vectors have at most 16 lanes): how a kernel
    /// visits only the lanes a mask holds.
    fn bits(mask: Self::Mask) -> u32;
    /// `if mask { if_true } else { if_false }`, per lane.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;

    /// Runs `task` out of line: in a function of its own, cold and never inlined, that
    /// is compiled for this lane type's instruction set. For work a kernel keeps apart
    /// (the interior nodes of an `Sdf` tree) so that its own registers stay free. A plain
    /// function out of line would be compiled for the baseline: there `Wide`'s loops run
    /// as baseline code, but each of `x86.rs`'s operations would be a call.
    #[inline(always)]
    fn apart<T: Task>(task: T) -> T::Output {
        run_apart(task)
    }

    /// Where the lane is finite: zero times an infinity or a NaN is NaN, which no
    /// comparison holds.
    #[inline(always)]
    fn finite(self) -> Self::Mask {
        (self * Self::splat(0.0)).ge(Self::splat(0.0))
    }
}

/// [`Lane::apart`] for the lane types whose instructions the baseline has.
#[cold]
#[inline(never)]
fn run_apart<T: Task>(task: T) -> T::Output {
    task.run()
}

/// Work handed to [`Isa::within`]: a struct, not a closure, because
/// its `run` must be `#[inline(always)]` to be compiled with the instruction set it is
/// run under (a closure body is a function of its own, compiled for the target's
/// baseline unless the inliner happens to take it).
pub trait Task {
    /// What the work returns.
    type Output;
    /// Does the work; implement it `#[inline(always)]`.
    fn run(self) -> Self::Output;
}

/// The scalar lane: exactly the `f32` operations the formulas were written with.
impl Lane for f32 {
    type Mask = bool;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(value: f32) -> f32 {
        value
    }

    #[inline(always)]
    fn load(values: &[f32]) -> f32 {
        values.first().copied().unwrap_or(0.0)
    }

    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        if let Some(slot) = out.first_mut() {
            *slot = self;
        }
    }

    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }

    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }

    // `f32::min` leaves the sign of a zero tie to the backend (x86 answers differently for
    // scalars and vectors depending on what it can prove), so it is spelled out as the
    // select x86 lowers `minnum(a, b)` to: `b` if `a` is NaN, else `b < a ? b : a`.
    #[inline(always)]
    fn min(self, other: f32) -> f32 {
        if self.is_nan() || other < self {
            other
        } else {
            self
        }
    }

    #[inline(always)]
    fn max(self, other: f32) -> f32 {
        if self.is_nan() || other > self {
            other
        } else {
            self
        }
    }

    #[inline(always)]
    fn min_cmp(self, other: f32) -> f32 {
        if self < other { self } else { other }
    }

    #[inline(always)]
    fn max_cmp(self, other: f32) -> f32 {
        if self > other { self } else { other }
    }

    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> f32 {
        let x = if self < lo { lo } else { self };
        if x > hi { hi } else { x }
    }

    #[inline(always)]
    fn lt(self, other: f32) -> bool {
        self < other
    }

    #[inline(always)]
    fn gt(self, other: f32) -> bool {
        self > other
    }

    #[inline(always)]
    fn ge(self, other: f32) -> bool {
        self >= other
    }

    #[inline(always)]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }

    #[inline(always)]
    fn and(a: bool, b: bool) -> bool {
        a & b
    }

    #[inline(always)]
    fn or(a: bool, b: bool) -> bool {
        a | b
    }

    #[inline(always)]
    fn not(mask: bool) -> bool {
        !mask
    }

    #[inline(always)]
    fn any(mask: bool) -> bool {
        mask
    }

    #[inline(always)]
    fn bits(mask: bool) -> u32 {
        u32::from(mask)
    }

    #[inline(always)]
    fn select(mask: bool, if_true: f32, if_false: f32) -> f32 {
        if mask { if_true } else { if_false }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spelled-out minimum and maximum are Rust's wherever Rust's is specified.
    #[test]
    fn min_and_max_follow_f32() {
        let values = [
            -2.0,
            -0.5,
            0.5,
            3.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for a in values {
            for b in values {
                let same =
                    |x: f32, y: f32| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
                assert!(same(Lane::min(a, b), a.min(b)), "min({a}, {b})");
                assert!(same(Lane::max(a, b), a.max(b)), "max({a}, {b})");
                assert!(
                    same(Lane::clamp(a, 0.0, 1.0), a.clamp(0.0, 1.0)),
                    "clamp({a})"
                );
            }
        }
    }

    /// `assemble` as `load`; compares, their combinations, `bits`, `any` and `select` on
    /// every level, whatever form its masks take, against the scalar lane by lane: signed
    /// zeros, infinities and NaNs included, in every lane position.
    struct Masks<'a> {
        a: &'a [f32],
        b: &'a [f32],
    }

    impl LaneKernel for Masks<'_> {
        type Output = Vec<String>;

        #[inline(always)]
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        fn run<L: Lane>(self) -> Vec<String> {
            let mut wrong = Vec::new();
            let n = L::LANES;
            for (a, b) in self.a.chunks(n).zip(self.b.chunks(n)) {
                let (va, vb) = (L::load(a), L::load(b));
                let (mut loaded, mut assembled) = (vec![0f32; n], vec![0f32; n]);
                va.store(&mut loaded);
                L::assemble(a).store(&mut assembled);
                if loaded
                    .iter()
                    .zip(&assembled)
                    .any(|(x, y)| x.to_bits() != y.to_bits())
                {
                    wrong.push(format!("assemble {assembled:?} vs load {loaded:?}"));
                }
                let masks = [
                    va.lt(vb),
                    va.gt(vb),
                    va.ge(vb),
                    va.is_nan(),
                    L::and(va.lt(vb), vb.ge(va)),
                    L::or(va.gt(vb), va.is_nan()),
                    L::not(va.ge(vb)),
                ];
                let scalar = |x: f32, y: f32| -> [bool; 7] {
                    [
                        x < y,
                        x > y,
                        x >= y,
                        x.is_nan(),
                        x < y && y >= x,
                        x > y || x.is_nan(),
                        !(x >= y),
                    ]
                };
                let mut picked = vec![0f32; n];
                for (k, &mask) in masks.iter().enumerate() {
                    L::select(mask, va, vb).store(&mut picked);
                    let bits = L::bits(mask);
                    let mut any = false;
                    for lane in 0..a.len() {
                        let expected = scalar(a[lane], b[lane])[k];
                        any |= expected;
                        let chosen = if expected { a[lane] } else { b[lane] };
                        if (bits >> lane & 1 != 0) != expected
                            || picked[lane].to_bits() != chosen.to_bits()
                        {
                            wrong
                                .push(format!("mask {k}, lane {lane}: {} vs {}", a[lane], b[lane]));
                        }
                    }
                    // Lanes past the inputs load 0, which no mask here sets for 0 vs 0
                    // but `ge` and its combinations, so `any` is checked on full vectors.
                    if a.len() == n && L::any(mask) != any {
                        wrong.push(format!("mask {k}: any is {}", L::any(mask)));
                    }
                }
            }
            wrong
        }
    }

    #[test]
    fn every_mask_form_gives_the_scalar_lanes() {
        let values = [
            -2.0,
            -0.0,
            0.0,
            0.5,
            3.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MIN_POSITIVE,
        ];
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for &x in &values {
            for &y in &values {
                a.push(x);
                b.push(y);
            }
        }
        // Rotations put every pair in every lane position of every width.
        for shift in 0..16 {
            a.rotate_left(shift);
            for level in SimdLevel::available() {
                let wrong = level.dispatch(Masks { a: &a, b: &b }).unwrap();
                assert!(wrong.is_empty(), "{level:?}: {wrong:?}");
            }
        }
    }

    /// A cap on the lanes picks the widest available level under it, and without a cap
    /// it is `detect`.
    #[test]
    fn widest_up_to_respects_its_cap_and_availability() {
        assert_eq!(SimdLevel::widest_up_to(usize::MAX), SimdLevel::detect());
        assert_eq!(SimdLevel::widest_up_to(1), SimdLevel::Scalar);
        for cap in [1, 3, 4, 7, 8, 15, 16, 64] {
            let level = SimdLevel::widest_up_to(cap);
            assert!(level.is_available(), "{cap}: {level:?}");
            assert!(level.lanes() <= cap, "{cap}: {level:?}");
            let wider = SimdLevel::available()
                .into_iter()
                .filter(|l| *l != SimdLevel::Portable && l.lanes() <= cap)
                .map(SimdLevel::lanes)
                .max()
                .unwrap_or(1);
            assert!(
                level.lanes() >= wider,
                "{cap}: {level:?} under {wider} lanes"
            );
        }
    }
}
