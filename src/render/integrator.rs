//! Whitted recursion, unrolled: with only mirror reflection, each hit spawns at most one new
//! ray, so the "recursion" is a loop that carries the product of specular colours. That makes
//! `bounces = 64` (or 1024) cost nothing on the stack.
//!
//! The integrator is generic over a [`FaultPolicy`] (the catalogue's student mistakes, see
//! `crate::fault`); every render but a diagnosis's uses [`NoFaults`], whose checks are the
//! constant `false`, so that its code is the code without them.

use super::faults;
use super::geometry::Ray;
use super::geometry::spawn::{spawn, spawn_to};
use super::real::{Color, Real, Vec3};
use super::scene::{Intersection, Scene};
use crate::fault::{Fault, FaultPolicy, NoFaults};
use crate::options::Spawn;
use crate::stats::RayCounts;

pub struct Whitted<'a, F: FaultPolicy = NoFaults> {
    scene: &'a Scene,
    bounces: u32,
    shadows: bool,
    spawn: Spawn,
    faults: F,
}

impl<'a> Whitted<'a> {
    pub fn new(scene: &'a Scene, bounces: u32, shadows: bool, spawn: Spawn) -> Self {
        Whitted::with_faults(scene, bounces, shadows, spawn, NoFaults)
    }
}

impl<'a, F: FaultPolicy> Whitted<'a, F> {
    pub fn with_faults(scene: &'a Scene, bounces: u32, shadows: bool, spawn: Spawn, faults: F) -> Self {
        Whitted { scene, bounces, shadows, spawn, faults }
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
            let Some(hit) = faults::intersect(scene, &ray, self.faults) else {
                color += throughput * faults::background(scene, ray.direction, depth, self.faults);
                break;
            };
            if depth == 0 {
                first = Some(hit);
            }
            let material = &scene.materials[hit.material as usize];
            if self.faults.has(Fault::NothingShaded) {
                color = material.diffuse;
                break;
            }
            color += throughput * self.direct_light(&ray, &hit, rays);
            let mirror = match self.spawn {
                // Compared as the course does: its float length widened to double, against 0.1.
                Spawn::Course => (material.specular.length() as f64) > Spawn::COURSE_MIRROR_THRESHOLD,
                _ => material.reflects(),
            };
            if depth == self.bounces || !(mirror || self.faults.has(Fault::ReflectionOnEveryMaterial)) {
                break;
            }
            if !self.faults.has(Fault::ReflectionWithoutKs) {
                throughput *= material.specular;
            }
            let normal = hit.surface.shading_normal;
            let incoming = self.view(ray.direction);
            let reflected = incoming - 2.0 * incoming.dot(normal) * normal;
            ray = spawn(self.spawn, &hit.surface, reflected);
            if self.faults.has(Fault::ReflectionAcne) {
                ray = faults::acne_reflected_ray(&hit, ray);
            }
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
        let mut lit = false;
        for light in &scene.lights {
            let mut incident = light.incident(surface.point);
            faults::fall_off(self.faults, light, surface.point, &mut incident);
            if self.shadows {
                rays.shadow += 1;
                if self.blocked(hit, incident.to_light, incident.position) {
                    continue;
                }
            }
            lit = true;
            let (normal, to_light, intensity) = (surface.shading_normal, incident.to_light, incident.intensity);
            color += if faults::faulty_shading(self.faults) {
                faults::shade(self.faults, material, normal, to_light, to_eye, intensity, surface.t)
            } else {
                material.shade(normal, to_light, to_eye, intensity)
            };
        }
        if self.faults.has(Fault::NoAmbientInShadow) && self.shadows && !lit && !scene.lights.is_empty() {
            return Color::ZERO;
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
        let (shadow_ray, mut t_max) = match position {
            _ if self.faults.has(Fault::ShadowAcne) => faults::acne_shadow_ray(self.spawn, hit, to_light, position),
            Some(position) => spawn_to(self.spawn, &hit.surface, position),
            None => (spawn(self.spawn, &hit.surface, to_light), Real::INFINITY),
        };
        if self.faults.has(Fault::ShadowsBeyondLight) {
            t_max = Real::INFINITY;
        }
        faults::occluded(self.scene, &shadow_ray, t_max, self.faults)
    }
}
