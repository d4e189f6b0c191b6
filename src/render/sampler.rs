//! Stratified jitter from a stateless hash, so that every sample is a pure function of
//! (seed, pixel, sample index): tiles can render in any order on any number of threads and the
//! picture is bit-identical.

use super::real::{Real, Vec2};
use crate::options::Seeding;

#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    /// Samples per side of the pixel's `n × n` strata.
    strata: u32,
    seed: u64,
    seeding: Seeding,
}

impl Sampler {
    /// `samples` must be a perfect square (the case loader checks); 1 means the pixel centre.
    pub fn new(samples: u32, seed: u64) -> Sampler {
        Sampler::with_seeding(samples, seed, Seeding::Seeded)
    }

    /// [`Sampler::new`] with the random numbers drawn as `seeding` says.
    pub fn with_seeding(samples: u32, seed: u64, seeding: Seeding) -> Sampler {
        let strata = (samples as f64).sqrt().round().max(1.0) as u32;
        Sampler { strata, seed, seeding }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.strata * self.strata
    }

    /// The samples of pixel `(x, y)`: the part of the hash that depends on the pixel alone is
    /// mixed once, not once per sample.
    #[inline(always)]
    pub fn pixel(&self, x: u32, y: u32) -> PixelSamples {
        let hash = match self.seeding {
            Seeding::Seeded => mix(mix(self.seed ^ 0x9e37_79b9_7f4a_7c15, x as u64), y as u64),
            Seeding::PixelIndex => 0,
        };
        PixelSamples { sampler: *self, x, y, hash }
    }
}

/// The samples of one pixel (see [`Sampler::pixel`]).
#[derive(Clone, Copy, Debug)]
pub struct PixelSamples {
    sampler: Sampler,
    x: u32,
    y: u32,
    /// The seed, `x` and `y` mixed.
    hash: u64,
}

impl PixelSamples {
    /// Position of sample `index` inside the pixel, in `[0, 1)²`: a uniformly jittered point in
    /// stratum `(index mod n, index div n)`. Always inlined: called once per sample, it costs
    /// a sampled render 19% when the compiler leaves it out of line (docs/statistical-verdict.md).
    #[inline(always)]
    pub fn offset(&self, index: u32) -> Vec2 {
        let strata = self.sampler.strata;
        if strata == 1 {
            return Vec2::splat(0.5);
        }
        if self.sampler.seeding == Seeding::PixelIndex {
            return pixel_seeded(self.x, self.y);
        }
        let n = strata as Real;
        let hash = mix(self.hash, index as u64);
        let stratum = Vec2::new((index % strata) as Real, (index / strata) as Real);
        let jitter = Vec2::new(unit_interval(hash), unit_interval(mix(hash, 0x5bd1_e995)));
        (stratum + jitter) / n
    }
}

/// [`Seeding::PixelIndex`]'s one point per pixel, out of line so that the seeded path stays as
/// small as it was.
#[cold]
fn pixel_seeded(x: u32, y: u32) -> Vec2 {
    let hash = mix(mix(0x9e37_79b9_7f4a_7c15, x as u64), y as u64);
    Vec2::new(unit_interval(hash), unit_interval(mix(hash, 0x5bd1_e995)))
}

/// One round of a 64-bit finaliser (Stafford's variant 13 of MurmurHash3's `fmix64`, as used by
/// SplitMix64) applied to `state + value`.
fn mix(state: u64, value: u64) -> u64 {
    let mut z = state.wrapping_add(value).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// 24 random bits scaled to `[0, 1)`: exact in both `f32` and `f64`, so the value can never
/// round up to 1.
fn unit_interval(bits: u64) -> Real {
    (bits >> 40) as Real * (1.0 / (1u64 << 24) as Real)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_is_the_centre() {
        let s = Sampler::new(1, 7);
        assert_eq!(s.pixel(3, 4).offset(0), Vec2::splat(0.5));
    }

    #[test]
    fn each_sample_stays_in_its_stratum() {
        let s = Sampler::new(16, 42);
        for index in 0..16 {
            let p = s.pixel(10, 20).offset(index);
            let (sx, sy) = ((index % 4) as Real, (index / 4) as Real);
            assert!(p.x >= sx / 4.0 && p.x < (sx + 1.0) / 4.0);
            assert!(p.y >= sy / 4.0 && p.y < (sy + 1.0) / 4.0);
        }
    }

    #[test]
    fn samples_depend_on_seed_pixel_and_index_only() {
        let a = Sampler::new(4, 1);
        assert_eq!(a.pixel(5, 6).offset(2), Sampler::new(4, 1).pixel(5, 6).offset(2));
        assert_ne!(a.pixel(5, 6).offset(2), Sampler::new(4, 2).pixel(5, 6).offset(2));
        assert_ne!(a.pixel(5, 6).offset(2), a.pixel(6, 5).offset(2));
    }

    #[test]
    fn jitter_is_roughly_uniform() {
        let s = Sampler::new(4, 3);
        let mean: Real = (0..10_000u32).map(|i| s.pixel(i, i / 7).offset(0).x * 2.0).sum::<Real>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
    }
}
