//! The watertight test of [`super::intersect_triangle`] on several lanes at once: four triangles
//! against one ray ([`intersect_pack`], for a mesh's leaves) and one triangle against eight rays
//! ([`intersect_triangle_rays`], for packets). Lane by lane the operations are the one-ray
//! test's, so every `t` and barycentric is what that test gives.

use super::super::real::{R4, R8, Real, Vec3, edge4, edge8, gamma, join4, lane_pair, lane_splat};
use super::super::Ray;
use super::super::lanes;
use super::*;
use crate::simd::{Isa, Lanes, MaskOps};

/// Four triangles side by side, one per SIMD lane, for [`intersect_pack`]: the same watertight
/// test as [`intersect_triangle`], operation for operation, on four triangles at once.
///
/// The triangles are consecutive in the mesh's numbering, so one index names them all: 160
/// bytes with `f32`, aligned so that a pack always spans exactly three cache lines (with an
/// index per lane, 176 bytes spanned three or four).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct TrianglePack {
    /// `corners[vertex][axis][lane]`.
    corners: [[[Real; 4]; 3]; 3],
    /// The first lane's triangle, as the mesh numbers it; lane `k` holds triangle `first + k`.
    first: u32,
    /// Bit per lane holding a triangle that can be hit: not padding, not of zero area.
    live: u32,
}

impl TrianglePack {
    /// Packs one to four triangles, numbered `first` onwards; the remaining lanes are padding
    /// that no ray hits. Zero-area triangles are kept (their numbers stay in place) but never
    /// hit, as in [`intersect_triangle`].
    pub fn new(first: u32, triangles: &[[Vec3; 3]]) -> TrianglePack {
        assert!((1..=4).contains(&triangles.len()), "a pack holds one to four triangles");
        let mut pack = TrianglePack { corners: [[[0.0; 4]; 3]; 3], first, live: 0 };
        for (lane, &[p0, p1, p2]) in triangles.iter().enumerate() {
            for (vertex, p) in [p0, p1, p2].into_iter().enumerate() {
                for axis in 0..3 {
                    pack.corners[vertex][axis][lane] = p[axis];
                }
            }
            if (p2 - p0).cross(p1 - p0).length_squared() != 0.0 {
                pack.live |= 1 << lane;
            }
        }
        pack
    }

    /// The triangle in `lane`, as the mesh numbers it (meaningless for padding lanes).
    #[inline(always)]
    pub fn id(&self, lane: usize) -> u32 {
        self.first + lane as u32
    }
}

/// The axes [`permute`] puts in x, y and z: the cyclic order that moves `axis_z` to z.
#[inline(always)]
fn permutation(axis_z: usize) -> [usize; 3] {
    match axis_z {
        0 => [1, 2, 0],
        1 => [2, 0, 1],
        _ => [0, 1, 2],
    }
}

/// [`TriangleRay`] splatted across the lanes of a pack test.
#[derive(Clone, Copy)]
pub struct PackRay<I: Isa> {
    /// Which axes become x, y and z (the permutation of [`TriangleRay`]).
    axes: [usize; 3],
    /// The origin's permuted components.
    origin: [R4<I>; 3],
    shear: [R4<I>; 3],
}

impl<I: Isa> PackRay<I> {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let triangle_ray = TriangleRay::new(ray);
        let axes = permutation(triangle_ray.axis_z);
        let shear = triangle_ray.shear;
        PackRay {
            axes,
            origin: [
                R4::<I>::splat(ray.origin[axes[0]]),
                R4::<I>::splat(ray.origin[axes[1]]),
                R4::<I>::splat(ray.origin[axes[2]]),
            ],
            shear: [R4::<I>::splat(shear.x), R4::<I>::splat(shear.y), R4::<I>::splat(shear.z)],
        }
    }
}

/// What a lane-parallel triangle test found: the lanes hit within the limit, and per lane the
/// values a hit is made of (`t`, and the edge functions and inverse determinant its barycentrics
/// come from). `L` is four lanes for [`intersect_pack`] (four triangles, one ray) and eight for
/// [`intersect_triangle_rays`] (one triangle, eight rays).
pub struct LaneHits<L> {
    /// Bit per lane hit in `(0, t_max]`.
    pub lanes: u32,
    t: L,
    edges: [L; 3],
    inv_det: L,
}

/// What [`intersect_pack`] found.
pub type PackHits<I> = LaneHits<R4<I>>;

