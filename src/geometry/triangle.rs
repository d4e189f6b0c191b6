//! Watertight ray–triangle intersection (Woop, Benthin & Wald 2013, as pbrt-v4's
//! `IntersectTriangle`) and the surface description of a triangle hit.
//!
//! Watertight means a ray through an edge or a vertex shared by several triangles hits at least
//! one of them: there are no cracks for rays to slip through, which epsilon-based tests
//! (Möller–Trumbore) cannot promise. The test moves the ray to the origin and shears space so
//! that the ray becomes the +z axis; each edge function is then evaluated from the same two
//! transformed vertices for both triangles sharing that edge, so they agree on its sign.

use glam::Vec3Swizzles;

use super::{Ray, SurfaceHit};
use super::real::{Real, Vec3, gamma};

mod pack;

pub use pack::{
    LaneHits, PackHits, PackRay, RayHits, RayLanes, TrianglePack, intersect_pack, intersect_pack_pair,
    intersect_triangle_rays, lane_hit,
};

/// The per-ray part of the test: which axis becomes z, and the shear that makes the ray
/// direction (0, 0, 1). Computing it once per ray saves that work for every triangle tested.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    origin: Vec3,
    /// Index of the largest |direction| component, which becomes z; dividing by it is safe.
    axis_z: usize,
    /// `(−dx/dz, −dy/dz, 1/dz)` of the permuted direction.
    shear: Vec3,
}

impl TriangleRay {
    pub fn new(ray: &Ray) -> Self {
        let a = ray.direction.abs();
        // pbrt's MaxComponentIndex, including its tie-breaking towards the later axis.
        let axis_z = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let d = permute(ray.direction, axis_z);
        TriangleRay {
            origin: ray.origin,
            axis_z,
            shear: Vec3::new(-d.x / d.z, -d.y / d.z, 1.0 / d.z),
        }
    }

    /// The vertex relative to the origin, permuted and sheared into ray space (z not yet scaled).
    #[inline]
    fn ray_space(&self, p: Vec3) -> Vec3 {
        let q = permute(p - self.origin, self.axis_z);
        Vec3::new(q.x + self.shear.x * q.z, q.y + self.shear.y * q.z, q.z)
    }
}

/// Cyclic permutation that moves component `axis_z` to z, keeping the handedness.
#[inline]
fn permute(v: Vec3, axis_z: usize) -> Vec3 {
    match axis_z {
        0 => v.yzx(),
        1 => v.zxy(),
        _ => v,
    }
}

/// Where on the triangle the ray hit: `point = b0·p0 + b1·p1 + b2·p2` at parameter `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: Real,
    pub b0: Real,
    pub b1: Real,
    pub b2: Real,
}

/// The edge function `a.x·b.y − a.y·b.x`, in f64.
///
/// Woop et al. recompute the edge functions in double precision when one comes out exactly
/// zero in single precision. Doing it always is cheaper than the branch and stronger: products
/// of two f32 values are exact in f64, so every sign is exact, not only the zero ones, and the
/// value is exactly antisymmetric, so two triangles sharing an edge always see opposite signs.
/// With `Real = f64` this is the plain double-precision computation, as in pbrt.
#[inline]
fn edge_function(a: Vec3, b: Vec3) -> Real {
    (a.x as f64 * b.y as f64 - a.y as f64 * b.x as f64) as Real
}

