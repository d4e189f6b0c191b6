//! FLIP's filtered maps of a picture: the spatially filtered colour and the edge and point
//! responses, by separable filtering with edge values repeated past the border, each pixel's taps
//! summed in the reference implementation's order (so that the maps round as its maps do).

use std::cell::RefCell;
use std::ops::Range;

use crate::rgb_image::RgbImage;

use super::color::{Perceiver, color_error, feature_input, flip_error, srgb_to_ycxcz, strengths};
use super::kernels::KERNELS;

/// What FLIP's per-pixel error reads of one picture, over a band of its rows.
#[derive(Clone)]
pub(super) struct Maps {
    width: usize,
    rows: Range<usize>,
    /// The spatially filtered YCxCz, one plane per channel.
    color: [Vec<f32>; 3],
    /// The edge and point responses `dx, dy, ddx, ddy`.
    features: [Vec<f32>; 4],
}

/// What FLIP keeps of a reference picture to compare others with it: its maps over the whole
/// picture and what its half of every pixel's error needs of them.
#[derive(Clone)]
pub(in crate::compare) struct Reference {
    pub(super) maps: Maps,
    /// Each pixel's filtered colour as FLIP compares colours ([`super::color::perceived`]).
    pub(super) perceived: Vec<[f32; 3]>,
    /// Each pixel's edge and point [`strengths`].
    pub(super) strengths: Vec<[f32; 2]>,
}

impl std::fmt::Debug for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "flip::Reference({} pixels)", self.perceived.len())
    }
}

impl Reference {
    pub(super) fn of(picture: &RgbImage) -> Reference {
        let maps = Maps::of(picture, 0..picture.height() as usize);
        let pixels = maps.color[0].len();
        let mut perceiver = Perceiver::default();
        let perceived = (0..pixels).map(|p| perceiver.perceived(maps.color(p))).collect();
        Reference {
            perceived,
            strengths: (0..pixels).map(|p| strengths(maps.features(p))).collect(),
            maps,
        }
    }

    /// FLIP's error at `pixel` of a picture whose filtered colour and feature responses there are
    /// `color` and `features` (the colour perceived through `perceiver`).
    pub(super) fn error(&self, pixel: usize, color: [f32; 3], features: [f32; 4], perceiver: &mut Perceiver) -> f32 {
        let color_error = color_error(self.perceived[pixel], perceiver.perceived(color));
        flip_error(color_error, self.strengths[pixel], strengths(features))
    }
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

/// The rows a band's maps cover and the rows they read.
struct Band {
    width: usize,
    height: usize,
    /// The picture's rows the planes hold (the band and the filters' reach).
    read: Range<usize>,
    rows: Range<usize>,
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

impl Band {
    /// Each row of `plane` (the rows `read`) filtered by `taps` into `out`, the row's end values
    /// repeated past its ends.
    fn horizontal(&self, plane: &[f32], taps: &[f32], out: &mut Vec<f32>) {
        let (width, radius) = (self.width, taps.len() / 2);
        out.clear();
        out.resize(plane.len(), 0.0);
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
    }

    /// The band's rows of `plane` (the rows `read`) filtered down the columns by `taps`, the
    /// picture's first and last rows repeated past its ends.
    fn vertical(&self, plane: &[f32], taps: &[f32]) -> Vec<f32> {
        let mut out = Vec::new();
        self.vertical_into(plane, taps, &mut out);
        out
    }

    /// [`Band::vertical`] into `out`.
    fn vertical_into(&self, plane: &[f32], taps: &[f32], out: &mut Vec<f32>) {
        let (width, radius) = (self.width, taps.len() / 2);
        out.clear();
        out.resize(self.rows.len() * width, 0.0);
        for (y, out_row) in self.rows.clone().zip(out.chunks_exact_mut(width)) {
            for (t, &tap) in taps.iter().enumerate() {
                let source = (y + t).saturating_sub(radius).min(self.height - 1) - self.read.start;
                for (o, &v) in out_row.iter_mut().zip(&plane[source * width..(source + 1) * width]) {
                    *o += tap * v;
                }
            }
        }
    }
}
