//! FLIP's colour pipeline, per pixel, as NVIDIA's reference implementation computes it
//! (`FLIP::color3` and the per-pixel tails of `computeColorDifference` and
//! `computeFeatureDifferenceAndFinalError`), in single precision and in the same order.

use std::sync::LazyLock;

const ILLUMINANT: [f32; 3] = [0.950_428_55, 1.000000000, 1.088_900_3];
const INV_ILLUMINANT: [f32; 3] = [1.052_156_9, 1.000000000, 0.918_357_7];

/// The colour difference's exponent, its knee (as a fraction of the largest difference) and the
/// error it maps the knee to.
const QC: f32 = 0.7;
const PC: f32 = 0.4;
const PT: f32 = 0.95;
/// The feature difference's exponent.
const QF: f32 = 0.5;

/// An sRGB code value's linear intensity, for every code.
static LINEAR: LazyLock<[f32; 256]> = LazyLock::new(|| {
    std::array::from_fn(|code| {
        let c = code as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    })
});

/// The largest colour difference (green against blue), after the exponent.
static MAX_DISTANCE: LazyLock<f32> =
    LazyLock::new(|| hyab(hunt_lab([0.0, 1.0, 0.0]), hunt_lab([0.0, 0.0, 1.0])).powf(QC));

/// An 8-bit sRGB pixel in FLIP's opponent space YCxCz (achromatic, red-green, blue-yellow).
pub(super) fn srgb_to_ycxcz(pixel: [u8; 3]) -> [f32; 3] {
    xyz_to_ycxcz(linear_rgb_to_xyz(pixel.map(|c| LINEAR[usize::from(c)])))
}

/// The achromatic channel as the feature detectors read it, in [0, 1].
pub(super) fn feature_input(achromatic: f32) -> f32 {
    achromatic * (1.0 / 116.0) + 16.0 / 116.0
}

/// A spatially filtered YCxCz value as FLIP compares colours: clamped to the display's gamut,
/// in CIELAB with the Hunt adjustment.
pub(super) fn perceived(ycxcz: [f32; 3]) -> [f32; 3] {
    let [r, g, b] = xyz_to_linear_rgb(ycxcz_to_xyz(ycxcz));
    hunt_lab([r.clamp(0.0, 1.0), g.clamp(0.0, 1.0), b.clamp(0.0, 1.0)])
}

/// [`perceived`], remembering the last colour it was given: a render's flat regions (a
/// background, an unlit floor) filter to the same colour pixel after pixel, and the previous
/// result is reused when the colour is the same to the bit, which is exact and skips three cube
/// roots.
#[derive(Default)]
pub(super) struct Perceiver {
    last: Option<([u32; 3], [f32; 3])>,
}

impl Perceiver {
    pub(super) fn perceived(&mut self, ycxcz: [f32; 3]) -> [f32; 3] {
        let bits = ycxcz.map(f32::to_bits);
        match self.last {
            Some((seen, result)) if seen == bits => result,
            _ => {
                let result = perceived(ycxcz);
                self.last = Some((bits, result));
                result
            }
        }
    }
}

/// A linear RGB colour in CIELAB with the Hunt adjustment.
fn hunt_lab(rgb: [f32; 3]) -> [f32; 3] {
    hunt(xyz_to_lab(linear_rgb_to_xyz(rgb)))
}

/// The colour error of two [`perceived`] colours, in [0, 1].
pub(super) fn color_error(reference: [f32; 3], test: [f32; 3]) -> f32 {
    let difference = hyab(reference, test).powf(QC);
    let max = *MAX_DISTANCE;
    let knee = PC * max;
    if difference < knee {
        difference * (PT / knee)
    } else {
        PT + ((difference - knee) / (max - knee)) * (1.0 - PT)
    }
}

/// The edge and point strengths of the feature responses `[dx, dy, ddx, ddy]`.
pub(super) fn strengths([dx, dy, ddx, ddy]: [f32; 4]) -> [f32; 2] {
    [(dx * dx + dy * dy).sqrt(), (ddx * ddx + ddy * ddy).sqrt()]
}

/// FLIP's error at a pixel: the colour error raised to one minus the feature difference, given
/// both images' edge and point [`strengths`].
pub(super) fn flip_error(color_error: f32, reference: [f32; 2], test: [f32; 2]) -> f32 {
    let edge = (reference[0] - test[0]).abs();
    let point = (reference[1] - test[1]).abs();
    let feature = ((1.0 / 2.0f32.sqrt()) * if edge > point { edge } else { point }).powf(QF);
    color_error.powf(1.0 - feature)
}

fn linear_rgb_to_xyz([r, g, b]: [f32; 3]) -> [f32; 3] {
    const A: [[f32; 3]; 3] = [
        [
            10_135_552.0 / 24_577_794.0,
            8_788_810.0 / 24_577_794.0,
            4_435_075.0 / 24_577_794.0,
        ],
        [
            2_613_072.0 / 12_288_897.0,
            8_788_810.0 / 12_288_897.0,
            887_015.0 / 12_288_897.0,
        ],
        [
            1_425_312.0 / 73_733_382.0,
            8_788_810.0 / 73_733_382.0,
            70_074_185.0 / 73_733_382.0,
        ],
    ];
    A.map(|row| row[0] * r + row[1] * g + row[2] * b)
}

fn xyz_to_linear_rgb([x, y, z]: [f32; 3]) -> [f32; 3] {
    const A: [[f32; 3]; 3] = [
        [3.241_003_3, -1.537_398_9, -0.498_615_86],
        [-0.969_224_33, 1.875_930_1, 0.041554224],
        [0.055639423, -0.204_011_2, 1.057_148_9],
    ];
    A.map(|row| row[0] * x + row[1] * y + row[2] * z)
}

fn xyz_to_ycxcz(xyz: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = [0, 1, 2].map(|i| xyz[i] * INV_ILLUMINANT[i]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

fn ycxcz_to_xyz([achromatic, red_green, blue_yellow]: [f32; 3]) -> [f32; 3] {
    let y = (achromatic + 16.0) / 116.0;
    let (cx, cz) = (red_green / 500.0, blue_yellow / 200.0);
    let xyz = [y + cx, y, y - cz];
    [0, 1, 2].map(|i| xyz[i] * ILLUMINANT[i])
}

fn xyz_to_lab(xyz: [f32; 3]) -> [f32; 3] {
    let delta = 6.0f32 / 29.0;
    let delta_square = delta * delta;
    let delta_cube = delta * delta_square;
    let factor = 1.0 / (3.0 * delta_square);
    let term = 4.0f32 / 29.0;
    let [x, y, z] = [0, 1, 2].map(|i| {
        let v = xyz[i] * INV_ILLUMINANT[i];
        if v > delta_cube {
            v.powf(1.0 / 3.0)
        } else {
            factor * v + term
        }
    });
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// The Hunt effect: chroma is perceived less at low luminance.
fn hunt([l, a, b]: [f32; 3]) -> [f32; 3] {
    [l, 0.01 * l * a, 0.01 * l * b]
}

/// Lightness by city-block distance, chroma by Euclidean distance.
fn hyab(reference: [f32; 3], test: [f32; 3]) -> f32 {
    let (da, db) = (reference[1] - test[1], reference[2] - test[2]);
    (reference[0] - test[0]).abs() + (da * da + db * db).sqrt()
}
