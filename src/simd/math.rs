//! Powers of eight `f32` lanes at once, for code that raises whole pictures' worth of values to
//! powers (FLIP's colour pipeline).
//!
//! `x^y` is `2^(y·log2 x)` computed in `f64` lanes and rounded once to `f32`: the logarithm by its
//! series in `(m − 1)/(m + 1)` around the significand, the exponential by its Taylor polynomial
//! on [−½, ½], each good to about 2⁻⁴⁰. So the result is the correctly rounded power except when
//! the exact power lies within about 2⁻⁴⁰ of a halfway point between two `f32`s, as with the C
//! library's `powf` (which also works in `f64`). It has to be that close: FLIP subtracts cube
//! roots of nearly equal colours, and a cube root a few units in the last place off (an `f32`
//! polynomial's) moved a class's FLIP means by up to 4·10⁻⁴ of themselves. Like every lane
//! operation, these compute the same bits on every path.

use super::{Isa, Lanes};

type V<I> = <I as Isa>::F32x8;
type D<I> = <I as Isa>::F64x4;

/// `x^y` for lanes `x ≥ 0` (a subnormal `x` counts as zero) and finite `y`: `0^y` is 0 for
/// `y > 0`, 1 for `y = 0` and infinity for `y < 0`, as `powf` has it. A power below the smallest
/// normal `f32` is 0, and one beyond the largest `f32` infinity.
#[inline(always)]
pub fn pow<I: Isa>(x: V<I>, y: V<I>) -> V<I> {
    let (zero, one) = (V::<I>::splat(0.0), V::<I>::splat(1.0));
    let tiny = x.lt(V::<I>::splat(f32::MIN_POSITIVE));
    let (significand, exponent) = I::split_exponent(V::<I>::select(tiny, one, x));
    // The significand into [√½, √2), so that the series' variable stays within ±0.172 (exact).
    let high = significand.gt(V::<I>::splat(std::f32::consts::SQRT_2));
    let m = V::<I>::select(high, significand * V::<I>::splat(0.5), significand);
    let e = V::<I>::select(high, exponent + one, exponent);
    let ((m0, m1), (e0, e1), (y0, y1)) = (I::split(m), I::split(e), I::split(y));
    let t0 = log2_parts::<I>(I::widen(m0), I::widen(e0)) * I::widen(y0);
    let t1 = log2_parts::<I>(I::widen(m1), I::widen(e1)) * I::widen(y1);
    // Clamped before rounding so that every lane converts the same way on every path.
    let (low, top) = (D::<I>::splat(-126.0), D::<I>::splat(127.0));
    let (c0, c1) = (t0.max(low).min(top), t1.max(low).min(top));
    let (n0, n1) = (round::<I>(c0), round::<I>(c1));
    let scale = I::power_of_two(I::join(I::narrow(n0), I::narrow(n1)));
    let (s0, s1) = I::split(scale);
    let power0 = I::narrow(exp2_fraction::<I>(c0 - n0) * I::widen(s0));
    let power1 = I::narrow(exp2_fraction::<I>(c1 - n1) * I::widen(s1));
    let power = I::join(power0, power1);
    let t = I::join(I::narrow(t0), I::narrow(t1));
    let power = V::<I>::select(t.lt(V::<I>::splat(-126.0)), zero, power);
    let power = V::<I>::select(t.gt(V::<I>::splat(127.0)), V::<I>::splat(f32::INFINITY), power);
    let of_zero = V::<I>::select(
        y.gt(zero),
        zero,
        V::<I>::select(y.eq(zero), one, V::<I>::splat(f32::INFINITY)),
    );
    V::<I>::select(tiny, of_zero, power)
}

/// `e + log2(m)` for `m` in [√½, √2]: `ln m = 2s·(1 + s²/3 + s⁴/5 + …)` with `s = (m − 1)/(m + 1)`,
/// to the s¹² term (the next is below 2⁻⁴⁰ of the sum).
#[inline(always)]
fn log2_parts<I: Isa>(m: D<I>, e: D<I>) -> D<I> {
    let one = D::<I>::splat(1.0);
    let s = (m - one) / (m + one);
    let s2 = s * s;
    let mut series = D::<I>::splat(1.0 / 13.0);
    for k in [11.0, 9.0, 7.0, 5.0, 3.0] {
        series = series * s2 + D::<I>::splat(1.0 / k);
    }
    let series = series * s2 + one;
    e + s * series * D::<I>::splat(2.0 * std::f64::consts::LOG2_E)
}

/// Each lane (|t| < 2⁵¹) rounded to the nearest integer, by adding and taking away 1.5·2⁵²: exact.
#[inline(always)]
fn round<I: Isa>(t: D<I>) -> D<I> {
    let shift = D::<I>::splat(6_755_399_441_055_744.0);
    (t + shift) - shift
}