/// What [`intersect_triangle_rays`] found.
pub type RayHits<I> = LaneHits<R8<I>>;

impl<L: Lanes<Elem = Real>> LaneHits<L> {
    /// Each lane's `t`; meaningful for `lanes` only.
    #[inline(always)]
    pub fn t(&self) -> L {
        self.t
    }

    /// What each lane's hit is made of: `t`, the three edge functions and the inverse
    /// determinant; meaningful for `lanes` only. `N` is the lane count.
    #[inline(always)]
    pub fn values<const N: usize>(&self) -> [[Real; N]; 5] {
        debug_assert_eq!(N, L::N);
        let mut values = [[0.0; N]; 5];
        self.t.store(&mut values[0]);
        self.edges[0].store(&mut values[1]);
        self.edges[1].store(&mut values[2]);
        self.edges[2].store(&mut values[3]);
        self.inv_det.store(&mut values[4]);
        values
    }
}

/// Lane `lane` of [`LaneHits::values`], as [`intersect_triangle`] would
/// report it.
#[inline(always)]
pub fn lane_hit<const N: usize>(values: &[[Real; N]; 5], lane: usize) -> TriangleHit {
    let inv_det = values[4][lane];
    TriangleHit { t: values[0][lane], b0: values[1][lane] * inv_det, b1: values[2][lane] * inv_det, b2: values[3][lane] * inv_det }
}

/// Vertex `v` of each lane of `pack`, relative to the origin, permuted and sheared.
#[inline(always)]
fn pack_vertex<I: Isa>(pack: &TrianglePack, ray: &PackRay<I>, v: usize) -> [R4<I>; 3] {
    let [kx, ky, kz] = ray.axes;
    let corner = &pack.corners[v];
    let qx = R4::<I>::load(&corner[kx]) - ray.origin[0];
    let qy = R4::<I>::load(&corner[ky]) - ray.origin[1];
    let qz = R4::<I>::load(&corner[kz]) - ray.origin[2];
    [qx + ray.shear[0] * qz, qy + ray.shear[1] * qz, qz]
}

/// [`edge_function`] on four lanes.
#[inline(always)]
fn pack_edge<I: Isa>(a: &[R4<I>; 3], b: &[R4<I>; 3]) -> R4<I> {
    edge4::<I>(a[0], a[1], b[0], b[1])
}

/// `max(|a|, max(|b|, |c|))` per lane (`Vec3::abs().max_element()`).
#[inline(always)]
fn max_abs3<L: Lanes>(a: L, b: L, c: L) -> L {
    a.abs().max(b.abs().max(c.abs()))
}

/// [`intersect_triangle`] on the four lanes of `pack`, with the same operations in the same
/// order, so that each lane's `t` and barycentrics are bit for bit those of the one-triangle test.
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn intersect_pack<I: Isa>(pack: &TrianglePack, ray: &PackRay<I>, t_max: Real) -> PackHits<I> {
    let (p0, p1, p2) = (pack_vertex(pack, ray, 0), pack_vertex(pack, ray, 1), pack_vertex(pack, ray, 2));
    let (e0, e1, e2) = (pack_edge::<I>(&p1, &p2), pack_edge::<I>(&p2, &p0), pack_edge::<I>(&p0, &p1));
    finish_test([p0, p1, p2], [e0, e1, e2], ray.shear[2], R4::<I>::splat(t_max), pack.live)
}

/// Up to eight rays whose triangle tests share a permutation (the same axis becomes z), one
/// per lane, for [`intersect_triangle_rays`].
pub struct RayLanes<I: Isa> {
    axes: [usize; 3],
    /// Each ray's origin, permuted.
    origin: [R8<I>; 3],
    shear: [R8<I>; 3],
}

impl<I: Isa> RayLanes<I> {
    /// `None` when the rays do not all turn the same axis into z (or there are none or more
    /// than eight); lanes past the last ray repeat it.
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Option<Self> {
        if rays.is_empty() || rays.len() > 8 {
            return None;
        }
        RayLanes::from_lanes(&lanes::RayLanes::gather(rays))
    }

