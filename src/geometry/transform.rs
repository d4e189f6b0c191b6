//! Affine transforms for instancing: rays go to object space, hits come back to world space with
//! their error bounds widened by the transformation's own rounding.

use super::aabb::Aabb;
use super::ray::{Ray, SurfaceHit};
use super::real::{Mat3, Mat4, Real, Vec3, gamma};
pub use crate::build_error::TransformError;

#[derive(Clone, Debug)]
pub struct Transform {
    object_to_world: Mat4,
    world_to_object: Mat4,
    /// Inverse transpose of the linear part: normals stay perpendicular to surfaces under
    /// non-uniform scale.
    normal_to_world: Mat3,
    /// `|M|` and `|M⁻¹|` entry by entry (linear part, translation), the factors of every
    /// error bound below; constants of the transform, so computed once rather than per ray.
    abs_object_to_world: (Mat3, Vec3),
    abs_world_to_object: (Mat3, Vec3),
}

impl Transform {
    /// Fails for matrices whose inverse would be meaningless, instead of producing NaN pictures:
    /// the determinant is compared with the cube of the largest entry, so a tiny but well-shaped
    /// scene (every entry 1e-4) is accepted, and so is a squash by 1e-4 along one axis, while a
    /// squash beyond ~1e5 (where an `f32` inverse keeps no correct digit) is not.
    pub fn new(object_to_world: Mat4) -> Result<Self, TransformError> {
        if !object_to_world.is_finite() {
            return Err(TransformError::NotFinite);
        }
        if object_to_world.row(3).to_array() != [0.0, 0.0, 0.0, 1.0] {
            return Err(TransformError::NotAffine);
        }
        let linear = Mat3::from_mat4(object_to_world);
        let scale = linear.to_cols_array().iter().fold(0.0 as Real, |m, v| m.max(v.abs()));
        let determinant = linear.determinant();
        let threshold = 64.0 * Real::EPSILON * scale * scale * scale;
        if scale == 0.0 || determinant.is_nan() || determinant.abs() <= threshold {
            return Err(TransformError::Singular);
        }
        let world_to_object = object_to_world.inverse();
        if !world_to_object.is_finite() {
            return Err(TransformError::Singular);
        }
        let normal_to_world = linear.inverse().transpose();
        let absolute = |m: Mat4| (Mat3::from_mat4(m).abs(), m.w_axis.truncate().abs());
        Ok(Transform {
            object_to_world,
            world_to_object,
            normal_to_world,
            abs_object_to_world: absolute(object_to_world),
            abs_world_to_object: absolute(world_to_object),
        })
    }

    pub fn object_to_world(&self) -> &Mat4 {
        &self.object_to_world
    }

    /// The ray in object space, and how far along it (in the ray's parameter) its origin was
    /// pushed. Transforming the origin rounds it by up to `gamma(3)·(|M⁻¹|·|o| + |t|)`, which
    /// can carry a spawned origin back through the surface it just left; like pbrt-v4, the
    /// origin is moved forward along the direction past that error, and callers add the shift
    /// back so that `t` stays the world ray's parameter.
    pub fn ray_to_object(&self, ray: &Ray) -> (Ray, Real) {
        let origin = self.world_to_object.transform_point3(ray.origin);
        let direction = self.world_to_object.transform_vector3(ray.direction);
        let length_squared = direction.length_squared();
        if length_squared == 0.0 {
            return (Ray::new(origin, direction), 0.0);
        }
        let (abs_linear, abs_translation) = self.abs_world_to_object;
        let origin_error = gamma(3) * (abs_linear * ray.origin.abs() + abs_translation);
        let shift = direction.abs().dot(origin_error) / length_squared;
        (Ray::new(origin + direction * shift, direction), shift)
    }

    pub fn point_to_world(&self, point: Vec3) -> Vec3 {
        self.object_to_world.transform_point3(point)
    }

    pub fn vector_to_world(&self, vector: Vec3) -> Vec3 {
        self.object_to_world.transform_vector3(vector)
    }

    /// The normal mapped by the inverse transpose, not normalised: normals mapped so keep
    /// their barycentric interpolation the image of the object-space one (for meshes placed in
    /// world space, see `Mesh::from_placed`).
    pub fn normal_to_world_unnormalised(&self, normal: Vec3) -> Vec3 {
        self.normal_to_world * normal
    }

