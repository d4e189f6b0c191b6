//! All of a scene's geometry: a handful of plain spheres tested side by side, infinite planes,
//! and everything else under a BVH.

use super::geometry::aabb::{Aabb, SlabRay};
use super::geometry::bvh::{BoxSet, Bvh, LeafCost, LeafVisitor, Visit, WIDTH, traverse};
use super::geometry::plane::{PLANE_LANES, Plane, PlanePack, intersect_planes};
use super::geometry::sphere::{SPHERE_LANES, Sphere, SphereRay, SpherePack, intersect_spheres};
use super::geometry::{Ray, SurfaceHit};
use super::object::{Object, Shape, ShapeHit};
use super::real::Real;
use crate::simd::{Isa, Kernel, Lanes, dispatch};

mod packet;

pub use packet::HitLanes;

/// Up to this many untransformed spheres are tested on every ray, side by side, which costs
/// less than the box tests of a tree; more go into the tree with everything else.
const SPHERE_PACK_LIMIT: usize = SPHERE_LANES;

#[derive(Debug)]
pub struct Aggregate {
    /// In the scene's order, which is also the order that breaks ties (see [`Aggregate::intersect`]).
    objects: Vec<Object>,
    /// What rays are traced against: `objects`, but with small instanced meshes placed in world
    /// space ([`Object::placed`]).
    traced: Vec<Object>,
    planes: Vec<(Plane, u32)>,
    /// The planes side by side, in order.
    plane_packs: Vec<PlanePack>,
    /// The spheres tested side by side: untransformed, and no more than `SPHERE_PACK_LIMIT`.
    spheres: Vec<SpherePack>,
    /// The other objects.
    rest: Rest,
}

#[derive(Debug)]
enum Rest {
    Nothing,
    /// A lone object, tested directly; behind its world box when it has a transform, since the
    /// box test costs less than moving the ray into the object's space.
    One { object: u32, bounds: Option<Aabb> },
    /// A handful of objects behind their boxes, tested by one slab test: `objects[lane]` is the
    /// object of box `lane`.
    Few { boxes: Box<BoxSet>, objects: Vec<u32> },
    /// A tree whose leaves hold positions in `objects`: object indices in the tree's leaf order.
    Tree { bvh: Bvh, objects: Vec<u32> },
}

/// The closest surface a ray met, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    pub surface: SurfaceHit,
    pub material: u32,
}

#[derive(Clone, Copy)]
enum Found {
    Object(u32, ShapeHit),
    Plane(usize, Real),
}

/// The nearest candidate so far. Of candidates at the same `t` the smaller id wins: objects in
/// the scene's order, then planes, so that the hit never depends on the order of the tests.
struct Closest {
    t: Real,
    id: u32,
    found: Option<Found>,
}

impl Closest {
    #[inline(always)]
    fn offer(&mut self, t: Real, id: u32, found: Found) -> bool {
        let nearer = t < self.t || (t == self.t && id < self.id);
        if nearer {
            (self.t, self.id, self.found) = (t, id, Some(found));
        }
        nearer
    }
}

impl Aggregate {
    pub fn new(objects: Vec<Object>, planes: Vec<(Plane, u32)>) -> Aggregate {
        let traced: Vec<Object> = objects.iter().map(|object| object.placed().unwrap_or_else(|| object.clone())).collect();
        let plain_spheres: Vec<(u32, _)> = objects
            .iter()
            .enumerate()
            .filter_map(|(index, object)| match (&object.shape, &object.transform) {
                (Shape::Sphere(sphere), None) => Some((index as u32, *sphere)),
                _ => None,
            })
            .collect();
        let packed = plain_spheres.len() <= SPHERE_PACK_LIMIT;
        let spheres = if packed { plain_spheres.chunks(SPHERE_LANES).map(SpherePack::new).collect() } else { Vec::new() };
        let others: Vec<u32> = (0..objects.len() as u32)
            .filter(|&index| {
                let object = &objects[index as usize];
                !(packed && matches!((&object.shape, &object.transform), (Shape::Sphere(_), None)))
            })
            .collect();
        let rest = match others.as_slice() {
            [] => Rest::Nothing,
            &[object] => {
                let lone = &traced[object as usize];
                Rest::One { object, bounds: lone.transform.is_some().then(|| lone.bounds()) }
            }
            few if few.len() <= WIDTH => {
                let bounds: Vec<Aabb> = few.iter().map(|&index| traced[index as usize].bounds()).collect();
                Rest::Few { boxes: Box::new(BoxSet::new(&bounds)), objects: others }
            }
            _ => {
                let bounds: Vec<Aabb> = others.iter().map(|&index| traced[index as usize].bounds()).collect();
                let bvh = Bvh::build_for(&bounds, LeafCost::Single);
                let in_leaf_order = bvh.prim_indices().iter().map(|&k| others[k as usize]).collect();
                Rest::Tree { bvh, objects: in_leaf_order }
            }
        };
        let plane_list: Vec<Plane> = planes.iter().map(|(plane, _)| *plane).collect();
        let plane_packs = plane_list.chunks(PLANE_LANES).map(PlanePack::new).collect();
        Aggregate { objects, traced, planes, plane_packs, spheres, rest }
    }

