//! Whitted recursion, unrolled: with only mirror reflection, each hit spawns at most one new
//! ray, so the "recursion" is a loop that carries the product of specular colours. That makes
//! `bounces = 64` (or 1024) cost nothing on the stack.

use super::geometry::Ray;
use super::geometry::spawn::{spawn, spawn_to};
use super::real::{Color, Real, Vec3};
use super::scene::{Intersection, Scene};
use crate::options::Spawn;
use crate::stats::RayCounts;

pub struct Whitted<'a> {
    scene: &'a Scene,
    bounces: u32,
    shadows: bool,
    spawn: Spawn,
}

impl<'a> Whitted<'a> {
    pub fn new(scene: &'a Scene, bounces: u32, shadows: bool, spawn: Spawn) -> Self {
        Whitted { scene, bounces, shadows, spawn }
    }

    /// The colour seen along a primary ray, and what that ray hit first (for the AOVs). The
    /// caller counts the primary ray; the shadow and reflection rays it spawns are added to `rays`.
    pub fn trace(&self, primary: Ray, rays: &mut RayCounts) -> (Color, Option<Intersection>) {
        let scene = self.scene;
        let mut color = Color::ZERO;
        let mut throughput = Color::ONE;
        let mut ray = primary;
        let mut first = None;
        for depth in 0..=self.bounces {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                color += throughput * scene.background.radiance(ray.direction);
                break;
            };
            if depth == 0 {
                first = Some(hit);
            }
            let material = &scene.materials[hit.material as usize];
            color += throughput * self.direct_light(&ray, &hit, rays);
            let mirror = match self.spawn {
                // Compared as the course does: its float length widened to double, against 0.1.
                Spawn::Course => (material.specular.length() as f64) > Spawn::COURSE_MIRROR_THRESHOLD,
                _ => material.reflects(),
            };
            if depth == self.bounces || !mirror {
                break;
            }
            throughput *= material.specular;
            let normal = hit.surface.shading_normal;
            let incoming = self.view(ray.direction);
            let reflected = incoming - 2.0 * incoming.dot(normal) * normal;
            ray = spawn(self.spawn, &hit.surface, reflected);
            rays.reflection += 1;
        }
        (color, first)
    }

    /// Ambient plus every light that reaches the point (all of them without `shadows`).
    fn direct_light(&self, ray: &Ray, hit: &Intersection, rays: &mut RayCounts) -> Color {
        let scene = self.scene;
        let material = &scene.materials[hit.material as usize];
        let surface = &hit.surface;
        let to_eye = -self.view(ray.direction);
        let mut color = scene.ambient * material.diffuse;
        for light in &scene.lights {
            let incident = light.incident(surface.point);
            if self.shadows {
                rays.shadow += 1;
                if self.blocked(hit, incident.to_light, incident.position) {
                    continue;
                }
            }
            color += material.shade(surface.shading_normal, incident.to_light, to_eye, incident.intensity);
        }
        color
    }

    /// The direction a ray travels in, for reflecting and for the highlight: unit length, except
    /// that the course uses it as computed (longer or shorter after one of its planes with a
    /// non-unit normal).
    fn view(&self, direction: Vec3) -> Vec3 {
        match self.spawn {
            Spawn::Course => direction,
            _ => direction.normalize(),
        }
    }

    fn blocked(&self, hit: &Intersection, to_light: Vec3, position: Option<Vec3>) -> bool {
        let (shadow_ray, t_max) = match position {
            Some(position) => spawn_to(self.spawn, &hit.surface, position),
            None => (spawn(self.spawn, &hit.surface, to_light), Real::INFINITY),
        };
        self.scene.geometry.occluded(&shadow_ray, t_max)
    }
}
