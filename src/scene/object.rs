//! One bounded primitive of a scene, with its material and optional instancing transform.

use std::sync::Arc;

use super::geometry::aabb::Aabb;
use super::geometry::mesh::{Mesh, MeshHit};
use super::geometry::sphere::Sphere;
use super::geometry::transform::Transform;
use super::geometry::triangle::{TriangleHit, TriangleRay, intersect_triangle, triangle_surface};
use super::geometry::{Ray, SurfaceHit};
use super::real::{Real, Vec3};

#[derive(Clone, Debug)]
pub struct Triangle {
    pub vertices: [Vec3; 3],
    pub normals: Option<[Vec3; 3]>,
}

#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    Triangle(Triangle),
    /// Shared, so that every instance of a mesh uses the one BVH built for it.
    Mesh(Arc<Mesh>),
}

#[derive(Clone, Debug)]
pub struct Object {
    pub shape: Shape,
    /// Object-to-world; `None` when the shape is already in world space.
    pub transform: Option<Arc<Transform>>,
    pub material: u32,
}

/// What `Object::intersect` found, kept small until the closest hit is known and only that one
/// is turned into a full `SurfaceHit`.
#[derive(Clone, Copy, Debug)]
pub enum ShapeHit {
    Sphere(Real),
    Triangle(TriangleHit),
    Mesh(MeshHit),
}

impl ShapeHit {
    pub fn t(&self) -> Real {
        match self {
            ShapeHit::Sphere(t) => *t,
            ShapeHit::Triangle(hit) => hit.t,
            ShapeHit::Mesh(hit) => hit.t,
        }
    }

    /// The same hit with its ray parameter moved by `shift`: between the parameter of an
    /// instance's object-space ray and that of the world ray it came from.
    fn shifted(mut self, shift: Real) -> ShapeHit {
        match &mut self {
            ShapeHit::Sphere(t) => *t += shift,
            ShapeHit::Triangle(hit) => hit.t += shift,
            ShapeHit::Mesh(hit) => hit.t += shift,
        }
        self
    }
}

impl Object {
    pub fn bounds(&self) -> Aabb {
        let local = match &self.shape {
            Shape::Sphere(sphere) => sphere.bounds(),
            Shape::Triangle(triangle) => triangle.vertices.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p)),
            Shape::Mesh(mesh) => mesh.bounds(),
        };
        match &self.transform {
            Some(transform) => transform.bounds_to_world(&local),
            None => local,
        }
    }

    /// The ray in the shape's own space and the shift of its parameter (see
    /// `Transform::ray_to_object`).
    fn local_ray(&self, world_ray: &Ray) -> (Ray, Real) {
        match &self.transform {
            Some(transform) => transform.ray_to_object(world_ray),
            None => (*world_ray, 0.0),
        }
    }

    /// The closest hit before `t_max`, with `t` in the world ray's parameter.
    pub fn intersect(&self, world_ray: &Ray, t_max: Real) -> Option<ShapeHit> {
        let (ray, shift) = self.local_ray(world_ray);
        let t_max = t_max - shift;
        let hit = match &self.shape {
            Shape::Sphere(sphere) => sphere.intersect(&ray, t_max).map(ShapeHit::Sphere),
            Shape::Triangle(triangle) => {
                let [p0, p1, p2] = triangle.vertices;
                intersect_triangle(&TriangleRay::new(&ray), t_max, p0, p1, p2).map(ShapeHit::Triangle)
            }
            Shape::Mesh(mesh) => mesh.intersect(&ray, t_max).map(ShapeHit::Mesh),
        }?;
        Some(hit.shifted(shift))
    }

    pub fn occluded(&self, world_ray: &Ray, t_max: Real) -> bool {
        match &self.shape {
            Shape::Mesh(mesh) => {
                let (ray, shift) = self.local_ray(world_ray);
                mesh.occluded(&ray, t_max - shift)
            }
            _ => self.intersect(world_ray, t_max).is_some(),
        }
    }

    /// The full hit record in world space.
    pub fn surface(&self, world_ray: &Ray, hit: &ShapeHit) -> SurfaceHit {
        let (ray, shift) = self.local_ray(world_ray);
        let surface = match (&self.shape, hit.shifted(-shift)) {
            (Shape::Sphere(sphere), ShapeHit::Sphere(t)) => sphere.surface(&ray, t),
            (Shape::Triangle(triangle), ShapeHit::Triangle(hit)) => {
                let [p0, p1, p2] = triangle.vertices;
                triangle_surface(p0, p1, p2, triangle.normals, &hit)
            }
            (Shape::Mesh(mesh), ShapeHit::Mesh(hit)) => mesh.surface(&hit),
            _ => unreachable!("a ShapeHit always comes from the same object's intersect"),
        };
        match &self.transform {
            Some(transform) => SurfaceHit { t: hit.t(), ..transform.hit_to_world(&surface) },
            None => surface,
        }
    }
}
