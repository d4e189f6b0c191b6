//! The x86-64 paths: lanes in SSE/AVX registers, kernels compiled with AVX2 or AVX-512 enabled.
//!
//! Both paths use the same lane types (128- and 256-bit registers); the AVX-512 path compiles
//! the kernels with AVX-512 enabled as well, which lets the compiler use its extra registers and
//! mask instructions. Every operation here is the IEEE operation of the portable path, lane by
//! lane: the comparisons are the ordered, quiet predicates Rust's `<`, `<=`, `>` and `==` are, and
//! `max`/`min` are the instructions whose rule the portable path copies.

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Isa, Kernel, Lanes, MaskOps};

pub(super) fn has_avx2() -> bool {
    is_x86_feature_detected!("avx2")
        && is_x86_feature_detected!("fma")
        && is_x86_feature_detected!("bmi1")
        && is_x86_feature_detected!("bmi2")
        && is_x86_feature_detected!("lzcnt")
        && is_x86_feature_detected!("popcnt")
}

#[cfg(feature = "avx512")]
pub(super) fn has_avx512() -> bool {
    has_avx2()
        && is_x86_feature_detected!("avx512f")
        && is_x86_feature_detected!("avx512vl")
        && is_x86_feature_detected!("avx512bw")
        && is_x86_feature_detected!("avx512dq")
        && is_x86_feature_detected!("avx512cd")
}

/// # Safety
/// The processor must support AVX2 ([`has_avx2`]).
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
pub(super) unsafe fn run_avx2<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<Avx2>()
}

/// # Safety
/// The processor must support AVX-512 ([`has_avx512`]).
#[cfg(feature = "avx512")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx512cd,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
pub(super) unsafe fn run_avx512<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<Avx512>()
}

/// The AVX2 instruction set. Only `run_avx2` names it, so its lanes only run where AVX2 does.
#[derive(Clone, Copy, Debug)]
pub struct Avx2(());

/// The AVX-512 instruction set (same lanes as [`Avx2`], compiled with AVX-512 enabled).
#[cfg(feature = "avx512")]
#[derive(Clone, Copy, Debug)]
pub struct Avx512(());

