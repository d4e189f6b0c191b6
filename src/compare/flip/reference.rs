//! What FLIP keeps of a reference picture, and the error of other pictures against it, computed
//! eight pixels at a time in SIMD lanes.

use crate::rgb_image::RgbImage;
use crate::simd::{Isa, Kernel, Lanes, dispatch};

use super::color::{color_error, flip_error, perceived, strengths};
use super::maps::Maps;

/// Pixels a lane group holds.
const LANES: usize = 8;

type V<I> = <I as Isa>::F32x8;

/// What FLIP keeps of a reference picture to compare others with it: its maps over the whole
/// picture and its perceived colours (three cube roots a pixel, too dear to make again for each
/// picture compared). Its edge and point strengths are made again from its feature map where
/// an error needs them (two square roots): a class's goldens are kept all through grading, and
/// 5 MB less each at 800×800 is 5 MB fewer pages to fault in.
#[derive(Clone)]
pub(in crate::compare) struct Reference {
    pub(super) maps: Maps,
    /// Each pixel's filtered colour as FLIP compares colours ([`perceived`]), by channel.
    perceived: [Vec<f32>; 3],
}

impl std::fmt::Debug for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "flip::Reference({} pixels)", self.perceived[0].len())
    }
}

impl Reference {
    pub(super) fn of(picture: &RgbImage) -> Reference {
        struct Perceived<'a>(&'a Maps);
        impl Kernel for Perceived<'_> {
            type Output = [Vec<f32>; 3];
            #[inline(always)]
            fn run<I: Isa>(self) -> Self::Output {
                let color = &self.0.color;
                let pixels = color[0].len();
                let mut planes: [Vec<f32>; 3] = Default::default();
                for plane in planes.iter_mut() {
                    plane.resize(pixels, 0.0);
                }
                for start in (0..pixels).step_by(LANES) {
                    for (plane, lanes) in planes.iter_mut().zip(perceived::<I>(planes_at::<I, 3>(color, start))) {
                        store_at::<I>(lanes, plane, start);
                    }
                }
                planes
            }
        }
        let maps = Maps::of(picture, 0..picture.height() as usize);
        let perceived = dispatch(Perceived(&maps));
        Reference { maps, perceived }
    }

    /// The sum of FLIP's error at each of `test`'s pixels, in their order.
    pub(super) fn error_sum(&self, test: &TestPixels) -> f64 {
        struct Errors<'a>(&'a Reference, &'a TestPixels);
        impl Kernel for Errors<'_> {
            type Output = Vec<f32>;
            #[inline(always)]
            fn run<I: Isa>(self) -> Vec<f32> {
                let Errors(reference, test) = self;
                let count = test.pixels.len();
                let mut errors = vec![0.0; count];
                for start in (0..count).step_by(LANES) {
                    let pixels = &test.pixels[start..(start + LANES).min(count)];
                    let color = planes_at::<I, 3>(&test.color, start);
                    let features = planes_at::<I, 4>(&test.features, start);
                    let expected = gather::<I, 3>(&reference.perceived, pixels);
                    let expected_strengths = strengths::<I>(gather::<I, 4>(&reference.maps.features, pixels));
                    let color_error = color_error::<I>(expected, perceived::<I>(color));
                    let error = flip_error::<I>(color_error, expected_strengths, strengths::<I>(features));
                    store_at::<I>(error, &mut errors, start);
                }
                errors
            }
        }
        dispatch(Errors(self, test)).iter().map(|&e| f64::from(e)).sum()
    }
}

/// A test picture's filtered colour and feature responses at some of its pixels (indices into
/// the whole picture), gathered for [`Reference::error_sum`].
pub(super) struct TestPixels {
    pixels: Vec<usize>,
    color: [Vec<f32>; 3],
    features: [Vec<f32>; 4],
}

impl TestPixels {
    pub(super) fn with_capacity(pixels: usize) -> TestPixels {
        TestPixels {
            pixels: Vec::with_capacity(pixels),
            color: std::array::from_fn(|_| Vec::with_capacity(pixels)),
            features: std::array::from_fn(|_| Vec::with_capacity(pixels)),
        }
    }

    pub(super) fn push(&mut self, pixel: usize, color: [f32; 3], features: [f32; 4]) {
        self.pixels.push(pixel);
        for (plane, value) in self.color.iter_mut().zip(color) {
            plane.push(value);
        }
        for (plane, value) in self.features.iter_mut().zip(features) {
            plane.push(value);
        }
    }
}

/// [`lanes_at`] of each plane.
#[inline(always)]
fn planes_at<I: Isa, const N: usize>(planes: &[Vec<f32>; N], start: usize) -> [V<I>; N] {
    let mut lanes = [V::<I>::splat(0.0); N];
    for (lanes, plane) in lanes.iter_mut().zip(planes) {
        *lanes = lanes_at::<I>(plane, start);
    }
    lanes
}

/// Each plane's values at `pixels` (up to eight) as lanes, zeros past the last.
#[inline(always)]
fn gather<I: Isa, const N: usize>(planes: &[Vec<f32>; N], pixels: &[usize]) -> [V<I>; N] {
    let mut lanes = [V::<I>::splat(0.0); N];
    for (lanes, plane) in lanes.iter_mut().zip(planes) {
        let mut values = [0.0; LANES];
        for (value, &pixel) in values.iter_mut().zip(pixels) {
            *value = plane[pixel];
        }
        *lanes = V::<I>::load(&values);
    }
    lanes
}

/// `plane[start..start + 8]` as lanes, zeros past the plane's end.
#[inline(always)]
fn lanes_at<I: Isa>(plane: &[f32], start: usize) -> V<I> {
    if start + LANES <= plane.len() {
        V::<I>::load(&plane[start..])
    } else {
        let mut lanes = [0.0; LANES];
        lanes[..plane.len() - start].copy_from_slice(&plane[start..]);
        V::<I>::load(&lanes)
    }
}

/// Stores `lanes` at `plane[start..]`, as many as fit.
#[inline(always)]
fn store_at<I: Isa>(lanes: V<I>, plane: &mut [f32], start: usize) {
    if start + LANES <= plane.len() {
        lanes.store(&mut plane[start..]);
    } else {
        let mut all = [0.0; LANES];
        lanes.store(&mut all);
        let end = plane.len();
        plane[start..].copy_from_slice(&all[..end - start]);
    }
}
