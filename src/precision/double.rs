//! `precision = "f64"`: every position, direction, error bound and colour in double precision.

instantiate!(f64, glam::DVec2, glam::DVec3, glam::DMat3, glam::DMat4);

/// Lanes of `Real` for the SIMD kernels (`crate::simd`); edge functions are already in `f64`.
pub type R4<I> = <I as crate::simd::Isa>::F64x4;
pub type R8<I> = <I as crate::simd::Isa>::F64x8;

/// Four lanes and four more as eight.
#[inline(always)]
pub fn join4<I: crate::simd::Isa>(low: R4<I>, high: R4<I>) -> R8<I> {
    I::join_f64(low, high)
}

/// No shuffle of `f64` rays into lanes: they are put in value by value.
#[inline(always)]
pub fn transpose_rays<I: crate::simd::Isa>(_values: &[f64; 48]) -> Option<[R8<I>; 6]> {
    None
}

/// Lane `a` of `x` in lanes 0–3 and lane `b` in lanes 4–7 (each index taken modulo 8).
#[inline(always)]
pub fn lane_pair<I: crate::simd::Isa>(x: R8<I>, [a, b]: [usize; 2]) -> R8<I> {
    I::lane_pair_f64(x, a, b)
}

/// Lane `lane` of `x` (taken modulo 8) in each of four lanes.
#[inline(always)]
pub fn lane_splat<I: crate::simd::Isa>(x: R8<I>, lane: usize) -> R4<I> {
    I::lane_splat_f64(x, lane)
}

/// The triangle test's edge function `a.x·b.y − a.y·b.x` on eight lanes (already `f64`).
#[inline(always)]
pub fn edge8<I: crate::simd::Isa>(ax: R8<I>, ay: R8<I>, bx: R8<I>, by: R8<I>) -> R8<I> {
    ax * by - ay * bx
}

/// The triangle test's edge function on four lanes (already `f64`).
#[inline(always)]
pub fn edge4<I: crate::simd::Isa>(ax: R4<I>, ay: R4<I>, bx: R4<I>, by: R4<I>) -> R4<I> {
    ax * by - ay * bx
}