macro_rules! isa {
    ($token:ty) => {
        impl Isa for $token {
            type F32x4 = F32x4;
            type F32x8 = F32x8;
            type F64x4 = F64x4;
            type F64x8 = F64x8;

            #[inline(always)]
            fn widen(x: F32x4) -> F64x4 {
                unsafe { F64x4(_mm256_cvtps_pd(x.0)) }
            }

            #[inline(always)]
            fn narrow(x: F64x4) -> F32x4 {
                unsafe { F32x4(_mm256_cvtpd_ps(x.0)) }
            }

            #[inline(always)]
            fn split(x: F32x8) -> (F32x4, F32x4) {
                unsafe {
                    (
                        F32x4(_mm256_castps256_ps128(x.0)),
                        F32x4(_mm256_extractf128_ps::<1>(x.0)),
                    )
                }
            }

            #[inline(always)]
            fn join(low: F32x4, high: F32x4) -> F32x8 {
                unsafe { F32x8(_mm256_set_m128(high.0, low.0)) }
            }

            #[inline(always)]
            fn join_f64(low: F64x4, high: F64x4) -> F64x8 {
                F64x8([low, high])
            }

            #[inline(always)]
            fn transpose_8x6(values: &[f32; 48]) -> [F32x8; 6] {
                // Fields 0–3 and 2–5 of each record, two overlapping loads (all within the 48),
                // then the rows wanted of each: 30 instructions where lane-by-lane inserts took
                // about a hundred.
                unsafe {
                    let ([f0, f1, f2, _], [_, f3, f4, f5]) = (transpose_8x4(values, 0), transpose_8x4(values, 2));
                    [F32x8(f0), F32x8(f1), F32x8(f2), F32x8(f3), F32x8(f4), F32x8(f5)]
                }
            }

            #[inline(always)]
            fn lane_pair(x: F32x8, a: usize, b: usize) -> F32x8 {
                // One permutation a value; the index vector is built once for all of a pair's
                // values. The instruction reads only an index's low three bits.
                unsafe {
                    let index = _mm256_set_m128i(_mm_set1_epi32(b as i32), _mm_set1_epi32(a as i32));
                    F32x8(_mm256_permutevar8x32_ps(x.0, index))
                }
            }

            #[inline(always)]
            fn lane_pair_f64(x: F64x8, a: usize, b: usize) -> F64x8 {
                unsafe { F64x8([F64x4(f64_lane(x, a)), F64x4(f64_lane(x, b))]) }
            }

            #[inline(always)]
            fn lane_splat_f64(x: F64x8, lane: usize) -> F64x4 {
                unsafe { F64x4(f64_lane(x, lane)) }
            }

            #[inline(always)]
            fn prefetch<T>(address: *const T) {
                // SAFETY: a prefetch never faults, whatever the address.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(address.cast()) }
            }

            #[inline(always)]
            fn split_exponent(x: F32x8) -> (F32x8, F32x8) {
                unsafe {
                    let bits = _mm256_castps_si256(x.0);
                    let significand = _mm256_or_si256(
                        _mm256_and_si256(bits, _mm256_set1_epi32(0x007f_ffff)),
                        _mm256_set1_epi32(0x3f80_0000),
                    );
                    let biased = _mm256_srli_epi32::<23>(_mm256_and_si256(bits, _mm256_set1_epi32(0x7f80_0000)));
                    let exponent = _mm256_sub_epi32(biased, _mm256_set1_epi32(127));
                    (
                        F32x8(_mm256_castsi256_ps(significand)),
                        F32x8(_mm256_cvtepi32_ps(exponent)),
                    )
                }
            }

            #[inline(always)]
            fn power_of_two(n: F32x8) -> F32x8 {
                unsafe {
                    let biased = _mm256_add_epi32(_mm256_cvttps_epi32(n.0), _mm256_set1_epi32(127));
                    F32x8(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(biased)))
                }
            }
        }
    };
}

isa!(Avx2);
#[cfg(feature = "avx512")]
isa!(Avx512);

/// Fields `first..first + 4` of eight records of six `f32`s (`values[6k..6k + 6]` the `k`-th) as
/// four lanes each: records `k` and `k + 4` side by side in each half, then a four-by-four
/// transposition in each half. Helpers are functions, not closures: a closure may be compiled
/// outside the kernel, without its instructions.
#[inline(always)]
unsafe fn transpose_8x4(values: &[f32; 48], first: usize) -> [__m256; 4] {
    assert!(first <= 2, "the fields read lie within the 48 values");
    unsafe {
        let at = values.as_ptr().add(first);
        let a0 = _mm256_set_m128(_mm_loadu_ps(at.add(24)), _mm_loadu_ps(at));
        let a1 = _mm256_set_m128(_mm_loadu_ps(at.add(30)), _mm_loadu_ps(at.add(6)));
        let a2 = _mm256_set_m128(_mm_loadu_ps(at.add(36)), _mm_loadu_ps(at.add(12)));
        let a3 = _mm256_set_m128(_mm_loadu_ps(at.add(42)), _mm_loadu_ps(at.add(18)));
        let (low01, high01) = (_mm256_unpacklo_ps(a0, a1), _mm256_unpackhi_ps(a0, a1));
        let (low23, high23) = (_mm256_unpacklo_ps(a2, a3), _mm256_unpackhi_ps(a2, a3));
        [
            _mm256_shuffle_ps::<0x44>(low01, low23),
            _mm256_shuffle_ps::<0xee>(low01, low23),
            _mm256_shuffle_ps::<0x44>(high01, high23),
            _mm256_shuffle_ps::<0xee>(high01, high23),
        ]
    }
}

