//! FLIP's filtered maps of a whole picture: the spatially filtered colour and the edge and point
//! responses, by separable filtering with edge values repeated past the border, each pixel's taps
//! summed in the reference implementation's order (so that the maps round as its maps do).

use image::RgbImage;

use super::color::{feature_input, srgb_to_ycxcz};
use super::kernels::KERNELS;

/// What FLIP's per-pixel error reads of one picture.
#[derive(Clone)]
pub(in crate::compare) struct Maps {
    /// The spatially filtered YCxCz, one plane per channel.
    color: [Vec<f32>; 3],
    /// The edge and point responses `dx, dy, ddx, ddy`.
    features: [Vec<f32>; 4],
}

impl std::fmt::Debug for Maps {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Maps({} pixels)", self.color[0].len())
    }
}

impl Maps {
    pub fn of(picture: &RgbImage) -> Maps {
        let (width, height) = (picture.width() as usize, picture.height() as usize);
        let pixels = width * height;
        let mut opponent: [Vec<f32>; 3] = std::array::from_fn(|_| Vec::with_capacity(pixels));
        for pixel in picture.pixels() {
            let value = srgb_to_ycxcz(pixel.0);
            for (plane, v) in opponent.iter_mut().zip(value) {
                plane.push(v);
            }
        }
        let k = &*KERNELS;
        let filter =
            |plane: &[f32], across: &[f32], down: &[f32]| vertical(&horizontal(plane, width, across), width, down);
        let first_blue_yellow = filter(&opponent[2], &k.blue_yellow[0], &k.blue_yellow[0]);
        let second_blue_yellow = filter(&opponent[2], &k.blue_yellow[1], &k.blue_yellow[1]);
        let color = [
            filter(&opponent[0], &k.achromatic, &k.achromatic),
            filter(&opponent[1], &k.red_green, &k.red_green),
            first_blue_yellow
                .iter()
                .zip(&second_blue_yellow)
                .map(|(a, b)| a + b)
                .collect(),
        ];
        let gray: Vec<f32> = opponent[0].iter().map(|&y| feature_input(y)).collect();
        let smoothed = horizontal(&gray, width, &k.gaussian);
        let features = [
            vertical(&horizontal(&gray, width, &k.first), width, &k.gaussian),
            vertical(&smoothed, width, &k.first),
            vertical(&horizontal(&gray, width, &k.second), width, &k.gaussian),
            vertical(&smoothed, width, &k.second),
        ];
        debug_assert!(color.iter().chain(&features).all(|plane| plane.len() == height * width));
        Maps { color, features }
    }

    pub fn color(&self, pixel: usize) -> [f32; 3] {
        self.color.each_ref().map(|plane| plane[pixel])
    }

    pub fn features(&self, pixel: usize) -> [f32; 4] {
        self.features.each_ref().map(|plane| plane[pixel])
    }
}

/// Each row filtered by `taps`, the row's end values repeated past its ends.
fn horizontal(plane: &[f32], width: usize, taps: &[f32]) -> Vec<f32> {
    let radius = taps.len() / 2;
    let mut out = vec![0.0f32; plane.len()];
    let mut padded = vec![0.0f32; width + 2 * radius];
    for (row, out_row) in plane.chunks_exact(width).zip(out.chunks_exact_mut(width)) {
        for (i, p) in padded.iter_mut().enumerate() {
            *p = row[i.saturating_sub(radius).min(width - 1)];
        }
        for (t, &tap) in taps.iter().enumerate() {
            for (o, &v) in out_row.iter_mut().zip(&padded[t..t + width]) {
                *o += tap * v;
            }
        }
    }
    out
}

/// Each column filtered by `taps`, the column's end values repeated past its ends.
fn vertical(plane: &[f32], width: usize, taps: &[f32]) -> Vec<f32> {
    let radius = taps.len() / 2;
    let height = plane.len() / width;
    let mut out = vec![0.0f32; plane.len()];
    for (y, out_row) in out.chunks_exact_mut(width).enumerate() {
        for (t, &tap) in taps.iter().enumerate() {
            let source = (y + t).saturating_sub(radius).min(height - 1);
            for (o, &v) in out_row.iter_mut().zip(&plane[source * width..(source + 1) * width]) {
                *o += tap * v;
            }
        }
    }
    out
}
