//! One bounded primitive of a scene, with its material and optional instancing transform.

use std::sync::Arc;

use super::geometry::aabb::Aabb;
use super::geometry::bvh::PACKET;
use super::geometry::mesh::{Mesh, MeshHit};
use super::geometry::sphere::Sphere;
use super::geometry::transform::Transform;
use super::geometry::triangle::{TriangleHit, TriangleRay, intersect_triangle, triangle_surface};
use super::geometry::{Ray, SurfaceHit};
use super::real::{Real, Vec3};
use crate::simd::{Isa, Kernel, dispatch};

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

/// Instanced meshes of up to this many triangles are traced placed in world space (see
/// [`Object::placed`]): a copy of a few dozen triangles per instance costs nothing, and the ray
/// is then neither moved into the instance's space nor its hit moved back.
const PLACED_MESH_LIMIT: usize = 64;

impl Object {
    /// The same object with its mesh moved into world space, when it is an instance of a mesh of
    /// at most `PLACED_MESH_LIMIT` triangles (and every moved corner and normal is finite).
    ///
    /// Placing rounds each corner once, at build time, where instancing rounds each ray into
    /// the instance's space and its hit back, so hit points and normals differ from
    /// instancing's by rounding only. The vertex normals are mapped by the inverse transpose
    /// without normalising, so that they interpolate to the direction the instance shades
    /// with; a mirroring transform swaps two corners, as for a lone triangle, so that the face
    /// normal stays the inverse transpose's.
    pub fn placed(&self) -> Option<Object> {
        let (Shape::Mesh(mesh), Some(transform)) = (&self.shape, &self.transform) else {
            return None;
        };
        if mesh.triangle_count() > PLACED_MESH_LIMIT {
            return None;
        }
        let finite = |vectors: &[Vec3; 3]| vectors.iter().all(|v| v.is_finite());
        let mut corners = Vec::with_capacity(mesh.triangle_count());
        let mut normals = Vec::with_capacity(mesh.triangle_count());
        for triangle in 0..mesh.triangle_count() as u32 {
            let mut placed = mesh.triangle(triangle).map(|p| transform.point_to_world(p));
            let mut vertex_normals =
                mesh.vertex_normals(triangle).map(|ns| ns.map(|n| transform.normal_to_world_unnormalised(n)));
            if transform.mirrors() {
                placed.swap(1, 2);
                if let Some(ns) = &mut vertex_normals {
                    ns.swap(1, 2);
                }
            }
            if !finite(&placed) || !vertex_normals.as_ref().is_none_or(finite) {
                return None;
            }
            corners.push(placed);
            normals.push(vertex_normals);
        }
        let placed = Mesh::from_placed(&corners, &normals);
        Some(Object { shape: Shape::Mesh(Arc::new(placed)), transform: None, material: self.material })
    }

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
        struct Closest<'a>(&'a Object, &'a Ray, Real);
        impl Kernel for Closest<'_> {
            type Output = Option<ShapeHit>;
            #[inline(always)]
            fn run<I: Isa>(self) -> Option<ShapeHit> {
                self.0.intersect_lanes::<I>(self.1, self.2)
            }
        }
        dispatch(Closest(self, world_ray, t_max))
    }

    /// [`Object::intersect`] inside a caller's kernel (see `crate::simd`): a mesh is traversed
    /// without a second dispatch.
    #[inline(always)]
    pub fn intersect_lanes<I: Isa>(&self, world_ray: &Ray, t_max: Real) -> Option<ShapeHit> {
        let (ray, shift) = self.local_ray(world_ray);
        let t_max = t_max - shift;
        let hit = match &self.shape {
            Shape::Sphere(sphere) => sphere.intersect(&ray, t_max).map(ShapeHit::Sphere),
            Shape::Triangle(triangle) => {
                let [p0, p1, p2] = triangle.vertices;
                intersect_triangle(&TriangleRay::new(&ray), t_max, p0, p1, p2).map(ShapeHit::Triangle)
            }
            Shape::Mesh(mesh) => mesh.closest_lanes::<I>(&ray, t_max).map(ShapeHit::Mesh),
        }?;
        Some(hit.shifted(shift))
    }

    /// [`Object::intersect_lanes`] for up to [`PACKET`] rays, ray `k` with its own `t_max[k]`;
    /// each result exactly what [`Object::intersect_lanes`] returns for that ray alone. A mesh
    /// traces the rays as one packet when they are coherent enough (see
    /// [`Mesh::closest_packet`]); other shapes take them one by one.
    ///
    /// # Panics
    /// If there are more than [`PACKET`] rays.
    #[inline(always)]
    pub fn intersect_packet<I: Isa>(&self, world_rays: &[Ray], t_max: &[Real; PACKET]) -> [Option<ShapeHit>; PACKET] {
        let mut found = [None; PACKET];
        let Shape::Mesh(mesh) = &self.shape else {
            for ((found, ray), &t_max) in found.iter_mut().zip(world_rays).zip(t_max) {
                *found = self.intersect_lanes::<I>(ray, t_max);
            }
            return found;
        };
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); PACKET];
        let (mut shifts, mut limits) = ([0.0; PACKET], [0.0; PACKET]);
        for (k, world_ray) in world_rays.iter().enumerate() {
            (rays[k], shifts[k]) = self.local_ray(world_ray);
            limits[k] = t_max[k] - shifts[k];
        }
        let hits = mesh.closest_packet::<I>(&rays[..world_rays.len()], &limits);
        for ((found, hit), shift) in found.iter_mut().zip(hits).zip(shifts) {
            *found = hit.map(|hit| ShapeHit::Mesh(hit).shifted(shift));
        }
        found
    }

    pub fn occluded(&self, world_ray: &Ray, t_max: Real) -> bool {
        struct Any<'a>(&'a Object, &'a Ray, Real);
        impl Kernel for Any<'_> {
            type Output = bool;
            #[inline(always)]
            fn run<I: Isa>(self) -> bool {
                self.0.occluded_lanes::<I>(self.1, self.2)
            }
        }
        dispatch(Any(self, world_ray, t_max))
    }

    /// [`Object::occluded`] inside a caller's kernel.
    #[inline(always)]
    pub fn occluded_lanes<I: Isa>(&self, world_ray: &Ray, t_max: Real) -> bool {
        match &self.shape {
            Shape::Mesh(mesh) => {
                let (ray, shift) = self.local_ray(world_ray);
                mesh.any_lanes::<I>(&ray, t_max - shift)
            }
            _ => self.intersect_lanes::<I>(world_ray, t_max).is_some(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use super::super::geometry::generate::blob;
    use super::super::geometry::mesh::VertexNormals;
    use super::super::real::Mat4;

    /// A small instanced mesh placed in world space is hit where the instance is, up to
    /// rounding, and shades with the same normals, also under a non-uniform, mirroring transform.
    #[test]
    fn a_placed_mesh_is_hit_and_shaded_as_its_instance() {
        let (positions, triangles) = blob(0, 5);
        let mesh = Arc::new(Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap());
        let matrix = Mat4::from_translation(Vec3::new(1.0, -2.0, 0.5))
            * Mat4::from_rotation_y(0.7)
            * Mat4::from_scale(Vec3::new(-1.5, 0.25, 2.0));
        let instance =
            Object { shape: Shape::Mesh(mesh.clone()), transform: Some(Arc::new(Transform::new(matrix).unwrap())), material: 3 };
        let placed = instance.placed().expect("20 triangles are placed");
        assert!(placed.transform.is_none());
        assert_eq!(placed.material, 3);
        let close = |a: Vec3, b: Vec3, tolerance: Real| (a - b).length() <= tolerance * (1.0 + a.length());
        for triangle in 0..mesh.triangle_count() as u32 {
            let [p0, p1, p2] = mesh.triangle(triangle);
            let target = matrix.transform_point3((p0 + p1 + p2) / 3.0);
            for origin in [Vec3::new(9.0, 4.0, -7.0), Vec3::new(-8.0, -6.0, 5.0), Vec3::new(0.5, 9.0, 0.0)] {
                let ray = Ray::new(origin, target - origin);
                let expected = instance.intersect(&ray, Real::INFINITY).expect("aimed at a triangle");
                let hit = placed.intersect(&ray, Real::INFINITY).expect("the placed mesh is hit too");
                assert!((hit.t() - expected.t()).abs() <= 1e-5 * expected.t(), "{triangle}: {hit:?} vs {expected:?}");
                let (surface, reference) = (placed.surface(&ray, &hit), instance.surface(&ray, &expected));
                assert!(close(surface.point, reference.point, 1e-5), "{surface:?} vs {reference:?}");
                assert!(close(surface.geometric_normal, reference.geometric_normal, 1e-5), "{surface:?} vs {reference:?}");
                assert!(close(surface.shading_normal, reference.shading_normal, 1e-5), "{surface:?} vs {reference:?}");
                assert!(placed.occluded(&ray, expected.t() * 1.01));
            }
        }
    }

    /// Rays offered as a packet, each with its own limit, find what each finds alone: through a
    /// transform, coherent (one packet) or not (ray by ray), limits cutting some hits off.
    #[test]
    fn a_packet_of_rays_finds_what_each_ray_finds_alone() {
        use crate::simd::{Isa, Kernel, dispatch};
        struct Packet<'a>(&'a Object, &'a [Ray], [Real; PACKET]);
        impl Kernel for Packet<'_> {
            type Output = [Option<ShapeHit>; PACKET];
            fn run<I: Isa>(self) -> Self::Output {
                self.0.intersect_packet::<I>(self.1, &self.2)
            }
        }
        let (positions, triangles) = blob(3, 2);
        let mesh = Arc::new(Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap());
        let matrix = Mat4::from_translation(Vec3::new(0.5, -2.0, 1.0)) * Mat4::from_scale(Vec3::new(3.0, 2.0, 2.5));
        let transform = Some(Arc::new(Transform::new(matrix).unwrap()));
        let origin = Vec3::new(0.3, -1.5, 9.0);
        let mut hits = 0;
        for (k, spread) in [0.05, 0.4, 3.0].into_iter().enumerate() {
            for object in [
                Object { shape: Shape::Mesh(mesh.clone()), transform: transform.clone(), material: 0 },
                Object { shape: Shape::Mesh(mesh.clone()), transform: None, material: 0 },
            ] {
                for count in [1, 5, PACKET] {
                    let rays: Vec<Ray> = (0..count)
                        .map(|i| {
                            let angle = (i + 3 * k) as Real;
                            let aim = Vec3::new(spread * angle.cos(), -2.0 + spread * angle.sin(), 0.0);
                            Ray::new(origin, aim - origin)
                        })
                        .collect();
                    let limits: [Real; PACKET] = std::array::from_fn(|i| if i % 3 == 1 { 8.0 } else { Real::INFINITY });
                    let packet = dispatch(Packet(&object, &rays, limits));
                    for (i, ray) in rays.iter().enumerate() {
                        let alone = object.intersect(ray, limits[i]);
                        assert_eq!(format!("{:?}", packet[i]), format!("{alone:?}"), "ray {i} of {count}, spread {spread}");
                        hits += alone.is_some() as usize;
                    }
                    assert!(packet[count..].iter().all(Option::is_none));
                }
            }
        }
        assert!(hits > 30, "the rays hit the mesh: {hits}");
    }

    #[test]
    fn large_or_untransformed_meshes_stay_as_they_are() {
        let (positions, triangles) = blob(1, 5);
        let large = Arc::new(Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap());
        let scale = Some(Arc::new(Transform::new(Mat4::from_scale(Vec3::splat(2.0))).unwrap()));
        assert!(Object { shape: Shape::Mesh(large), transform: scale.clone(), material: 0 }.placed().is_none());
        let (positions, triangles) = blob(0, 5);
        let small = Arc::new(Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap());
        assert!(Object { shape: Shape::Mesh(small.clone()), transform: None, material: 0 }.placed().is_none());
        assert!(Object { shape: Shape::Mesh(small), transform: scale, material: 0 }.placed().is_some());
    }
}