    /// [`RayLanes::new`] of rays already side by side: [`TriangleRay::new`] lane by lane.
    #[inline(always)]
    pub fn from_lanes(rays: &lanes::RayLanes<I>) -> Option<Self> {
        let d = rays.direction.abs();
        // `TriangleRay::new`'s choice of the largest component, as masks: x where it beats y
        // and z, y where it does not beat y and y beats z, z elsewhere.
        let x_beats_y = d.x.gt(d.y);
        let x_largest = x_beats_y.and(d.x.gt(d.z)).bits();
        let y_largest = d.y.gt(d.z).and_not(x_beats_y).bits();
        let axis_z = match (x_largest, y_largest) {
            (0xff, _) => 0,
            (_, 0xff) => 1,
            (0, 0) => 2,
            _ => return None,
        };
        let axes = permutation(axis_z);
        let (o, d) = ([rays.origin.x, rays.origin.y, rays.origin.z], [rays.direction.x, rays.direction.y, rays.direction.z]);
        let (dx, dy, dz) = (d[axes[0]], d[axes[1]], d[axes[2]]);
        let origin = [o[axes[0]], o[axes[1]], o[axes[2]]];
        let shear = [-dx / dz, -dy / dz, R8::<I>::splat(1.0) / dz];
        Some(RayLanes { axes, origin, shear })
    }

    /// Lane `lane`'s ray as [`PackRay::new`] makes it, for testing a pack's four triangles
    /// against that ray alone (cheaper than four tests of all eight lanes when few rays are left).
    #[inline(always)]
    pub fn pack_ray(&self, lane: usize) -> PackRay<I> {
        let (o, s) = (&self.origin, &self.shear);
        PackRay {
            axes: self.axes,
            origin: [lane_splat::<I>(o[0], lane), lane_splat::<I>(o[1], lane), lane_splat::<I>(o[2], lane)],
            shear: [lane_splat::<I>(s[0], lane), lane_splat::<I>(s[1], lane), lane_splat::<I>(s[2], lane)],
        }
    }
}

/// Vertex `v` of each triangle of `pack` twice over (lanes 0–3 and 4–7), relative to the
/// origin of the pair's ray in each half, permuted and sheared.
#[inline(always)]
fn pair_vertex<I: Isa>(pack: &TrianglePack, axes: [usize; 3], origin: &[R8<I>; 3], shear: &[R8<I>; 3], v: usize) -> [R8<I>; 3] {
    let corner = &pack.corners[v];
    let qx = twice::<I>(&corner[axes[0]]) - origin[0];
    let qy = twice::<I>(&corner[axes[1]]) - origin[1];
    let qz = twice::<I>(&corner[axes[2]]) - origin[2];
    [qx + shear[0] * qz, qy + shear[1] * qz, qz]
}

/// Four lanes repeated as eight.
#[inline(always)]
fn twice<I: Isa>(values: &[Real; 4]) -> R8<I> {
    let lanes = R4::<I>::load(values);
    join4::<I>(lanes, lanes)
}

/// [`intersect_pack`] of two rays of `rays` at once, lanes `pair[0]` and `pair[1]` with the
/// limits in those lanes of `t_max`: lanes 0–3 are the first ray against the pack's four
/// triangles, lanes 4–7 the second.
/// Lane by lane the operations of [`intersect_pack`], so each lane's hit is bit for bit that
/// test's; one test of eight lanes where two of four would repeat the work done in `f32`.
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn intersect_pack_pair<I: Isa>(pack: &TrianglePack, rays: &RayLanes<I>, pair: [usize; 2], t_max: R8<I>) -> RayHits<I> {
    let (o, s) = (&rays.origin, &rays.shear);
    let origin = [lane_pair::<I>(o[0], pair), lane_pair::<I>(o[1], pair), lane_pair::<I>(o[2], pair)];
    let shear = [lane_pair::<I>(s[0], pair), lane_pair::<I>(s[1], pair), lane_pair::<I>(s[2], pair)];
    let p0 = pair_vertex::<I>(pack, rays.axes, &origin, &shear, 0);
    let p1 = pair_vertex::<I>(pack, rays.axes, &origin, &shear, 1);
    let p2 = pair_vertex::<I>(pack, rays.axes, &origin, &shear, 2);
    let (e0, e1, e2) = (
        edge8::<I>(p1[0], p1[1], p2[0], p2[1]),
        edge8::<I>(p2[0], p2[1], p0[0], p0[1]),
        edge8::<I>(p0[0], p0[1], p1[0], p1[1]),
    );
    finish_test([p0, p1, p2], [e0, e1, e2], shear[2], lane_pair::<I>(t_max, pair), pack.live | pack.live << 4)
}

