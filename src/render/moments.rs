//! What a pixel keeps of its samples: the mean colour always, and the variance of that mean
//! when the render takes several samples per pixel, so that a comparison can tell sampling noise
//! from a change (`crate::compare`'s statistical verdict).
//!
//! The renderer picks the kind once per render ([`MeanOnly`] or [`WithVariance`]), so a
//! one-sample render never squares a sample. The mean is the same sum divided by the count in
//! both kinds: adding the variance changes no colour bit.
//!
//! **The variance of the mean.** A (sub)pixel's `n` stratified samples `x_k` give the mean
//! `m = Σx_k / n` and the sample variance `s² = Σ(x_k − m)² / (n − 1)`; the variance of `m` is
//! estimated as `s² / n`. With one sample per stratum that estimate is conservative: its
//! expectation is `Var(m)` plus `Σ(μ_k − μ)² / (n(n − 1))`, the spread of the strata's own means,
//! which stratification removes from `m` but not from `s²`.
//!
//! **The Gaussian filter.** An output pixel is `Σ w_ij m_ij` over its 3×3 block of sub-pixels
//! with weights `w = [1 2 1]⊗[1 2 1]/16`. Every sample position is a hash of (seed, sub-pixel,
//! index), so the sub-pixels' means are independent and the variance of the weighted sum is
//! `Σ w_ij² Var(m_ij)` (`Σ w² = 9/64`: the filter divides the noise variance of a flat region by
//! about 7). The sums run in a fixed order, so the variance is as bit-identical across thread
//! counts and SIMD paths as the colour.

use super::real::{Color, Real, Vec3, to_f32};

/// The moments a pixel carries from its samples to the film.
pub trait Moments: Sized {
    /// One band of rows' variances for the film (nothing for [`MeanOnly`]).
    type Band: Send;

    /// The moments of a (sub)pixel's samples, summed in their order (a pixel always has one).
    fn of_samples(samples: &[Color]) -> Self;
    /// One sample through the pixel centre: no spread to speak of.
    fn single(color: Color) -> Self;
    fn zero() -> Self;
    /// `self += weight · other` for the mean, `weight² · other` for the variance.
    fn add_weighted(&mut self, other: &Self, weight: Real);
    fn mean(&self) -> Color;

    fn band(pixels: usize) -> Self::Band;
    fn store(band: &mut Self::Band, offset: usize, pixel: &Self);
    /// The film's variance plane from its bands, top to bottom.
    fn assemble(bands: Vec<Self::Band>) -> Option<Vec<[f32; 3]>>;
}

/// The mean colour only: one sample per pixel (or per sub-pixel of the filter).
pub struct MeanOnly(Color);

impl Moments for MeanOnly {
    type Band = ();

    #[inline]
    fn of_samples(samples: &[Color]) -> Self {
        let mut sum = Color::ZERO;
        for &sample in samples {
            sum += sample;
        }
        MeanOnly(sum / samples.len() as Real)
    }
    fn single(color: Color) -> Self {
        MeanOnly(color)
    }
    fn zero() -> Self {
        MeanOnly(Color::ZERO)
    }
    #[inline]
    fn add_weighted(&mut self, other: &Self, weight: Real) {
        self.0 += other.0 * weight;
    }
    fn mean(&self) -> Color {
        self.0
    }
    fn band(_: usize) {}
    fn store(_: &mut (), _: usize, _: &Self) {}
    fn assemble(_: Vec<()>) -> Option<Vec<[f32; 3]>> {
        None
    }
}

/// The mean colour and the variance of that mean, per channel.
pub struct WithVariance {
    mean: Color,
    variance: Color,
}

impl Moments for WithVariance {
    type Band = Vec<[f32; 3]>;

    /// The samples' sum (exactly [`MeanOnly`]'s), and their sums shifted by the first sample,
    /// which keeps `Σd² − (Σd)²/n` free of cancellation in `f32` when the samples are close
    /// together. The first sample's own shift is zero (or NaN, as any sum with a NaN is).
    #[inline]
    fn of_samples(samples: &[Color]) -> Self {
        let shift = samples.first().copied().unwrap_or(Color::ZERO);
        let (mut sum, mut shifted, mut squares) = (Color::ZERO, Color::ZERO, Color::ZERO);
        for &sample in samples {
            let d = sample - shift;
            sum += sample;
            shifted += d;
            squares += d * d;
        }
        let n = samples.len() as Real;
        let variance = if samples.len() > 1 {
            let spread = squares - shifted * shifted / n;
            (spread / ((n - 1.0) * n)).max(Color::ZERO)
        } else {
            Color::ZERO
        };
        WithVariance { mean: sum / n, variance }
    }
    fn single(color: Color) -> Self {
        WithVariance {
            mean: color,
            variance: Color::ZERO,
        }
    }
    fn zero() -> Self {
        WithVariance::single(Color::ZERO)
    }
    #[inline]
    fn add_weighted(&mut self, other: &Self, weight: Real) {
        self.mean += other.mean * weight;
        self.variance += other.variance * (weight * weight);
    }
    fn mean(&self) -> Color {
        self.mean
    }
    fn band(pixels: usize) -> Vec<[f32; 3]> {
        vec![[0.0; 3]; pixels]
    }
    fn store(band: &mut Vec<[f32; 3]>, offset: usize, pixel: &Self) {
        band[offset] = film_vector(pixel.variance);
    }
    fn assemble(bands: Vec<Vec<[f32; 3]>>) -> Option<Vec<[f32; 3]>> {
        Some(bands.concat())
    }
}

/// No NaN or infinity may reach a file: a value that overflowed `f32` is clamped to the
/// largest finite one and a NaN (which valid input cannot produce) becomes zero.
pub(super) fn film_vector(v: Vec3) -> [f32; 3] {
    v.to_array().map(|c| {
        let c = to_f32(c);
        if c.is_nan() { 0.0 } else { c.clamp(-f32::MAX, f32::MAX) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn moments(samples: &[Real]) -> WithVariance {
        WithVariance::of_samples(&samples.iter().map(|&s| Color::splat(s)).collect::<Vec<_>>())
    }

    #[test]
    fn variance_of_the_mean_is_the_sample_variance_over_n() {
        // Mean 2.5, sample variance 5/3, variance of the mean 5/12.
        let m = moments(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m.mean.x, 2.5);
        assert!((m.variance.x - 5.0 / 12.0).abs() < 1e-6, "{}", m.variance.x);
    }

    #[test]
    fn equal_samples_have_no_variance_and_the_mean_is_the_plain_sum() {
        let m = moments(&[0.3; 16]);
        assert_eq!(m.variance, Color::ZERO);
        assert_eq!(MeanOnly::of_samples(&[Color::splat(0.3); 16]).0, m.mean);
    }

    #[test]
    fn weighted_sums_add_variance_with_squared_weights() {
        let mut total = WithVariance::zero();
        for _ in 0..4 {
            total.add_weighted(&moments(&[0.0, 1.0]), 0.25);
        }
        // Each part: sample variance 1/2, variance of the mean 1/4; four of them at weight 1/4:
        // 4 · (1/4) / 16.
        assert_eq!(total.mean.x, 0.5);
        assert!((total.variance.x - 0.0625).abs() < 1e-7, "{}", total.variance.x);
    }
}
