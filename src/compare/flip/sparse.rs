//! FLIP of a picture that differs from its reference in a few pixels. Filtering is linear, so the
//! test picture's maps are the reference's maps plus the filtered differences: each differing
//! pixel adds its kernels' weights to the pixels in its reach, and only those pixels are
//! measured. The cost follows the number of differing pixels, not the picture's size.

use crate::rgb_image::RgbImage;

use super::color::{feature_input, srgb_to_ycxcz};
use super::kernels::{KERNELS, MAX_TAPS, clamped_weight};
use super::reference::{Reference, TestPixels};

/// The sum of FLIP's error map of `test` against `reference` (`picture`'s maps), which differ
/// only at the pixel indices `differing`.
pub(super) fn error_sum(picture: &RgbImage, reference: &Reference, test: &RgbImage, differing: &[usize]) -> f64 {
    let k = &*KERNELS;
    let (width, height) = (picture.width() as usize, picture.height() as usize);
    let mut changes = Changes::new(width * height);
    let (spatial, feature) = (k.spatial_radius(), k.feature_radius());
    assert!(k.achromatic.len() <= MAX_TAPS && k.gaussian.len() <= MAX_TAPS);
    for &pixel in differing {
        let (x, y) = (pixel % width, pixel / width);
        let at = |picture: &RgbImage| picture.get_pixel(x as u32, y as u32).0;
        let (before, after) = (srgb_to_ycxcz(at(picture)), srgb_to_ycxcz(at(test)));
        let delta = [0, 1, 2].map(|c| after[c] - before[c]);
        let gray = feature_input(after[0]) - feature_input(before[0]);

        let xs = Reach::new(x, width, spatial);
        let ys = Reach::new(y, height, spatial);
        let [ax, rx, bx1, bx2] =
            [&k.achromatic, &k.red_green, &k.blue_yellow[0], &k.blue_yellow[1]].map(|t| xs.weights(t));
        let [ay, ry, by1, by2] =
            [&k.achromatic, &k.red_green, &k.blue_yellow[0], &k.blue_yellow[1]].map(|t| ys.weights(t));
        for (j, ty) in ys.targets().enumerate() {
            for (i, tx) in xs.targets().enumerate() {
                let change = changes.at(ty * width + tx);
                change[0] += ay[j] * ax[i] * delta[0];
                change[1] += ry[j] * rx[i] * delta[1];
                change[2] += (by1[j] * bx1[i] + by2[j] * bx2[i]) * delta[2];
            }
        }

        let xs = Reach::new(x, width, feature);
        let ys = Reach::new(y, height, feature);
        let [gx, dx, ddx] = [&k.gaussian, &k.first, &k.second].map(|t| xs.weights(t));
        let [gy, dy, ddy] = [&k.gaussian, &k.first, &k.second].map(|t| ys.weights(t));
        for (j, ty) in ys.targets().enumerate() {
            for (i, tx) in xs.targets().enumerate() {
                let change = changes.at(ty * width + tx);
                change[3] += gy[j] * dx[i] * gray;
                change[4] += dy[j] * gx[i] * gray;
                change[5] += gy[j] * ddx[i] * gray;
                change[6] += ddy[j] * gx[i] * gray;
            }
        }
    }
    let mut reached = TestPixels::with_capacity(changes.reached.len());
    for (&p, change) in changes.reached.iter().zip(&changes.sums) {
        let (color, features) = (reference.maps.color(p), reference.maps.features(p));
        let color = [0, 1, 2].map(|c| color[c] + change[c]);
        let features = [0, 1, 2, 3].map(|c| features[c] + change[3 + c]);
        reached.push(p, color, features);
    }
    reference.error_sum(&reached)
}

/// The changes to the maps (colour, then features) at the pixels the differences reach, in the
/// order first reached; a pixel's slot is found through one index per pixel.
struct Changes {
    slot: Vec<u32>,
    reached: Vec<usize>,
    sums: Vec<[f32; 7]>,
}

impl Changes {
    fn new(pixels: usize) -> Changes {
        Changes {
            slot: vec![u32::MAX; pixels],
            reached: Vec::new(),
            sums: Vec::new(),
        }
    }

    fn at(&mut self, pixel: usize) -> &mut [f32; 7] {
        let slot = &mut self.slot[pixel];
        if *slot == u32::MAX {
            *slot = self.sums.len() as u32;
            self.reached.push(pixel);
            self.sums.push([0.0; 7]);
        }
        &mut self.sums[*slot as usize]
    }
}

/// The pixels along one axis that a source pixel's kernels reach.
struct Reach {
    source: usize,
    len: usize,
    first: usize,
    last: usize,
}

impl Reach {
    fn new(source: usize, len: usize, radius: usize) -> Reach {
        Reach {
            source,
            len,
            first: source.saturating_sub(radius),
            last: (source + radius).min(len - 1),
        }
    }

    fn targets(&self) -> std::ops::RangeInclusive<usize> {
        self.first..=self.last
    }

    /// The weight `taps` gives the source at each target, in target order.
    fn weights(&self, taps: &[f32]) -> [f32; MAX_TAPS] {
        let mut weights = [0.0; MAX_TAPS];
        for (w, target) in weights.iter_mut().zip(self.targets()) {
            *w = clamped_weight(taps, self.source, target, self.len);
        }
        weights
    }
}
