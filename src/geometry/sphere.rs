//! Spheres, intersected with the numerically stable quadratic of pbrt-v4 and Ray Tracing Gems
//! ch. 7 ("Precision Improvements for Ray/Sphere Intersection").

use super::aabb::Aabb;
use super::ray::{Ray, SurfaceHit};
use super::lanes::{Mask, RayLanes, SurfaceLanes, V3};
use super::real::{R8, Real, Vec3, gamma};
use crate::simd::{Isa, Lanes, MaskOps};

#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: Real,
}

impl Sphere {
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        Aabb { min: self.center - r, max: self.center + r }
    }

    /// The nearest `t` in `(0, t_max]` where the ray meets the sphere.
    ///
    /// The textbook `b² − 4ac` cancels catastrophically when the ray passes far from the centre
    /// relative to the radius (or the sphere is tiny and far away); computing the discriminant
    /// from the distance between the centre and the ray's closest approach avoids that, and the
    /// `q`-form of the roots avoids cancellation between `−b` and the root.
    pub fn intersect(&self, ray: &Ray, t_max: Real) -> Option<Real> {
        if self.radius <= 0.0 {
            return None;
        }
        let origin = ray.origin - self.center;
        let a = ray.direction.length_squared();
        if a == 0.0 {
            return None;
        }
        let b = 2.0 * ray.direction.dot(origin);
        let c = origin.length_squared() - self.radius * self.radius;
        let closest_approach = (origin - ray.direction * (b / (2.0 * a))).length();
        let discriminant = 4.0 * a * (self.radius + closest_approach) * (self.radius - closest_approach);
        if discriminant < 0.0 {
            return None;
        }
        let root = discriminant.sqrt();
        let q = if b < 0.0 { -0.5 * (b - root) } else { -0.5 * (b + root) };
        if q == 0.0 {
            return None;
        }
        let (mut t0, mut t1) = (q / a, c / q);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        // The nearer root in front of the origin, else the farther one: the first root with
        // `t > 0` (finite), which counts when it is within `t_max`. `SpherePack` does the same.
        let t = if t0 > 0.0 && t0.is_finite() { t0 } else { t1 };
        (t > 0.0 && t <= t_max && t.is_finite()).then_some(t)
    }

    /// The hit point is re-projected onto the sphere so that its error no longer grows with the
    /// ray parameter; what remains is bounded by pbrt's `gamma(5)·|p − c|` plus the rounding of
    /// adding the centre back.
    pub fn surface(&self, ray: &Ray, t: Real) -> SurfaceHit {
        let along = ray.at(t) - self.center;
        let length = along.length();
        let normal = if length > 0.0 { along / length } else { Vec3::Y };
        let relative = normal * self.radius;
        let point = self.center + relative;
        let point_error = gamma(5) * relative.abs() + gamma(1) * point.abs();
        SurfaceHit { t, point, point_error, geometric_normal: normal, shading_normal: normal }
    }
}

/// Spheres tested side by side in [`intersect_spheres`].
pub const SPHERE_LANES: usize = 8;

/// Up to eight spheres side by side, one per SIMD lane, for [`intersect_spheres`].
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct SpherePack {
    /// `center[axis][lane]`.
    center: [[Real; SPHERE_LANES]; 3],
    radius: [Real; SPHERE_LANES],
    /// Each lane's sphere, as the caller numbers it.
    ids: [u32; SPHERE_LANES],
    /// Bit per lane holding a sphere that can be hit: not padding, a positive radius.
    live: u32,
}

impl SpherePack {
    /// Packs one to eight `(id, sphere)`; the remaining lanes are padding that no ray hits.
    pub fn new(spheres: &[(u32, Sphere)]) -> SpherePack {
        assert!((1..=SPHERE_LANES).contains(&spheres.len()), "a pack holds one to eight spheres");
        let mut pack = SpherePack {
            center: [[0.0; SPHERE_LANES]; 3],
            radius: [0.0; SPHERE_LANES],
            ids: [u32::MAX; SPHERE_LANES],
            live: 0,
        };
        for (lane, (id, sphere)) in spheres.iter().enumerate() {
            for axis in 0..3 {
                pack.center[axis][lane] = sphere.center[axis];
            }
            pack.radius[lane] = sphere.radius;
            pack.ids[lane] = *id;
            if sphere.radius > 0.0 {
                pack.live |= 1 << lane;
            }
        }
        pack
    }

    pub fn ids(&self) -> &[u32; SPHERE_LANES] {
        &self.ids
    }
}

