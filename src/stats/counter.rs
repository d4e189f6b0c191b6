//! Counting rays by kind without slowing the render down.
//!
//! Each pixel counts its rays into a [`RayCounts`] on the stack (a few integer additions per
//! pixel, in code shared by counted and uncounted renders), and each band of rows sums its
//! pixels' counts into a [`RayCounter`] of its own; the bands' counters are merged once at the
//! end. No atomics, no shared cache lines. The renderer is generic over the band counter, so with
//! the zero-sized [`NoCount`] the summing compiles away.

use serde::Serialize;

/// Exact numbers of rays traced, by kind. Sums of integers, so the totals are the same for any
/// number of threads and any order in which bands finish.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RayCounts {
    /// Sample rays through the image plane: one per sample, per sub-pixel with the filter.
    pub camera: u64,
    /// The extra ray through an output pixel's centre for its depth and normal, traced when the
    /// colour comes from several samples (with one sample and no filter the camera ray is reused).
    pub aov: u64,
    /// Rays towards lights: one per light per shading point, with `shadows`.
    pub shadow: u64,
    /// Mirror reflection rays.
    pub reflection: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.camera + self.aov + self.shadow + self.reflection
    }
}

/// What a band of rows sums its pixels' ray counts into.
pub trait RayCounter: Default + Send {
    fn add(&mut self, rays: &RayCounts);

    /// Adds another band's counts to this one.
    fn merge(self, other: Self) -> Self;
}

/// The counter for renders nobody measures: zero-sized, and every call does nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCount;

impl RayCounter for NoCount {
    #[inline(always)]
    fn add(&mut self, _rays: &RayCounts) {}

    #[inline(always)]
    fn merge(self, _other: Self) -> Self {
        NoCount
    }
}

impl RayCounter for RayCounts {
    #[inline(always)]
    fn add(&mut self, rays: &RayCounts) {
        self.camera += rays.camera;
        self.aov += rays.aov;
        self.shadow += rays.shadow;
        self.reflection += rays.reflection;
    }

    fn merge(mut self, other: Self) -> Self {
        self.add(&other);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adds_and_merges_by_summing_each_kind() {
        let mut a = RayCounts::default();
        a.add(&RayCounts {
            camera: 2,
            aov: 1,
            shadow: 0,
            reflection: 4,
        });
        a.add(&RayCounts {
            camera: 1,
            aov: 0,
            shadow: 3,
            reflection: 0,
        });
        let b = RayCounts {
            camera: 1,
            aov: 0,
            shadow: 0,
            reflection: 1,
        };
        let sum = a.merge(b);
        assert_eq!(
            sum,
            RayCounts {
                camera: 4,
                aov: 1,
                shadow: 3,
                reflection: 5
            }
        );
        assert_eq!(sum.total(), 13);
        assert_eq!(std::mem::size_of::<NoCount>(), 0);
    }
}