/// Lane `lane` (taken modulo 8) of `x` in each of four lanes: the lane's two 32-bit halves
/// permuted out of both halves of `x`, then the half that holds it chosen by a blend (no store
/// and reload, no branch on the lane).
#[inline(always)]
unsafe fn f64_lane(x: F64x8, lane: usize) -> __m256d {
    unsafe {
        let word = 2 * (lane % 4) as i64;
        let index = _mm256_set1_epi64x(((word + 1) << 32) | word);
        let [low, high] = x.0;
        let from_low = _mm256_permutevar8x32_ps(_mm256_castpd_ps(low.0), index);
        let from_high = _mm256_permutevar8x32_ps(_mm256_castpd_ps(high.0), index);
        let take_high = _mm256_castsi256_ps(_mm256_set1_epi32(-((lane / 4 % 2) as i32)));
        _mm256_castps_pd(_mm256_blendv_ps(from_low, from_high, take_high))
    }
}

/// Four `f32` lanes folded as [`Lanes::min_lane`]'s halving tree with `packed` and `scalar`
/// (both `min` or both `max`): lanes 0 and 1 against 2 and 3, then lane 0 against lane 1.
#[inline(always)]
unsafe fn fold4_ps(
    v: __m128,
    packed: unsafe fn(__m128, __m128) -> __m128,
    scalar: unsafe fn(__m128, __m128) -> __m128,
) -> f32 {
    unsafe {
        let halves = packed(v, _mm_movehl_ps(v, v));
        _mm_cvtss_f32(scalar(halves, _mm_movehdup_ps(halves)))
    }
}

/// Four `f64` lanes folded as [`fold4_ps`] folds four `f32`.
#[inline(always)]
unsafe fn fold4_pd(
    v: __m256d,
    packed: unsafe fn(__m128d, __m128d) -> __m128d,
    scalar: unsafe fn(__m128d, __m128d) -> __m128d,
) -> f64 {
    unsafe {
        let halves = packed(_mm256_castpd256_pd128(v), _mm256_extractf128_pd::<1>(v));
        _mm_cvtsd_f64(scalar(halves, _mm_unpackhi_pd(halves, halves)))
    }
}

