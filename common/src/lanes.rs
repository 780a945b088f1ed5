//! Lanes of doubles: the arithmetic the elementary functions ([`crate::elementary`]) are
//! written in, once for one double ([`f64`]) and once for four side by side ([`F64x4`]).
//!
//! A kernel written over [`Real`] is one sequence of operations on each lane; the trait's
//! operations are the IEEE basic operations (`+ - * /`, `sqrt`, fused multiply-add, each
//! correctly rounded), exact operations on the representation (`abs`, `copysign`, negation,
//! comparisons, bit patterns, integer arithmetic on them, table look-ups by a computed index),
//! and `select`. **The rule**: every lane operation is the same IEEE operation as the scalar
//! one, applied to that lane alone, so lane `i` of a kernel's result on [`F64x4`] has the bits
//! of the same kernel on [`f64`] applied to lane `i` of the input, on every host and with any
//! compiler flags (IEEE 754 defines each of these results exactly; Rust never contracts `a * b +
//! c` into a fused multiply-add nor reassociates). Nothing here calls the C library: `sqrt` is
//! an instruction, and `mul_add` is one wherever the target has FMA units (on x86-64 without
//! them, Rust calls the C library's `fma`, which is correctly rounded by definition, so it too
//! gives the same bits).
//!
//! The one thing the rule does not fix is which NaN a NaN result is (its sign and payload):
//! compilers may swap the operands of a commutative operation, and the hardware propagates the
//! first. A NaN is a NaN in every lane and build; its bits are not compared.
//!
//! Kernels are branch-free: they compute every case a lane may need and pick with
//! [`Real::select`] on a mask made by a comparison, so the four lanes of an [`F64x4`] follow one
//! instruction stream. Where a case is rare and would cost the common one time (the ends of
//! `exp`'s range, the argument reduction of `sin` and `cos` for |x| > 2^20), a kernel branches
//! on "any lane needs it" ([`Mask::any`]) and then computes the general form for every lane
//! (or lane by lane with the scalar code, [`Real::map`]) and selects: still the same bits in
//! every lane as the scalar kernel, because the general form gives the common one's bits where
//! both apply.
//!
//! [`F64x4`] is a plain array of four doubles (aligned to 32 bytes) whose operations are
//! `#[inline(always)]` loops over the lanes: inside a function compiled for AVX2 and FMA
//! (`#[target_feature(enable = "avx2,fma")]`, as [`crate::propagator`] does at run time) LLVM
//! turns each into one 256-bit instruction; anywhere else they are four scalar operations. No
//! nightly `std::simd`, no dependency.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A lane mask: the result of a comparison, one truth value per lane.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// Whether every lane is set.
    fn all(self) -> bool;
    /// Whether any lane is set.
    fn any(self) -> bool;
}

/// The bit patterns of a [`Real`], one `u64` per lane, with the integer operations the kernels
/// use on them (exact, wrapping).
pub trait Bits: Copy {
    /// Every lane `v`.
    fn splat(v: u64) -> Self;
    /// Bitwise and.
    fn and(self, other: Self) -> Self;
    /// Bitwise or.
    fn or(self, other: Self) -> Self;
    /// Bitwise exclusive or.
    fn xor(self, other: Self) -> Self;
    /// Shift left by `n` bits (`n` < 64).
    fn shl(self, n: u32) -> Self;
    /// Logical shift right by `n` bits (`n` < 64).
    fn shr(self, n: u32) -> Self;
    /// Wrapping addition.
    fn wrapping_add(self, other: Self) -> Self;
    /// Wrapping subtraction.
    fn wrapping_sub(self, other: Self) -> Self;
    /// `table[self & (N - 1)]` in each lane (`N` a power of two, so every index is in range).
    fn lookup<const N: usize>(self, table: &[u64; N]) -> Self;
}

