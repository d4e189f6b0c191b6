//! Which SIMD instruction set the ray kernels run on, and the lane types they are written with.
//!
//! The kernels (BVH traversal, the triangle and sphere tests) are written once, generic over an
//! instruction set [`Isa`], against the lane types it provides ([`Lanes`]: 4 or 8 `f32` or `f64`
//! side by side). Each kernel is compiled once per path: [`SimdPath::Portable`] (plain arrays,
//! any processor), [`SimdPath::Avx2`] and [`SimdPath::Avx512`] (x86-64 intrinsics, each kernel
//! compiled with those instructions enabled; AVX-512 only in a build with the `avx512` feature,
//! since it renders no faster than AVX2 and every path is a full copy of the kernels to
//! compile). [`dispatch`] runs a kernel on the path chosen at
//! run time: AVX2 where the processor has it ([`preferred`]: measured faster than AVX-512), else
//! the widest it supports, unless the environment variable `GOLDRAY_SIMD` (`portable`, `avx2`,
//! `avx512`) or [`set_path`] chooses another.
//!
//! **Every path computes the same numbers.** Each lane operation is one IEEE operation with one
//! defined result (Rust never fuses a multiply and an add), `max`/`min` follow x86's rule on
//! every path (`a > b ? a : b`, so a NaN yields the second operand), and the kernels do the same
//! operations in the same order whatever the lane type. So a picture is bit-identical whichever
//! path renders it; `tests/simd_paths.rs` forces each available path and compares the EXR bytes.

use std::ops::{Add, Div, Mul, Neg, Sub};
use std::sync::atomic::{AtomicU8, Ordering};

pub mod math;
mod portable;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use portable::Portable;
#[cfg(target_arch = "x86_64")]
pub use x86::Avx2;
#[cfg(all(target_arch = "x86_64", feature = "avx512"))]
pub use x86::Avx512;

/// An instruction set the kernels can be compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SimdPath {
    /// Plain arrays of lanes, left to the compiler: any processor.
    Portable,
    /// x86-64 with AVX2 and FMA (Haswell, 2013, and later).
    Avx2,
    /// x86-64 with AVX-512 F, VL, BW and DQ (Skylake-SP, Ice Lake, Zen 4 and later), in a build
    /// with the `avx512` feature.
    Avx512,
}

impl SimdPath {
    pub const ALL: [SimdPath; 3] = [SimdPath::Portable, SimdPath::Avx2, SimdPath::Avx512];

