//! Eight rays side by side, one per SIMD lane, for integrators that trace a pixel's samples (or a
//! run of pixels) together: vectors, rays and hit records as lanes of [`Real`].
//!
//! Every operation here is the one glam performs on a single `Vec3`, in the same order (`dot` is
//! `x·x' + y·y' + z·z'`, `normalize` multiplies by `1 / length`, division divides), so each lane
//! holds exactly the number a ray traced alone would: a picture does not depend on whether its
//! rays were traced eight at a time. These are kernels' building blocks: compile them only
//! inside a kernel (see `crate::simd`).

use std::ops::{Add, Mul, Neg, Sub};

use super::aabb::Aabb;
use super::ray::{Ray, SurfaceHit};
use super::real::{R8, Real, Vec3, gamma, transpose_rays};
use crate::simd::{Isa, Lanes, MaskOps};

/// Rays traced together.
pub const LANES: usize = 8;

/// A true/false flag per lane.
pub type Mask<I> = <R8<I> as Lanes>::Mask;

/// Eight vectors, one per lane.
#[derive(Clone, Copy)]
pub struct V3<I: Isa> {
    pub x: R8<I>,
    pub y: R8<I>,
    pub z: R8<I>,
}

/// For each 8-bit set of lanes, 1 in the lanes of the set and 0 elsewhere.
const FLAGS: [[Real; LANES]; 1 << LANES] = {
    let mut flags = [[0.0; LANES]; 1 << LANES];
    let mut bits = 0;
    while bits < 1 << LANES {
        let mut lane = 0;
        while lane < LANES {
            if bits & (1 << lane) != 0 {
                flags[bits][lane] = 1.0;
            }
            lane += 1;
        }
        bits += 1;
    }
    flags
};

/// The lanes whose bit is set in `bits`, as a mask for [`Lanes::select`].
#[inline(always)]
pub fn mask<I: Isa>(bits: u32) -> Mask<I> {
    R8::<I>::load(&FLAGS[(bits & 0xff) as usize]).gt(R8::<I>::splat(0.0))
}

/// The index of every set bit of `bits`, lowest first: the lanes of a set. Kernels loop over
/// these rather than call a closure per lane: a closure is compiled as a function of its own,
/// without the instructions of the kernel that calls it, and the SIMD code inside it would then
/// call each intrinsic as a function.
pub fn set_lanes(mut bits: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let lane = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            lane
        })
    })
}