/// One or more lanes of doubles (see the module documentation for the rule every
/// implementation keeps: each lane operation is the scalar IEEE operation).
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The mask of a comparison.
    type Mask: Mask;
    /// The bit patterns.
    type Bits: Bits;
    /// The lanes as an array of `f64`.
    type Array: Copy + AsRef<[f64]> + AsMut<[f64]>;
    /// Number of lanes.
    const LANES: usize;

    /// Every lane `v`.
    fn splat(v: f64) -> Self;
    /// The lanes as an array.
    fn to_array(self) -> Self::Array;
    /// The lanes of an array.
    fn from_array(a: Self::Array) -> Self;
    /// Square root (correctly rounded).
    fn sqrt(self) -> Self;
    /// `self * a + b` with one rounding.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Absolute value (clears the sign bit).
    fn abs(self) -> Self;
    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// Whether the sign bit is set (also for -0 and a NaN with its sign bit set).
    fn sign_bit(self) -> Self::Mask;
    /// `self < other` (false if either is NaN).
    fn lt(self, other: Self) -> Self::Mask;
    /// `self <= other` (false if either is NaN).
    fn le(self, other: Self) -> Self::Mask;
    /// `self > other` (false if either is NaN).
    fn gt(self, other: Self) -> Self::Mask;
    /// `self >= other` (false if either is NaN).
    fn ge(self, other: Self) -> Self::Mask;
    /// `self == other` (false if either is NaN; `-0 == +0`).
    fn eq(self, other: Self) -> Self::Mask;
    /// Whether a lane is NaN.
    fn is_nan(self) -> Self::Mask;
    /// `a` where `mask` is set, `b` elsewhere.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// The bit patterns.
    fn to_bits(self) -> Self::Bits;
    /// The doubles of bit patterns.
    fn from_bits(bits: Self::Bits) -> Self;
    /// Whether a lane of `bits` is not zero.
    fn nonzero(bits: Self::Bits) -> Self::Mask;
    /// `f` applied to each lane (for a case computed lane by lane with scalar code).
    fn map(self, f: impl FnMut(f64) -> f64) -> Self;
}

/// The lanes `f(0), f(1), ...` (one per lane of `R`).
#[inline(always)]
pub fn gather<R: Real>(mut f: impl FnMut(usize) -> f64) -> R {
    let mut a = R::splat(0.0).to_array();
    for (i, v) in a.as_mut().iter_mut().enumerate() {
        *v = f(i);
    }
    R::from_array(a)
}

/// Lane `i` of `v`.
#[inline(always)]
pub fn lane<R: Real>(v: R, i: usize) -> f64 {
    v.to_array().as_ref()[i]
}

/// The mask set in the lanes `i` where `f(i)` holds.
#[inline(always)]
pub fn mask<R: Real>(mut f: impl FnMut(usize) -> bool) -> R::Mask {
    gather::<R>(|i| if f(i) { 1.0 } else { 0.0 }).gt(R::splat(0.0))
}

impl Mask for bool {
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

impl Bits for u64 {
    #[inline(always)]
    fn splat(v: u64) -> Self {
        v
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        self & other
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        self | other
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        self ^ other
    }
    #[inline(always)]
    fn shl(self, n: u32) -> Self {
        self << n
    }
    #[inline(always)]
    fn shr(self, n: u32) -> Self {
        self >> n
    }
    #[inline(always)]
    fn wrapping_add(self, other: Self) -> Self {
        u64::wrapping_add(self, other)
    }
    #[inline(always)]
    fn wrapping_sub(self, other: Self) -> Self {
        u64::wrapping_sub(self, other)
    }
    #[inline(always)]
    fn lookup<const N: usize>(self, table: &[u64; N]) -> Self {
        const { assert!(N.is_power_of_two()) };
        table[self as usize & (N - 1)]
    }
}

impl Real for f64 {
    type Mask = bool;
    type Bits = u64;
    type Array = [f64; 1];
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn to_array(self) -> [f64; 1] {
        [self]
    }
    #[inline(always)]
    fn from_array(a: [f64; 1]) -> Self {
        a[0]
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn sign_bit(self) -> bool {
        self.is_sign_negative()
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn ge(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    #[allow(clippy::float_cmp)] // an IEEE comparison is what this is
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn is_nan(self) -> bool {
        f64::is_nan(self)
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn to_bits(self) -> u64 {
        f64::to_bits(self)
    }
    #[inline(always)]
    fn from_bits(bits: u64) -> Self {
        f64::from_bits(bits)
    }
    #[inline(always)]
    fn nonzero(bits: u64) -> bool {
        bits != 0
    }
    #[inline(always)]
    fn map(self, mut f: impl FnMut(f64) -> f64) -> Self {
        f(self)
    }
}

/// Four doubles, one per lane (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
pub struct F64x4(pub [f64; 4]);

/// Four `u64` lanes: the bit patterns of an [`F64x4`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(C, align(32))]
pub struct U64x4(pub [u64; 4]);

/// The mask of a comparison of [`F64x4`]s: all ones in a lane where it holds, zero elsewhere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(C, align(32))]
pub struct M64x4(pub [u64; 4]);

/// `[f(0), f(1), f(2), f(3)]`.
#[inline(always)]
fn lanes4<T>(f: impl FnMut(usize) -> T) -> [T; 4] {
    std::array::from_fn(f)
}

impl M64x4 {
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        M64x4(lanes4(|i| if f(i) { u64::MAX } else { 0 }))
    }
}

impl BitAnd for M64x4 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        M64x4(lanes4(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for M64x4 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        M64x4(lanes4(|i| self.0[i] | o.0[i]))
    }
}

impl Not for M64x4 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        M64x4(lanes4(|i| !self.0[i]))
    }
}

impl Mask for M64x4 {
    #[inline(always)]
    fn all(self) -> bool {
        self.0.iter().all(|&m| m != 0)
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().any(|&m| m != 0)
    }
}

impl Bits for U64x4 {
    #[inline(always)]
    fn splat(v: u64) -> Self {
        U64x4([v; 4])
    }
    #[inline(always)]
    fn and(self, o: Self) -> Self {
        U64x4(lanes4(|i| self.0[i] & o.0[i]))
    }
    #[inline(always)]
    fn or(self, o: Self) -> Self {
        U64x4(lanes4(|i| self.0[i] | o.0[i]))
    }
    #[inline(always)]
    fn xor(self, o: Self) -> Self {
        U64x4(lanes4(|i| self.0[i] ^ o.0[i]))
    }
    #[inline(always)]
    fn shl(self, n: u32) -> Self {
        U64x4(lanes4(|i| self.0[i] << n))
    }
    #[inline(always)]
    fn shr(self, n: u32) -> Self {
        U64x4(lanes4(|i| self.0[i] >> n))
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        U64x4(lanes4(|i| self.0[i].wrapping_add(o.0[i])))
    }
    #[inline(always)]
    fn wrapping_sub(self, o: Self) -> Self {
        U64x4(lanes4(|i| self.0[i].wrapping_sub(o.0[i])))
    }
    #[inline(always)]
    fn lookup<const N: usize>(self, table: &[u64; N]) -> Self {
        U64x4(lanes4(|i| self.0[i].lookup(table)))
    }
}

macro_rules! binary_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                F64x4(lanes4(|i| self.0[i] $op o.0[i]))
            }
        }
    };
}

