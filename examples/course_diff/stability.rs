//! Which pixels of a picture are ill-conditioned: those that change by more than the tolerance
//! when the camera moves by a hundred-thousandth of its distance to what it looks at, a change far
//! below anything a scene file means. Where the two renderers disagree on such pixels, rounding
//! decides the picture and neither is more right than the other; a disagreement on a stable pixel
//! is a real difference.

use std::collections::HashSet;
use std::path::Path;

use goldray::case::{AssignmentOptions, parse_assignment_scene};
use goldray::film::{Tonemap, color_image, depth_image, normals_image};
use goldray::pipeline::render_case;
use goldray::rgb_image::RgbImage;

/// The camera moves this fraction of its distance along each axis, both ways.
const NUDGE: f64 = 1e-5;

/// Pixels of image `kind` (colour, normals, depth) that goldray renders differently, beyond
/// `tolerance`, from `reference` (its own unmoved picture) after any of six camera nudges.
pub fn unstable_pixels(
    text: &str,
    path: &Path,
    options: &AssignmentOptions,
    kind: usize,
    reference: &RgbImage,
    tolerance: u8,
) -> Result<HashSet<(u32, u32)>, String> {
    let case = parse_assignment_scene(text, path, options).map_err(|e| e.to_string())?;
    let distance = options.depth_range.map_or(10.0, |(min, max)| (min + max) / 2.0);
    let mut unstable = HashSet::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut nudged = case.clone();
            nudged.camera.center[axis] += sign * NUDGE * distance;
            let film = render_case(&nudged).map_err(|e| e.to_string())?;
            let image = match kind {
                0 => color_image(&film, Tonemap::Clamp),
                1 => normals_image(&film, Tonemap::Clamp),
                _ => {
                    let (min, max) = options.depth_range.unwrap_or((0.0, 1.0));
                    depth_image(&film, min as f32, max as f32, Tonemap::Clamp)
                }
            };
            unstable.extend(differing(&image, reference, tolerance));
        }
    }
    Ok(unstable)
}

/// Pixels where some channel differs by more than `tolerance`.
pub fn differing(a: &RgbImage, b: &RgbImage, tolerance: u8) -> Vec<(u32, u32)> {
    a.enumerate_pixels()
        .filter(|(x, y, p)| {
            p.0.iter()
                .zip(b.get_pixel(*x, *y).0)
                .any(|(u, v)| u.abs_diff(v) > tolerance)
        })
        .map(|(x, y, _)| (x, y))
        .collect()
}
