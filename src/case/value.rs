//! The case file's own kinds of value, read with the located readers of [`crate::located_toml`]:
//! points, colours and directions.

use crate::located_toml::{Field, Result};

/// Reads of the values a scene is made of. A trait rather than methods of `Field`, because what
/// makes a colour or a direction valid is the renderer's business, not the TOML reader's.
pub(crate) trait SceneValues {
    fn vec3(&self) -> Result<[f64; 3]>;
    /// Linear RGB; negative light or reflectance has no physical meaning and breaks tone mapping.
    fn color(&self) -> Result<[f64; 3]>;
    /// A vector that will be normalised downstream, so its length must survive `1/length`.
    fn direction(&self) -> Result<[f64; 3]>;
}

impl SceneValues for Field<'_, '_> {
    fn vec3(&self) -> Result<[f64; 3]> {
        self.numbers("an array of 3 numbers [x, y, z]")
    }

    fn color(&self) -> Result<[f64; 3]> {
        let rgb: [f64; 3] = self.numbers("an array of 3 numbers [r, g, b]")?;
        match rgb.iter().position(|c| *c < 0.0) {
            Some(i) => Err(self.array("")?[i].invalid("must be ≥ 0 (colours are non-negative)")),
            None => Ok(rgb),
        }
    }

    fn direction(&self) -> Result<[f64; 3]> {
        let v = self.vec3()?;
        if has_usable_length(v) {
            Ok(v)
        } else {
            Err(self.invalid("must have a nonzero, finite length"))
        }
    }
}

/// Whether `v` survives normalisation (`1/length` finite). Shared with the assignment importer so
/// that both formats accept the same directions.
pub(crate) fn has_usable_length(v: [f64; 3]) -> bool {
    let length = glam::DVec3::from(v).length();
    length > 0.0 && length.is_finite() && (1.0 / length).is_finite()
}
