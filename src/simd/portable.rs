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
        let [a, b, c, d] = x.0;
        Array([a.into(), b.into(), c.into(), d.into()])
    }

    #[inline(always)]
    fn narrow(x: Array<f64, 4>) -> Array<f32, 4> {
        let [a, b, c, d] = x.0;
        Array([a as f32, b as f32, c as f32, d as f32])
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
    fn join_f64(low: Array<f64, 4>, high: Array<f64, 4>) -> Array<f64, 8> {
        let ([a, b, c, d], [e, f, g, h]) = (low.0, high.0);
        Array([a, b, c, d, e, f, g, h])
    }

    #[inline(always)]
    fn transpose_8x6(values: &[f32; 48]) -> [Array<f32, 8>; 6] {
        std::array::from_fn(|field| Array(std::array::from_fn(|k| values[6 * k + field])))
    }

    #[inline(always)]
    fn lane_pair(x: Array<f32, 8>, a: usize, b: usize) -> Array<f32, 8> {
        let (a, b) = (x.0[a % 8], x.0[b % 8]);
        Array([a, a, a, a, b, b, b, b])
    }

    #[inline(always)]
    fn lane_pair_f64(x: Array<f64, 8>, a: usize, b: usize) -> Array<f64, 8> {
        let (a, b) = (x.0[a % 8], x.0[b % 8]);
        Array([a, a, a, a, b, b, b, b])
    }

    #[inline(always)]
    fn lane_splat_f64(x: Array<f64, 8>, lane: usize) -> Array<f64, 4> {
        Array([x.0[lane % 8]; 4])
    }

    #[inline(always)]
    fn prefetch<T>(_: *const T) {}

    #[inline(always)]
    fn split_exponent(x: Array<f32, 8>) -> (Array<f32, 8>, Array<f32, 8>) {
        let bits = x.0.map(f32::to_bits);
        (
            Array(bits.map(|b| f32::from_bits((b & 0x007f_ffff) | 0x3f80_0000))),
            Array(bits.map(|b| (((b >> 23) & 0xff) as i32 - 127) as f32)),
        )
    }

    #[inline(always)]
    fn power_of_two(n: Array<f32, 8>) -> Array<f32, 8> {
        Array(n.0.map(|n| f32::from_bits(((n as i32 + 127) as u32) << 23)))
    }
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

/// Each lane operation written out lane by lane (`[f(a[0], b[0]), f(a[1], b[1]), …]`) rather than
/// as a loop or `array::map`: a kernel inlines thousands of them, and LLVM had to rotate, unroll
/// and scalarise every loop again (the eight-lane integrator's portable copy alone took most of
/// the crate's release build). The operations and their order are the same either way.
macro_rules! array_lanes {
    ($t:ty, $bits:ty, $n:literal, [$($lane:literal),*]) => {
        impl Array<$t, $n> {
            #[inline(always)]
            fn zip(self, other: Self, f: impl Fn($t, $t) -> $t) -> Self {
                let (a, b) = (self.0, other.0);
                Array([$(f(a[$lane], b[$lane])),*])
            }

            #[inline(always)]
            fn each(self, f: impl Fn($t) -> $t) -> Self {
                let a = self.0;
                Array([$(f(a[$lane])),*])
            }

            /// The lanes folded with `f` as [`Lanes::min_lane`]'s halving tree.
            #[inline(always)]
            fn fold(self, f: impl Fn($t, $t) -> $t) -> $t {
                let mut lanes = self.0;
                let mut half = $n / 2;
                while half > 0 {
                    for lane in 0..half {
                        lanes[lane] = f(lanes[lane], lanes[lane + half]);
                    }
                    half /= 2;
                }
                lanes[0]
            }

            #[inline(always)]
            fn compare(self, other: Self, f: impl Fn($t, $t) -> bool) -> Bits {
                let (a, b) = (self.0, other.0);
                Bits(0 $(| ((f(a[$lane], b[$lane]) as u32) << $lane))*)
            }
        }

        impl Add for Array<$t, $n> {
            type Output = Self;
            #[inline(always)]
            fn add(self, other: Self) -> Self {
                self.zip(other, |a, b| a + b)
            }
        }

        impl Sub for Array<$t, $n> {
            type Output = Self;
            #[inline(always)]
            fn sub(self, other: Self) -> Self {
                self.zip(other, |a, b| a - b)
            }
        }

        impl Mul for Array<$t, $n> {
            type Output = Self;
            #[inline(always)]
            fn mul(self, other: Self) -> Self {
                self.zip(other, |a, b| a * b)
            }
        }

        impl Div for Array<$t, $n> {
            type Output = Self;
            #[inline(always)]
            fn div(self, other: Self) -> Self {
                self.zip(other, |a, b| a / b)
            }
        }

        impl Neg for Array<$t, $n> {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                self.each(|a| -a)
            }
        }

        impl Lanes for Array<$t, $n> {
            type Elem = $t;
            type Mask = Bits;
            const N: usize = $n;

            #[inline(always)]
            fn splat(value: $t) -> Self {
                Array([value; $n])
            }
            #[inline(always)]
            fn load(values: &[$t]) -> Self {
                let values = &values[..$n];
                Array([$(values[$lane]),*])
            }
            #[inline(always)]
            fn store(self, out: &mut [$t]) {
                out[..$n].copy_from_slice(&self.0);
            }
            #[inline(always)]
            fn from_array<const M: usize>(values: [$t; M]) -> Self {
                assert_eq!(M, $n, "{} values for {} lanes", M, $n);
                Array([$(values[$lane]),*])
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                self.each(<$t>::sqrt)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                self.each(<$t>::abs)
            }
            #[inline(always)]
            fn mul_add_exact(self, factor: Self, addend: Self) -> Self {
                // Unfused: exact products round once either way, and a fused multiply-add
                // would be a library call where the processor has none.
                let (a, b, c) = (self.0, factor.0, addend.0);
                Array([$(a[$lane] * b[$lane] + c[$lane]),*])
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
            fn min_lane(self) -> $t {
                self.fold(|a, b| if a < b { a } else { b })
            }
            #[inline(always)]
            fn max_lane(self) -> $t {
                self.fold(|a, b| if a > b { a } else { b })
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
            fn mask(bits: u32) -> Bits {
                Bits(bits & ((1 << $n) - 1))
            }
            #[inline(always)]
            fn select(mask: Bits, if_true: Self, if_false: Self) -> Self {
                let (t, f) = (if_true.0, if_false.0);
                Array([$(if mask.0 & (1 << $lane) != 0 { t[$lane] } else { f[$lane] }),*])
            }
            #[inline(always)]
            fn adjust_bits(self, increment: Bits, decrement: Bits) -> Self {
                let a = self.0;
                let step = |lane: usize| -> $bits {
                    if increment.0 & (1 << lane) != 0 {
                        1
                    } else if decrement.0 & (1 << lane) != 0 {
                        <$bits>::MAX
                    } else {
                        0
                    }
                };
                Array([$(<$t>::from_bits(a[$lane].to_bits().wrapping_add(step($lane)))),*])
            }
        }
    };
}

array_lanes!(f32, u32, 4, [0, 1, 2, 3]);
array_lanes!(f32, u32, 8, [0, 1, 2, 3, 4, 5, 6, 7]);
array_lanes!(f64, u64, 4, [0, 1, 2, 3]);
array_lanes!(f64, u64, 8, [0, 1, 2, 3, 4, 5, 6, 7]);
