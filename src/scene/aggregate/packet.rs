//! [`Aggregate`]'s queries for eight rays at once, a ray per SIMD lane: each sphere and plane is
//! tested against all eight rays in one go, and the other objects ray by ray. Lane by lane the
//! answer is exactly [`Aggregate::intersect`]'s and [`Aggregate::occluded`]'s for that ray
//! alone: the same tests in the same arithmetic, and the same rule for ties (candidates are
//! offered in the order of their ids, and a later one wins only when strictly nearer).

use super::super::geometry::bvh::PACKET;
use super::super::geometry::lanes::{LANES, RayLanes, RaySlabs, SurfaceLanes, V3, mask, set_lanes};
use super::super::real::{R8, Vec3};
use super::*;
use crate::simd::MaskOps;

/// What eight rays hit first.
pub struct HitLanes<I: Isa> {
    /// A bit per lane whose ray hit something; the other lanes' surfaces are meaningless.
    pub hits: u32,
    pub surface: SurfaceLanes<I>,
    /// Each lane's material.
    pub material: [u32; LANES],
}

impl Aggregate {
    /// [`Aggregate::intersect`] for each ray of `rays` whose bit is set in `active`.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn intersect_packet<I: Isa>(&self, rays: &RayLanes<I>, active: u32) -> HitLanes<I> {
        let infinity = R8::<I>::splat(Real::INFINITY);
        let mut nearest = infinity;
        let mut ids = [u32::MAX; LANES];
        let mut material = [0; LANES];
        let (mut sphere_lanes, mut plane_lanes) = (0, 0);
        let (mut center, mut radius) = (V3::<I>::splat(Vec3::ZERO), R8::<I>::splat(0.0));
        if !self.spheres.is_empty() {
            let sphere_rays = SphereRay::<I>::lanes(rays);
            for pack in &self.spheres {
                for k in set_lanes(pack.live()) {
                    let sphere = pack.sphere(k);
                    let (hits, t) = sphere.intersect_rays::<I>(&sphere_rays, infinity, active);
                    let nearer = hits & active & t.lt(nearest).bits();
                    if nearer != 0 {
                        let chosen = mask::<I>(nearer);
                        nearest = R8::<I>::select(chosen, t, nearest);
                        center = V3::select(chosen, V3::splat(sphere.center), center);
                        radius = R8::<I>::select(chosen, R8::<I>::splat(sphere.radius), radius);
                        sphere_lanes |= nearer;
                        let id = pack.ids()[k];
                        for lane in set_lanes(nearer) {
                            (ids[lane], material[lane]) = (id, self.objects[id as usize].material);
                        }
                    }
                }
            }
        }
        let (mut normal, mut offset, mut shading_normal) =
            (V3::<I>::splat(Vec3::Y), R8::<I>::splat(0.0), V3::<I>::splat(Vec3::Y));
        let plane_ids = self.objects.len() as u32;
        for (index, (plane, plane_material)) in self.planes.iter().enumerate() {
            let (hits, t) = plane.intersect_rays::<I>(rays, infinity);
            let nearer = hits & active & t.lt(nearest).bits();
            if nearer != 0 {
                let chosen = mask::<I>(nearer);
                nearest = R8::<I>::select(chosen, t, nearest);
                normal = V3::select(chosen, V3::splat(plane.normal), normal);
                offset = R8::<I>::select(chosen, R8::<I>::splat(plane.offset), offset);
                shading_normal = V3::select(chosen, V3::splat(plane.shading_normal), shading_normal);
                plane_lanes |= nearer;
                sphere_lanes &= !nearer;
                let id = plane_ids + index as u32;
                for lane in set_lanes(nearer) {
                    (ids[lane], material[lane]) = (id, *plane_material);
                }
            }
        }
        let mut surface = match (sphere_lanes != 0, plane_lanes != 0) {
            (_, false) => Sphere::surface_lanes(center, radius, rays, nearest),
            (false, true) => Plane::surface_lanes(normal, offset, shading_normal, rays, nearest),
            (true, true) => SurfaceLanes::select(
                mask::<I>(plane_lanes),
                &Plane::surface_lanes(normal, offset, shading_normal, rays, nearest),
                &Sphere::surface_lanes(center, radius, rays, nearest),
            ),
        };
        let mut hits = sphere_lanes | plane_lanes;
        let candidates = self.rest_candidates::<I>(rays, active);
        if candidates != 0 {
            let scalar_rays = rays.rays();
            let mut others = [None; LANES];
            let mut t = [0.0; LANES];
            nearest.store(&mut t);
            let found = self.closest_rest_packet::<I>(&scalar_rays, candidates, &t, &ids);
            for k in set_lanes(candidates) {
                if let Some(found) = found[k] {
                    let intersection = self.intersection(&scalar_rays[k], found);
                    others[k] = Some(intersection.surface);
                    material[k] = intersection.material;
                    hits |= 1 << k;
                }
            }
            if others.iter().any(Option::is_some) {
                surface = surface.with_lanes(&others);
            }
        }
        HitLanes { hits, surface, material }
    }

    /// [`Aggregate::occluded`] for each ray of `rays` whose bit is set in `active`, each with its
    /// own `t_max`: a bit per blocked ray.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn occluded_packet<I: Isa>(&self, rays: &RayLanes<I>, t_max: R8<I>, active: u32) -> u32 {
        let mut blocked = 0;
        if !self.spheres.is_empty() {
            let sphere_rays = SphereRay::<I>::lanes(rays);
            for pack in &self.spheres {
                for k in set_lanes(pack.live()) {
                    if blocked == active {
                        break;
                    }
                    blocked |= pack.sphere(k).intersect_rays::<I>(&sphere_rays, t_max, active & !blocked).0 & active;
                }
            }
        }
        for (plane, _) in &self.planes {
            if blocked == active {
                return blocked;
            }
            blocked |= plane.intersect_rays::<I>(rays, t_max).0 & active;
        }
        let candidates = if blocked == active { 0 } else { self.rest_candidates::<I>(rays, active & !blocked) };
        if candidates != 0 {
            let scalar_rays = rays.rays();
            let mut limits = [0.0; LANES];
            t_max.store(&mut limits);
            for k in set_lanes(candidates) {
                if self.any_rest::<I>(&scalar_rays[k], limits[k]) {
                    blocked |= 1 << k;
                }
            }
        }
        blocked
    }

    /// For each ray of `candidates`, what [`Aggregate::closest_rest`] finds beyond the nearest
    /// sphere or plane hit so far (at `t[k]`, of object `ids[k]`). A lone object is offered the
    /// candidates as a packet ([`Object::intersect_packet`]); otherwise ray by ray.
    #[inline(always)]
    fn closest_rest_packet<I: Isa>(
        &self,
        rays: &[Ray; LANES],
        candidates: u32,
        t: &[Real; LANES],
        ids: &[u32; LANES],
    ) -> [Option<Found>; LANES] {
        let mut found = [None; LANES];
        let Rest::One { object, bounds } = &self.rest else {
            for k in set_lanes(candidates) {
                let mut closest = Closest { t: t[k], id: ids[k], found: None };
                self.closest_rest::<I>(&rays[k], &mut closest);
                found[k] = closest.found;
            }
            return found;
        };
        // The candidates that enter the object's box, as `closest_rest` tests it, packed first.
        let (mut packed, mut lanes, mut limits) = ([rays[0]; PACKET], [0; PACKET], [0.0; PACKET]);
        let mut count = 0;
        for k in set_lanes(candidates) {
            if bounds.is_none_or(|bounds| bounds.hit_by(&SlabRay::new(&rays[k]), t[k])) {
                (packed[count], lanes[count], limits[count]) = (rays[k], k, t[k]);
                count += 1;
            }
        }
        if count == 0 {
            return found;
        }
        let hits = self.traced[*object as usize].intersect_packet::<I>(&packed[..count], &limits);
        for (hit, &k) in hits.into_iter().zip(&lanes[..count]) {
            if let Some(hit) = hit {
                let mut closest = Closest { t: t[k], id: ids[k], found: None };
                closest.offer(hit.t(), *object, Found::Object(*object, hit));
                found[k] = closest.found;
            }
        }
        found
    }

    /// The rays of `active` that may meet one of the objects that are neither packed spheres nor
    /// planes: those whose bounds they may enter, when the objects have bounds to cull with.
    #[inline(always)]
    fn rest_candidates<I: Isa>(&self, rays: &RayLanes<I>, active: u32) -> u32 {
        match &self.rest {
            Rest::Nothing => 0,
            Rest::One { bounds: Some(bounds), .. } => active & RaySlabs::new(rays).may_enter(bounds),
            Rest::Few { boxes, .. } => {
                let slabs = RaySlabs::new(rays);
                let mut candidates = 0;
                for bounds in boxes.boxes() {
                    candidates |= slabs.may_enter(&bounds);
                    if candidates & active == active {
                        break;
                    }
                }
                active & candidates
            }
            Rest::One { bounds: None, .. } | Rest::Tree { .. } => active,
        }
    }
}