/// Defines a lane type over one register: its arithmetic, and its mask (a register of the same
/// type whose lanes are all ones or all zeros).
macro_rules! register_lanes {
    (
        $name:ident, $mask:ident, $reg:ty, $elem:ty, $n:expr,
        load: $load:ident, store: $store:ident, splat: $splat:ident, setr: $setr:ident [$($lane:literal),*],
        add: $add:ident, sub: $sub:ident, mul: $mul:ident, div: $div:ident, sqrt: $sqrt:ident,
        fmadd: $fmadd:ident, max: $max:ident, min: $min:ident, and: $and:ident, or: $or:ident, andnot: $andnot:ident,
        xor: $xor:ident, blend: $blend:ident, movemask: $movemask:ident,
        cmp: |$a:ident, $b:ident, $pred:ident| $cmp:expr,
        bits: $to_bits:ident, from_bits: $from_bits:ident, int_add: $int_add:ident, int_sub: $int_sub:ident,
        min_lane: |$min_v:ident| $min_lane:expr, max_lane: |$max_v:ident| $max_lane:expr,
        mask: |$mask_bits:ident| $mask_expr:expr
    ) => {
        #[derive(Clone, Copy, Debug)]
        pub struct $name($reg);

        #[derive(Clone, Copy, Debug)]
        pub struct $mask($reg);

        impl $name {
            #[inline(always)]
            fn compare<const $pred: i32>(self, other: Self) -> $mask {
                let ($a, $b) = (self.0, other.0);
                $mask(unsafe { $cmp })
            }
        }

        impl MaskOps for $mask {
            #[inline(always)]
            fn and(self, other: Self) -> Self {
                $mask(unsafe { $and(self.0, other.0) })
            }
            #[inline(always)]
            fn or(self, other: Self) -> Self {
                $mask(unsafe { $or(self.0, other.0) })
            }
            #[inline(always)]
            fn and_not(self, other: Self) -> Self {
                $mask(unsafe { $andnot(other.0, self.0) })
            }
            #[inline(always)]
            fn bits(self) -> u32 {
                unsafe { $movemask(self.0) as u32 }
            }
        }

        impl Add for $name {
            type Output = Self;
            #[inline(always)]
            fn add(self, other: Self) -> Self {
                $name(unsafe { $add(self.0, other.0) })
            }
        }

        impl Sub for $name {
            type Output = Self;
            #[inline(always)]
            fn sub(self, other: Self) -> Self {
                $name(unsafe { $sub(self.0, other.0) })
            }
        }

        impl Mul for $name {
            type Output = Self;
            #[inline(always)]
            fn mul(self, other: Self) -> Self {
                $name(unsafe { $mul(self.0, other.0) })
            }
        }

        impl Div for $name {
            type Output = Self;
            #[inline(always)]
            fn div(self, other: Self) -> Self {
                $name(unsafe { $div(self.0, other.0) })
            }
        }

        impl Neg for $name {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                $name(unsafe { $xor(self.0, $splat(-0.0)) })
            }
        }

        impl Lanes for $name {
            type Elem = $elem;
            type Mask = $mask;
            const N: usize = $n;

            #[inline(always)]
            fn splat(value: $elem) -> Self {
                $name(unsafe { $splat(value) })
            }
            #[inline(always)]
            fn load(values: &[$elem]) -> Self {
                let values = &values[..$n];
                $name(unsafe { $load(values.as_ptr()) })
            }
            #[inline(always)]
            fn store(self, out: &mut [$elem]) {
                let out = &mut out[..$n];
                unsafe { $store(out.as_mut_ptr(), self.0) }
            }
            #[inline(always)]
            fn from_array<const M: usize>(values: [$elem; M]) -> Self {
                assert_eq!(M, $n, "{} values for {} lanes", M, $n);
                $name(unsafe { $setr($(values[$lane]),*) })
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $name(unsafe { $sqrt(self.0) })
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $name(unsafe { $andnot($splat(-0.0), self.0) })
            }
            #[inline(always)]
            fn mul_add_exact(self, factor: Self, addend: Self) -> Self {
                $name(unsafe { $fmadd(self.0, factor.0, addend.0) })
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                $name(unsafe { $max(self.0, other.0) })
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                $name(unsafe { $min(self.0, other.0) })
            }
            #[inline(always)]
            fn min_lane(self) -> $elem {
                let $min_v = self.0;
                unsafe { $min_lane }
            }
            #[inline(always)]
            fn max_lane(self) -> $elem {
                let $max_v = self.0;
                unsafe { $max_lane }
            }
            #[inline(always)]
            fn lt(self, other: Self) -> $mask {
                self.compare::<_CMP_LT_OQ>(other)
            }
            #[inline(always)]
            fn le(self, other: Self) -> $mask {
                self.compare::<_CMP_LE_OQ>(other)
            }
            #[inline(always)]
            fn gt(self, other: Self) -> $mask {
                self.compare::<_CMP_GT_OQ>(other)
            }
            #[inline(always)]
            fn eq(self, other: Self) -> $mask {
                self.compare::<_CMP_EQ_OQ>(other)
            }
            #[inline(always)]
            fn is_nan(self) -> $mask {
                self.compare::<_CMP_UNORD_Q>(self)
            }
            #[inline(always)]
            fn mask($mask_bits: u32) -> $mask {
                $mask(unsafe { $mask_expr })
            }
            #[inline(always)]
            fn select(mask: $mask, if_true: Self, if_false: Self) -> Self {
                $name(unsafe { $blend(if_false.0, if_true.0, mask.0) })
            }
            #[inline(always)]
            fn adjust_bits(self, increment: $mask, decrement: $mask) -> Self {
                // A set mask lane is all ones, −1 as an integer.
                $name(unsafe {
                    let bits = $int_sub($to_bits(self.0), $to_bits(increment.0));
                    $from_bits($int_add(bits, $to_bits(decrement.0)))
                })
            }
        }
    };
}

