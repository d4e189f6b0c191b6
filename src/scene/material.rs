//! The assignment's Phong material.

use super::real::{Color, Real, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub diffuse: Color,
    pub specular: Color,
    pub shininess: Real,
}

impl Default for Material {
    /// White and matte, the assignment's defaults for an unspecified material.
    fn default() -> Self {
        Material { diffuse: Color::ONE, specular: Color::ZERO, shininess: 0.0 }
    }
}

impl Material {
    /// Whether reflected rays can carry anything back: materials without a specular colour
    /// never spawn them.
    pub fn reflects(&self) -> bool {
        self.specular != Color::ZERO
    }

    /// Diffuse plus specular light from one light: `max(L·N, 0)·I·kd + max(R·V, 0)^s·I·ks` with
    /// `R = 2(L·N)N − L`. Negative cosines are clamped before `powf`, so any shininess (0
    /// included, where `0^0 = 1`) gives a finite result. With a unit normal both cosines are at
    /// most 1; the course's reference renderer clamps only below, which shows on its planes,
    /// whose normals keep the length they were written with.
    pub fn shade(&self, normal: Vec3, to_light: Vec3, to_eye: Vec3, intensity: Color) -> Color {
        let cos_light = to_light.dot(normal);
        let diffuse = cos_light.max(0.0) * self.diffuse;
        let reflected = 2.0 * cos_light * normal - to_light;
        let cos_view = reflected.dot(to_eye).max(0.0);
        // Without a specular colour the highlight adds 0·h = 0, so `powf` is skipped, unless
        // h may overflow (cos_view > 1, only on such a plane): there the reference adds 0·∞ = NaN.
        if !self.reflects() && cos_view <= 1.0 {
            return diffuse * intensity;
        }
        // `powf(x, 1)` is `x` exactly; the course's scenes use shininess 1 for their floors,
        // and the call costs a sampled render of such a scene about 2% of its instructions.
        let highlight = if self.shininess == 1.0 { cos_view } else { cos_view.powf(self.shininess) };
        (diffuse + highlight * self.specular) * intensity
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambert_and_highlight() {
        let m = Material { diffuse: Vec3::new(1.0, 0.5, 0.0), specular: Vec3::ONE, shininess: 10.0 };
        let head_on = m.shade(Vec3::Z, Vec3::Z, Vec3::Z, Vec3::ONE);
        assert!((head_on - Vec3::new(2.0, 1.5, 1.0)).length() < 1e-6);
        let grazing_eye = m.shade(Vec3::Z, Vec3::Z, Vec3::X, Vec3::ONE);
        assert!((grazing_eye - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-6);
        let behind = m.shade(Vec3::Z, -Vec3::Z, Vec3::Z, Vec3::ONE);
        assert_eq!(behind, Vec3::ZERO);
    }

    #[test]
    fn extreme_shininess_stays_finite() {
        for shininess in [0.0, 1.0e4, 1.0e6] {
            let m = Material { diffuse: Vec3::ZERO, specular: Vec3::ONE, shininess };
            let c = m.shade(Vec3::Z, Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.0, -0.6, 0.8), Vec3::ONE);
            assert!(c.is_finite(), "{shininess}: {c}");
        }
    }
}
