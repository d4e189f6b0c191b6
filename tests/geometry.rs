//! Integration tests of the geometry module: watertight triangles, BVH traversal and the packed
//! (SIMD) mesh queries against brute force (also where the tree's quantised boxes are tightest), mesh and OBJ loading, and the procedural blob. Shared helpers live here; the tests
//! are split by topic into the files under `tests/geometry/`.

#[path = "geometry/bvh.rs"]
mod bvh;
#[path = "geometry/generate.rs"]
mod generate;
#[path = "geometry/obj.rs"]
mod obj;
#[path = "geometry/packs.rs"]
mod packs;
#[path = "geometry/quantised.rs"]
mod quantised;
#[path = "geometry/timing.rs"]
mod timing;
#[path = "geometry/watertight.rs"]
mod watertight;

use goldray::geometry::Ray;
use goldray::real::{Real, Vec3};

/// A small seeded generator (SplitMix64), so failures reproduce without extra dependencies.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[low, high)`.
    pub fn uniform(&mut self, low: Real, high: Real) -> Real {
        let unit = (self.next_u64() >> 40) as Real / (1u64 << 24) as Real;
        low + (high - low) * unit
    }

    pub fn in_box(&mut self, half_size: Real) -> Vec3 {
        Vec3::new(
            self.uniform(-half_size, half_size),
            self.uniform(-half_size, half_size),
            self.uniform(-half_size, half_size),
        )
    }

    /// Uniform on the unit sphere.
    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_box(1.0);
            let length = v.length();
            if length > 0.1 && length <= 1.0 {
                return v / length;
            }
        }
    }
}

/// A ray from `origin` through `target`, with the unnormalised difference as direction so
/// that `t = 1` is the target.
pub fn ray_through(origin: Vec3, target: Vec3) -> Ray {
    Ray::new(origin, target - origin)
}