/// The hit of the ray with the triangle `p0 p1 p2` in `(0, t_max]`, if any.
///
/// Zero-area triangles never hit. A hit whose `t` is too close to 0 for its sign to be certain,
/// given the rounding error of the computation (pbrt's `deltaT` bound), is rejected: that is
/// the ray leaving the surface it starts on.
#[inline]
pub fn intersect_triangle(
    ray: &TriangleRay,
    t_max: Real,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
) -> Option<TriangleHit> {
    if (p2 - p0).cross(p1 - p0).length_squared() == 0.0 {
        return None;
    }
    let (p0t, p1t, p2t) = (ray.ray_space(p0), ray.ray_space(p1), ray.ray_space(p2));
    let e0 = edge_function(p1t, p2t);
    let e1 = edge_function(p2t, p0t);
    let e2 = edge_function(p0t, p1t);
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    let z = Vec3::new(p0t.z, p1t.z, p2t.z) * ray.shear.z;
    let t_scaled = e0 * z.x + e1 * z.y + e2 * z.z;
    // Written so that a NaN determinant (degenerate ray direction) falls through to a miss.
    let in_front = (det > 0.0 && t_scaled > 0.0) || (det < 0.0 && t_scaled < 0.0);
    if !in_front {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Compared as computed, not as `t_scaled` against `t_max · det`: whether a hit counts then
    // depends on its `t` alone, as the packed test and the closest-hit tie rule need.
    if t.is_nan() || t > t_max {
        return None;
    }

    // pbrt's bounds, with one correction: the shear's x and y terms are bounded by the
    // *unscaled* z (|shear.x|, |shear.y| ≤ 1), while t uses z scaled by 1/d.z. pbrt uses the
    // scaled z for both, which is the same for its unit-length rays, but an instance's object-
    // space ray has length 1/scale: the bound then grew with the instance's scale until it
    // rejected every hit on a mesh scaled by 3000, and shrank below the true error for meshes
    // scaled down.
    let max_zt = z.abs().max_element();
    let max_unscaled_zt = Vec3::new(p0t.z, p1t.z, p2t.z).abs().max_element();
    let max_xt = Vec3::new(p0t.x, p1t.x, p2t.x).abs().max_element();
    let max_yt = Vec3::new(p0t.y, p1t.y, p2t.y).abs().max_element();
    let delta_z = gamma(3) * max_zt;
    let delta_x = gamma(5) * (max_xt + max_unscaled_zt);
    let delta_y = gamma(5) * (max_yt + max_unscaled_zt);
    let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = Vec3::new(e0, e1, e2).abs().max_element();
    let delta_t =
        3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    if t.is_nan() || t <= delta_t {
        return None;
    }
    Some(TriangleHit {
        t,
        b0: e0 * inv_det,
        b1: e1 * inv_det,
        b2: e2 * inv_det,
    })
}

/// Describes the hit surface for shading and for spawning secondary rays.
///
/// The geometric normal is `normalize(cross(p1 − p0, p2 − p0))`, so the vertex order decides
/// which side is the front, as in the assignment; it is never flipped towards the ray because
/// shading is one-sided. The shading normal interpolates `vertex_normals` barycentrically and
/// falls back to the geometric normal when that interpolation is zero or not finite.
pub fn triangle_surface(
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    vertex_normals: Option<[Vec3; 3]>,
    hit: &TriangleHit,
) -> SurfaceHit {
    let (w0, w1, w2) = (p0 * hit.b0, p1 * hit.b1, p2 * hit.b2);
    // Hits only come from triangles with a nonzero cross product, whose normal always exists;
    // the zero vector stands in for the rest rather than a NaN.
    let geometric_normal = face_normal(p0, p1, p2).unwrap_or(Vec3::ZERO);
    let shading_normal = vertex_normals
        .and_then(|[n0, n1, n2]| normalize(n0 * hit.b0 + n1 * hit.b1 + n2 * hit.b2))
        .unwrap_or(geometric_normal);
    SurfaceHit {
        t: hit.t,
        point: w0 + w1 + w2,
        point_error: gamma(7) * (w0.abs() + w1.abs() + w2.abs()),
        geometric_normal,
        shading_normal,
    }
}

/// The unit normal `normalize(cross(p1 − p0, p2 − p0))`, or `None` for a degenerate triangle.
///
/// The edges are divided by their largest component first, so the cross product neither
/// overflows for huge triangles nor underflows for tiny ones.
pub fn face_normal(p0: Vec3, p1: Vec3, p2: Vec3) -> Option<Vec3> {
    let (a, b) = (p1 - p0, p2 - p0);
    let scale = a.abs().max(b.abs()).max_element();
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    normalize((a / scale).cross(b / scale))
}

/// `v / |v|`, or `None` when `v` is zero or not finite. Scaling by the largest component first
/// keeps `|v|²` from underflowing or overflowing.
pub fn normalize(v: Vec3) -> Option<Vec3> {
    let largest = v.abs().max_element();
    if !(largest > 0.0 && v.is_finite()) {
        return None;
    }
    let scaled = v / largest;
    Some(scaled / scaled.length())
}

#[cfg(test)]
mod tests {
    use super::*;

    const P0: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    const P1: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    const P2: Vec3 = Vec3::new(0.0, 1.0, 0.0);

    fn shoot(origin: Vec3, direction: Vec3, t_max: Real) -> Option<TriangleHit> {
        intersect_triangle(
            &TriangleRay::new(&Ray::new(origin, direction)),
            t_max,
            P0,
            P1,
            P2,
        )
    }

    #[test]
    fn hit_reports_t_and_barycentrics() {
        let hit = shoot(
            Vec3::new(0.25, 0.5, 2.0),
            Vec3::new(0.0, 0.0, -0.5),
            Real::INFINITY,
        )
        .expect("hit");
        assert!((hit.t - 4.0).abs() < 1e-6);
        assert!((hit.b0 - 0.25).abs() < 1e-6);
        assert!((hit.b1 - 0.25).abs() < 1e-6);
        assert!((hit.b2 - 0.5).abs() < 1e-6);
        let surface = triangle_surface(P0, P1, P2, None, &hit);
        assert!((surface.point - Vec3::new(0.25, 0.5, 0.0)).length() < 1e-6);
        assert_eq!(surface.geometric_normal, Vec3::Z);
        assert_eq!(surface.shading_normal, Vec3::Z);
    }

    #[test]
    fn back_side_hits_too_and_normal_is_not_flipped() {
        let hit = shoot(Vec3::new(0.2, 0.2, -1.0), Vec3::Z, Real::INFINITY).expect("hit");
        assert_eq!(
            triangle_surface(P0, P1, P2, None, &hit).geometric_normal,
            Vec3::Z
        );
    }

    #[test]
    fn misses() {
        assert!(
            shoot(Vec3::new(0.6, 0.6, 1.0), Vec3::NEG_Z, Real::INFINITY).is_none(),
            "outside"
        );
        assert!(
            shoot(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, Real::INFINITY).is_none(),
            "behind"
        );
        assert!(
            shoot(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.99).is_none(),
            "beyond t_max"
        );
        assert!(
            shoot(Vec3::new(-1.0, 0.2, 0.0), Vec3::X, Real::INFINITY).is_none(),
            "in plane"
        );
        assert!(
            shoot(Vec3::new(0.2, 0.2, 1.0), Vec3::ZERO, Real::INFINITY).is_none(),
            "no dir"
        );
        assert!(
            shoot(Vec3::new(0.2, 0.2, 1.0), Vec3::NAN, Real::INFINITY).is_none(),
            "NaN dir"
        );
    }

    #[test]
    fn zero_area_triangles_never_hit() {
        let ray = TriangleRay::new(&Ray::new(Vec3::new(0.5, 0.0, 1.0), Vec3::NEG_Z));
        let collinear = intersect_triangle(&ray, Real::INFINITY, P0, P1, Vec3::new(2.0, 0.0, 0.0));
        assert!(collinear.is_none());
        assert!(intersect_triangle(&ray, Real::INFINITY, P1, P1, P1).is_none());
    }

    #[test]
    fn shading_normal_interpolates_and_falls_back() {
        let hit = TriangleHit {
            t: 1.0,
            b0: 0.5,
            b1: 0.5,
            b2: 0.0,
        };
        let normals = [Vec3::X, Vec3::Y, Vec3::Z];
        let shading = triangle_surface(P0, P1, P2, Some(normals), &hit).shading_normal;
        assert!((shading - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6);
        let opposite = [Vec3::X, Vec3::NEG_X, Vec3::Z];
        assert_eq!(
            triangle_surface(P0, P1, P2, Some(opposite), &hit).shading_normal,
            Vec3::Z
        );
        let nan = [Vec3::NAN, Vec3::X, Vec3::Z];
        assert_eq!(
            triangle_surface(P0, P1, P2, Some(nan), &hit).shading_normal,
            Vec3::Z
        );
    }

    #[test]
    fn face_normal_survives_extreme_scales() {
        for scale in [1e-30, 1e-4, 1.0, 1e6, 1e30] {
            let n = face_normal(P0 * scale, P1 * scale, P2 * scale).expect("normal");
            assert!((n - Vec3::Z).length() < 1e-6, "scale {scale}: {n}");
        }
        assert_eq!(face_normal(P0, P1, P1), None);
    }

    /// Origins exactly on the triangle's plane (x + y + z = 3000, coordinates exact in f32):
    /// the true hit is at t = 0, and any positive t comes from rounding in the shear and edge
    /// functions, which pbrt's `deltaT` bound must reject.
    #[test]
    fn hits_too_close_to_the_origin_to_be_certain_are_rejected() {
        let (a, b, c) = (
            Vec3::splat(1000.0),
            Vec3::new(1010.0, 990.0, 1000.0),
            Vec3::new(1000.0, 1010.0, 990.0),
        );
        let mut checked = 0;
        for k in 1..63 {
            for m in 1..(64 - k) {
                let (u, v) = (k as Real / 64.0, m as Real / 64.0);
                let origin = Vec3::new(
                    1000.0 + 10.0 * u,
                    1000.0 - 10.0 * u + 10.0 * v,
                    1000.0 - 10.0 * v,
                );
                assert_eq!(origin.x + origin.y + origin.z, 3000.0);
                let direction =
                    Vec3::new(0.3 + u, -0.7 + v, 1.1 - u * v) * if k % 2 == 0 { 1.0 } else { -1.0 };
                let ray = TriangleRay::new(&Ray::new(origin, direction));
                let hit = intersect_triangle(&ray, Real::INFINITY, a, b, c);
                assert!(
                    hit.is_none(),
                    "origin {origin}, direction {direction}: {hit:?}"
                );
                checked += 1;
            }
        }
        assert!(checked > 1000);
    }
}
