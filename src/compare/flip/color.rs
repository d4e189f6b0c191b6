//! FLIP's colour pipeline, per pixel, as NVIDIA's reference implementation computes it
//! (`FLIP::color3` and the per-pixel tails of `computeColorDifference` and
//! `computeFeatureDifferenceAndFinalError`), in single precision and in the same order, eight
//! pixels at a time in SIMD lanes. The powers (three cube roots a colour, and three more an
//! error) are [`crate::simd::math::pow`], within a few units in the last place of `powf`'s and
//! the same on every path: they were half of grading's FLIP time as calls to the C library.

use std::sync::LazyLock;

use crate::simd::math::pow;
use crate::simd::{Isa, Lanes, Portable};

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
static MAX_DISTANCE: LazyLock<f32> = LazyLock::new(|| {
    let color = |rgb: [f32; 3]| rgb.map(V::<Portable>::splat);
    let distance = hyab::<Portable>(
        hunt_lab::<Portable>(color([0.0, 1.0, 0.0])),
        hunt_lab::<Portable>(color([0.0, 0.0, 1.0])),
    );
    let mut lanes = [0.0; 8];
    pow::<Portable>(distance, V::<Portable>::splat(QC)).store(&mut lanes);
    lanes[0]
});

/// An 8-bit sRGB pixel in FLIP's opponent space YCxCz (achromatic, red-green, blue-yellow).
pub(super) fn srgb_to_ycxcz(pixel: [u8; 3]) -> [f32; 3] {
    let [r, g, b] = pixel.map(|c| LINEAR[usize::from(c)]);
    xyz_to_ycxcz(RGB_TO_XYZ.map(|row| row[0] * r + row[1] * g + row[2] * b))
}

/// The achromatic channel as the feature detectors read it, in [0, 1].
pub(super) fn feature_input(achromatic: f32) -> f32 {
    achromatic * (1.0 / 116.0) + 16.0 / 116.0
}

/// Eight lanes of `f32`.
type V<I> = <I as Isa>::F32x8;

/// Spatially filtered YCxCz values as FLIP compares colours: clamped to the display's gamut, in
/// CIELAB with the Hunt adjustment.
#[inline(always)]
pub(super) fn perceived<I: Isa>(ycxcz: [V<I>; 3]) -> [V<I>; 3] {
    let [r, g, b] = xyz_to_linear_rgb::<I>(ycxcz_to_xyz::<I>(ycxcz));
    hunt_lab::<I>([to_unit::<I>(r), to_unit::<I>(g), to_unit::<I>(b)])
}

/// Each lane clamped to [0, 1] by `f32::clamp`'s comparisons (so that a −0 stays −0).
// The kernels' helpers are functions, not closures: a closure may be compiled outside the
// kernel, without its instructions.
#[inline(always)]
fn to_unit<I: Isa>(c: V<I>) -> V<I> {
    let (zero, one) = (V::<I>::splat(0.0), V::<I>::splat(1.0));
    V::<I>::select(c.gt(one), one, V::<I>::select(c.lt(zero), zero, c))
}

/// A linear RGB colour in CIELAB with the Hunt adjustment.
#[inline(always)]
fn hunt_lab<I: Isa>(rgb: [V<I>; 3]) -> [V<I>; 3] {
    hunt::<I>(xyz_to_lab::<I>(linear_rgb_to_xyz::<I>(rgb)))
}

/// The colour error of two [`perceived`] colours, in [0, 1].
#[inline(always)]
pub(super) fn color_error<I: Isa>(reference: [V<I>; 3], test: [V<I>; 3]) -> V<I> {
    let difference = pow::<I>(hyab::<I>(reference, test), V::<I>::splat(QC));
    let max = *MAX_DISTANCE;
    let knee = PC * max;
    let below = difference * V::<I>::splat(PT / knee);
    let above =
        V::<I>::splat(PT) + ((difference - V::<I>::splat(knee)) / V::<I>::splat(max - knee)) * V::<I>::splat(1.0 - PT);
    V::<I>::select(difference.lt(V::<I>::splat(knee)), below, above)
}

/// The edge and point strengths of the feature responses `[dx, dy, ddx, ddy]`.
#[inline(always)]
pub(super) fn strengths<I: Isa>([dx, dy, ddx, ddy]: [V<I>; 4]) -> [V<I>; 2] {
    [(dx * dx + dy * dy).sqrt(), (ddx * ddx + ddy * ddy).sqrt()]
}