    pub fn objects(&self) -> &[Object] {
        &self.objects
    }

    /// The infinite planes and their materials.
    pub fn planes(&self) -> &[(Plane, u32)] {
        &self.planes
    }

    /// The tree over the objects that are neither planes nor a handful of plain spheres, when
    /// there are more than eight of them (up to eight are tested by one slab test).
    pub fn bvh(&self) -> Option<&Bvh> {
        match &self.rest {
            Rest::Tree { bvh, .. } => Some(bvh),
            _ => None,
        }
    }

    /// The closest surface along the ray. Of surfaces hit at exactly the same `t`, the object
    /// listed first in the scene wins, and objects win over planes.
    pub fn intersect(&self, ray: &Ray) -> Option<Intersection> {
        struct Nearest<'a>(&'a Aggregate, &'a Ray);
        impl Kernel for Nearest<'_> {
            type Output = Option<Found>;
            #[inline(always)]
            fn run<I: Isa>(self) -> Option<Found> {
                self.0.closest_lanes::<I>(self.1)
            }
        }
        Some(self.intersection(ray, dispatch(Nearest(self, ray))?))
    }

    /// The full hit record of what [`Aggregate::closest_lanes`] found along `ray`.
    fn intersection(&self, ray: &Ray, found: Found) -> Intersection {
        match found {
            Found::Object(index, hit) => {
                let object = &self.traced[index as usize];
                Intersection { surface: object.surface(ray, &hit), material: object.material }
            }
            Found::Plane(index, t) => {
                let (plane, material) = &self.planes[index];
                Intersection { surface: plane.surface(ray, t), material: *material }
            }
        }
    }

    #[inline(always)]
    fn closest_lanes<I: Isa>(&self, ray: &Ray) -> Option<Found> {
        let mut closest = Closest { t: Real::INFINITY, id: u32::MAX, found: None };
        if !self.spheres.is_empty() {
            let sphere_ray = SphereRay::<I>::new(ray);
            for pack in &self.spheres {
                let (mut lanes, t) = intersect_spheres::<I>(pack, &sphere_ray, closest.t);
                if lanes != 0 {
                    let mut t_lanes = [0.0; SPHERE_LANES];
                    t.store(&mut t_lanes);
                    while lanes != 0 {
                        let lane = lanes.trailing_zeros() as usize;
                        lanes &= lanes - 1;
                        let id = pack.ids()[lane];
                        closest.offer(t_lanes[lane], id, Found::Object(id, ShapeHit::Sphere(t_lanes[lane])));
                    }
                }
            }
        }
        let plane_ids = self.objects.len() as u32;
        for (k, pack) in self.plane_packs.iter().enumerate() {
            let (mut lanes, t) = intersect_planes::<I>(pack, ray, closest.t);
            if lanes != 0 {
                let mut t_lanes = [0.0; PLANE_LANES];
                t.store(&mut t_lanes);
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let index = k * PLANE_LANES + lane;
                    closest.offer(t_lanes[lane], plane_ids + index as u32, Found::Plane(index, t_lanes[lane]));
                }
            }
        }
        self.closest_rest::<I>(ray, &mut closest);
        closest.found
    }

    /// Offers `closest` what the ray meets among the objects that are neither packed spheres
    /// nor planes.
    #[inline(always)]
    fn closest_rest<I: Isa>(&self, ray: &Ray, closest: &mut Closest) {
        match &self.rest {
            Rest::Nothing => {}
            Rest::One { object, bounds } => {
                if bounds.is_none_or(|bounds| bounds.hit_by(&SlabRay::new(ray), closest.t))
                    && let Some(hit) = self.traced[*object as usize].intersect_lanes::<I>(ray, closest.t)
                {
                    closest.offer(hit.t(), *object, Found::Object(*object, hit));
                }
            }
            Rest::Few { boxes, objects } => {
                let (hits, t) = boxes.entered::<I>(ray, closest.t);
                if hits != 0 {
                    let mut keys = [0; WIDTH];
                    for &key in BoxSet::nearest_first(hits, &t, &mut keys) {
                        let lane = BoxSet::lane(key);
                        if !BoxSet::may_hold(t[lane], closest.t) {
                            break;
                        }
                        let index = objects[lane];
                        if let Some(hit) = self.traced[index as usize].intersect_lanes::<I>(ray, closest.t) {
                            closest.offer(hit.t(), index, Found::Object(index, hit));
                        }
                    }
                }
            }
            Rest::Tree { bvh, objects } => {
                let t_max = closest.t;
                traverse::<I>(bvh.nodes(), ray, t_max, &mut ClosestInLeaves { aggregate: self, objects, ray, closest });
            }
        }
    }

    /// Whether anything blocks the ray before `t_max`; stops at the first blocker found.
    pub fn occluded(&self, ray: &Ray, t_max: Real) -> bool {
        struct Blocked<'a>(&'a Aggregate, &'a Ray, Real);
        impl Kernel for Blocked<'_> {
            type Output = bool;
            #[inline(always)]
            fn run<I: Isa>(self) -> bool {
                self.0.any_lanes::<I>(self.1, self.2)
            }
        }
        dispatch(Blocked(self, ray, t_max))
    }

    #[inline(always)]
    fn any_lanes<I: Isa>(&self, ray: &Ray, t_max: Real) -> bool {
        if !self.spheres.is_empty() {
            let sphere_ray = SphereRay::<I>::new(ray);
            if self.spheres.iter().any(|pack| intersect_spheres::<I>(pack, &sphere_ray, t_max).0 != 0) {
                return true;
            }
        }
        if self.plane_packs.iter().any(|pack| intersect_planes::<I>(pack, ray, t_max).0 != 0) {
            return true;
        }
        self.any_rest::<I>(ray, t_max)
    }

    /// Whether an object that is neither a packed sphere nor a plane blocks the ray before `t_max`.
    #[inline(always)]
    fn any_rest<I: Isa>(&self, ray: &Ray, t_max: Real) -> bool {
        match &self.rest {
            Rest::Nothing => false,
            Rest::One { object, bounds } => {
                bounds.is_none_or(|bounds| bounds.hit_by(&SlabRay::new(ray), t_max))
                    && self.traced[*object as usize].occluded_lanes::<I>(ray, t_max)
            }
            Rest::Few { boxes, objects } => {
                let (mut hits, _) = boxes.entered::<I>(ray, t_max);
                while hits != 0 {
                    let lane = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    if self.traced[objects[lane] as usize].occluded_lanes::<I>(ray, t_max) {
                        return true;
                    }
                }
                false
            }
            Rest::Tree { bvh, objects } => {
                let mut blockers = BlockersInLeaves { aggregate: self, objects, ray, blocked: false };
                traverse::<I>(bvh.nodes(), ray, t_max, &mut blockers);
                blockers.blocked
            }
        }
    }
}