binary_op!(Add, add, +);
binary_op!(Sub, sub, -);
binary_op!(Mul, mul, *);
binary_op!(Div, div, /);

impl Neg for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        F64x4(lanes4(|i| -self.0[i]))
    }
}

impl Real for F64x4 {
    type Mask = M64x4;
    type Bits = U64x4;
    type Array = [f64; 4];
    const LANES: usize = 4;

    #[inline(always)]
    fn splat(v: f64) -> Self {
        F64x4([v; 4])
    }
    #[inline(always)]
    fn to_array(self) -> [f64; 4] {
        self.0
    }
    #[inline(always)]
    fn from_array(a: [f64; 4]) -> Self {
        F64x4(a)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F64x4(lanes4(|i| self.0[i].sqrt()))
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        F64x4(lanes4(|i| self.0[i].mul_add(a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F64x4(lanes4(|i| self.0[i].abs()))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        F64x4(lanes4(|i| self.0[i].copysign(sign.0[i])))
    }
    #[inline(always)]
    fn sign_bit(self) -> M64x4 {
        // The sign bit spread over the lane: an arithmetic shift of the pattern.
        M64x4(lanes4(|i| ((self.0[i].to_bits() as i64) >> 63) as u64))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M64x4 {
        M64x4::from_fn(|i| self.0[i] < o.0[i])
    }
    #[inline(always)]
    fn le(self, o: Self) -> M64x4 {
        M64x4::from_fn(|i| self.0[i] <= o.0[i])
    }
    #[inline(always)]
    fn gt(self, o: Self) -> M64x4 {
        M64x4::from_fn(|i| self.0[i] > o.0[i])
    }
    #[inline(always)]
    fn ge(self, o: Self) -> M64x4 {
        M64x4::from_fn(|i| self.0[i] >= o.0[i])
    }
    #[inline(always)]
    #[allow(clippy::float_cmp)] // an IEEE comparison is what this is
    fn eq(self, o: Self) -> M64x4 {
        M64x4::from_fn(|i| self.0[i] == o.0[i])
    }
    #[inline(always)]
    fn is_nan(self) -> M64x4 {
        M64x4::from_fn(|i| self.0[i].is_nan())
    }
    #[inline(always)]
    fn select(mask: M64x4, a: Self, b: Self) -> Self {
        F64x4(lanes4(|i| if mask.0[i] != 0 { a.0[i] } else { b.0[i] }))
    }
    #[inline(always)]
    fn to_bits(self) -> U64x4 {
        U64x4(lanes4(|i| self.0[i].to_bits()))
    }
    #[inline(always)]
    fn from_bits(bits: U64x4) -> Self {
        F64x4(lanes4(|i| f64::from_bits(bits.0[i])))
    }
    #[inline(always)]
    fn nonzero(bits: U64x4) -> M64x4 {
        M64x4::from_fn(|i| bits.0[i] != 0)
    }
    #[inline(always)]
    fn map(self, mut f: impl FnMut(f64) -> f64) -> Self {
        F64x4(lanes4(|i| f(self.0[i])))
    }
}