    pub fn name(self) -> &'static str {
        match self {
            SimdPath::Portable => "portable",
            SimdPath::Avx2 => "avx2",
            SimdPath::Avx512 => "avx512",
        }
    }

    /// Whether this build has the path and this processor can run it.
    pub fn is_supported(self) -> bool {
        match self {
            SimdPath::Portable => true,
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 => x86::has_avx2(),
            #[cfg(all(target_arch = "x86_64", feature = "avx512"))]
            SimdPath::Avx512 => x86::has_avx512(),
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    fn from_name(name: &str) -> Option<SimdPath> {
        SimdPath::ALL
            .into_iter()
            .find(|path| path.name().eq_ignore_ascii_case(name.trim()))
    }

    /// How `PATH` stores it (zero: not chosen yet); `path` decodes it.
    fn code(self) -> u8 {
        match self {
            SimdPath::Portable => 1,
            SimdPath::Avx2 => 2,
            SimdPath::Avx512 => 3,
        }
    }

    fn from_code(code: u8) -> SimdPath {
        SimdPath::ALL[code as usize - 1]
    }
}

/// The paths this processor can run, narrowest first.
pub fn available() -> Vec<SimdPath> {
    SimdPath::ALL.into_iter().filter(|path| path.is_supported()).collect()
}

/// The widest path this processor supports.
pub fn detected() -> SimdPath {
    *available().last().expect("the portable path is always available")
}

/// The path kernels run on unless told otherwise: AVX2 where the processor has it, even when it
/// also has AVX-512. The kernels work on eight lanes, which one AVX2 register holds, and on the
/// one AVX-512 machine measured (a Sapphire Rapids class Xeon) the AVX2 path was the faster:
/// camera rays through the 1M-triangle mesh 11.8-12.1 against 10.9-11.0 Mrays/s, random rays on
/// a par, the Whitted spheres 89-98 against 102-105 ms. AVX-512 stays a choice in a build with
/// the `avx512` feature (`GOLDRAY_SIMD=avx512`); it computes the same pictures.
pub fn preferred() -> SimdPath {
    if SimdPath::Avx2.is_supported() {
        SimdPath::Avx2
    } else {
        detected()
    }
}

/// Zero until the path is first asked for.
static PATH: AtomicU8 = AtomicU8::new(0);

/// The path kernels run on: [`set_path`]'s choice, else `GOLDRAY_SIMD`'s when this processor
/// supports it, else [`preferred`].
#[inline]
pub fn path() -> SimdPath {
    match PATH.load(Ordering::Relaxed) {
        1 => SimdPath::Portable,
        2 => SimdPath::Avx2,
        3 => SimdPath::Avx512,
        _ => initial_path(),
    }
}

#[cold]
fn initial_path() -> SimdPath {
    let requested = std::env::var("GOLDRAY_SIMD")
        .ok()
        .and_then(|name| SimdPath::from_name(&name));
    let path = requested.filter(|path| path.is_supported()).unwrap_or_else(preferred);
    // A concurrent `set_path` wins over the default.
    let _ = PATH.compare_exchange(0, path.code(), Ordering::Relaxed, Ordering::Relaxed);
    SimdPath::from_code(PATH.load(Ordering::Relaxed))
}

/// Makes every kernel of this process run on `path` from now on (for tests and benchmarks that
/// compare paths). Renders never depend on the path, only their speed does.
pub fn set_path(path: SimdPath) -> Result<(), UnsupportedPath> {
    if !path.is_supported() {
        return Err(UnsupportedPath(path));
    }
    PATH.store(path.code(), Ordering::Relaxed);
    Ok(())
}

/// [`set_path`] was asked for a path this processor cannot run, or this build does not have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the {} SIMD path is not available: this processor cannot run it or this build leaves it out", .0.name())]
pub struct UnsupportedPath(pub SimdPath);

/// A kernel: code generic over the instruction set, run by [`dispatch`]. `run` must be
/// `#[inline(always)]`, and so must every generic function it calls, so that the whole kernel is
/// compiled inside the trampoline that enables the path's instructions.
pub trait Kernel {
    type Output;
    fn run<I: Isa>(self) -> Self::Output;
}

/// Runs `kernel` on the current [`path`].
#[inline]
pub fn dispatch<K: Kernel>(kernel: K) -> K::Output {
    run_on(path(), kernel)
}

/// Runs `kernel` on `path` whatever the current one is, for a test that compares paths
/// without changing the path of everything else running in the process.
pub fn dispatch_on<K: Kernel>(path: SimdPath, kernel: K) -> Result<K::Output, UnsupportedPath> {
    if !path.is_supported() {
        return Err(UnsupportedPath(path));
    }
    Ok(run_on(path, kernel))
}

/// `kernel` on `path`, which the processor must support.
#[inline(always)]
fn run_on<K: Kernel>(path: SimdPath, kernel: K) -> K::Output {
    match path {
        #[cfg(all(target_arch = "x86_64", feature = "avx512"))]
        // SAFETY: both callers pass only paths the processor supports.
        SimdPath::Avx512 => unsafe { x86::run_avx512(kernel) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: both callers pass only paths the processor supports.
        SimdPath::Avx2 => unsafe { x86::run_avx2(kernel) },
        _ => kernel.run::<Portable>(),
    }
}

/// An instruction set: the lane types its kernels use. Implemented only by tokens that
/// [`dispatch`] hands to kernels compiled for them.
pub trait Isa: Copy + 'static {
    type F32x4: Lanes<Elem = f32>;
    type F32x8: Lanes<Elem = f32>;
    type F64x4: Lanes<Elem = f64>;
    type F64x8: Lanes<Elem = f64>;
    /// Each lane converted exactly to `f64`.
    fn widen(x: Self::F32x4) -> Self::F64x4;
    /// Each lane rounded to the nearest `f32`.
    fn narrow(x: Self::F64x4) -> Self::F32x4;
    /// Lanes 0–3 and 4–7.
    fn split(x: Self::F32x8) -> (Self::F32x4, Self::F32x4);
    /// The inverse of [`Isa::split`].
    fn join(low: Self::F32x4, high: Self::F32x4) -> Self::F32x8;
    /// [`Isa::join`] of `f64` lanes.
    fn join_f64(low: Self::F64x4, high: Self::F64x4) -> Self::F64x8;
    /// Eight records of six values (`values[6k..6k + 6]` the `k`-th) field by field: lane `k`
    /// of the `j`-th result is `values[6k + j]` (eight rays' origins and directions into lanes).
    fn transpose_8x6(values: &[f32; 48]) -> [Self::F32x8; 6];
    /// Lane `a` of `x` in lanes 0–3 and lane `b` in lanes 4–7 (each index taken modulo 8):
    /// two of eight rays' values side by side, for a test of both against four triangles.
    fn lane_pair(x: Self::F32x8, a: usize, b: usize) -> Self::F32x8;
    /// [`Isa::lane_pair`] of `f64` lanes.
    fn lane_pair_f64(x: Self::F64x8, a: usize, b: usize) -> Self::F64x8;
    /// Lane `lane` of `x` (taken modulo 8) in each of four lanes.
    fn lane_splat_f64(x: Self::F64x8, lane: usize) -> Self::F64x4;
    /// Asks for the cache line holding `address` to be loaded, without waiting for it (a hint
    /// that changes no result; nothing on the portable path).
    fn prefetch<T>(address: *const T);
    /// Each lane `x` (positive and normal) as `(m, e)`, `x = m·2^e` with `m` in [1, 2) and `e` an
    /// integer held as a float: read from the bits, so exact. Other lanes give unspecified
    /// values, the same on every path.
    fn split_exponent(x: Self::F32x8) -> (Self::F32x8, Self::F32x8);
    /// `2^n` for each lane `n`, an integer in [-126, 127] held as a float: made from the bits.
    fn power_of_two(n: Self::F32x8) -> Self::F32x8;
}

/// `N` floating-point lanes with the same operation applied to each.
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    type Elem: Copy + From<f32>;
    type Mask: MaskOps;
    const N: usize;
    fn splat(value: Self::Elem) -> Self;
    /// The first `N` values of `values`.
    fn load(values: &[Self::Elem]) -> Self;
    /// The `N` values, put into lanes where they are (in registers on x86) rather than read
    /// back from memory as [`Lanes::load`] does: values just written one by one would wait for
    /// those writes before the load could read them.
    ///
    /// # Panics
    /// If `M` is not `N`.
    fn from_array<const M: usize>(values: [Self::Elem; M]) -> Self;
    fn store(self, out: &mut [Self::Elem]);
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `self · factor + addend` for a product the caller knows to be exact (a power of two times
    /// a small integer, say): then a fused multiply-add, one instruction on x86, and a
    /// multiplication followed by an addition round once and alike, so every path has the same
    /// bits. With an inexact product the paths may differ in the last place.
    fn mul_add_exact(self, factor: Self, addend: Self) -> Self;
    /// `self > other ? self : other` per lane (x86's `max`): a NaN in either gives `other`.
    fn max(self, other: Self) -> Self;
    /// `self < other ? self : other` per lane (x86's `min`): a NaN in either gives `other`.
    fn min(self, other: Self) -> Self;
    /// The lanes folded with [`Lanes::min`] as a halving tree: lane `i` against lane
    /// `i + N/2`, the results' `i` against `i + N/4`, and so on. With the operands' order fixed
    /// the result is the same lane on every path, NaN or not; a few shuffles on x86 where a
    /// scalar fold takes a comparison and a select per lane.
    fn min_lane(self) -> Self::Elem;
    /// [`Lanes::min_lane`] with [`Lanes::max`].
    fn max_lane(self) -> Self::Elem;
    fn lt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    fn eq(self, other: Self) -> Self::Mask;
    /// Lanes that are NaN.
    fn is_nan(self) -> Self::Mask;
    /// The mask whose lane `i` is set when bit `i` of `bits` is (bits past the last lane are
    /// ignored): lanes chosen by number, as [`MaskOps::bits`] names them.
    fn mask(bits: u32) -> Self::Mask;
    /// `mask ? if_true : if_false` per lane.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Each lane's bit pattern, read as an integer, plus one where `increment` is set and minus
    /// one where `decrement` is set (never both): for a finite lane other than zero, the next
    /// float away from zero and the next towards it.
    fn adjust_bits(self, increment: Self::Mask, decrement: Self::Mask) -> Self;

    /// Each lane moved to the next float towards +∞ where `direction` is positive and towards
    /// −∞ where it is negative, lane by lane exactly `next_up` and `next_down` (an infinity
    /// already there and a NaN stay as they are); left alone where `direction` is zero or NaN.
    #[inline(always)]
    fn step_towards(self, direction: Self) -> Self {
        let zero = Self::splat(0.0.into());
        let (up, down) = (direction.gt(zero), direction.lt(zero));
        let (positive, negative, is_zero) = (self.gt(zero), self.lt(zero), self.eq(zero));
        let finite = self.abs().lt(Self::splat(f32::INFINITY.into()));
        // A zero that moves steps from the zero of its side: ±0's bits plus one are ±tiny's.
        let leaving_zero = is_zero.and(up.or(down));
        let start = Self::select(leaving_zero, Self::select(down, Self::splat((-0.0).into()), zero), self);
        let away = positive.and(up).or(negative.and(down)).and(finite).or(leaving_zero);
        let towards_zero = positive.and(down).or(negative.and(up));
        start.adjust_bits(away, towards_zero)
    }
}

/// A true/false flag per lane, the result of comparing [`Lanes`].
pub trait MaskOps: Copy {
    fn and(self, other: Self) -> Self;
    fn or(self, other: Self) -> Self;
    /// `self && !other`.
    fn and_not(self, other: Self) -> Self;
    /// Bit `i` set when lane `i` is true.
    fn bits(self) -> u32;
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Probe;

    impl Kernel for Probe {
        type Output = ([f32; 8], u32, [f32; 4], [f64; 4], u32);
        #[inline(always)]
        fn run<I: Isa>(self) -> Self::Output {
            let a = I::F32x8::load(&[1.0, -2.0, f32::NAN, 4.0, 0.0, -0.0, 7.0, f32::INFINITY]);
            let b = I::F32x8::splat(0.5);
            let mut max = [0.0; 8];
            a.max(b).store(&mut max);
            let bits = a.gt(b).or(a.is_nan()).bits();
            let x = I::F32x4::load(&[1.5, 2.0, 3.0, 1.0e-40]);
            let wide = I::widen(x) * I::widen(x);
            let mut narrow = [0.0; 4];
            I::narrow(wide).store(&mut narrow);
            let mut sums = [0.0; 4];
            I::F64x4::select(wide.le(I::F64x4::splat(3.0)), wide, -wide)
                .sqrt()
                .store(&mut sums);
            (
                max,
                bits,
                narrow,
                sums,
                x.lt(I::F32x4::splat(2.0)).and_not(x.eq(x.abs())).bits(),
            )
        }
    }

    /// Each lane type's `from_array` and `load` of the same values, stored back, as bits.
    struct FromArray;

    impl Kernel for FromArray {
        type Output = [Vec<u64>; 2];
        fn run<I: Isa>(self) -> Self::Output {
            let v = [
                1.5f32,
                -0.0,
                f32::NAN,
                f32::INFINITY,
                1.0e-40,
                -7.0,
                3.25,
                f32::MIN_POSITIVE,
            ];
            let w = v.map(f64::from);
            let (mut f4, mut f8, mut d4, mut d8) = ([0.0; 4], [0.0; 8], [0.0; 4], [0.0; 8]);
            let mut from_array = Vec::new();
            I::F32x4::from_array([v[0], v[1], v[2], v[3]]).store(&mut f4);
            I::F32x8::from_array(v).store(&mut f8);
            I::F64x4::from_array([w[4], w[5], w[6], w[7]]).store(&mut d4);
            I::F64x8::from_array(w).store(&mut d8);
            from_array.extend(f4.iter().chain(&f8).map(|x| x.to_bits() as u64));
            from_array.extend(d4.iter().chain(&d8).map(|x| x.to_bits()));
            let mut loaded = Vec::new();
            I::F32x4::load(&v).store(&mut f4);
            I::F32x8::load(&v).store(&mut f8);
            I::F64x4::load(&w[4..]).store(&mut d4);
            I::F64x8::load(&w).store(&mut d8);
            loaded.extend(f4.iter().chain(&f8).map(|x| x.to_bits() as u64));
            loaded.extend(d4.iter().chain(&d8).map(|x| x.to_bits()));
            [from_array, loaded]
        }
    }

    #[test]
    fn values_put_into_lanes_are_the_values_loaded_on_every_path() {
        for path in available() {
            let [from_array, loaded] = dispatch_on(path, FromArray).unwrap();
            assert_eq!(from_array, loaded, "{path:?}");
            assert_eq!(
                from_array[4 + 4],
                1.0e-40f32.to_bits() as u64,
                "{path:?}: lanes in order"
            );
        }
    }

    /// Each lane type's `mask` of every lane pattern (and of bits past the last lane), read
    /// back with `bits` and through `select`.
    struct MasksByNumber;

    impl Kernel for MasksByNumber {
        type Output = Vec<[u32; 6]>;
        fn run<I: Isa>(self) -> Self::Output {
            let pick = |selected: I::F32x8| {
                let mut lanes = [0.0; 8];
                selected.store(&mut lanes);
                lanes
                    .iter()
                    .enumerate()
                    .map(|(lane, &x)| ((x == 1.0) as u32) << lane)
                    .sum::<u32>()
            };
            (0..512u32)
                .map(|bits| {
                    let chosen = I::F32x8::select(I::F32x8::mask(bits), I::F32x8::splat(1.0), I::F32x8::splat(0.0));
                    [
                        I::F32x4::mask(bits).bits(),
                        I::F32x8::mask(bits).bits(),
                        I::F64x4::mask(bits).bits(),
                        I::F64x8::mask(bits).bits(),
                        pick(chosen),
                        bits,
                    ]
                })
                .collect()
        }
    }

    #[test]
    fn lanes_chosen_by_number_are_those_lanes_on_every_path() {
        for path in available() {
            for [f4, f8, d4, d8, selected, bits] in dispatch_on(path, MasksByNumber).unwrap() {
                assert_eq!([f4, d4], [bits & 0xf; 2], "{path:?}: four lanes of {bits:#b}");
                assert_eq!(
                    [f8, d8, selected],
                    [bits & 0xff; 3],
                    "{path:?}: eight lanes of {bits:#b}"
                );
            }
        }
    }

    #[test]
    fn every_available_path_computes_the_same_lanes() {
        let portable = Probe.run::<Portable>();
        assert_eq!(portable.0[2], 0.5, "NaN gives the second operand");
        assert_eq!(portable.1, 0b1100_1101);
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: each trampoline runs only where the processor supports it.
            let results = [
                x86::has_avx2().then(|| unsafe { x86::run_avx2(Probe) }),
                #[cfg(feature = "avx512")]
                x86::has_avx512().then(|| unsafe { x86::run_avx512(Probe) }),
            ];
            for result in results.into_iter().flatten() {
                assert_eq!(format!("{result:?}"), format!("{portable:?}"));
            }
        }
    }

    /// 48 distinct values: NaNs with distinct payloads, signed zeros, negative and fractional
    /// numbers.
    fn movement_input() -> [f32; 48] {
        std::array::from_fn(|i| match i % 5 {
            0 => f32::from_bits(0x7fc0_0000 | i as u32),
            1 => -(i as f32),
            2 if i % 2 == 0 => 0.0,
            2 => -0.0,
            _ => 1.0 + i as f32 / 64.0,
        })
    }

    /// `transpose_8x6` of 48 distinct values (NaNs with distinct payloads, signed zeros among
    /// them), and `lane_pair`, `lane_pair_f64` and `lane_splat_f64` of every lane or pair of
    /// lanes (and out-of-range indices), stored back.
    struct Movements;

    impl Kernel for Movements {
        type Output = (Vec<[u32; 8]>, Vec<[u32; 8]>, Vec<[u64; 8]>, Vec<[u64; 4]>);
        fn run<I: Isa>(self) -> Self::Output {
            let values = movement_input();
            let bits = |lanes: I::F32x8| {
                let mut out = [0.0; 8];
                lanes.store(&mut out);
                out.map(f32::to_bits)
            };
            let fields = I::transpose_8x6(&values).map(bits).to_vec();
            let source = I::F32x8::load(&values[8..16]);
            let pairs = (0..10)
                .flat_map(|a| (0..10).map(move |b| (a, b)))
                .map(|(a, b)| bits(I::lane_pair(source, a, b)))
                .collect();
            let wide = I::F64x8::load(&values[8..16].iter().map(|&v| f64::from(v)).collect::<Vec<_>>());
            let wide_pairs = (0..10)
                .flat_map(|a| (0..10).map(move |b| (a, b)))
                .map(|(a, b)| {
                    let mut out = [0.0; 8];
                    I::lane_pair_f64(wide, a, b).store(&mut out);
                    out.map(f64::to_bits)
                })
                .collect();
            let wide_splats = (0..10)
                .map(|lane| {
                    let mut out = [0.0; 4];
                    I::lane_splat_f64(wide, lane).store(&mut out);
                    out.map(f64::to_bits)
                })
                .collect();
            (fields, pairs, wide_pairs, wide_splats)
        }
    }

    #[test]
    fn lanes_are_moved_to_where_they_belong_on_every_path() {
        for path in available() {
            let (fields, pairs, wide_pairs, wide_splats) = dispatch_on(path, Movements).unwrap();
            let input = movement_input();
            for (field, lanes) in fields.iter().enumerate() {
                for (k, &lane) in lanes.iter().enumerate() {
                    assert_eq!(
                        lane,
                        input[6 * k + field].to_bits(),
                        "{path:?}: field {field} of ray {k}"
                    );
                }
            }
            for (n, lanes) in pairs.iter().enumerate() {
                let (a, b) = (n / 10, n % 10);
                let expected: [u32; 8] =
                    std::array::from_fn(|k| input[8 + if k < 4 { a % 8 } else { b % 8 }].to_bits());
                assert_eq!(*lanes, expected, "{path:?}: lane_pair({a}, {b})");
            }
            let wide = |lane: usize| f64::from(input[8 + lane % 8]).to_bits();
            for (n, lanes) in wide_pairs.iter().enumerate() {
                let (a, b) = (n / 10, n % 10);
                let expected: [u64; 8] = std::array::from_fn(|k| wide(if k < 4 { a } else { b }));
                assert_eq!(*lanes, expected, "{path:?}: lane_pair_f64({a}, {b})");
            }
            for (lane, lanes) in wide_splats.iter().enumerate() {
                assert_eq!(*lanes, [wide(lane); 4], "{path:?}: lane_splat_f64({lane})");
            }
        }
    }

    /// Lanes of eight values, shifted through every rotation of a set with NaNs, signed zeros
    /// and infinities in it, folded by each lane type.
    struct Folds;

    impl Kernel for Folds {
        type Output = Vec<u64>;
        #[inline(always)]
        fn run<I: Isa>(self) -> Vec<u64> {
            let values = [
                3.0,
                -0.0,
                f32::NAN,
                0.0,
                -7.5,
                f32::INFINITY,
                2.0,
                f32::NEG_INFINITY,
                1.0,
                -0.0,
                5.0,
            ];
            let mut folds = Vec::new();
            for start in 0..values.len() {
                let lanes: Vec<f32> = (0..8).map(|k| values[(start + k) % values.len()]).collect();
                let wide: Vec<f64> = lanes.iter().map(|&v| v as f64).collect();
                let (x8, x4) = (I::F32x8::load(&lanes), I::F32x4::load(&lanes));
                let (d8, d4) = (I::F64x8::load(&wide), I::F64x4::load(&wide));
                for f in [x8.min_lane(), x8.max_lane(), x4.min_lane(), x4.max_lane()] {
                    folds.push(f.to_bits() as u64);
                }
                for d in [d8.min_lane(), d8.max_lane(), d4.min_lane(), d4.max_lane()] {
                    folds.push(d.to_bits());
                }
            }
            folds
        }
    }

    #[test]
    fn lanes_fold_to_the_same_bits_on_every_path() {
        let portable = Folds.run::<Portable>();
        // Lanes 3.0, −0.0, NaN, 0.0, −7.5, ∞, 2.0, −∞: the NaN lane meets 2.0 first and gives
        // it, so the smallest lane is −∞ and the largest ∞.
        assert_eq!(f32::from_bits(portable[0] as u32), f32::NEG_INFINITY);
        assert_eq!(f32::from_bits(portable[1] as u32), f32::INFINITY);
        // Of 3.0, −0.0, NaN, 0.0: 3.0 against the NaN gives the NaN, −0.0 against 0.0 the second
        // operand, and the NaN against 0.0 gives 0.0, as the smallest lane and the largest.
        assert_eq!(portable[2], 0.0f32.to_bits() as u64);
        assert_eq!(portable[3], 0.0f32.to_bits() as u64);
        for path in available() {
            assert_eq!(
                dispatch_on(path, Folds).expect("an available path"),
                portable,
                "{path:?}"
            );
        }
    }

    /// Every pair of a value and a direction that `step_towards` treats apart, as `f32`.
    fn stepping_cases() -> Vec<(f32, f32)> {
        let tiny = f32::from_bits(1);
        let values = [
            0.0,
            -0.0,
            tiny,
            -tiny,
            1.0,
            -1.0,
            0.75,
            -3.5e7,
            1.0e-40,
            f32::MIN_POSITIVE,
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let directions = [1.0, -1.0, 0.0, -0.0, 1.0e-30, f32::NEG_INFINITY, f32::NAN];
        values
            .iter()
            .flat_map(|&v| directions.iter().map(move |&d| (v, d)))
            .collect()
    }

    /// What `next_up` and `next_down` make of `value` for `direction`, as bits.
    fn stepped_alone<T: Into<f64> + Copy>(value: T, direction: T, up: fn(T) -> T, down: fn(T) -> T) -> T {
        let d: f64 = direction.into();
        if d > 0.0 {
            up(value)
        } else if d < 0.0 {
            down(value)
        } else {
            value
        }
    }

    struct Stepping(Vec<(f32, f32)>);

    impl Kernel for Stepping {
        type Output = (Vec<u32>, Vec<u32>, Vec<u64>, Vec<u64>);
        #[inline(always)]
        fn run<I: Isa>(self) -> Self::Output {
            fn each<L: Lanes>(cases: &[(f32, f32)], width: usize) -> Vec<L::Elem>
            where
                L::Elem: Default,
            {
                let mut out = Vec::new();
                for chunk in cases.chunks(width) {
                    let (mut values, mut directions) =
                        (vec![L::Elem::default(); width], vec![L::Elem::default(); width]);
                    for (k, &(v, d)) in chunk.iter().enumerate() {
                        (values[k], directions[k]) = (v.into(), d.into());
                    }
                    let mut stepped = vec![L::Elem::default(); width];
                    L::load(&values).step_towards(L::load(&directions)).store(&mut stepped);
                    out.extend_from_slice(&stepped[..chunk.len()]);
                }
                out
            }
            let cases = &self.0;
            (
                each::<I::F32x8>(cases, 8).into_iter().map(f32::to_bits).collect(),
                each::<I::F32x4>(cases, 4).into_iter().map(f32::to_bits).collect(),
                each::<I::F64x8>(cases, 8).into_iter().map(f64::to_bits).collect(),
                each::<I::F64x4>(cases, 4).into_iter().map(f64::to_bits).collect(),
            )
        }
    }

    #[test]
    fn stepping_is_next_up_and_next_down_lane_by_lane_on_every_path() {
        let cases = stepping_cases();
        let single: Vec<u32> = cases
            .iter()
            .map(|&(v, d)| stepped_alone(v, d, f32::next_up, f32::next_down).to_bits())
            .collect();
        let double: Vec<u64> = cases
            .iter()
            .map(|&(v, d)| stepped_alone(f64::from(v), f64::from(d), f64::next_up, f64::next_down).to_bits())
            .collect();
        let expected = (single.clone(), single, double.clone(), double);
        let mut results = vec![Stepping(cases.clone()).run::<Portable>()];
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: each trampoline runs only where the processor supports it.
            results.extend(x86::has_avx2().then(|| unsafe { x86::run_avx2(Stepping(cases.clone())) }));
            #[cfg(feature = "avx512")]
            results.extend(x86::has_avx512().then(|| unsafe { x86::run_avx512(Stepping(cases.clone())) }));
        }
        for result in results {
            assert_eq!(result, expected);
        }
    }

    #[test]
    fn paths_are_named_and_the_portable_one_always_runs() {
        assert_eq!(SimdPath::from_name(" AVX2 "), Some(SimdPath::Avx2));
        assert!(available().contains(&SimdPath::Portable));
        assert!(available().contains(&detected()));
        assert!(available().contains(&preferred()));
        assert!(
            preferred() == SimdPath::Avx2 || preferred() == detected(),
            "AVX2 where the processor has it"
        );
    }
}