/// The per-ray part of [`intersect_spheres`]: one ray splatted across the lanes, or a ray per
/// lane ([`SphereRay::lanes`]).
pub struct SphereRay<I: Isa> {
    origin: [R8<I>; 3],
    direction: [R8<I>; 3],
    /// `|d|²`, `2·|d|²` and `4·|d|²`, as [`Sphere::intersect`] computes them.
    a: R8<I>,
    two_a: R8<I>,
    four_a: R8<I>,
    /// Lanes whose direction has zero length, which hit nothing.
    still: Mask<I>,
}

impl<I: Isa> SphereRay<I> {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        SphereRay::lanes(&RayLanes { origin: V3::splat(ray.origin), direction: V3::splat(ray.direction) })
    }

    /// A ray per lane.
    #[inline(always)]
    pub fn lanes(rays: &RayLanes<I>) -> Self {
        let (o, d) = (rays.origin, rays.direction);
        let a = d.length_squared();
        SphereRay {
            origin: [o.x, o.y, o.z],
            direction: [d.x, d.y, d.z],
            a,
            two_a: R8::<I>::splat(2.0) * a,
            four_a: R8::<I>::splat(4.0) * a,
            still: a.eq(R8::<I>::splat(0.0)),
        }
    }

    /// The lanes whose line passes the sphere of `center` and `radius` wide enough that no
    /// rounding brings it within reach: `|o × d|² > (r²(1 + m) + |o|²·m(1 + m))·|d|²` with
    /// `o` the origin relative to the centre and `m` [`SKIP_MARGIN`]. The right side bounds
    /// `(r + m·|o|)²·|d|²` from above, so the line's distance `|o × d| / |d|` exceeds
    /// `r + m·|o|`. Overflow and NaN make the comparison false: such lanes are not skipped.
    #[inline(always)]
    fn pass_wide_of(&self, center: V3<I>, radius: Real) -> u32 {
        let splat = R8::<I>::splat;
        let [dx, dy, dz] = self.direction;
        let (ox, oy, oz) = (self.origin[0] - center.x, self.origin[1] - center.y, self.origin[2] - center.z);
        let (cx, cy, cz) = (oy * dz - oz * dy, oz * dx - ox * dz, ox * dy - oy * dx);
        let off_line = cx * cx + cy * cy + cz * cz;
        let margin = SKIP_MARGIN;
        let reach = splat(radius * radius * (1.0 + margin)) + (ox * ox + oy * oy + oz * oz) * splat(margin * (1.0 + margin));
        off_line.gt(reach * self.a).bits()
    }
}

/// [`Sphere::intersect`] on eight lanes, each a sphere and a ray (either may be the same in
/// every lane), with the same operations in the same order: a bit per lane hit in `(0, t_max]`,
/// and each lane's `t`.
#[inline(always)]
fn intersect_lanes<I: Isa>(center: [R8<I>; 3], radius: R8<I>, ray: &SphereRay<I>, t_max: R8<I>) -> (u32, R8<I>) {
    let splat = R8::<I>::splat;
    let zero = splat(0.0);
    let [dx, dy, dz] = ray.direction;
    let ox = ray.origin[0] - center[0];
    let oy = ray.origin[1] - center[1];
    let oz = ray.origin[2] - center[2];
    let b = splat(2.0) * (dx * ox + dy * oy + dz * oz);
    let c = (ox * ox + oy * oy + oz * oz) - radius * radius;
    let along = b / ray.two_a;
    let (px, py, pz) = (ox - dx * along, oy - dy * along, oz - dz * along);
    let closest_approach = (px * px + py * py + pz * pz).sqrt();
    let discriminant = ray.four_a * (radius + closest_approach) * (radius - closest_approach);
    let root = discriminant.sqrt();
    let q = R8::<I>::select(b.lt(zero), splat(-0.5) * (b - root), splat(-0.5) * (b + root));
    let (r0, r1) = (q / ray.a, c / q);
    let swap = r0.gt(r1);
    let (t0, t1) = (R8::<I>::select(swap, r1, r0), R8::<I>::select(swap, r0, r1));
    let infinity = splat(Real::INFINITY);
    let t = R8::<I>::select(t0.gt(zero).and(t0.abs().lt(infinity)), t0, t1);
    let hit = t
        .gt(zero)
        .and(t.le(t_max))
        .and(t.abs().lt(infinity))
        .and_not(discriminant.lt(zero))
        .and_not(q.eq(zero))
        .and_not(ray.still);
    (hit.bits(), t)
}

