//! The default precision: what golden images are rendered with, and the fastest.

instantiate!(f32, glam::Vec2, glam::Vec3, glam::Mat3, glam::Mat4);

/// Lanes of `Real` for the SIMD kernels (`crate::simd`); the triangle test's edge functions
/// widen them to `f64`, where their products are exact.
pub type R4<I> = <I as crate::simd::Isa>::F32x4;
pub type R8<I> = <I as crate::simd::Isa>::F32x8;

/// Four lanes and four more as eight.
#[inline(always)]
pub fn join4<I: crate::simd::Isa>(low: R4<I>, high: R4<I>) -> R8<I> {
    I::join(low, high)
}

/// Eight rays' origins and directions (`values[6k..6k + 6]` the `k`-th ray's) into lanes,
/// component by component: `[ox, oy, oz, dx, dy, dz]`.
#[inline(always)]
pub fn transpose_rays<I: crate::simd::Isa>(values: &[f32; 48]) -> Option<[R8<I>; 6]> {
    Some(I::transpose_8x6(values))
}

/// Lane `a` of `x` in lanes 0–3 and lane `b` in lanes 4–7.
#[inline(always)]
pub fn lane_pair<I: crate::simd::Isa>(x: R8<I>, [a, b]: [usize; 2]) -> R8<I> {
    I::lane_pair(x, a, b)
}

/// Lane `lane` of `x` in each of four lanes.
#[inline(always)]
pub fn lane_splat<I: crate::simd::Isa>(x: R8<I>, lane: usize) -> R4<I> {
    I::split(I::lane_pair(x, lane, lane)).0
}

/// The triangle test's edge function `a.x·b.y − a.y·b.x` on eight lanes, in `f64` (exact
/// products) rounded back, as `geometry::triangle` computes it lane by lane.
#[inline(always)]
pub fn edge8<I: crate::simd::Isa>(ax: R8<I>, ay: R8<I>, bx: R8<I>, by: R8<I>) -> R8<I> {
    let [(ax0, ax1), (ay0, ay1), (bx0, bx1), (by0, by1)] = [I::split(ax), I::split(ay), I::split(bx), I::split(by)];
    I::join(edge4::<I>(ax0, ay0, bx0, by0), edge4::<I>(ax1, ay1, bx1, by1))
}

/// The triangle test's edge function on four lanes, as [`edge8`]. Both products are exact in
/// `f64`, so fusing the first with the subtraction leaves the subtraction the one rounding
/// before the narrowing, as `edge_function`'s.
#[inline(always)]
pub fn edge4<I: crate::simd::Isa>(ax: R4<I>, ay: R4<I>, bx: R4<I>, by: R4<I>) -> R4<I> {
    use crate::simd::Lanes;
    I::narrow(I::widen(ax).mul_add_exact(I::widen(by), -(I::widen(ay) * I::widen(bx))))
}