register_lanes!(
    F32x4, M32x4, __m128, f32, 4,
    load: _mm_loadu_ps, store: _mm_storeu_ps, splat: _mm_set1_ps, setr: _mm_setr_ps [0, 1, 2, 3],
    add: _mm_add_ps, sub: _mm_sub_ps, mul: _mm_mul_ps, div: _mm_div_ps, sqrt: _mm_sqrt_ps,
    fmadd: _mm_fmadd_ps, max: _mm_max_ps, min: _mm_min_ps, and: _mm_and_ps, or: _mm_or_ps, andnot: _mm_andnot_ps,
    xor: _mm_xor_ps, blend: _mm_blendv_ps, movemask: _mm_movemask_ps,
    cmp: |a, b, P| _mm_cmp_ps::<P>(a, b),
    bits: _mm_castps_si128, from_bits: _mm_castsi128_ps, int_add: _mm_add_epi32, int_sub: _mm_sub_epi32,
    min_lane: |v| fold4_ps(v, _mm_min_ps, _mm_min_ss), max_lane: |v| fold4_ps(v, _mm_max_ps, _mm_max_ss),
    mask: |bits| {
        let lane_bits = _mm_setr_epi32(1, 2, 4, 8);
        _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(bits as i32), lane_bits), lane_bits))
    }
);

register_lanes!(
    F32x8, M32x8, __m256, f32, 8,
    load: _mm256_loadu_ps, store: _mm256_storeu_ps, splat: _mm256_set1_ps,
    setr: _mm256_setr_ps [0, 1, 2, 3, 4, 5, 6, 7],
    add: _mm256_add_ps, sub: _mm256_sub_ps, mul: _mm256_mul_ps, div: _mm256_div_ps, sqrt: _mm256_sqrt_ps,
    fmadd: _mm256_fmadd_ps, max: _mm256_max_ps, min: _mm256_min_ps, and: _mm256_and_ps, or: _mm256_or_ps, andnot: _mm256_andnot_ps,
    xor: _mm256_xor_ps, blend: _mm256_blendv_ps, movemask: _mm256_movemask_ps,
    cmp: |a, b, P| _mm256_cmp_ps::<P>(a, b),
    bits: _mm256_castps_si256, from_bits: _mm256_castsi256_ps, int_add: _mm256_add_epi32, int_sub: _mm256_sub_epi32,
    min_lane: |v| fold4_ps(_mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v)), _mm_min_ps, _mm_min_ss),
    max_lane: |v| fold4_ps(_mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v)), _mm_max_ps, _mm_max_ss),
    mask: |bits| {
        let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits), lane_bits))
    }
);

register_lanes!(
    F64x4, M64x4, __m256d, f64, 4,
    load: _mm256_loadu_pd, store: _mm256_storeu_pd, splat: _mm256_set1_pd, setr: _mm256_setr_pd [0, 1, 2, 3],
    add: _mm256_add_pd, sub: _mm256_sub_pd, mul: _mm256_mul_pd, div: _mm256_div_pd, sqrt: _mm256_sqrt_pd,
    fmadd: _mm256_fmadd_pd, max: _mm256_max_pd, min: _mm256_min_pd, and: _mm256_and_pd, or: _mm256_or_pd, andnot: _mm256_andnot_pd,
    xor: _mm256_xor_pd, blend: _mm256_blendv_pd, movemask: _mm256_movemask_pd,
    cmp: |a, b, P| _mm256_cmp_pd::<P>(a, b),
    bits: _mm256_castpd_si256, from_bits: _mm256_castsi256_pd, int_add: _mm256_add_epi64, int_sub: _mm256_sub_epi64,
    min_lane: |v| fold4_pd(v, _mm_min_pd, _mm_min_sd), max_lane: |v| fold4_pd(v, _mm_max_pd, _mm_max_sd),
    mask: |bits| {
        let lane_bits = _mm256_setr_epi64x(1, 2, 4, 8);
        _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(_mm256_set1_epi64x(bits as i64), lane_bits), lane_bits))
    }
);

/// Eight `f64` lanes as two halves of four.
#[derive(Clone, Copy, Debug)]
pub struct F64x8([F64x4; 2]);

#[derive(Clone, Copy, Debug)]
pub struct M64x8([M64x4; 2]);

