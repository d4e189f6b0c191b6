//! The standard normal distribution: what the statistical verdict's z values are read against.
//! `erfc` comes from `libm` (the standard library has none); the quantile is Acklam's rational
//! approximation (relative error 1.2·10⁻⁹) polished by one Halley step on `erfc`, which takes it to
//! the precision of `erfc` itself, far into the tails a Šidák correction reaches.

/// `P(Z ≤ x)`.
pub fn cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// `P(Z > x)`, accurate where `1 − cdf(x)` would round to 0.
pub fn upper_tail(x: f64) -> f64 {
    0.5 * libm::erfc(x / std::f64::consts::SQRT_2)
}

/// The `x` with `P(Z > x) = tail`, for `tail` in (0, 1).
pub fn upper_quantile(tail: f64) -> f64 {
    -quantile_of_lower(tail)
}

/// The `x` with `P(Z ≤ x) = p`, computed from the side where `p` is small for accuracy.
fn quantile_of_lower(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    if p > 0.5 {
        return -quantile_of_lower(1.0 - p);
    }
    let x = if p < 0.024_25 {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    // One Halley step: e is the error in probability, u the step in x.
    let e = cdf(x) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (x * x / 2.0).exp();
    x - u / (1.0 + x * u / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        assert!((cdf(0.0) - 0.5).abs() < 1e-15);
        assert!((cdf(1.959_963_984_540_054) - 0.975).abs() < 1e-12);
        assert!((upper_quantile(0.025) - 1.959_963_984_540_054).abs() < 1e-9);
        assert!((upper_quantile(0.5)).abs() < 1e-12);
        // Far in the tail: P(Z > 6) = 9.8659e-10.
        assert!((upper_tail(6.0) / 9.865_876_450_377e-10 - 1.0).abs() < 1e-9);
        assert!((upper_quantile(9.865_876_450_377e-10) - 6.0).abs() < 1e-8);
    }

    #[test]
    fn quantile_inverts_the_tail_everywhere() {
        for k in 1..300 {
            let tail = 10f64.powf(-(k as f64) / 20.0);
            if tail >= 1.0 {
                continue;
            }
            let x = upper_quantile(tail);
            assert!((upper_tail(x) / tail - 1.0).abs() < 1e-9, "tail {tail}: x {x}");
        }
    }
}