impl<I: Isa> V3<I> {
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V3 { x: R8::<I>::splat(v.x), y: R8::<I>::splat(v.y), z: R8::<I>::splat(v.z) }
    }

    /// `vectors[lane]` in each lane; lanes past the end repeat the last vector.
    #[inline(always)]
    pub fn gather(vectors: &[Vec3]) -> Self {
        let mut axes = [[0.0; LANES]; 3];
        for lane in 0..LANES {
            let v = vectors[lane.min(vectors.len() - 1)];
            (axes[0][lane], axes[1][lane], axes[2][lane]) = (v.x, v.y, v.z);
        }
        V3::load(&axes)
    }

    /// `axes[axis][lane]`.
    #[inline(always)]
    pub fn load(axes: &[[Real; LANES]; 3]) -> Self {
        V3 { x: R8::<I>::load(&axes[0]), y: R8::<I>::load(&axes[1]), z: R8::<I>::load(&axes[2]) }
    }

    /// The lanes as `axes[axis][lane]`.
    #[inline(always)]
    pub fn store(self) -> [[Real; LANES]; 3] {
        let mut axes = [[0.0; LANES]; 3];
        self.x.store(&mut axes[0]);
        self.y.store(&mut axes[1]);
        self.z.store(&mut axes[2]);
        axes
    }

    /// The lanes as vectors.
    #[inline(always)]
    pub fn vectors(self) -> [Vec3; LANES] {
        let axes = self.store();
        std::array::from_fn(|lane| Vec3::new(axes[0][lane], axes[1][lane], axes[2][lane]))
    }

    #[inline(always)]
    pub fn scale(self, s: R8<I>) -> Self {
        V3 { x: self.x * s, y: self.y * s, z: self.z * s }
    }

    /// Each component divided by `s`, as glam's `Vec3 / Real`.
    #[inline(always)]
    pub fn divide(self, s: R8<I>) -> Self {
        V3 { x: self.x / s, y: self.y / s, z: self.z / s }
    }

    #[inline(always)]
    pub fn dot(self, other: Self) -> R8<I> {
        self.x * other.x + self.y * other.y + self.z * other.z
    }

    #[inline(always)]
    pub fn length_squared(self) -> R8<I> {
        self.dot(self)
    }

    #[inline(always)]
    pub fn length(self) -> R8<I> {
        self.dot(self).sqrt()
    }

    /// glam's `normalize`: the vector times `1 / length`.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self.scale(R8::<I>::splat(1.0) / self.length())
    }

    /// glam's `normalize_or_zero`: zero where `1 / length` is not finite and positive.
    #[inline(always)]
    pub fn normalize_or_zero(self) -> Self {
        let reciprocal = R8::<I>::splat(1.0) / self.length();
        let usable = reciprocal.gt(R8::<I>::splat(0.0)).and_not(reciprocal.abs().eq(R8::<I>::splat(Real::INFINITY)));
        V3::select(usable, self.scale(reciprocal), V3::splat(Vec3::ZERO))
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        V3 { x: self.x.abs(), y: self.y.abs(), z: self.z.abs() }
    }

    /// `mask ? if_true : if_false` per lane.
    #[inline(always)]
    pub fn select(mask: Mask<I>, if_true: Self, if_false: Self) -> Self {
        V3 {
            x: R8::<I>::select(mask, if_true.x, if_false.x),
            y: R8::<I>::select(mask, if_true.y, if_false.y),
            z: R8::<I>::select(mask, if_true.z, if_false.z),
        }
    }
}

impl<I: Isa> Add for V3<I> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl<I: Isa> Sub for V3<I> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

/// Component by component, as glam's `Vec3 * Vec3`.
impl<I: Isa> Mul for V3<I> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 { x: self.x * o.x, y: self.y * o.y, z: self.z * o.z }
    }
}

impl<I: Isa> Neg for V3<I> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3 { x: -self.x, y: -self.y, z: -self.z }
    }
}

/// Eight rays `origin + t·direction`.
#[derive(Clone, Copy)]
pub struct RayLanes<I: Isa> {
    pub origin: V3<I>,
    pub direction: V3<I>,
}

impl<I: Isa> RayLanes<I> {
    /// `rays[lane]` in each lane; lanes past the end repeat the last ray.
    ///
    /// # Panics
    /// If `rays` is empty.
    #[inline(always)]
    pub fn gather(rays: &[Ray]) -> Self {
        // A full packet of `f32` rays is shuffled into lanes from its 48 values at once.
        if let Ok(values) = <&[Real; 6 * LANES]>::try_from(bytemuck::cast_slice::<Ray, Real>(rays))
            && let Some([ox, oy, oz, dx, dy, dz]) = transpose_rays::<I>(values)
        {
            return RayLanes { origin: V3 { x: ox, y: oy, z: oz }, direction: V3 { x: dx, y: dy, z: dz } };
        }
        let mut axes = [[[0.0; LANES]; 3]; 2];
        for lane in 0..LANES {
            let ray = &rays[lane.min(rays.len() - 1)];
            let (o, d) = (ray.origin, ray.direction);
            (axes[0][0][lane], axes[0][1][lane], axes[0][2][lane]) = (o.x, o.y, o.z);
            (axes[1][0][lane], axes[1][1][lane], axes[1][2][lane]) = (d.x, d.y, d.z);
        }
        // Put into lanes as values: loaded from the array, each lane would wait for the eight
        // writes before it (a load cannot take its value from several smaller writes).
        let [o, d] = axes;
        RayLanes {
            origin: V3 { x: R8::<I>::from_array(o[0]), y: R8::<I>::from_array(o[1]), z: R8::<I>::from_array(o[2]) },
            direction: V3 { x: R8::<I>::from_array(d[0]), y: R8::<I>::from_array(d[1]), z: R8::<I>::from_array(d[2]) },
        }
    }

