//! The statistical verdict: when both images carry the variance of each pixel's mean colour (EXRs
//! of renders with several samples per pixel), a colour difference is judged against the noise
//! the two renders could have made, not against a fixed threshold.
//!
//! **The test.** Each colour value (pixel × channel) is a two-sample Z test on the difference of
//! the means: `z = (actual − expected) / σ` with `σ² = var_expected + var_actual`, the variances
//! of the two means as the renders estimated them (see `render::moments`). The test is two-sided.
//!
//! **Multiple comparisons: Šidák.** A 128×128 picture is 49,152 tests; at a per-test 1% the suite
//! would fail every run. The family of tests is held at [`FAMILY_ALPHA`] = 1% (the chance that a
//! correct render fails) with Šidák's per-test level `1 − (1 − α)^(1/m)`. Šidák rather than
//! Benjamini–Hochberg because the question is "is anything different at all?", which is the
//! family-wise error BH does not control (it controls the share of false discoveries among the
//! discoveries, useful when many pixels are expected to differ); because pixels are independent
//! given the stateless sampler, where Šidák is exact (the three channels of one pixel are
//! positively correlated, where it stays valid and slightly conservative); and because its fixed
//! per-test threshold makes the power of the test a closed formula, which BH's data-dependent
//! threshold does not.
//!
//! **Values with no variance in either image** (background, a flat surface the pixel covers
//! whole, every sample alike) are not tested: they are judged by the tolerance's `pixel` rule, as
//! in a deterministic render, and count towards `fail_fraction`. A zero estimate from few samples
//! is not proof of no noise: an edge that the golden's samples all missed may be hit by another
//! seed. But then the image whose samples hit it has the variance, and it covers the difference:
//! one stray sample of `n` gives `z = 1`, `k` of them `√(k(n − 1)/(n − k))`, far below the Šidák
//! threshold until the coverage itself differs. Both estimates are zero only when both images'
//! samples each saw a single colour, and then a difference is no noise the renders could make.
//!
//! **The floor.** `σ` is never taken below `2⁻¹⁶ · max(1, |expected|, |actual|)` (1.5·10⁻⁵ for
//! colours up to 1, about 260 `f32` ulps): a smooth surface's variance can be as small as its
//! rounding, and a golden blessed by another build may differ from this one in the last bits.
//! The floor keeps such differences from counting as evidence while any visible change (an 8-bit
//! code is 0.004) stays hundreds of σ away.
//!
//! **Power.** Every verdict says what it could have seen: the smallest shift `δ`, added to every
//! tested colour value of the whole picture or of an 8×8 area, that the test detects with 80%
//! probability, `1 − Π_i P(|N(δ/σ_i, 1)| ≤ z*) ≥ 0.8`, with the deterministic values' rule
//! included (a shift beyond `pixel` on more pixels than `fail_fraction` allows fails for sure).

use serde::Serialize;

use super::image::{COLOR_CHANNELS, Encoding, Image, Plane};
use super::metrics::PixelError;
use super::normal;
use super::power::power;
pub use super::power::{Power, Sigmas};
use super::tolerance::Tolerance;
use crate::film::{Film, Tonemap, tone_curve};

/// The chance that a render differing from its golden only by sampling noise fails.
pub const FAMILY_ALPHA: f64 = 0.01;
/// The smallest σ, relative to the larger of 1 and the two values (see the module documentation).
pub const RELATIVE_FLOOR: f64 = 1.0 / 65536.0;