/// [`Sphere::intersect`] on the lanes of `pack`: a bit per lane hit in `(0, t_max]`, and each
/// lane's `t`.
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn intersect_spheres<I: Isa>(pack: &SpherePack, ray: &SphereRay<I>, t_max: Real) -> (u32, R8<I>) {
    let center = [R8::<I>::load(&pack.center[0]), R8::<I>::load(&pack.center[1]), R8::<I>::load(&pack.center[2])];
    let (hits, t) = intersect_lanes(center, R8::<I>::load(&pack.radius), ray, R8::<I>::splat(t_max));
    (hits & pack.live, t)
}

/// How far outside a sphere, as a fraction of the radius and of the distance from the ray's
/// origin to the centre, a ray's line must pass for [`Sphere::intersect_rays`] to skip the ray.
/// Rounding moves [`Sphere::intersect`]'s closest approach by about 20 ulps of that distance
/// (the cancellation in `o − d·(b/2a)`), so a skipped ray is one whose discriminant is negative:
/// one the full test misses.
const SKIP_MARGIN: Real = 1.0e-4;

impl Sphere {
    /// [`Sphere::intersect`] for a ray per lane of `rays`, each with its own `t_max`; only the
    /// lanes of `active` count. When every one of them passes wide of the sphere, the test (three
    /// divisions and two square roots a lane) is skipped for a cheaper one.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn intersect_rays<I: Isa>(&self, rays: &SphereRay<I>, t_max: R8<I>, active: u32) -> (u32, R8<I>) {
        if self.radius <= 0.0 {
            return (0, t_max);
        }
        let c = V3::<I>::splat(self.center);
        if rays.pass_wide_of(c, self.radius) & active == active {
            return (0, t_max);
        }
        intersect_lanes([c.x, c.y, c.z], R8::<I>::splat(self.radius), rays, t_max)
    }

    /// [`Sphere::surface`] for a ray per lane, each lane's sphere given by its centre and radius.
    #[inline(always)]
    pub fn surface_lanes<I: Isa>(center: V3<I>, radius: R8<I>, rays: &RayLanes<I>, t: R8<I>) -> SurfaceLanes<I> {
        let along = rays.at(t) - center;
        let length = along.length();
        let normal = V3::select(length.gt(R8::<I>::splat(0.0)), along.divide(length), V3::splat(Vec3::Y));
        let relative = normal.scale(radius);
        let point = center + relative;
        let point_error = relative.abs().scale(R8::<I>::splat(gamma(5))) + point.abs().scale(R8::<I>::splat(gamma(1)));
        SurfaceLanes { t, point, point_error, geometric_normal: normal, shading_normal: normal }
    }
}

impl SpherePack {
    /// The sphere in `lane`.
    pub fn sphere(&self, lane: usize) -> Sphere {
        let center = Vec3::new(self.center[0][lane], self.center[1][lane], self.center[2][lane]);
        Sphere { center, radius: self.radius[lane] }
    }