    /// A bit per lane whose origin and direction are finite.
    #[inline(always)]
    pub fn finite(&self) -> u32 {
        let infinity = R8::<I>::splat(Real::INFINITY);
        let mut finite = 0xff;
        for v in [self.origin.x, self.origin.y, self.origin.z, self.direction.x, self.direction.y, self.direction.z] {
            finite &= v.abs().lt(infinity).bits();
        }
        finite
    }

    #[inline(always)]
    pub fn at(&self, t: R8<I>) -> V3<I> {
        self.origin + self.direction.scale(t)
    }

    /// The rays one by one.
    #[inline(always)]
    pub fn rays(&self) -> [Ray; LANES] {
        let (origins, directions) = (self.origin.vectors(), self.direction.vectors());
        std::array::from_fn(|lane| Ray::new(origins[lane], directions[lane]))
    }
}

/// Eight [`SurfaceHit`]s, one per lane.
#[derive(Clone, Copy)]
pub struct SurfaceLanes<I: Isa> {
    pub t: R8<I>,
    pub point: V3<I>,
    pub point_error: V3<I>,
    pub geometric_normal: V3<I>,
    pub shading_normal: V3<I>,
}

impl<I: Isa> SurfaceLanes<I> {
    /// `mask ? if_true : if_false` per lane, field by field.
    #[inline(always)]
    pub fn select(mask: Mask<I>, if_true: &Self, if_false: &Self) -> Self {
        SurfaceLanes {
            t: R8::<I>::select(mask, if_true.t, if_false.t),
            point: V3::select(mask, if_true.point, if_false.point),
            point_error: V3::select(mask, if_true.point_error, if_false.point_error),
            geometric_normal: V3::select(mask, if_true.geometric_normal, if_false.geometric_normal),
            shading_normal: V3::select(mask, if_true.shading_normal, if_false.shading_normal),
        }
    }

    /// These lanes with lane `k` replaced by `hits[k]` wherever `hits[k]` is `Some`.
    #[inline(always)]
    pub fn with_lanes(&self, hits: &[Option<SurfaceHit>; LANES]) -> Self {
        let mut t = [0.0; LANES];
        self.t.store(&mut t);
        // Each field spelled out: `array::map` would take the loads and stores into a closure,
        // compiled without the kernel's target features.
        let mut vectors =
            [self.point.store(), self.point_error.store(), self.geometric_normal.store(), self.shading_normal.store()];
        for (lane, hit) in hits.iter().enumerate() {
            if let Some(hit) = hit {
                t[lane] = hit.t;
                for (field, v) in
                    [hit.point, hit.point_error, hit.geometric_normal, hit.shading_normal].into_iter().enumerate()
                {
                    (vectors[field][0][lane], vectors[field][1][lane], vectors[field][2][lane]) = (v.x, v.y, v.z);
                }
            }
        }
        let [point, point_error, geometric_normal, shading_normal] =
            [V3::load(&vectors[0]), V3::load(&vectors[1]), V3::load(&vectors[2]), V3::load(&vectors[3])];
        SurfaceLanes { t: R8::<I>::load(&t), point, point_error, geometric_normal, shading_normal }
    }
}

/// Eight rays with their inverse directions, for [`RaySlabs::may_enter`].
pub struct RaySlabs<I: Isa> {
    origin: V3<I>,
    inverse: V3<I>,
}

impl<I: Isa> RaySlabs<I> {
    #[inline(always)]
    pub fn new(rays: &RayLanes<I>) -> Self {
        let one = R8::<I>::splat(1.0);
        let d = rays.direction;
        RaySlabs { origin: rays.origin, inverse: V3 { x: one / d.x, y: one / d.y, z: one / d.z } }
    }