/// Vertex `v` of triangle `triangle` of `pack`, relative to each ray's origin, permuted and
/// sheared.
#[inline(always)]
fn rays_vertex<I: Isa>(pack: &TrianglePack, triangle: usize, rays: &RayLanes<I>, v: usize) -> [R8<I>; 3] {
    let [kx, ky, kz] = rays.axes;
    let corner = &pack.corners[v];
    let qx = R8::<I>::splat(corner[kx][triangle]) - rays.origin[0];
    let qy = R8::<I>::splat(corner[ky][triangle]) - rays.origin[1];
    let qz = R8::<I>::splat(corner[kz][triangle]) - rays.origin[2];
    [qx + rays.shear[0] * qz, qy + rays.shear[1] * qz, qz]
}

/// [`intersect_triangle`] of triangle `triangle` of `pack` against each ray of `rays`, the rays
/// in lanes: the same operations in the same order as the one-ray test (and as
/// [`intersect_pack`]), so each lane's hit is bit for bit that ray's. `t_max` is per ray.
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn intersect_triangle_rays<I: Isa>(
    pack: &TrianglePack,
    triangle: usize,
    rays: &RayLanes<I>,
    t_max: R8<I>,
) -> RayHits<I> {
    let (p0, p1, p2) = (rays_vertex(pack, triangle, rays, 0), rays_vertex(pack, triangle, rays, 1), rays_vertex(pack, triangle, rays, 2));
    let (e0, e1, e2) = (
        edge8::<I>(p1[0], p1[1], p2[0], p2[1]),
        edge8::<I>(p2[0], p2[1], p0[0], p0[1]),
        edge8::<I>(p0[0], p0[1], p1[0], p1[1]),
    );
    finish_test([p0, p1, p2], [e0, e1, e2], rays.shear[2], t_max, u32::MAX)
}

/// The watertight test's second half, shared by both lane layouts: from the vertices (moved,
/// permuted and sheared in x and y) and the edge functions to the lanes hit in `(0, t_max]`,
/// with the one-ray test's operations in its order. `live` masks lanes holding no triangle.
#[inline(always)]
fn finish_test<L: Lanes<Elem = Real>>(p: [[L; 3]; 3], e: [L; 3], shear_z: L, t_max: L, live: u32) -> LaneHits<L> {
    let splat = L::splat;
    let ([p0, p1, p2], [e0, e1, e2]) = (p, e);
    let zero = splat(0.0);
    let negative = e0.lt(zero).or(e1.lt(zero)).or(e2.lt(zero));
    let positive = e0.gt(zero).or(e1.gt(zero)).or(e2.gt(zero));
    let det = e0 + e1 + e2;
    let (z0, z1, z2) = (p0[2] * shear_z, p1[2] * shear_z, p2[2] * shear_z);
    let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
    let in_front = det.gt(zero).and(t_scaled.gt(zero)).or(det.lt(zero).and(t_scaled.lt(zero)));
    // Most packs are missed by every lane, seen from the edges alone: the division and the
    // error bound below are only needed for the others.
    let inside = in_front.and_not(negative.and(positive));
    if inside.bits() & live == 0 {
        return LaneHits { lanes: 0, t: zero, edges: [e0, e1, e2], inv_det: zero };
    }
    let inv_det = splat(1.0) / det;
    let t = t_scaled * inv_det;
    let candidates = inside.and(t.le(t_max));
    if candidates.bits() & live == 0 {
        return LaneHits { lanes: 0, t, edges: [e0, e1, e2], inv_det };
    }
    let max3 = max_abs3::<L>;
    let max_zt = max3(z0, z1, z2);
    let max_unscaled_zt = max3(p0[2], p1[2], p2[2]);
    let max_xt = max3(p0[0], p1[0], p2[0]);
    let max_yt = max3(p0[1], p1[1], p2[1]);
    let delta_z = splat(gamma(3)) * max_zt;
    let delta_x = splat(gamma(5)) * (max_xt + max_unscaled_zt);
    let delta_y = splat(gamma(5)) * (max_yt + max_unscaled_zt);
    let delta_e = splat(2.0) * (splat(gamma(2)) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = max3(e0, e1, e2);
    let delta_t =
        splat(3.0) * (splat(gamma(3)) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    let hit = candidates.and_not(t.le(delta_t));
    LaneHits { lanes: hit.bits() & live, t, edges: [e0, e1, e2], inv_det }
}

impl TrianglePack {
    /// Bit per lane holding a triangle that can be hit.
    pub fn live(&self) -> u32 {
        self.live
    }
}
