//! Robust ray spawning: secondary rays start just far enough off the surface that rounding can
//! never put their origin on the wrong side, which no fixed epsilon can promise at every scale
//! (pbrt-v4 `OffsetRayOrigin`).

use super::lanes::{RayLanes, SurfaceLanes, V3};
use super::ray::{Ray, SurfaceHit};
use super::real::{R8, Real, Vec3, real};
use crate::options::Spawn;
use crate::simd::{Isa, Lanes};

/// Shadow rays to a point stop this fraction short of it, so that a light sitting on a surface
/// is not shadowed by that surface. Relative, so it scales with the scene.
pub const SHADOW_RAY_SHORTFALL: Real = 1.0e-4;

/// Moves `point` along the geometric normal, to the side `direction` leaves towards, by the
/// projection of its error box on the normal, then one more ulp away so that the rounding of
/// the addition cannot undo it.
pub fn spawn_ray_offset(hit: &SurfaceHit, direction: Vec3) -> Vec3 {
    let normal = hit.geometric_normal;
    let distance = normal.abs().dot(hit.point_error);
    let mut offset = normal * distance;
    if direction.dot(normal) < 0.0 {
        offset = -offset;
    }
    let mut origin = hit.point + offset;
    for axis in 0..3 {
        if offset[axis] > 0.0 {
            origin[axis] = origin[axis].next_up();
        } else if offset[axis] < 0.0 {
            origin[axis] = origin[axis].next_down();
        }
    }
    origin
}

pub fn spawn_ray(hit: &SurfaceHit, direction: Vec3) -> Ray {
    Ray::new(spawn_ray_offset(hit, direction), direction)
}

/// A ray towards `target` whose parameter reaches the target at `t = 1`; returns the ray and
/// the `t_max` that stops it just short of the target.
pub fn spawn_ray_to(hit: &SurfaceHit, target: Vec3) -> (Ray, Real) {
    let origin = spawn_ray_offset(hit, target - hit.point);
    (Ray::new(origin, target - origin), 1.0 - SHADOW_RAY_SHORTFALL)
}

/// A ray leaving `hit` towards `direction`, under `policy`.
pub fn spawn(policy: Spawn, hit: &SurfaceHit, direction: Vec3) -> Ray {
    match policy {
        Spawn::ErrorBounds => spawn_ray(hit, direction),
        Spawn::FixedEpsilon(epsilon) => Ray::new(hit.point + direction.normalize() * real(epsilon), direction),
        Spawn::Course => Ray::new(hit.point + direction * real(Spawn::COURSE_OFFSET), direction),
    }
}

/// [`spawn_ray_to`] under `policy`: a fixed epsilon skips that distance at both ends.
pub fn spawn_to(policy: Spawn, hit: &SurfaceHit, target: Vec3) -> (Ray, Real) {
    match policy {
        Spawn::ErrorBounds => spawn_ray_to(hit, target),
        Spawn::FixedEpsilon(epsilon) => {
            let to_target = target - hit.point;
            let skipped = real(epsilon) / to_target.length();
            (Ray::new(hit.point + to_target * skipped, to_target), 1.0 - 2.0 * skipped)
        }
        // The course's shadow ray: unit direction, 0.01 along it, blocked up to the light's
        // distance from the shading point (not from where the ray starts).
        Spawn::Course => {
            let to_target = target - hit.point;
            let distance = to_target.length();
            let direction = to_target / distance;
            (Ray::new(hit.point + direction * real(Spawn::COURSE_OFFSET), direction), distance)
        }
    }
}

/// [`spawn_ray_offset`] for a hit and a direction per lane.
#[inline(always)]
fn spawn_offset_lanes<I: Isa>(hit: &SurfaceLanes<I>, direction: V3<I>) -> V3<I> {
    let normal = hit.geometric_normal;
    let distance = normal.abs().dot(hit.point_error);
    let offset = normal.scale(distance);
    let offset = V3::select(direction.dot(normal).lt(R8::<I>::splat(0.0)), -offset, offset);
    let origin = hit.point + offset;
    V3 { x: origin.x.step_towards(offset.x), y: origin.y.step_towards(offset.y), z: origin.z.step_towards(offset.z) }
}

/// [`spawn`] for a hit and a direction per lane.
#[inline(always)]
pub fn spawn_lanes<I: Isa>(policy: Spawn, hit: &SurfaceLanes<I>, direction: V3<I>) -> RayLanes<I> {
    let origin = match policy {
        Spawn::ErrorBounds => spawn_offset_lanes(hit, direction),
        Spawn::FixedEpsilon(epsilon) => hit.point + direction.normalize().scale(R8::<I>::splat(real(epsilon))),
        Spawn::Course => hit.point + direction.scale(R8::<I>::splat(real(Spawn::COURSE_OFFSET))),
    };
    RayLanes { origin, direction }
}

/// [`spawn_to`] for a hit and a target per lane: the rays and each lane's `t_max`.
#[inline(always)]
pub fn spawn_to_lanes<I: Isa>(policy: Spawn, hit: &SurfaceLanes<I>, target: V3<I>) -> (RayLanes<I>, R8<I>) {
    let splat = R8::<I>::splat;
    match policy {
        Spawn::ErrorBounds => {
            let origin = spawn_offset_lanes(hit, target - hit.point);
            (RayLanes { origin, direction: target - origin }, splat(1.0 - SHADOW_RAY_SHORTFALL))
        }
        Spawn::FixedEpsilon(epsilon) => {
            let to_target = target - hit.point;
            let skipped = splat(real(epsilon)) / to_target.length();
            let origin = hit.point + to_target.scale(skipped);
            (RayLanes { origin, direction: to_target }, splat(1.0) - splat(2.0) * skipped)
        }
        Spawn::Course => {
            let to_target = target - hit.point;
            let distance = to_target.length();
            let direction = to_target.divide(distance);
            let origin = hit.point + direction.scale(splat(real(Spawn::COURSE_OFFSET)));
            (RayLanes { origin, direction }, distance)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit_at(point: Vec3, error: Vec3) -> SurfaceHit {
        SurfaceHit { t: 1.0, point, point_error: error, geometric_normal: Vec3::Y, shading_normal: Vec3::Y }
    }

    #[test]
    fn origin_moves_to_the_side_the_ray_leaves_by() {
        let hit = hit_at(Vec3::new(1.0e6, 2.0, 0.0), Vec3::splat(1.0e-3));
        let up = spawn_ray(&hit, Vec3::new(0.0, 1.0, 1.0));
        assert!(up.origin.y > 2.0 + 1.0e-3);
        let down = spawn_ray(&hit, Vec3::new(0.0, -1.0, 1.0));
        assert!(down.origin.y < 2.0 - 1.0e-3);
        assert_eq!(up.origin.x, 1.0e6, "only the normal direction moves");
    }

    #[test]
    fn an_offset_lost_to_rounding_still_moves_one_ulp() {
        let hit = hit_at(Vec3::new(0.0, 1.0, 0.0), Vec3::splat(Real::EPSILON * 1.0e-4));
        let ray = spawn_ray(&hit, Vec3::Y);
        assert_eq!(ray.origin.y, (1.0 as Real).next_up());
    }

    #[test]
    fn rays_to_a_point_stop_short_of_it() {
        let hit = hit_at(Vec3::ZERO, Vec3::splat(1.0e-6));
        let (ray, t_max) = spawn_ray_to(&hit, Vec3::new(0.0, 4.0, 0.0));
        let end = ray.at(t_max);
        assert!(end.y < 4.0 && end.y > 3.99);
    }
}
