//! Counting rays by kind without slowing the render down.
//!
//! Every band of rows counts into its own counter, passed by `&mut` down the integrator, and the
//! bands' counters are summed once at the end: no atomics or shared cache lines in the hot loop.
//! The renderer is generic over [`RayCounter`], so with the zero-sized [`NoCount`] every
//! `count` call is an empty inline function and the counting compiles away entirely.

use serde::Serialize;

/// Why a ray was traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// A sample ray through the image plane (one per sample, per sub-pixel with the filter).
    Camera,
    /// The extra ray through an output pixel's centre for its depth and normal, traced when the
    /// colour comes from several samples (with one sample and no filter the camera ray is reused).
    Aov,
    /// A shadow ray towards a light (one per light per shading point, with `shadows`).
    Shadow,
    /// A mirror reflection ray.
    Reflection,
}

/// Something that counts rays as the integrator traces them.
pub trait RayCounter: Default + Send {
    fn count(&mut self, kind: RayKind);

    /// Adds another band's counts to this one.
    fn merge(self, other: Self) -> Self;
}

/// The counter for renders nobody measures: zero-sized, and every call does nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCount;

impl RayCounter for NoCount {
    #[inline(always)]
    fn count(&mut self, _kind: RayKind) {}

    #[inline(always)]
    fn merge(self, _other: Self) -> Self {
        NoCount
    }
}

/// Exact numbers of rays traced, by kind. Sums of integers, so the totals are the same for any
/// number of threads and any order in which bands finish.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RayCounts {
    pub camera: u64,
    pub aov: u64,
    pub shadow: u64,
    pub reflection: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.camera + self.aov + self.shadow + self.reflection
    }
}

impl RayCounter for RayCounts {
    #[inline(always)]
    fn count(&mut self, kind: RayKind) {
        match kind {
            RayKind::Camera => self.camera += 1,
            RayKind::Aov => self.aov += 1,
            RayKind::Shadow => self.shadow += 1,
            RayKind::Reflection => self.reflection += 1,
        }
    }

    fn merge(self, other: Self) -> Self {
        RayCounts {
            camera: self.camera + other.camera,
            aov: self.aov + other.aov,
            shadow: self.shadow + other.shadow,
            reflection: self.reflection + other.reflection,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_by_kind_and_merges_by_summing() {
        let mut a = RayCounts::default();
        for kind in [RayKind::Camera, RayKind::Camera, RayKind::Shadow, RayKind::Aov] {
            a.count(kind);
        }
        let mut b = RayCounts::default();
        b.count(RayKind::Reflection);
        b.count(RayKind::Camera);
        let sum = a.merge(b);
        assert_eq!(sum, RayCounts { camera: 3, aov: 1, shadow: 1, reflection: 1 });
        assert_eq!(sum.total(), 6);
        assert_eq!(std::mem::size_of::<NoCount>(), 0);
    }
}
