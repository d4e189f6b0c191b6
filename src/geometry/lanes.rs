//! Eight rays side by side, one per SIMD lane, for integrators that trace a pixel's samples (or a
//! run of pixels) together: vectors, rays and hit records as lanes of [`Real`].
//!
//! Every operation here is the one glam performs on a single `Vec3`, in the same order (`dot` is
//! `x·x' + y·y' + z·z'`, `normalize` multiplies by `1 / length`, division divides), so each lane
//! holds exactly the number a ray traced alone would: a picture does not depend on whether its
//! rays were traced eight at a time. These are kernels' building blocks: compile them only
//! inside a kernel (see `crate::simd`).

use std::ops::{Add, Mul, Neg, Sub};

use super::ray::{Ray, SurfaceHit};
use super::real::{R8, Real, Vec3};
use crate::simd::{Isa, Lanes, MaskOps};

/// Rays traced together.
pub const LANES: usize = 8;

/// A true/false flag per lane.
pub type Mask<I> = <R8<I> as Lanes>::Mask;

/// Eight vectors, one per lane.
pub struct V3<I: Isa> {
    pub x: R8<I>,
    pub y: R8<I>,
    pub z: R8<I>,
}

impl<I: Isa> Clone for V3<I> {
    #[inline(always)]
    fn clone(&self) -> Self {
        *self
    }
}

impl<I: Isa> Copy for V3<I> {}

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

/// Lane `lane` of `value`.
#[inline(always)]
pub fn lane<I: Isa>(value: R8<I>, lane: usize) -> Real {
    let mut lanes = [0.0; LANES];
    value.store(&mut lanes);
    lanes[lane]
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
pub struct RayLanes<I: Isa> {
    pub origin: V3<I>,
    pub direction: V3<I>,
}

impl<I: Isa> Clone for RayLanes<I> {
    #[inline(always)]
    fn clone(&self) -> Self {
        *self
    }
}

impl<I: Isa> Copy for RayLanes<I> {}

impl<I: Isa> RayLanes<I> {
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
pub struct SurfaceLanes<I: Isa> {
    pub t: R8<I>,
    pub point: V3<I>,
    pub point_error: V3<I>,
    pub geometric_normal: V3<I>,
    pub shading_normal: V3<I>,
}

impl<I: Isa> Clone for SurfaceLanes<I> {
    #[inline(always)]
    fn clone(&self) -> Self {
        *self
    }
}

impl<I: Isa> Copy for SurfaceLanes<I> {}

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
        let mut vectors = [self.point, self.point_error, self.geometric_normal, self.shading_normal].map(V3::store);
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
        let [point, point_error, geometric_normal, shading_normal] = vectors.map(|axes| V3::load(&axes));
        SurfaceLanes { t: R8::<I>::load(&t), point, point_error, geometric_normal, shading_normal }
    }
}