impl MaskOps for M64x8 {
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        M64x8([self.0[0].and(other.0[0]), self.0[1].and(other.0[1])])
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        M64x8([self.0[0].or(other.0[0]), self.0[1].or(other.0[1])])
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        M64x8([self.0[0].and_not(other.0[0]), self.0[1].and_not(other.0[1])])
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        self.0[0].bits() | self.0[1].bits() << 4
    }
}

macro_rules! halves_op {
    ($trait:ident, $method:ident) => {
        impl $trait for F64x8 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                F64x8([self.0[0].$method(other.0[0]), self.0[1].$method(other.0[1])])
            }
        }
    };
}

halves_op!(Add, add);
halves_op!(Sub, sub);
halves_op!(Mul, mul);
halves_op!(Div, div);

impl Neg for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        F64x8([-self.0[0], -self.0[1]])
    }
}

impl Lanes for F64x8 {
    type Elem = f64;
    type Mask = M64x8;
    const N: usize = 8;

    #[inline(always)]
    fn splat(value: f64) -> Self {
        F64x8([F64x4::splat(value); 2])
    }
    #[inline(always)]
    fn load(values: &[f64]) -> Self {
        F64x8([F64x4::load(&values[..4]), F64x4::load(&values[4..8])])
    }
    #[inline(always)]
    fn store(self, out: &mut [f64]) {
        self.0[0].store(&mut out[..4]);
        self.0[1].store(&mut out[4..8]);
    }
    #[inline(always)]
    fn from_array<const M: usize>(values: [f64; M]) -> Self {
        assert_eq!(M, 8, "{M} values for 8 lanes");
        F64x8([
            F64x4::from_array([values[0], values[1], values[2], values[3]]),
            F64x4::from_array([values[4], values[5], values[6], values[7]]),
        ])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F64x8([self.0[0].sqrt(), self.0[1].sqrt()])
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F64x8([self.0[0].abs(), self.0[1].abs()])
    }
    #[inline(always)]
    fn mul_add_exact(self, factor: Self, addend: Self) -> Self {
        F64x8([
            self.0[0].mul_add_exact(factor.0[0], addend.0[0]),
            self.0[1].mul_add_exact(factor.0[1], addend.0[1]),
        ])
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        F64x8([self.0[0].max(other.0[0]), self.0[1].max(other.0[1])])
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        F64x8([self.0[0].min(other.0[0]), self.0[1].min(other.0[1])])
    }
    #[inline(always)]
    fn min_lane(self) -> f64 {
        self.0[0].min(self.0[1]).min_lane()
    }
    #[inline(always)]
    fn max_lane(self) -> f64 {
        self.0[0].max(self.0[1]).max_lane()
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M64x8 {
        M64x8([self.0[0].lt(other.0[0]), self.0[1].lt(other.0[1])])
    }
    #[inline(always)]
    fn le(self, other: Self) -> M64x8 {
        M64x8([self.0[0].le(other.0[0]), self.0[1].le(other.0[1])])
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M64x8 {
        M64x8([self.0[0].gt(other.0[0]), self.0[1].gt(other.0[1])])
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M64x8 {
        M64x8([self.0[0].eq(other.0[0]), self.0[1].eq(other.0[1])])
    }
    #[inline(always)]
    fn is_nan(self) -> M64x8 {
        M64x8([self.0[0].is_nan(), self.0[1].is_nan()])
    }
    #[inline(always)]
    fn mask(bits: u32) -> M64x8 {
        M64x8([F64x4::mask(bits), F64x4::mask(bits >> 4)])
    }
    #[inline(always)]
    fn select(mask: M64x8, if_true: Self, if_false: Self) -> Self {
        F64x8([
            F64x4::select(mask.0[0], if_true.0[0], if_false.0[0]),
            F64x4::select(mask.0[1], if_true.0[1], if_false.0[1]),
        ])
    }
    #[inline(always)]
    fn adjust_bits(self, increment: M64x8, decrement: M64x8) -> Self {
        F64x8([
            self.0[0].adjust_bits(increment.0[0], decrement.0[0]),
            self.0[1].adjust_bits(increment.0[1], decrement.0[1]),
        ])
    }
}
