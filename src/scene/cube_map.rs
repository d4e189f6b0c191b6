//! The assignment's cube-map background, sampled exactly as its reference renderer does
//! (docs/ARCHITECTURE.md, "Cube maps"): texel row 0 is the PNG's top row, faces chosen by the
//! largest component, bilinear weights with edge-clamped indices.

use std::path::Path;

use rayon::prelude::*;

use super::real::{Color, Real, Vec3};
pub use crate::build_error::CubeMapError;

/// One face: linear texel values `byte / 255` (the reference applies no gamma), row 0 at the top.
#[derive(Debug)]
struct Face {
    width: usize,
    height: usize,
    texels: Vec<[Real; 3]>,
}

#[derive(Debug)]
pub struct CubeMap {
    /// In the order of `FACE_NAMES`.
    faces: [Face; 6],
}

const FACE_NAMES: [&str; 6] = ["right", "left", "up", "down", "front", "back"];
const RIGHT: usize = 0;
const LEFT: usize = 1;
const UP: usize = 2;
const DOWN: usize = 3;
const FRONT: usize = 4;
const BACK: usize = 5;

impl CubeMap {
    /// Loads `dir/{left,right,up,down,front,back}.png`, decoding the six faces in parallel.
    pub fn load(dir: &Path) -> Result<CubeMap, CubeMapError> {
        let faces: Vec<Face> = FACE_NAMES
            .par_iter()
            .map(|name| load_face(&dir.join(format!("{name}.png"))))
            .collect::<Result<_, _>>()?;
        let faces: [Face; 6] = faces.try_into().expect("six names give six faces");
        Ok(CubeMap { faces })
    }

    pub fn radiance(&self, direction: Vec3) -> Color {
        let d = direction.normalize_or_zero();
        let (x, y, z) = (d.x, d.y, d.z);
        let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
        let half = |a: Real, b: Real| (a / b + 1.0) * 0.5;
        let (face, u, v) = if ax >= ay && ax >= az {
            if x > 0.0 { (RIGHT, half(z, x), half(y, x)) } else { (LEFT, half(z, x), 1.0 - half(y, x)) }
        } else if ay >= az {
            if y > 0.0 { (UP, half(x, y), half(z, y)) } else { (DOWN, 1.0 - half(x, y), 1.0 - half(z, y)) }
        } else if z > 0.0 {
            (FRONT, 1.0 - half(x, z), half(y, z))
        } else {
            (BACK, half(x, z), 1.0 - half(y, z))
        };
        if !(u.is_finite() && v.is_finite()) {
            return Color::ZERO;
        }
        self.faces[face].bilinear(u, v)
    }
}

impl Face {
    fn bilinear(&self, u: Real, v: Real) -> Color {
        let x = u * self.width as Real;
        let y = (1.0 - v) * self.height as Real;
        let (x0, y0) = (x.floor(), y.floor());
        let (alpha, beta) = (x - x0, y - y0);
        let texel = |dx: Real, dy: Real| {
            let column = ((x0 + dx).max(0.0) as usize).min(self.width - 1);
            let row = ((y0 + dy).max(0.0) as usize).min(self.height - 1);
            Color::from_array(self.texels[row * self.width + column])
        };
        texel(0.0, 0.0) * ((1.0 - alpha) * (1.0 - beta))
            + texel(1.0, 0.0) * (alpha * (1.0 - beta))
            + texel(0.0, 1.0) * ((1.0 - alpha) * beta)
            + texel(1.0, 1.0) * (alpha * beta)
    }
}

fn load_face(path: &Path) -> Result<Face, CubeMapError> {
    let error = |reason: String| CubeMapError { path: path.to_path_buf(), reason };
    let image = image::open(path).map_err(|e| error(e.to_string()))?.into_rgb8();
    let (width, height) = (image.width() as usize, image.height() as usize);
    if width == 0 || height == 0 {
        return Err(error("the image is empty".to_string()));
    }
    let texels = image.pixels().map(|p| p.0.map(|c| c as Real / 255.0)).collect();
    Ok(Face { width, height, texels })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform_face(value: Real) -> Face {
        Face { width: 2, height: 2, texels: vec![[value; 3]; 4] }
    }

    fn cube(values: [Real; 6]) -> CubeMap {
        CubeMap { faces: values.map(uniform_face) }
    }

    #[test]
    fn picks_the_face_of_the_largest_component_with_ties_to_x_then_y() {
        let map = cube([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
        assert_eq!(map.radiance(Vec3::new(2.0, 1.0, 1.0)).x, 0.1);
        assert_eq!(map.radiance(Vec3::new(-2.0, 1.0, 1.0)).x, 0.2);
        assert_eq!(map.radiance(Vec3::new(0.0, 3.0, -1.0)).x, 0.3);
        assert_eq!(map.radiance(Vec3::new(0.0, -3.0, 1.0)).x, 0.4);
        assert_eq!(map.radiance(Vec3::new(0.5, 0.0, 1.0)).x, 0.5);
        assert_eq!(map.radiance(Vec3::new(0.5, 0.0, -1.0)).x, 0.6);
        assert_eq!(map.radiance(Vec3::new(1.0, 1.0, 1.0)).x, 0.1, "a three-way tie goes to x");
        assert_eq!(map.radiance(Vec3::new(0.0, -1.0, 1.0)).x, 0.4, "a y–z tie goes to y");
    }

    #[test]
    fn bilinear_weights_follow_the_reference_indexing() {
        // Columns 0..3 hold 0, 0.25, 0.5, 0.75 on every row.
        let face = Face { width: 4, height: 1, texels: (0..4).map(|i| [i as Real * 0.25; 3]).collect() };
        // u = 0.3 → X = 1.2 → 0.8·texel(1) + 0.2·texel(2).
        assert!((face.bilinear(0.3, 0.5).x - (0.8 * 0.25 + 0.2 * 0.5)).abs() < 1e-6);
        // Past the last column the index clamps to the edge.
        assert!((face.bilinear(0.99, 0.5).x - 0.75).abs() < 1e-6);
    }

    #[test]
    fn v_counts_up_from_the_bottom_row() {
        let face = Face { width: 1, height: 2, texels: vec![[1.0; 3], [0.0; 3]] };
        assert!(face.bilinear(0.5, 0.99).x > 0.9, "v near 1 is the top row");
        assert!(face.bilinear(0.5, 0.01).x < 0.1, "v near 0 is the bottom row");
    }

    #[test]
    fn missing_face_names_its_path() {
        let dir = tempfile::tempdir().unwrap();
        let error = CubeMap::load(dir.path()).unwrap_err();
        assert!(error.path.starts_with(dir.path()), "{error}");
    }
}
