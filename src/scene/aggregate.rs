//! All of a scene's geometry: bounded objects under a BVH, infinite planes beside it.

use super::object::{Object, ShapeHit};
use super::geometry::bvh::Bvh;
use super::geometry::plane::Plane;
use super::geometry::{Ray, SurfaceHit};
use super::real::Real;

/// Below this many objects a linear scan is cheaper than a BVH, and a scene of one sphere pays
/// for no tree at all.
const LINEAR_SCAN_LIMIT: usize = 4;

#[derive(Debug)]
pub struct Aggregate {
    objects: Vec<Object>,
    bvh: Option<Bvh>,
    planes: Vec<(Plane, u32)>,
}

/// The closest surface a ray met, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    pub surface: SurfaceHit,
    pub material: u32,
}

enum Closest {
    Object(usize, ShapeHit),
    Plane(usize, Real),
}

impl Aggregate {
    pub fn new(objects: Vec<Object>, planes: Vec<(Plane, u32)>) -> Aggregate {
        let bvh = (objects.len() > LINEAR_SCAN_LIMIT)
            .then(|| Bvh::build(&objects.iter().map(Object::bounds).collect::<Vec<_>>()));
        Aggregate { objects, bvh, planes }
    }

    pub fn objects(&self) -> &[Object] {
        &self.objects
    }

    /// The infinite planes, tested beside the BVH, with their materials.
    pub fn planes(&self) -> &[(Plane, u32)] {
        &self.planes
    }

    pub fn bvh(&self) -> Option<&Bvh> {
        self.bvh.as_ref()
    }

    pub fn intersect(&self, ray: &Ray) -> Option<Intersection> {
        let mut closest = None;
        let mut t_max = Real::INFINITY;
        for (index, (plane, _)) in self.planes.iter().enumerate() {
            if let Some(t) = plane.intersect(ray, t_max) {
                t_max = t;
                closest = Some(Closest::Plane(index, t));
            }
        }
        let mut test = |index: u32, t_max: Real| {
            let hit = self.objects[index as usize].intersect(ray, t_max)?;
            closest = Some(Closest::Object(index as usize, hit));
            Some(hit.t())
        };
        match &self.bvh {
            Some(bvh) => {
                bvh.closest(ray, t_max, &mut test);
            }
            None => {
                for index in 0..self.objects.len() as u32 {
                    if let Some(t) = test(index, t_max) {
                        t_max = t;
                    }
                }
            }
        }
        Some(match closest? {
            Closest::Object(index, hit) => {
                let object = &self.objects[index];
                Intersection { surface: object.surface(ray, &hit), material: object.material }
            }
            Closest::Plane(index, t) => {
                let (plane, material) = &self.planes[index];
                Intersection { surface: plane.surface(ray, t), material: *material }
            }
        })
    }

    /// Whether anything blocks the ray before `t_max`; stops at the first blocker found.
    pub fn occluded(&self, ray: &Ray, t_max: Real) -> bool {
        if self.planes.iter().any(|(plane, _)| plane.intersect(ray, t_max).is_some()) {
            return true;
        }
        let test = |index: u32, t_max: Real| self.objects[index as usize].occluded(ray, t_max);
        match &self.bvh {
            Some(bvh) => bvh.any(ray, t_max, test),
            None => (0..self.objects.len() as u32).any(|index| test(index, t_max)),
        }
    }
}
