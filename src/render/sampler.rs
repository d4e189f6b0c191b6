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
    /// Appends the positions of the pixel's samples, each moved by `origin` (the pixel's corner
    /// on the raster), to `points`, in index order: sample `index` is a uniformly jittered point
    /// in stratum `(index mod n, index div n)`. The strata are walked row by row, so that no
    /// sample pays for a division to find its own. Always inlined: it runs once per pixel, but
    /// its body once per sample.
    #[inline(always)]
    pub fn push_points(&self, origin: Vec2, points: &mut Vec<Vec2>) {
        let strata = self.sampler.strata;
        if strata == 1 {
            points.push(origin + Vec2::splat(0.5));
            return;
        }
        if self.sampler.seeding == Seeding::PixelIndex {
            let point = origin + pixel_seeded(self.x, self.y);
            points.extend(std::iter::repeat_n(point, (strata * strata) as usize));
            return;
        }
        let n = strata as Real;
        let mut index = 0;
        for row in 0..strata {
            for column in 0..strata {
                let hash = mix(self.hash, index);
                index += 1;
                let stratum = Vec2::new(column as Real, row as Real);
                let jitter = Vec2::new(unit_interval(hash), unit_interval(mix(hash, 0x5bd1_e995)));
                points.push(origin + (stratum + jitter) / n);
            }
        }
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

    /// The sample positions of pixel `(x, y)` inside it.
    fn offsets(sampler: Sampler, x: u32, y: u32) -> Vec<Vec2> {
        let mut points = Vec::new();
        sampler.pixel(x, y).push_points(Vec2::ZERO, &mut points);
        points
    }

    #[test]
    fn one_sample_is_the_centre() {
        assert_eq!(offsets(Sampler::new(1, 7), 3, 4), [Vec2::splat(0.5)]);
    }

    #[test]
    fn points_are_the_offsets_moved_to_the_pixel() {
        let s = Sampler::new(9, 5);
        let mut points = Vec::new();
        s.pixel(2, 3).push_points(Vec2::new(2.0, 3.0), &mut points);
        let moved: Vec<Vec2> = offsets(s, 2, 3).iter().map(|offset| Vec2::new(2.0, 3.0) + *offset).collect();
        assert_eq!(points, moved);
        let fixed = Sampler::with_seeding(4, 5, Seeding::PixelIndex);
        assert_eq!(offsets(fixed, 2, 3), [offsets(fixed, 2, 3)[0]; 4]);
    }

    #[test]
    fn each_sample_stays_in_its_stratum() {
        let s = Sampler::new(16, 42);
        let points = offsets(s, 10, 20);
        assert_eq!(points.len(), 16);
        for (index, p) in (0..16).zip(points) {
            let (sx, sy) = ((index % 4) as Real, (index / 4) as Real);
            assert!(p.x >= sx / 4.0 && p.x < (sx + 1.0) / 4.0);
            assert!(p.y >= sy / 4.0 && p.y < (sy + 1.0) / 4.0);
        }
    }

    #[test]
    fn samples_depend_on_seed_pixel_and_index_only() {
        let a = Sampler::new(4, 1);
        let third = |sampler, x, y| offsets(sampler, x, y)[2];
        assert_eq!(third(a, 5, 6), third(Sampler::new(4, 1), 5, 6));
        assert_ne!(third(a, 5, 6), third(Sampler::new(4, 2), 5, 6));
        assert_ne!(third(a, 5, 6), third(a, 6, 5));
    }

    #[test]
    fn jitter_is_roughly_uniform() {
        let s = Sampler::new(4, 3);
        let mean: Real = (0..10_000u32).map(|i| offsets(s, i, i / 7)[0].x * 2.0).sum::<Real>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
    }
}