/// How far each colour value of a student's 8-bit picture may stray from the golden picture
/// because of sampling noise, in 8-bit codes: what a rubric's `statistical = true` adds to its
/// `threshold` (see docs/grading.md, "The rubric").
///
/// A student's jittered picture has no variance channel, so its noise is estimated from the
/// golden's: the student's mean is assumed as noisy as the golden's (the same sample count),
/// which makes the difference's variance `2·var` in linear values, where `var` is the largest
/// variance of the golden's 3×3 neighbourhood of the pixel. The neighbourhood is the floor a
/// zero estimate needs here: where the golden's samples all missed an edge that clips the pixel,
/// the golden has no variance, but the student's samples may hit it; the edge runs on through a
/// neighbour, where the golden's samples did see it. (In an EXR comparison the image whose
/// samples hit the edge carries that variance itself.) It is converted to codes
/// through the tone map around the golden's mean, `σ_code = (T(m + σ) − T(m − σ)) / 2`, which
/// follows the sRGB curve's slope and is 0 where the colour is clamped; the allowance is
/// [`critical_z`] of the values with variance (Šidák at [`FAMILY_ALPHA`]) times `σ_code`.
/// `None` when the film has no variance.
pub fn png_allowance(film: &Film, tonemap: Tonemap) -> Option<Vec<[f32; 3]>> {
    let variance = film.variance.as_ref()?;
    let (w, h) = (film.width as usize, film.height as usize);
    let neighbourhood = |i: usize| -> [f32; 3] {
        let (x, y) = (i % w, i / w);
        let mut largest = [0.0_f32; 3];
        for ny in y.saturating_sub(1)..(y + 2).min(h) {
            for nx in x.saturating_sub(1)..(x + 2).min(w) {
                let v = variance[ny * w + nx];
                largest = std::array::from_fn(|c| if v[c] > largest[c] { v[c] } else { largest[c] });
            }
        }
        largest
    };
    let widened: Vec<[f32; 3]> = (0..variance.len()).map(neighbourhood).collect();
    let noisy = widened.iter().flatten().filter(|&&v| v > 0.0).count();
    let z = critical_z(FAMILY_ALPHA, noisy);
    Some(
        film.color
            .iter()
            .zip(&widened)
            .map(|(mean, var)| {
                std::array::from_fn(|c| {
                    let sigma = (2.0 * f64::from(var[c])).sqrt() as f32;
                    let spread = tone_curve(mean[c] + sigma, tonemap) - tone_curve(mean[c] - sigma, tonemap);
                    (z * f64::from(spread / 2.0)) as f32
                })
            })
            .collect(),
    )
}

/// What the statistical test found and what it could have found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Noise {
    /// Family-wise: the chance that noise alone fails the comparison.
    pub alpha: f64,
    pub correction: &'static str,
    /// Colour values tested (pixels × channels with variance in either image).
    pub tests: usize,
    /// Colour values with no variance in either image, judged by the `pixel` rule instead.
    pub deterministic_values: usize,
    /// The |z| a value must exceed to count as a difference.
    pub z_critical: f64,
    /// Values over `z_critical`.
    pub significant: usize,
    /// The value with the largest |z|; `None` when nothing was tested.
    pub strongest: Option<Evidence>,
    pub power: Power,
}

/// One tested colour value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Evidence {
    #[serde(flatten)]
    pub at: PixelError,
    pub sigma: f64,
    pub z: f64,
}

/// The σ of every colour value, when both images are linear and carry variance.
pub fn sigmas(expected: &Image, actual: &Image) -> Option<Sigmas> {
    if expected.encoding != Encoding::Linear || actual.encoding != Encoding::Linear {
        return None;
    }
    let (ve, va) = (expected.variance.as_ref()?, actual.variance.as_ref()?);
    let (e, a) = (colour_planes(expected)?, colour_planes(actual)?);
    if ve.len() != expected.pixels() || va.len() != actual.pixels() || expected.pixels() != actual.pixels() {
        return None;
    }
    Some(
        (0..expected.pixels())
            .map(|i| std::array::from_fn(|c| sigma(e[c][i], a[c][i], ve[i][c], va[i][c])))
            .collect(),
    )
}

/// The σ of one value's difference, or `None` when neither image has variance there. A variance
/// that is not a finite non-negative number (from a damaged or foreign file) counts as none, so
/// the value is held to the strict `pixel` rule rather than excused.
pub fn sigma(expected: f32, actual: f32, var_expected: f32, var_actual: f32) -> Option<f64> {
    let clean = |v: f32| if v.is_finite() && v > 0.0 { f64::from(v) } else { 0.0 };
    let variance = clean(var_expected) + clean(var_actual);
    if variance == 0.0 {
        return None;
    }
    let scale = 1f64.max(f64::from(expected).abs()).max(f64::from(actual).abs());
    let floor = if scale.is_finite() { RELATIVE_FLOOR * scale } else { 0.0 };
    Some(variance.max(floor * floor).sqrt())
}