/// [`Aggregate::closest_rest`]'s visitor of the rest's tree: offers `closest` every object of
/// each leaf reached. A visitor, not a closure: a closure is compiled on its own, without the
/// kernel's target features, and runs every lane operation of the objects' tests as a call.
struct ClosestInLeaves<'a> {
    aggregate: &'a Aggregate,
    objects: &'a [u32],
    ray: &'a Ray,
    closest: &'a mut Closest,
}

impl<I: Isa> LeafVisitor<I> for ClosestInLeaves<'_> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit {
        for &index in &self.objects[first as usize..(first + count) as usize] {
            if let Some(hit) = self.aggregate.traced[index as usize].intersect_lanes::<I>(self.ray, *t_limit) {
                self.closest.offer(hit.t(), index, Found::Object(index, hit));
                *t_limit = self.closest.t;
            }
        }
        Visit::Continue
    }
}

/// [`Aggregate::any_rest`]'s visitor of the rest's tree: stops at the first object of a leaf
/// that blocks the ray (a visitor for the reason [`ClosestInLeaves`] is).
struct BlockersInLeaves<'a> {
    aggregate: &'a Aggregate,
    objects: &'a [u32],
    ray: &'a Ray,
    blocked: bool,
}

impl<I: Isa> LeafVisitor<I> for BlockersInLeaves<'_> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit {
        for &index in &self.objects[first as usize..(first + count) as usize] {
            if self.aggregate.traced[index as usize].occluded_lanes::<I>(self.ray, *t_limit) {
                self.blocked = true;
                return Visit::Stop;
            }
        }
        Visit::Continue
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use super::super::geometry::sphere::Sphere;
    use super::super::real::Vec3;

    fn sphere(material: u32) -> Object {
        Object { shape: Shape::Sphere(Sphere { center: Vec3::ZERO, radius: 1.0 }), transform: None, material }
    }

    fn first_material(aggregate: &Aggregate) -> u32 {
        let ray = Ray::new(Vec3::new(0.1, 0.2, 5.0), Vec3::new(0.0, 0.0, -1.0));
        aggregate.intersect(&ray).expect("hit").material
    }

    /// Coinciding surfaces are hit at exactly the same `t`: the object listed first wins, whether
    /// the spheres are tested side by side or in a tree, and objects win over planes.
    #[test]
    fn of_surfaces_hit_at_the_same_t_the_first_listed_wins() {
        for count in [2, 8, 9, 20] {
            let aggregate = Aggregate::new((0..count).map(sphere).collect(), Vec::new());
            assert_eq!(aggregate.bvh().is_some(), count as usize > SPHERE_PACK_LIMIT, "{count} spheres");
            assert_eq!(first_material(&aggregate), 0, "{count} spheres");
        }
        let on_the_sphere = Plane::new(Vec3::Z, 1.0);
        let aggregate = Aggregate::new(vec![sphere(3)], vec![(on_the_sphere, 7), (on_the_sphere, 8)]);
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(aggregate.intersect(&ray).expect("hit").material, 3);
        let planes_only = Aggregate::new(Vec::new(), vec![(on_the_sphere, 7), (on_the_sphere, 8)]);
        assert_eq!(planes_only.intersect(&ray).expect("hit").material, 7);
    }

    /// In a tree of the rest's objects, a ray is blocked before `t_max` exactly when its closest
    /// hit is nearer than `t_max`, and the closest hit is the nearest sphere along it: both leaf
    /// visitors see every object of the leaves they reach.
    #[test]
    fn a_tree_of_objects_blocks_where_its_closest_hit_is_nearer() {
        let spheres: Vec<Object> = (0..20)
            .map(|i| {
                let center = Vec3::new((i % 5) as Real * 2.5 - 5.0, (i / 5) as Real * 2.5 - 3.75, -((i % 3) as Real));
                Object { shape: Shape::Sphere(Sphere { center, radius: 1.0 }), transform: None, material: i }
            })
            .collect();
        let centers: Vec<Vec3> = spheres
            .iter()
            .map(|object| match &object.shape {
                Shape::Sphere(sphere) => sphere.center,
                _ => unreachable!(),
            })
            .collect();
        let aggregate = Aggregate::new(spheres, Vec::new());
        assert!(aggregate.bvh().is_some(), "20 spheres make a tree");
        let (mut hits, mut misses) = (0, 0);
        for y in -30..30 {
            for x in -30..30 {
                let origin = Vec3::new(x as Real * 0.23, y as Real * 0.17, 10.0);
                let ray = Ray::new(origin, Vec3::new(0.0, 0.0, -1.0));
                let closest = aggregate.intersect(&ray);
                let nearest = centers
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| (origin.truncate() - c.truncate()).length_squared() < 1.0 - 1e-3)
                    .min_by(|a, b| b.1.z.total_cmp(&a.1.z))
                    .map(|(i, _)| i as u32);
                match &closest {
                    Some(hit) => {
                        hits += 1;
                        if let Some(nearest) = nearest {
                            assert_eq!(hit.material, nearest, "ray from {origin}");
                        }
                        assert!(aggregate.occluded(&ray, hit.surface.t * 1.001), "ray from {origin}");
                        assert!(!aggregate.occluded(&ray, hit.surface.t * 0.999), "ray from {origin}");
                    }
                    None => {
                        misses += 1;
                        assert!(!aggregate.occluded(&ray, Real::INFINITY), "ray from {origin}");
                    }
                }
            }
        }
        assert!(hits > 500 && misses > 500, "{hits} hits, {misses} misses");
    }
}