    /// A bit per ray that may meet `bounds` at some `t ≥ 0`: a culling test, never a verdict. It
    /// errs only towards "may", and more widely than the traversal's slab test (whose boxes the
    /// single-ray queries must pass anyway): the far distance of each slab is widened by
    /// `1 + 4·gamma(3)` where the traversal widens by `1 + 2·gamma(3)`, there is no `t_max`, and
    /// a slab whose distances are undefined (a ray in the plane of a face, or anything not
    /// finite) constrains nothing. So a ray the single-ray query would find inside the box is
    /// never dropped.
    #[inline(always)]
    pub fn may_enter(&self, bounds: &Aabb) -> u32 {
        let splat = R8::<I>::splat;
        let widen = splat(1.0 + 4.0 * gamma(3));
        let (mut near, mut far) = (splat(0.0), splat(Real::INFINITY));
        for (o, inverse, min, max) in [
            (self.origin.x, self.inverse.x, bounds.min.x, bounds.max.x),
            (self.origin.y, self.inverse.y, bounds.min.y, bounds.max.y),
            (self.origin.z, self.inverse.z, bounds.min.z, bounds.max.z),
        ] {
            let (t0, t1) = ((splat(min) - o) * inverse, (splat(max) - o) * inverse);
            let undefined = t0.is_nan().or(t1.is_nan());
            let slab_near = R8::<I>::select(undefined, splat(Real::NEG_INFINITY), t0.min(t1));
            let slab_far = R8::<I>::select(undefined, splat(Real::INFINITY), t0.max(t1) * widen);
            near = slab_near.max(near);
            far = slab_far.min(far);
        }
        !near.gt(far).bits() & 0xff
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::Portable;

    fn may_enter(bounds: &Aabb, rays: &[Ray]) -> u32 {
        let mut axes = [[[0.0; LANES]; 3]; 2];
        for (lane, ray) in rays.iter().enumerate() {
            for (axis, (o, d)) in [(ray.origin.x, ray.direction.x), (ray.origin.y, ray.direction.y), (ray.origin.z, ray.direction.z)]
                .into_iter()
                .enumerate()
            {
                (axes[0][axis][lane], axes[1][axis][lane]) = (o, d);
            }
        }
        let lanes = RayLanes::<Portable> { origin: V3::load(&axes[0]), direction: V3::load(&axes[1]) };
        RaySlabs::new(&lanes).may_enter(bounds) & ((1 << rays.len()) - 1)
    }

    /// Rays that touch the box, at its corners, along its edges and in the planes of its faces,
    /// with zero direction components, are never culled; rays that pass it by or point away are.
    #[test]
    fn rays_that_touch_a_box_are_never_culled() {
        for scale in [1.0e-3, 1.0, 7.0e4] {
            let bounds = Aabb { min: Vec3::new(-1.0, 0.5, -3.0) * scale, max: Vec3::new(2.0, 1.5, -2.0) * scale };
            let corner = bounds.max;
            let touching = [
                Ray::new(Vec3::ZERO, corner),
                Ray::new(Vec3::new(corner.x, corner.y, 10.0 * scale), -Vec3::Z),
                Ray::new(Vec3::new(bounds.min.x, 1.0 * scale, 10.0 * scale), -Vec3::Z),
                Ray::new(Vec3::new(-5.0 * scale, bounds.max.y, bounds.min.z), Vec3::X),
                Ray::new(bounds.min, Vec3::Y),
                Ray::new((bounds.min + bounds.max) * 0.5, Vec3::new(0.3, -0.2, 0.9)),
                Ray::new(Vec3::new(0.5, 1.0, 5.0) * scale, Vec3::new(0.0, 0.0, -1.0e-3)),
                Ray::new(Vec3::new(-3.0, -4.0, 2.0) * scale, bounds.min - Vec3::new(-3.0, -4.0, 2.0) * scale),
            ];
            assert_eq!(may_enter(&bounds, &touching), 0xff, "scale {scale}");
            let missing = [
                Ray::new(Vec3::ZERO, -corner),
                Ray::new(Vec3::new(corner.x * 1.01 + scale, corner.y, 10.0 * scale), -Vec3::Z),
                Ray::new(Vec3::new(0.5, 1.0, 5.0) * scale, Vec3::Z),
                Ray::new(Vec3::new(0.0, 10.0, 0.0) * scale, Vec3::new(1.0, 0.0, 0.0)),
            ];
            assert_eq!(may_enter(&bounds, &missing), 0, "scale {scale}");
        }
    }
}