/// The R, G and B planes of an image.
fn colour_planes(image: &Image) -> Option<[&Plane; 3]> {
    let plane = |name: &str| image.channels.iter().find(|c| c.name == name).map(|c| &c.values);
    Some([plane("R")?, plane("G")?, plane("B")?])
}

/// The z of every tested value (`None` for the deterministic ones and non-finite colours).
pub fn z_scores(expected: &Image, actual: &Image, sigmas: &Sigmas) -> Vec<[Option<f64>; 3]> {
    let (Some(e), Some(a)) = (colour_planes(expected), colour_planes(actual)) else {
        return vec![[None; 3]; sigmas.len()];
    };
    sigmas
        .iter()
        .enumerate()
        .map(|(i, s)| {
            std::array::from_fn(|c| {
                let (ev, av) = (e[c][i], a[c][i]);
                let sigma = s[c].filter(|_| ev.is_finite() && av.is_finite())?;
                Some((f64::from(av) - f64::from(ev)) / sigma)
            })
        })
        .collect()
}

/// The |z| a value must exceed for `tests` tests held together at `alpha`, two-sided.
pub fn critical_z(alpha: f64, tests: usize) -> f64 {
    let per_test = -(((-alpha).ln_1p()) / tests.max(1) as f64).exp_m1();
    normal::upper_quantile(per_test / 2.0)
}

/// Runs the test on images whose `sigmas` were computed by [`sigmas`].
pub fn test(expected: &Image, actual: &Image, sigmas: &Sigmas, tolerance: &Tolerance) -> Noise {
    let tests = sigmas.iter().flatten().filter(|s| s.is_some()).count();
    let deterministic_values = sigmas.len() * 3 - tests;
    let z_critical = critical_z(FAMILY_ALPHA, tests);
    let width = expected.width as usize;
    let mut significant = 0;
    let mut strongest: Option<Evidence> = None;
    for (i, zs) in z_scores(expected, actual, sigmas).iter().enumerate() {
        for (c, z) in zs.iter().enumerate() {
            let Some(z) = *z else { continue };
            significant += usize::from(z.abs() > z_critical);
            if strongest.is_none_or(|s| z.abs() > s.z.abs()) {
                let value = |image: &Image| {
                    let plane = image.channels.iter().find(|ch| ch.name == COLOR_CHANNELS[c]);
                    plane.map_or(f32::NAN, |ch| ch.values[i])
                };
                strongest = Some(Evidence {
                    at: PixelError {
                        x: (i % width) as u32,
                        y: (i / width) as u32,
                        channel: COLOR_CHANNELS[c],
                        expected: value(expected),
                        actual: value(actual),
                    },
                    sigma: sigmas[i][c].unwrap_or(0.0),
                    z,
                });
            }
        }
    }
    Noise {
        alpha: FAMILY_ALPHA,
        correction: "sidak",
        tests,
        deterministic_values,
        z_critical,
        significant,
        strongest,
        power: power(expected.width, expected.height, sigmas, z_critical, tolerance),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidak_threshold_grows_with_the_number_of_tests() {
        assert!((critical_z(0.05, 1) - 1.959_963_984_540_054).abs() < 1e-9);
        let many = critical_z(0.01, 49_152);
        assert!((5.0..5.5).contains(&many), "{many}");
    }

    #[test]
    fn no_variance_on_either_side_is_not_tested_and_the_floor_holds() {
        assert_eq!(sigma(0.5, 0.6, 0.0, 0.0), None);
        assert_eq!(sigma(0.5, 0.6, f32::NAN, -1.0), None);
        assert_eq!(sigma(0.5, 0.5, 1e-30, 0.0), Some(RELATIVE_FLOOR));
        let expected = (f64::from(0.01_f32) + f64::from(0.03_f32)).sqrt();
        assert_eq!(sigma(0.5, 0.5, 0.01, 0.03), Some(expected));
    }
}
