//! FLIP's filters at its default viewing setup, built as the reference implementation builds them
//! (NVIDIA's `FLIP::image::setSpatialFilters` and `setFeatureFilter`, in single precision and in
//! the same order), so that filtering here rounds as it does there.

use std::sync::LazyLock;

/// The longest kernel, in taps (the spatial filters have 21 at the default viewing setup).
pub(super) const MAX_TAPS: usize = 32;

/// Pixels per degree of visual angle: `nv_flip::DEFAULT_PIXELS_PER_DEGREE`, a 0.7 m viewing
/// distance from a 0.7 m wide 4K monitor. A test checks it against the crate.
pub(super) const PIXELS_PER_DEGREE: f32 = 67.0;

use std::f32::consts::PI;

/// The contrast sensitivity functions as sums of Gaussians (the paper's `a`, `b` constants), for
/// the achromatic, red-green and blue-yellow channels; blue-yellow is the only one with a second
/// Gaussian.
const A1: [f32; 3] = [1.0, 1.0, 34.1];
const B1: [f32; 3] = [0.0047, 0.0053, 0.04];
const A2_BLUE_YELLOW: f32 = 13.5;
const B2_BLUE_YELLOW: f32 = 0.025;
/// The largest `b` among the channels' Gaussians, which sets the spatial filters' radius.
const B_MAX: f32 = 0.04;
/// The edge and point detectors' width in degrees.
const FEATURE_WIDTH: f32 = 0.082;

/// One-dimensional taps, index `i` for offset `i - radius`. Every 2-D filter of FLIP is separable
/// (or, for blue-yellow, a sum of two separable ones).
pub(super) struct Kernels {
    /// Spatial (contrast sensitivity) filters, radius [`Kernels::spatial_radius`].
    pub achromatic: Vec<f32>,
    pub red_green: Vec<f32>,
    pub blue_yellow: [Vec<f32>; 2],
    /// Feature detectors, radius [`Kernels::feature_radius`]: a Gaussian, its first and its
    /// second derivative (positive and negative weights of each derivative sum to ±1).
    pub gaussian: Vec<f32>,
    pub first: Vec<f32>,
    pub second: Vec<f32>,
}

impl Kernels {
    pub fn spatial_radius(&self) -> usize {
        self.achromatic.len() / 2
    }

    pub fn feature_radius(&self) -> usize {
        self.gaussian.len() / 2
    }
}

/// The kernels, made once per process.
pub(super) static KERNELS: LazyLock<Kernels> = LazyLock::new(|| {
    let (achromatic, red_green, blue_yellow) = spatial_filters();
    let (gaussian, first, second) = feature_filters();
    Kernels {
        achromatic,
        red_green,
        blue_yellow,
        gaussian,
        first,
        second,
    }
});

/// `a·√(π/b)·exp(−π²x²/b)`, the paper's form of a Gaussian.
fn gaussian_ab(x2: f32, a: f32, b: f32) -> f32 {
    a * (PI / b).sqrt() * (-(PI * PI) * x2 / b).exp()
}

/// The square root of [`gaussian_ab`]'s amplitude: one factor of a separated sum of Gaussians.
fn gaussian_ab_sqrt(x2: f32, a: f32, b: f32) -> f32 {
    (a * (PI / b).sqrt()).sqrt() * (-(PI * PI) * x2 / b).exp()
}

fn spatial_filters() -> (Vec<f32>, Vec<f32>, [Vec<f32>; 2]) {
    let radius = (3.0 * (B_MAX / (2.0 * (PI * PI))).sqrt() * PIXELS_PER_DEGREE).ceil() as i32;
    let delta = 1.0 / PIXELS_PER_DEGREE;
    let offsets = || (-radius..=radius).map(|i| i as f32 * delta).map(|x| x * x);
    let mut achromatic: Vec<f32> = offsets().map(|x2| gaussian_ab(x2, A1[0], B1[0])).collect();
    let mut red_green: Vec<f32> = offsets().map(|x2| gaussian_ab(x2, A1[1], B1[1])).collect();
    let mut first: Vec<f32> = offsets().map(|x2| gaussian_ab_sqrt(x2, A1[2], B1[2])).collect();
    let mut second: Vec<f32> = offsets()
        .map(|x2| gaussian_ab_sqrt(x2, A2_BLUE_YELLOW, B2_BLUE_YELLOW))
        .collect();
    let sum = |taps: &[f32]| taps.iter().fold(0.0f32, |s, &t| s + t);
    let (achromatic_norm, red_green_norm) = (1.0 / sum(&achromatic), 1.0 / sum(&red_green));
    let (first_sum, second_sum) = (sum(&first), sum(&second));
    let blue_yellow_norm = 1.0 / (first_sum * first_sum + second_sum * second_sum).sqrt();
    achromatic.iter_mut().for_each(|t| *t *= achromatic_norm);
    red_green.iter_mut().for_each(|t| *t *= red_green_norm);
    first
        .iter_mut()
        .chain(second.iter_mut())
        .for_each(|t| *t *= blue_yellow_norm);
    (achromatic, red_green, [first, second])
}

fn feature_filters() -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let deviation = 0.5 * FEATURE_WIDTH * PIXELS_PER_DEGREE;
    let radius = (3.0 * deviation).ceil() as i32;
    let mut gaussian = Vec::new();
    let mut first = Vec::new();
    let mut second = Vec::new();
    let (mut gaussian_sum, mut first_sums, mut second_sums) = (0.0f32, [0.0f32; 2], [0.0f32; 2]);
    for i in -radius..=radius {
        let x = i as f32;
        let g = (-(x * x) / (2.0 * deviation * deviation)).exp();
        gaussian_sum += g;
        let dg = -x * g;
        if dg > 0.0 {
            first_sums[0] += dg;
        } else {
            first_sums[1] -= dg;
        }
        let ddg = (x * x / (deviation * deviation) - 1.0) * g;
        if ddg > 0.0 {
            second_sums[0] += ddg;
        } else {
            second_sums[1] -= ddg;
        }
        gaussian.push(g);
        first.push(dg);
        second.push(ddg);
    }
    gaussian.iter_mut().for_each(|g| *g /= gaussian_sum);
    let normalise = |taps: &mut Vec<f32>, sums: [f32; 2]| {
        taps.iter_mut()
            .for_each(|t| *t /= if *t > 0.0 { sums[0] } else { sums[1] })
    };
    normalise(&mut first, first_sums);
    normalise(&mut second, second_sums);
    (gaussian, first, second)
}

/// The weight a separable filter gives the value at `source` when filtering at `target`, along
/// one axis of length `len` whose ends are extended by repeating the edge value (as FLIP
/// filters). Zero when `target` is out of the kernel's reach.
pub(super) fn clamped_weight(taps: &[f32], source: usize, target: usize, len: usize) -> f32 {
    let radius = taps.len() / 2;
    if source > 0 && source + 1 < len {
        return match (source + radius).checked_sub(target) {
            Some(i) if i < taps.len() => taps[i],
            _ => 0.0,
        };
    }
    (0..taps.len())
        .filter(|&i| (target + i).saturating_sub(radius).min(len - 1) == source)
        .fold(0.0, |sum, i| sum + taps[i])
}
