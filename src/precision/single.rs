//! The default precision: what golden images are rendered with, and the fastest.

instantiate!(f32, glam::Vec2, glam::Vec3, glam::Mat3, glam::Mat4);

/// Lanes of `Real` for the SIMD kernels (`crate::simd`), and the exact widening to `f64` that the
/// triangle test's edge functions use.
pub type R4<I> = <I as crate::simd::Isa>::F32x4;
pub type R8<I> = <I as crate::simd::Isa>::F32x8;

#[inline(always)]
pub fn wide4<I: crate::simd::Isa>(x: R4<I>) -> I::F64x4 {
    I::widen(x)
}

#[inline(always)]
pub fn narrow4<I: crate::simd::Isa>(x: I::F64x4) -> R4<I> {
    I::narrow(x)
}