    /// Whether the transform mirrors (its linear part has a negative determinant): triangles
    /// moved by it reverse their winding.
    pub fn mirrors(&self) -> bool {
        Mat3::from_mat4(self.object_to_world).determinant() < 0.0
    }

    /// Unit world normal; a normal that degenerates (it cannot for a non-singular transform,
    /// but rounding is rounding) keeps the object-space direction rather than becoming NaN.
    pub fn normal_to_world(&self, normal: Vec3) -> Vec3 {
        (self.normal_to_world * normal).try_normalize().unwrap_or(normal)
    }

    /// The error bound follows pbrt-v4's `Transform::operator()(Point3fi)`: the rounding of the
    /// matrix product itself, plus the incoming error carried through `|M|`. It also covers the
    /// way back: a ray spawned here is transformed to object space again, which rounds its
    /// origin by up to `gamma(3)·(|M⁻¹|·|p| + |t⁻¹|)`; mapped to world space by `|M|`, that is
    /// added too, so the spawn offset along the normal always exceeds it (far from the origin
    /// or under anisotropic scale, the return trip alone can otherwise re-hit the surface).
    pub fn hit_to_world(&self, hit: &SurfaceHit) -> SurfaceHit {
        let point = self.point_to_world(hit.point);
        let (abs_linear, translation) = self.abs_object_to_world;
        let (abs_inverse_linear, inverse_translation) = self.abs_world_to_object;
        let forward_error = gamma(3) * (abs_linear * hit.point.abs() + translation)
            + (1.0 + gamma(3)) * (abs_linear * hit.point_error);
        let return_error = gamma(3) * (abs_inverse_linear * point.abs() + inverse_translation);
        SurfaceHit {
            t: hit.t,
            point,
            point_error: forward_error + (1.0 + gamma(3)) * (abs_linear * return_error),
            geometric_normal: self.normal_to_world(hit.geometric_normal),
            shading_normal: self.normal_to_world(hit.shading_normal),
        }
    }

    /// World bounds of an object-space box: the box of its eight transformed corners.
    pub fn bounds_to_world(&self, bounds: &Aabb) -> Aabb {
        let mut world = Aabb::EMPTY;
        for corner in 0..8 {
            let pick = |bit: usize, lo: Real, hi: Real| if corner & bit == 0 { lo } else { hi };
            let p = Vec3::new(
                pick(1, bounds.min.x, bounds.max.x),
                pick(2, bounds.min.y, bounds.max.y),
                pick(4, bounds.min.z, bounds.max.z),
            );
            world = world.grow(self.point_to_world(p));
        }
        world
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_singular_and_accepts_tiny_scales() {
        let flat = Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0));
        assert_eq!(Transform::new(flat).unwrap_err(), TransformError::Singular);
        let tiny = Mat4::from_scale(Vec3::splat(1.0e-4));
        assert!(Transform::new(tiny).is_ok());
        let squashed = Mat4::from_scale(Vec3::new(1.0, 1.0e-4, 1.0));
        assert!(Transform::new(squashed).is_ok());
        // Flatter than the precision can invert: 1e-6 passes in f64 but not in f32.
        let flattened = Mat4::from_scale(Vec3::new(1.0, Real::EPSILON, 1.0));
        assert_eq!(Transform::new(flattened).unwrap_err(), TransformError::Singular);
        let nan = Mat4::from_scale(Vec3::new(Real::NAN, 1.0, 1.0));
        assert_eq!(Transform::new(nan).unwrap_err(), TransformError::NotFinite);
    }

    #[test]
    fn normals_use_the_inverse_transpose() {
        let squash = Transform::new(Mat4::from_scale(Vec3::new(1.0, 0.2, 1.0))).unwrap();
        let diagonal = Vec3::new(1.0, 1.0, 0.0).normalize();
        let world = squash.normal_to_world(diagonal);
        assert!((world - Vec3::new(0.2, 1.0, 0.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn ray_parameter_is_preserved_through_object_space() {
        let transform = Transform::new(
            Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)) * Mat4::from_scale(Vec3::new(2.0, 3.0, 4.0)),
        )
        .unwrap();
        let ray = Ray::new(Vec3::new(-5.0, 1.0, 2.0), Vec3::new(1.0, 0.25, 0.1));
        let (local, shift) = transform.ray_to_object(&ray);
        assert!(shift > 0.0 && shift < 1e-5, "the origin moves by its rounding error only: {shift}");
        let t = 3.0;
        let back = transform.point_to_world(local.at(t - shift));
        assert!((back - ray.at(t)).length() < 1e-5);
    }
}
