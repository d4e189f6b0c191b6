//! Perspective cameras: the native one, and the course reference renderer's, quirks included.

use super::geometry::Ray;
use super::geometry::lanes::{RayLanes, V3};
use super::real::{R8, Real, Vec2, Vec3};
use crate::simd::{Isa, Lanes};
use crate::options::Profile;

#[derive(Clone, Debug)]
pub struct Camera {
    center: Vec3,
    model: Model,
}

#[derive(Clone, Debug)]
enum Model {
    /// Orthonormal basis; `fov` is vertical and the horizontal extent follows the aspect ratio.
    Native { forward: Vec3, right: Vec3, up: Vec3, tan_half_fov: Real },
    /// The assignment's camera: `up` is used exactly as given (not normalised, not made
    /// perpendicular), the image plane sits at `1/tan(angle/2)` and there is no aspect
    /// correction. Student renders are graded against this, so it must not be "fixed".
    Mit6837 { direction: Vec3, horizontal: Vec3, up: Vec3, distance: Real },
}

impl Camera {
    /// `direction` and `up` must be non-zero and not parallel (the case loader checks).
    pub fn new(profile: Profile, center: Vec3, direction: Vec3, up: Vec3, fov_degrees: Real) -> Camera {
        let half_angle = fov_degrees.to_radians() * 0.5;
        let model = match profile {
            Profile::Native => {
                let forward = direction.normalize();
                let right = forward.cross(up).normalize();
                Model::Native { forward, right, up: right.cross(forward), tan_half_fov: half_angle.tan() }
            }
            Profile::Mit6837 => Model::Mit6837 {
                direction: direction.normalize(),
                horizontal: direction.cross(up).normalize(),
                up,
                distance: 1.0 / half_angle.tan(),
            },
        };
        Camera { center, model }
    }

    /// The primary ray through `raster`, a continuous position in a `width × height` image whose
    /// row 0 is the top and whose pixel `(i, j)` covers `[i, i+1) × [j, j+1)`; the pixel's own
    /// sample point for a one-sample render is its centre `(i + ½, j + ½)`.
    pub fn ray(&self, raster: Vec2, width: u32, height: u32) -> Ray {
        let (w, h) = (width as Real, height as Real);
        let direction = match &self.model {
            Model::Native { forward, right, up, tan_half_fov } => {
                let x = (2.0 * raster.x / w - 1.0) * tan_half_fov * (w / h);
                let y = (1.0 - 2.0 * raster.y / h) * tan_half_fov;
                (*forward + *right * x + *up * y).normalize()
            }
            Model::Mit6837 { direction, horizontal, up, distance } => {
                // The reference samples pixel (x, y) at integer coordinates with y = 0 at the
                // bottom, mapping 0 and w−1 to the image edges.
                let x = raster.x - 0.5;
                let y = (h - raster.y) - 0.5;
                let ndc_x = if width > 1 { 2.0 * x / (w - 1.0) - 1.0 } else { 0.0 };
                let ndc_y = if height > 1 { 2.0 * y / (h - 1.0) - 1.0 } else { 0.0 };
                (*direction * *distance + *horizontal * ndc_x + *up * ndc_y).normalize()
            }
        };
        Ray::new(self.center, direction)
    }

    /// [`Camera::ray`] for eight raster positions `(x, y)`, a ray per lane, with the same
    /// operations in the same order.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn ray_lanes<I: Isa>(&self, x: R8<I>, y: R8<I>, width: u32, height: u32) -> RayLanes<I> {
        let splat = R8::<I>::splat;
        let (w, h) = (width as Real, height as Real);
        let direction = match &self.model {
            Model::Native { forward, right, up, tan_half_fov } => {
                let x = (splat(2.0) * x / splat(w) - splat(1.0)) * splat(*tan_half_fov) * splat(w / h);
                let y = (splat(1.0) - splat(2.0) * y / splat(h)) * splat(*tan_half_fov);
                (V3::splat(*forward) + V3::splat(*right).scale(x) + V3::splat(*up).scale(y)).normalize()
            }
            Model::Mit6837 { direction, horizontal, up, distance } => {
                let x = x - splat(0.5);
                let y = (splat(h) - y) - splat(0.5);
                let ndc_x = if width > 1 { splat(2.0) * x / splat(w - 1.0) - splat(1.0) } else { splat(0.0) };
                let ndc_y = if height > 1 { splat(2.0) * y / splat(h - 1.0) - splat(1.0) } else { splat(0.0) };
                (V3::splat(*direction * *distance) + V3::splat(*horizontal).scale(ndc_x) + V3::splat(*up).scale(ndc_y))
                    .normalize()
            }
        };
        RayLanes { origin: V3::splat(self.center), direction }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(profile: Profile) -> Camera {
        Camera::new(profile, Vec3::new(0.0, 0.0, 10.0), -Vec3::Z, Vec3::Y, 90.0)
    }

    #[test]
    fn native_centre_looks_forward_and_row_zero_is_the_top() {
        let cam = camera(Profile::Native);
        let centre = cam.ray(Vec2::new(50.0, 25.0), 100, 50);
        assert!((centre.direction - -Vec3::Z).length() < 1e-6);
        let top = cam.ray(Vec2::new(50.0, 0.0), 100, 50);
        assert!(top.direction.y > 0.0);
        let corner = cam.ray(Vec2::new(100.0, 25.0), 100, 50);
        assert!((corner.direction.x / -corner.direction.z - 2.0).abs() < 1e-5, "aspect 2 at 90°");
    }

    #[test]
    fn mit6837_maps_pixel_zero_and_last_to_the_edges_and_flips_rows() {
        let cam = camera(Profile::Mit6837);
        let bottom_left = cam.ray(Vec2::new(0.5, 99.5), 100, 100);
        let expected = Vec3::new(-1.0, -1.0, -1.0).normalize();
        assert!((bottom_left.direction - expected).length() < 1e-6);
        let top_right = cam.ray(Vec2::new(99.5, 0.5), 100, 100);
        assert!((top_right.direction - Vec3::new(1.0, 1.0, -1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn mit6837_uses_up_as_given() {
        let tilted_up = Vec3::new(0.0, 2.0, 1.0);
        let cam = Camera::new(Profile::Mit6837, Vec3::ZERO, -Vec3::Z, tilted_up, 90.0);
        let top_centre = cam.ray(Vec2::new(1.5, 0.5), 3, 3);
        let expected = (-Vec3::Z + tilted_up).normalize();
        assert!((top_centre.direction - expected).length() < 1e-6);
    }

    #[test]
    fn one_pixel_images_look_straight_ahead() {
        for profile in [Profile::Native, Profile::Mit6837] {
            let ray = camera(profile).ray(Vec2::splat(0.5), 1, 1);
            assert!((ray.direction - -Vec3::Z).length() < 1e-6, "{profile:?}");
        }
    }
}
