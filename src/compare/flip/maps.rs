//! FLIP's filtered maps of a picture: the spatially filtered colour and the edge and point
//! responses, by separable filtering with edge values repeated past the border, each pixel's taps
//! summed in the reference implementation's order (so that the maps round as its maps do).

use std::cell::RefCell;
use std::ops::Range;

use crate::rgb_image::RgbImage;

use super::color::{feature_input, srgb_to_ycxcz};
use super::filter::Band;
use super::kernels::KERNELS;

/// What FLIP's per-pixel error reads of one picture, over a band of its rows.
#[derive(Clone)]
pub(super) struct Maps {
    width: usize,
    rows: Range<usize>,
    /// The spatially filtered YCxCz, one plane per channel.
    pub(super) color: [Vec<f32>; 3],
    /// The edge and point responses `dx, dy, ddx, ddy`.
    pub(super) features: [Vec<f32>; 4],
}

impl Maps {
    /// The maps of `picture`'s rows `rows`, exactly as over the whole picture (each read the
    /// picture's rows within the filters' reach).
    pub fn of(picture: &RgbImage, rows: Range<usize>) -> Maps {
        let (width, height) = (picture.width() as usize, picture.height() as usize);
        let k = &*KERNELS;
        let reach = k.spatial_radius().max(k.feature_radius());
        let read = rows.start.saturating_sub(reach)..(rows.end + reach).min(height);
        let band = Band {
            width,
            height,
            read: read.clone(),
            rows: rows.clone(),
        };
        let (color, features) = SCRATCH.with_borrow_mut(|scratch| {
            let Scratch {
                opponent,
                gray,
                across,
                smoothed,
                second,
            } = scratch;
            for plane in opponent.iter_mut() {
                plane.clear();
            }
            for pixel in picture.as_raw()[read.start * width * 3..read.end * width * 3].chunks_exact(3) {
                let value = srgb_to_ycxcz([pixel[0], pixel[1], pixel[2]]);
                for (plane, v) in opponent.iter_mut().zip(value) {
                    plane.push(v);
                }
            }
            let mut filter = |plane: &[f32], taps: &[f32]| {
                band.horizontal(plane, taps, across);
                band.vertical(across, taps)
            };
            let mut color = [
                filter(&opponent[0], &k.achromatic),
                filter(&opponent[1], &k.red_green),
                filter(&opponent[2], &k.blue_yellow[0]),
            ];
            band.horizontal(&opponent[2], &k.blue_yellow[1], across);
            band.vertical_into(across, &k.blue_yellow[1], second);
            for (first, second) in color[2].iter_mut().zip(second.iter()) {
                *first += second;
            }
            gray.clear();
            gray.extend(opponent[0].iter().map(|&y| feature_input(y)));
            band.horizontal(gray, &k.gaussian, smoothed);
            band.horizontal(gray, &k.first, across);
            let dx = band.vertical(across, &k.gaussian);
            band.horizontal(gray, &k.second, across);
            let ddx = band.vertical(across, &k.gaussian);
            let features = [
                dx,
                band.vertical(smoothed, &k.first),
                ddx,
                band.vertical(smoothed, &k.second),
            ];
            (color, features)
        });
        Maps {
            width,
            rows,
            color,
            features,
        }
    }
    /// The pixels (indices into the whole picture) the maps cover.
    pub fn pixels(&self) -> Range<usize> {
        self.rows.start * self.width..self.rows.end * self.width
    }

    /// The filtered colour at `pixel`, an index into the whole picture within [`Maps::pixels`].
    pub fn color(&self, pixel: usize) -> [f32; 3] {
        let i = pixel - self.rows.start * self.width;
        [self.color[0][i], self.color[1][i], self.color[2][i]]
    }

    /// The feature responses at `pixel`, as [`Maps::color`].
    pub fn features(&self, pixel: usize) -> [f32; 4] {
        let i = pixel - self.rows.start * self.width;
        [
            self.features[0][i],
            self.features[1][i],
            self.features[2][i],
            self.features[3][i],
        ]
    }
}

/// The working planes of one filtering, kept by each thread: a class's pictures are filtered one
/// after another, and planes made afresh for each cost a page fault every 4 KB (most of the
/// system time of grading a class).
#[derive(Default)]
struct Scratch {
    opponent: [Vec<f32>; 3],
    gray: Vec<f32>,
    across: Vec<f32>,
    smoothed: Vec<f32>,
    second: Vec<f32>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}