    /// Bit per lane holding a sphere that can be hit.
    pub fn live(&self) -> u32 {
        self.live
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_sphere() -> Sphere {
        Sphere { center: Vec3::ZERO, radius: 1.0 }
    }

    #[test]
    fn hits_front_then_back_from_inside() {
        let s = unit_sphere();
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!((s.intersect(&ray, Real::INFINITY).unwrap() - 4.0).abs() < 1e-6);
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert!((s.intersect(&inside, Real::INFINITY).unwrap() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn respects_t_max_and_misses() {
        let s = unit_sphere();
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(s.intersect(&ray, 3.9).is_none());
        let miss = Ray::new(Vec3::new(0.0, 1.01, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(s.intersect(&miss, Real::INFINITY).is_none());
    }

    #[test]
    fn tiny_far_sphere_is_hit_where_the_naive_quadratic_cancels() {
        let s = Sphere { center: Vec3::new(0.0, 0.0, -1.0e4), radius: 1.0e-2 };
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.005, -1.0e4).normalize());
        let t = s.intersect(&ray, Real::INFINITY).expect("the ray passes through the sphere");
        let hit = s.surface(&ray, t);
        let off_surface = ((hit.point - s.center).length() - s.radius).abs();
        assert!(off_surface <= hit.point_error.length(), "{off_surface} > {:?}", hit.point_error);
    }

    #[test]
    fn zero_radius_and_zero_direction_never_hit() {
        let point = Sphere { center: Vec3::ZERO, radius: 0.0 };
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(point.intersect(&ray, Real::INFINITY).is_none());
        let still = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        assert!(unit_sphere().intersect(&still, Real::INFINITY).is_none());
    }

    #[test]
    fn surface_point_lies_on_sphere_within_its_error_bound() {
        let s = Sphere { center: Vec3::new(3.0, -2.0, 7.0), radius: 2.5 };
        let ray = Ray::new(Vec3::new(0.3, 0.1, -20.0), (s.center - Vec3::new(0.0, 0.0, -20.0)).normalize());
        let t = s.intersect(&ray, Real::INFINITY).unwrap();
        let hit = s.surface(&ray, t);
        assert!((hit.geometric_normal.length() - 1.0).abs() < 1e-6);
        let off = ((hit.point - s.center).length() - s.radius).abs();
        assert!(off <= hit.point_error.length() + 1e-6, "{off}");
    }

    /// Eight rays through [`Sphere::intersect_rays`] on one SIMD path: the hit bits, each lane's
    /// `t`, and whether the packet was skipped as passing wide.
    struct EightRays(Sphere, [Ray; 8]);

    impl crate::simd::Kernel for EightRays {
        type Output = (u32, [Real; 8], bool);
        #[inline(always)]
        fn run<I: Isa>(self) -> Self::Output {
            let EightRays(sphere, rays) = self;
            let lanes = RayLanes {
                origin: V3::gather(&rays.map(|ray| ray.origin)),
                direction: V3::gather(&rays.map(|ray| ray.direction)),
            };
            let sphere_rays = SphereRay::<I>::lanes(&lanes);
            let (hits, t) = sphere.intersect_rays::<I>(&sphere_rays, R8::<I>::splat(Real::INFINITY), 0xff);
            let mut each = [0.0; 8];
            t.store(&mut each);
            (hits, each, sphere_rays.pass_wide_of(V3::splat(sphere.center), sphere.radius) == 0xff)
        }
    }

    #[test]
    fn rays_in_lanes_hit_as_each_does_alone_even_where_they_graze() {
        // A stateless hash for the test's directions.
        let unit = |seed: u64| {
            let z = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15);
            ((z ^ (z >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9) >> 40) as Real / (1u64 << 24) as Real
        };
        let (mut skipped, mut tested) = (0, 0);
        let deltas = [-1.0e-3, -1.0e-6, 0.0, 1.0e-6, 1.0e-5, 2.0e-4, 1.0e-3, 0.01, 0.03, 0.05, 0.1, 0.15];
        for (case, &scale) in [1.0e-3, 1.0, 37.0, 1.0e4].iter().enumerate() {
            let sphere = Sphere { center: Vec3::new(0.3, -1.2, 2.0) * scale, radius: 0.7 * scale };
            // Origins from just outside the sphere to far away, and lines passing the centre at
            // (1 + δ) radii: on both sides of the surface and of the skip's margin.
            for (row, (&away, &delta)) in [1.2, 3.0, 25.0, 2_000.0]
                .iter()
                .flat_map(|away| deltas.iter().map(move |delta| (away, delta)))
                .enumerate()
            {
                let rays = std::array::from_fn(|lane| {
                    let seed = (case * 1_000 + row * 10 + lane) as u64;
                    let towards = Vec3::new(unit(seed) - 0.5, unit(seed + 7_919) - 0.5, unit(seed + 104_729) + 0.1).normalize();
                    let across = towards.any_orthonormal_vector();
                    let distance = away * sphere.radius * (1.0 + 0.1 * unit(seed + 3));
                    let sine = sphere.radius * (1.0 + delta) / distance;
                    let origin = sphere.center + towards * distance;
                    Ray::new(origin, (-towards * (1.0 - sine * sine).sqrt() + across * sine) * (0.5 + unit(seed + 11)))
                });
                for path in crate::simd::available() {
                    let (hits, t, wide) = crate::simd::dispatch_on(path, EightRays(sphere, rays)).expect("available");
                    if wide {
                        skipped += 1;
                    } else {
                        tested += 1;
                    }
                    for (lane, ray) in rays.iter().enumerate() {
                        let alone = sphere.intersect(ray, Real::INFINITY);
                        let in_lanes = (hits & (1 << lane) != 0).then_some(t[lane]);
                        assert_eq!(
                            in_lanes.map(Real::to_bits),
                            alone.map(Real::to_bits),
                            "scale {scale}, δ {delta}, lane {lane} on {path:?}"
                        );
                    }
                }
            }
        }
        assert!(skipped > 0 && tested > 0, "skipped {skipped}, tested {tested}");
    }
}
