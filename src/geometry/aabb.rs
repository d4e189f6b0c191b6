//! Axis-aligned bounding boxes and the conservative ray–slab test that BVH traversal relies on.

use super::Ray;
use super::real::{Real, Vec3, gamma};

/// An axis-aligned box, closed on all sides.
///
/// The empty box has `min = +∞` and `max = −∞`, so it is the identity of [`Aabb::union`] and
/// a ray can never hit it.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Zeroable)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(Real::INFINITY),
        max: Vec3::splat(Real::NEG_INFINITY),
    };

    pub fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }

    /// The smallest box holding all `points` (empty for no points).
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Aabb::EMPTY, Aabb::grow)
    }

    #[inline]
    pub fn union(self, other: Aabb) -> Self {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    #[inline]
    pub fn grow(self, point: Vec3) -> Self {
        Aabb {
            min: self.min.min(point),
            max: self.max.max(point),
        }
    }

    /// True when no point lies inside, i.e. some `min > max` (also when a bound is NaN).
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    /// Halves each bound before adding so that boxes near `Real::MAX` do not overflow.
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        self.min * 0.5 + self.max * 0.5
    }

    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Zero for an empty box, so that the SAH gives empty children no weight.
    #[inline]
    pub fn surface_area(&self) -> Real {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Index (0, 1, 2 for x, y, z) of the widest side; ties go to the earlier axis.
    #[inline]
    pub fn longest_axis(&self) -> usize {
        let d = self.extent();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// Whether the ray meets the box for some `t` in `[0, t_max]`: [`hit_lanes`] for one box.
    #[inline]
    pub fn hit_by(&self, ray: &SlabRay, t_max: Real) -> bool {
        let lanes = |v: Vec3| [[v.x], [v.y], [v.z]];
        hit_lanes(&lanes(self.min), &lanes(self.max), ray, t_max).1[0]
    }
}

/// The slab test of `N` boxes at once, each box one lane of the per-axis arrays `min` and `max`
/// (structure of arrays, so that the compiler runs the lanes side by side in SIMD registers).
/// Returns each box's entry distance and whether the ray meets it for some `t` in `[0, t_max]`.
///
/// Conservative: it may report a hit the exact test would not, but never misses a box the
/// ray really touches, which is what keeps BVH traversal from losing triangles. Two details
/// make that so. The far distance on each axis is scaled by `1 + 2·gamma(3)` (pbrt-v4), which
/// covers the rounding of the subtraction and multiplication. And a zero direction component
/// gives an infinite inverse, so an origin lying exactly on that slab's plane computes
/// `0 · ∞ = NaN`; the comparisons below are false for NaN, so that slab then constrains
/// nothing, i.e. the plane counts as inside the box, as a closed box should. An empty box
/// (`min = +∞`, `max = −∞`) is never hit: its far distance is `−∞` on every axis.
#[inline(always)]
pub fn hit_lanes<const N: usize>(
    min: &[[Real; N]; 3],
    max: &[[Real; N]; 3],
    ray: &SlabRay,
    t_max: Real,
) -> ([Real; N], [bool; N]) {
    let far_scale = 1.0 + 2.0 * gamma(3);
    let mut t_enter: [Real; N] = [0.0; N];
    let mut t_exit = [t_max; N];
    for axis in 0..3 {
        let (near, far) = if ray.direction_is_negative[axis] {
            (&max[axis], &min[axis])
        } else {
            (&min[axis], &max[axis])
        };
        let (origin, inverse) = (ray.origin[axis], ray.inverse_direction[axis]);
        for lane in 0..N {
            let t_near = (near[lane] - origin) * inverse;
            let t_far = (far[lane] - origin) * inverse * far_scale;
            // A NaN compares false and so leaves the running bound as it is.
            if t_near > t_enter[lane] {
                t_enter[lane] = t_near;
            }
            if t_far < t_exit[lane] {
                t_exit[lane] = t_far;
            }
        }
    }
    (t_enter, std::array::from_fn(|lane| t_enter[lane] <= t_exit[lane]))
}

/// The per-ray part of the slab test, computed once per ray instead of once per box.
#[derive(Clone, Copy, Debug)]
pub struct SlabRay {
    pub origin: Vec3,
    /// `1 / direction` per component; ±∞ where the direction component is ±0.
    pub inverse_direction: Vec3,
    /// Chooses the near and far plane of each slab (and the nearer BVH child). Taken from the
    /// inverse so that a direction of −0.0 counts as negative, consistently with its −∞ inverse.
    pub direction_is_negative: [bool; 3],
}

impl SlabRay {
    pub fn new(ray: &Ray) -> Self {
        let inverse_direction = ray.direction.recip();
        SlabRay {
            origin: ray.origin,
            inverse_direction,
            direction_is_negative: [
                inverse_direction.x < 0.0,
                inverse_direction.y < 0.0,
                inverse_direction.z < 0.0,
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    fn hits(aabb: &Aabb, origin: Vec3, direction: Vec3, t_max: Real) -> bool {
        aabb.hit_by(&SlabRay::new(&Ray::new(origin, direction)), t_max)
    }

    #[test]
    fn empty_box_is_union_identity_and_never_hit() {
        let b = unit_box();
        assert_eq!(Aabb::EMPTY.union(b), b);
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert!(!hits(&Aabb::EMPTY, Vec3::ZERO, Vec3::X, Real::INFINITY));
    }

    #[test]
    fn measures() {
        let b = Aabb::from_points([Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(b.centroid(), Vec3::new(0.5, 1.0, 1.5));
        assert_eq!(b.surface_area(), 22.0);
        assert_eq!(b.longest_axis(), 2);
        assert!(!b.is_empty());
    }

    #[test]
    fn ray_hits_and_misses() {
        let b = unit_box();
        assert!(hits(&b, Vec3::new(0.5, 0.5, -1.0), Vec3::Z, Real::INFINITY));
        assert!(
            !hits(&b, Vec3::new(0.5, 0.5, -1.0), Vec3::Z, 0.5),
            "box beyond t_max"
        );
        assert!(
            !hits(&b, Vec3::new(0.5, 0.5, 2.0), Vec3::Z, Real::INFINITY),
            "box behind"
        );
        assert!(hits(&b, Vec3::splat(0.5), Vec3::Z, 0.1), "origin inside");
        assert!(!hits(
            &b,
            Vec3::new(2.0, 0.5, -1.0),
            Vec3::Z,
            Real::INFINITY
        ));
    }

    #[test]
    fn origin_on_a_slab_plane_with_zero_direction_component_still_hits() {
        let b = unit_box();
        for x in [0.0, 1.0] {
            for direction in [Vec3::Z, Vec3::NEG_Z, Vec3::new(-0.0, 0.0, 1.0)] {
                assert!(hits(
                    &b,
                    Vec3::new(x, 0.5, -3.0 * direction.z),
                    direction,
                    10.0
                ));
            }
        }
        assert!(
            hits(&b, Vec3::new(1.0, 1.0, -1.0), Vec3::Z, 10.0),
            "along an edge of the box"
        );
    }

    #[test]
    fn flat_box_is_hit_despite_rounding() {
        let flat = Aabb::new(Vec3::new(0.1, 0.1, 0.3), Vec3::new(0.7, 0.9, 0.3));
        let origin = Vec3::new(-0.3, 0.2, -0.7);
        let direction = Vec3::new(0.5, 0.3, 1.0);
        assert!(hits(&flat, origin, direction, Real::INFINITY));
    }
    /// The box test in f64 (within ~1e-16 of exact), without any widening.
    fn hits_precisely(aabb: &Aabb, origin: Vec3, direction: Vec3) -> bool {
        let (mut t_enter, mut t_exit) = (0.0f64, f64::INFINITY);
        for axis in 0..3 {
            let (o, d) = (origin[axis] as f64, direction[axis] as f64);
            let (t0, t1) = (
                (aabb.min[axis] as f64 - o) / d,
                (aabb.max[axis] as f64 - o) / d,
            );
            t_enter = t_enter.max(t0.min(t1));
            t_exit = t_exit.min(t0.max(t1));
        }
        t_enter <= t_exit
    }

    /// Rays aimed at edges and corners of boxes touch them only at a point, where the entry
    /// distance of one slab equals the exit distance of another; rounding must not separate them.
    #[test]
    fn rays_grazing_edges_and_corners_are_not_culled() {
        let mut state = 1u64;
        let mut uniform = |low: Real, high: Real| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            low + (high - low) * ((state >> 40) as Real / (1u64 << 24) as Real)
        };
        let mut grazing_hits = 0;
        for i in 0..20_000 {
            let min = Vec3::new(
                uniform(-50.0, 50.0),
                uniform(-50.0, 50.0),
                uniform(-50.0, 50.0),
            );
            let aabb = Aabb::new(
                min,
                min + Vec3::new(uniform(0.1, 9.0), uniform(0.1, 9.0), uniform(0.1, 9.0)),
            );
            let along_edge = uniform(aabb.min.z, aabb.max.z);
            let target = match i % 3 {
                0 => aabb.max,
                1 => Vec3::new(aabb.min.x, aabb.max.y, along_edge),
                _ => Vec3::new(aabb.max.x, aabb.min.y, along_edge),
            };
            let origin = Vec3::new(
                uniform(-90.0, 90.0),
                uniform(-90.0, 90.0),
                uniform(-90.0, 90.0),
            );
            let direction = target - origin;
            if hits_precisely(&aabb, origin, direction) {
                grazing_hits += 1;
                assert!(
                    hits(&aabb, origin, direction, Real::INFINITY),
                    "{aabb:?} {origin} {direction}"
                );
            }
        }
        assert!(grazing_hits > 5000, "{grazing_hits}");
    }
}
