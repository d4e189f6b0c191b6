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