/// FLIP's error at a pixel: the colour error raised to one minus the feature difference, given
/// both images' edge and point [`strengths`].
#[inline(always)]
pub(super) fn flip_error<I: Isa>(color_error: V<I>, reference: [V<I>; 2], test: [V<I>; 2]) -> V<I> {
    let edge = (reference[0] - test[0]).abs();
    let point = (reference[1] - test[1]).abs();
    let feature = pow::<I>(V::<I>::splat(1.0 / 2.0f32.sqrt()) * edge.max(point), V::<I>::splat(QF));
    pow::<I>(color_error, V::<I>::splat(1.0) - feature)
}

#[inline(always)]
fn linear_rgb_to_xyz<I: Isa>(rgb: [V<I>; 3]) -> [V<I>; 3] {
    multiply::<I>(&RGB_TO_XYZ, rgb)
}

#[inline(always)]
fn xyz_to_linear_rgb<I: Isa>(xyz: [V<I>; 3]) -> [V<I>; 3] {
    multiply::<I>(&XYZ_TO_RGB, xyz)
}

/// `matrix · v`, each row's products summed left to right.
#[inline(always)]
fn multiply<I: Isa>(matrix: &[[f32; 3]; 3], v: [V<I>; 3]) -> [V<I>; 3] {
    [
        row::<I>(&matrix[0], v),
        row::<I>(&matrix[1], v),
        row::<I>(&matrix[2], v),
    ]
}

#[inline(always)]
fn row<I: Isa>(r: &[f32; 3], [x, y, z]: [V<I>; 3]) -> V<I> {
    V::<I>::splat(r[0]) * x + V::<I>::splat(r[1]) * y + V::<I>::splat(r[2]) * z
}

const RGB_TO_XYZ: [[f32; 3]; 3] = [
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

const XYZ_TO_RGB: [[f32; 3]; 3] = [
    [3.241_003_3, -1.537_398_9, -0.498_615_86],
    [-0.969_224_33, 1.875_930_1, 0.041554224],
    [0.055639423, -0.204_011_2, 1.057_148_9],
];

fn xyz_to_ycxcz(xyz: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = [0, 1, 2].map(|i| xyz[i] * INV_ILLUMINANT[i]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

#[inline(always)]
fn ycxcz_to_xyz<I: Isa>([achromatic, red_green, blue_yellow]: [V<I>; 3]) -> [V<I>; 3] {
    let y = (achromatic + V::<I>::splat(16.0)) / V::<I>::splat(116.0);
    let (cx, cz) = (red_green / V::<I>::splat(500.0), blue_yellow / V::<I>::splat(200.0));
    [
        (y + cx) * V::<I>::splat(ILLUMINANT[0]),
        y * V::<I>::splat(ILLUMINANT[1]),
        (y - cz) * V::<I>::splat(ILLUMINANT[2]),
    ]
}

#[inline(always)]
fn xyz_to_lab<I: Isa>(xyz: [V<I>; 3]) -> [V<I>; 3] {
    let [x, y, z] = [
        lab_curve::<I>(xyz[0], 0),
        lab_curve::<I>(xyz[1], 1),
        lab_curve::<I>(xyz[2], 2),
    ];
    [
        V::<I>::splat(116.0) * y - V::<I>::splat(16.0),
        V::<I>::splat(500.0) * (x - y),
        V::<I>::splat(200.0) * (y - z),
    ]
}

/// CIELAB's curve of an XYZ channel relative to the illuminant's (`channel` 0, 1 or 2).
#[inline(always)]
fn lab_curve<I: Isa>(value: V<I>, channel: usize) -> V<I> {
    let delta = 6.0f32 / 29.0;
    let delta_square = delta * delta;
    let delta_cube = delta * delta_square;
    let factor = 1.0 / (3.0 * delta_square);
    let term = 4.0f32 / 29.0;
    let v = value * V::<I>::splat(INV_ILLUMINANT[channel]);
    let linear = V::<I>::splat(factor) * v + V::<I>::splat(term);
    V::<I>::select(
        v.gt(V::<I>::splat(delta_cube)),
        pow::<I>(v, V::<I>::splat(1.0 / 3.0)),
        linear,
    )
}

/// The Hunt effect: chroma is perceived less at low luminance.
#[inline(always)]
fn hunt<I: Isa>([l, a, b]: [V<I>; 3]) -> [V<I>; 3] {
    let scale = V::<I>::splat(0.01) * l;
    [l, scale * a, scale * b]
}

/// Lightness by city-block distance, chroma by Euclidean distance.
#[inline(always)]
fn hyab<I: Isa>(reference: [V<I>; 3], test: [V<I>; 3]) -> V<I> {
    let (da, db) = (reference[1] - test[1], reference[2] - test[2]);
    (reference[0] - test[0]).abs() + (da * da + db * db).sqrt()
}