/// `2^f` for `f` in [−½, ½]: `Σ (f ln 2)^k / k!` to k = 10 (the rest is below 2⁻⁴²).
#[inline(always)]
fn exp2_fraction<I: Isa>(f: D<I>) -> D<I> {
    const C: [f64; 11] = [
        1.0,
        std::f64::consts::LN_2,
        0.240_226_506_959_100_7,
        0.055_504_108_664_821_576,
        0.009_618_129_107_628_477,
        0.001_333_355_814_642_844_1,
        0.000_154_035_303_933_816_06,
        1.525_273_380_405_983_8e-5,
        1.321_548_679_014_430_5e-6,
        1.017_808_600_923_969_6e-7,
        7.054_911_620_801_121e-9,
    ];
    let mut power = D::<I>::splat(C[10]);
    for &c in C[..10].iter().rev() {
        power = power * f + D::<I>::splat(c);
    }
    power
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{Kernel, SimdPath, available, dispatch_on};

    struct Powers<'a>(&'a [f32], &'a [f32]);
    impl Kernel for Powers<'_> {
        type Output = Vec<f32>;
        #[inline(always)]
        fn run<I: Isa>(self) -> Vec<f32> {
            let mut out = vec![0.0; self.0.len()];
            for ((x, y), out) in self
                .0
                .chunks_exact(8)
                .zip(self.1.chunks_exact(8))
                .zip(out.chunks_exact_mut(8))
            {
                pow::<I>(V::<I>::load(x), V::<I>::load(y)).store(out);
            }
            out
        }
    }

    /// Bases across the range FLIP uses and beyond, against exponents it uses and others.
    fn cases() -> (Vec<f32>, Vec<f32>) {
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        let exponents = [1.0 / 3.0, 0.7, 0.5, 0.013, 1.0, 2.4, -0.5, 0.0];
        let mut x = 1.0e-30f32;
        while x < 1.0e6 {
            for &y in &exponents {
                xs.push(x);
                ys.push(y);
            }
            x *= 1.37;
        }
        for &(x, y) in &[
            (0.0, 0.7),
            (0.0, 0.0),
            (0.0, -1.0),
            (1.0e-40, 0.5),
            (1.0, 0.3),
            (4.0, 0.5),
        ] {
            xs.push(x);
            ys.push(y);
        }
        while xs.len() % 8 != 0 {
            xs.push(2.0);
            ys.push(0.5);
        }
        (xs, ys)
    }

    #[test]
    fn powers_are_correctly_rounded() {
        let (xs, ys) = cases();
        let got = dispatch_on(SimdPath::Portable, Powers(&xs, &ys)).expect("portable");
        for ((&x, &y), &got) in xs.iter().zip(&ys).zip(&got) {
            let exact = f64::from(x).powf(f64::from(y));
            if x < f32::MIN_POSITIVE {
                assert_eq!(got, 0.0f32.powf(y), "0^{y}");
            } else if exact < f64::from(f32::MIN_POSITIVE) {
                assert!(got == 0.0 || f64::from(got) < 1e-37, "{x}^{y} = {got}");
            } else {
                // Correctly rounded: within half a unit in the last place (and a hair for the
                // rare power that lies almost halfway).
                let error = (f64::from(got) - exact).abs() / exact;
                assert!(
                    error <= 2f64.powi(-24) * 1.000_01,
                    "{x}^{y}: {got} against {exact} (relative error {error:e})"
                );
            }
        }
    }

    #[test]
    fn cube_roots_round_as_the_exact_ones_do() {
        // FLIP's cube roots: 100,000 values across (0.008, 1.1), each against the exact root
        // rounded to `f32`.
        let xs: Vec<f32> = (0..100_000).map(|i| 0.008 + 1.092 * (i as f32 / 100_000.0)).collect();
        let ys = vec![1.0f32 / 3.0; xs.len()];
        let got = dispatch_on(SimdPath::Portable, Powers(&xs, &ys)).expect("portable");
        let differing = xs
            .iter()
            .zip(&got)
            .filter(|&(&x, &got)| got != f64::from(x).powf(f64::from(1.0f32 / 3.0)) as f32)
            .count();
        assert_eq!(differing, 0);
    }

    #[test]
    fn every_path_computes_the_same_powers() {
        let (xs, ys) = cases();
        let portable = dispatch_on(SimdPath::Portable, Powers(&xs, &ys)).expect("portable");
        for path in available() {
            let got = dispatch_on(path, Powers(&xs, &ys)).expect("available");
            let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&portable), "{}", path.name());
        }
    }
}
