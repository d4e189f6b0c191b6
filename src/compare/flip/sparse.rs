//! FLIP of a picture that differs from its reference in a few pixels. Filtering is linear, so the
//! test picture's maps are the reference's maps plus the filtered differences: each differing
//! pixel adds its kernels' weights to the pixels in its reach, and only those pixels are
//! measured. The cost follows the number of differing pixels, not the picture's size.

use image::RgbImage;

use super::color::{color_error, feature_input, flip_error, srgb_to_ycxcz};
use super::kernels::{KERNELS, clamped_weight};
use super::maps::Maps;

/// The longest kernel, in taps (the spatial filters have 21 at the default viewing setup).
const MAX_TAPS: usize = 32;

/// The sum of FLIP's error map of `test` against `reference` (whose maps are `maps`), which
/// differ only at the pixel indices `differing` (ascending).
pub(super) fn error_sum(reference: &RgbImage, maps: &Maps, test: &RgbImage, differing: &[usize]) -> f64 {
    let k = &*KERNELS;
    let (width, height) = (reference.width() as usize, reference.height() as usize);
    let pixels = width * height;
    let mut color: [Vec<f32>; 3] = std::array::from_fn(|_| vec![0.0; pixels]);
    let mut features: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; pixels]);
    let mut reached = vec![false; pixels];
    let (spatial, feature) = (k.spatial_radius(), k.feature_radius());
    assert!(k.achromatic.len() <= MAX_TAPS && k.gaussian.len() <= MAX_TAPS);
    for &pixel in differing {
        let (x, y) = (pixel % width, pixel / width);
        let at = |picture: &RgbImage| picture.get_pixel(x as u32, y as u32).0;
        let (before, after) = (srgb_to_ycxcz(at(reference)), srgb_to_ycxcz(at(test)));
        let delta = [0, 1, 2].map(|c| after[c] - before[c]);
        let gray = feature_input(after[0]) - feature_input(before[0]);

        let xs = Reach::new(x, width, spatial);
        let ys = Reach::new(y, height, spatial);
        let [ax, rx, bx1, bx2] =
            [&k.achromatic, &k.red_green, &k.blue_yellow[0], &k.blue_yellow[1]].map(|t| xs.weights(t));
        let [ay, ry, by1, by2] =
            [&k.achromatic, &k.red_green, &k.blue_yellow[0], &k.blue_yellow[1]].map(|t| ys.weights(t));
        for (j, ty) in ys.targets().enumerate() {
            let row = ty * width;
            for (i, tx) in xs.targets().enumerate() {
                let p = row + tx;
                reached[p] = true;
                color[0][p] += ay[j] * ax[i] * delta[0];
                color[1][p] += ry[j] * rx[i] * delta[1];
                color[2][p] += (by1[j] * bx1[i] + by2[j] * bx2[i]) * delta[2];
            }
        }

        let xs = Reach::new(x, width, feature);
        let ys = Reach::new(y, height, feature);
        let [gx, dx, ddx] = [&k.gaussian, &k.first, &k.second].map(|t| xs.weights(t));
        let [gy, dy, ddy] = [&k.gaussian, &k.first, &k.second].map(|t| ys.weights(t));
        for (j, ty) in ys.targets().enumerate() {
            let row = ty * width;
            for (i, tx) in xs.targets().enumerate() {
                let p = row + tx;
                reached[p] = true;
                features[0][p] += gy[j] * dx[i] * gray;
                features[1][p] += dy[j] * gx[i] * gray;
                features[2][p] += gy[j] * ddx[i] * gray;
                features[3][p] += ddy[j] * gx[i] * gray;
            }
        }
    }
    reached
        .iter()
        .enumerate()
        .filter(|&(_, &r)| r)
        .map(|(p, _)| {
            let (before, features_before) = (maps.color(p), maps.features(p));
            let after = [0, 1, 2].map(|c| before[c] + color[c][p]);
            let features_after = [0, 1, 2, 3].map(|c| features_before[c] + features[c][p]);
            f64::from(flip_error(color_error(before, after), features_before, features_after))
        })
        .sum()
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
