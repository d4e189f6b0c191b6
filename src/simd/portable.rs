//! The portable path: lanes as plain arrays, one operation per element, for any processor.

use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Isa, Lanes, MaskOps};

/// The portable instruction set.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

impl Isa for Portable {
    type F32x4 = Array<f32, 4>;
    type F32x8 = Array<f32, 8>;
    type F64x4 = Array<f64, 4>;
    type F64x8 = Array<f64, 8>;

    #[inline(always)]
    fn widen(x: Array<f32, 4>) -> Array<f64, 4> {
        Array(x.0.map(f64::from))
    }

    #[inline(always)]
    fn narrow(x: Array<f64, 4>) -> Array<f32, 4> {
        Array(x.0.map(|v| v as f32))
    }

    #[inline(always)]
    fn split(x: Array<f32, 8>) -> (Array<f32, 4>, Array<f32, 4>) {
        let [a, b, c, d, e, f, g, h] = x.0;
        (Array([a, b, c, d]), Array([e, f, g, h]))
    }

    #[inline(always)]
    fn join(low: Array<f32, 4>, high: Array<f32, 4>) -> Array<f32, 8> {
        let ([a, b, c, d], [e, f, g, h]) = (low.0, high.0);
        Array([a, b, c, d, e, f, g, h])
    }

    #[inline(always)]
    fn prefetch<T>(_: *const T) {}
}

/// `N` lanes of `T`.
#[derive(Clone, Copy, Debug)]
pub struct Array<T, const N: usize>(pub [T; N]);

/// One bit per lane.
#[derive(Clone, Copy, Debug)]
pub struct Bits(u32);

impl MaskOps for Bits {
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        Bits(self.0 & other.0)
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        Bits(self.0 | other.0)
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        Bits(self.0 & !other.0)
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        self.0
    }
}

macro_rules! array_lanes {
    ($t:ty) => {
        impl<const N: usize> Array<$t, N> {
            #[inline(always)]
            fn zip(self, other: Self, f: impl Fn($t, $t) -> $t) -> Self {
                let mut out = self.0;
                for lane in 0..N {
                    out[lane] = f(self.0[lane], other.0[lane]);
                }
                Array(out)
            }

            #[inline(always)]
            fn compare(self, other: Self, f: impl Fn($t, $t) -> bool) -> Bits {
                let mut bits = 0;
                for lane in 0..N {
                    bits |= (f(self.0[lane], other.0[lane]) as u32) << lane;
                }
                Bits(bits)
            }
        }

        impl<const N: usize> Add for Array<$t, N> {
            type Output = Self;
            #[inline(always)]
            fn add(self, other: Self) -> Self {
                self.zip(other, |a, b| a + b)
            }
        }

        impl<const N: usize> Sub for Array<$t, N> {
            type Output = Self;
            #[inline(always)]
            fn sub(self, other: Self) -> Self {
                self.zip(other, |a, b| a - b)
            }
        }

        impl<const N: usize> Mul for Array<$t, N> {
            type Output = Self;
            #[inline(always)]
            fn mul(self, other: Self) -> Self {
                self.zip(other, |a, b| a * b)
            }
        }

        impl<const N: usize> Div for Array<$t, N> {
            type Output = Self;
            #[inline(always)]
            fn div(self, other: Self) -> Self {
                self.zip(other, |a, b| a / b)
            }
        }

        impl<const N: usize> Neg for Array<$t, N> {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                Array(self.0.map(|a| -a))
            }
        }

        impl<const N: usize> Lanes for Array<$t, N> {
            type Elem = $t;
            type Mask = Bits;
            const N: usize = N;

            #[inline(always)]
            fn splat(value: $t) -> Self {
                Array([value; N])
            }
            #[inline(always)]
            fn load(values: &[$t]) -> Self {
                Array(values[..N].try_into().expect("N values"))
            }
            #[inline(always)]
            fn store(self, out: &mut [$t]) {
                out[..N].copy_from_slice(&self.0);
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                Array(self.0.map(<$t>::sqrt))
            }
            #[inline(always)]
            fn abs(self) -> Self {
                Array(self.0.map(<$t>::abs))
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                self.zip(other, |a, b| if a > b { a } else { b })
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                self.zip(other, |a, b| if a < b { a } else { b })
            }
            #[inline(always)]
            fn lt(self, other: Self) -> Bits {
                self.compare(other, |a, b| a < b)
            }
            #[inline(always)]
            fn le(self, other: Self) -> Bits {
                self.compare(other, |a, b| a <= b)
            }
            #[inline(always)]
            fn gt(self, other: Self) -> Bits {
                self.compare(other, |a, b| a > b)
            }
            #[inline(always)]
            fn eq(self, other: Self) -> Bits {
                self.compare(other, |a, b| a == b)
            }
            #[inline(always)]
            fn is_nan(self) -> Bits {
                self.compare(self, |a, _| a.is_nan())
            }
            #[inline(always)]
            fn select(mask: Bits, if_true: Self, if_false: Self) -> Self {
                let mut out = if_false.0;
                for lane in 0..N {
                    if mask.0 & (1 << lane) != 0 {
                        out[lane] = if_true.0[lane];
                    }
                }
                Array(out)
            }
        }
    };
}

array_lanes!(f32);
array_lanes!(f64);
