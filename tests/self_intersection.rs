//! pbrt-v4 style "reintersect" properties: rays spawned from a hit point never hit the surface
//! they leave, for triangles and spheres with coordinates anywhere from 1e-8 to 1e8, in world
//! space and under random instancing transforms.

use goldray::geometry::Ray;
use goldray::geometry::spawn::{spawn_ray, spawn_ray_to};
use goldray::geometry::sphere::Sphere;
use goldray::geometry::transform::Transform;
use goldray::geometry::triangle::{TriangleRay, intersect_triangle, triangle_surface};
use goldray::real::{Mat4, Real, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

const SPAWNED_PER_HIT: usize = 1000;

fn config() -> Config {
    Config {
        cases: 96,
        rng_seed: RngSeed::Fixed(0x0601_d4a7),
        failure_persistence: None,
        ..Config::default()
    }
}

/// Magnitudes spread evenly over sixteen decades, either sign.
fn log_uniform() -> impl Strategy<Value = Real> {
    (-8.0f64..8.0, any::<bool>()).prop_map(|(exponent, negative)| {
        let magnitude = 10f64.powf(exponent) as Real;
        if negative { -magnitude } else { magnitude }
    })
}

fn point() -> impl Strategy<Value = Vec3> {
    (log_uniform(), log_uniform(), log_uniform()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn unit_vector() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, 0.0f32..std::f32::consts::TAU).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

/// Random non-degenerate affine transforms: per-axis scales over eight decades, a rotation,
/// and a translation over sixteen.
fn transform() -> impl Strategy<Value = Transform> {
    (
        point(),
        unit_vector(),
        0.0f32..std::f32::consts::TAU,
        -4.0f64..4.0,
        -1.0f64..1.0,
        -1.0f64..1.0,
    )
        .prop_map(|(translation, axis, angle, scale, squash_y, squash_z)| {
            let s = 10f64.powf(scale);
            let scales = Vec3::new(
                s as Real,
                (s * 10f64.powf(squash_y)) as Real,
                (s * 10f64.powf(squash_z)) as Real,
            );
            Transform::new(Mat4::from_scale_rotation_translation(
                scales,
                glam::Quat::from_axis_angle(axis, angle),
                translation,
            ))
            .expect("scales within eight decades are not singular")
        })
}

/// `count` directions from a fixed sequence, turned into the hemisphere around `normal`.
fn hemisphere(normal: Vec3, count: usize) -> impl Iterator<Item = Vec3> {
    (0..count).filter_map(move |i| {
        let z = 1.0 - 2.0 * ((i as Real + 0.5) / count as Real);
        let phi = i as Real * 2.399_963;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let d = if d.dot(normal) < 0.0 { -d } else { d };
        (d.dot(normal) > 0.0).then_some(d)
    })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn rays_leaving_a_triangle_never_hit_it_again(p0 in point(), p1 in point(), p2 in point(), b in (0.01f32..1.0, 0.01f32..1.0), from in unit_vector(), distance in log_uniform()) {
        let (u, v) = if b.0 + b.1 > 1.0 { (1.0 - b.0, 1.0 - b.1) } else { b };
        let target = p0 * (1.0 - u - v) + p1 * u + p2 * v;
        let origin = target + from * distance.abs();
        let ray = Ray::new(origin, target - origin);
        let Some(hit) = intersect_triangle(&TriangleRay::new(&ray), Real::INFINITY, p0, p1, p2) else {
            return Ok(());
        };
        let surface = triangle_surface(p0, p1, p2, None, &hit);
        let side = if surface.geometric_normal.dot(ray.direction) < 0.0 { surface.geometric_normal } else { -surface.geometric_normal };
        for direction in hemisphere(side, SPAWNED_PER_HIT) {
            let spawned = spawn_ray(&surface, direction);
            let again = intersect_triangle(&TriangleRay::new(&spawned), Real::INFINITY, p0, p1, p2);
            prop_assert!(again.is_none(), "re-hit at t = {:?} leaving {:?} along {direction}", again.map(|h| h.t), surface.point);
            // A target closer to the plane than the hit point's own error is not on either side.
            let target = surface.point + direction * distance.abs();
            let clearance = (target - surface.point).dot(side);
            if clearance > 4.0 * side.abs().dot(surface.point_error) {
                let (shadow, t_max) = spawn_ray_to(&surface, target);
                let blocked = intersect_triangle(&TriangleRay::new(&shadow), t_max, p0, p1, p2);
                prop_assert!(blocked.is_none(), "shadow ray to {target} re-hit at t = {:?}", blocked.map(|h| h.t));
            }
        }
    }

    #[test]
    fn rays_leaving_a_sphere_never_hit_it_again(center in point(), radius in log_uniform(), from in unit_vector(), aim in unit_vector()) {
        let sphere = Sphere { center, radius: radius.abs() };
        let target = center + aim * (0.5 * sphere.radius);
        let origin = center + from * (4.0 * sphere.radius);
        let ray = Ray::new(origin, target - origin);
        let Some(t) = sphere.intersect(&ray, Real::INFINITY) else { return Ok(()) };
        let surface = sphere.surface(&ray, t);
        for direction in hemisphere(surface.geometric_normal, SPAWNED_PER_HIT) {
            let spawned = spawn_ray(&surface, direction);
            let again = sphere.intersect(&spawned, Real::INFINITY);
            prop_assert!(again.is_none(), "re-hit at t = {again:?} leaving {:?} along {direction}", surface.point);
        }
    }

    #[test]
    fn rays_leaving_an_instanced_sphere_never_hit_it_again(instance in transform(), from in unit_vector(), aim in unit_vector()) {
        let sphere = Sphere { center: Vec3::ZERO, radius: 1.0 };
        let world_target = instance.point_to_world(aim * 0.5);
        let world_origin = instance.point_to_world(from * 4.0);
        let ray = Ray::new(world_origin, world_target - world_origin);
        let (local_ray, _) = instance.ray_to_object(&ray);
        let Some(t) = sphere.intersect(&local_ray, Real::INFINITY) else { return Ok(()) };
        let local = sphere.surface(&local_ray, t);
        let surface = instance.hit_to_world(&local);
        for direction in hemisphere(surface.geometric_normal, SPAWNED_PER_HIT) {
            let (spawned, _) = instance.ray_to_object(&spawn_ray(&surface, direction));
            let again = sphere.intersect(&spawned, Real::INFINITY);
            prop_assert!(again.is_none(), "re-hit at t = {again:?} leaving {:?} along {direction}", surface.point);
        }
    }

    #[test]
    fn rays_leaving_an_instanced_triangle_never_hit_it_again(instance in transform(), b in (0.01f32..1.0, 0.01f32..1.0), from in unit_vector()) {
        let (p0, p1, p2) = (Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -0.5, 0.2), Vec3::new(0.1, 1.0, -0.3));
        let (u, v) = if b.0 + b.1 > 1.0 { (1.0 - b.0, 1.0 - b.1) } else { b };
        let target = instance.point_to_world(p0 * (1.0 - u - v) + p1 * u + p2 * v);
        let origin = target + instance.vector_to_world(from) * 3.0;
        let ray = Ray::new(origin, target - origin);
        let (local_ray, _) = instance.ray_to_object(&ray);
        let Some(hit) = intersect_triangle(&TriangleRay::new(&local_ray), Real::INFINITY, p0, p1, p2) else { return Ok(()) };
        let surface = instance.hit_to_world(&triangle_surface(p0, p1, p2, None, &hit));
        let side = if surface.geometric_normal.dot(ray.direction) < 0.0 { surface.geometric_normal } else { -surface.geometric_normal };
        for direction in hemisphere(side, SPAWNED_PER_HIT) {
            let (spawned, _) = instance.ray_to_object(&spawn_ray(&surface, direction));
            let again = intersect_triangle(&TriangleRay::new(&spawned), Real::INFINITY, p0, p1, p2);
            prop_assert!(again.is_none(), "re-hit at t = {:?} leaving {:?} along {direction}", again.map(|h| h.t), surface.point);
        }
    }
}
