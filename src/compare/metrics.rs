//! The numbers a comparison is judged on. Every channel value pair is classified before any
//! arithmetic, because `NaN > threshold` is false: a NaN that reached a subtraction would make a
//! broken pixel look perfect.

use std::time::{Duration, Instant};

use serde::{Deserialize, Deserializer, Serialize};

use super::image::{COLOR_CHANNELS, Channel, Encoding, Image, Plane};

/// One channel of one pixel in both images.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PixelError {
    pub x: u32,
    pub y: u32,
    pub channel: &'static str,
    pub expected: f32,
    pub actual: f32,
}

/// [`PixelError`] as read back from JSON: the channel named by a string, and `null` for the
/// infinite values JSON cannot write.
#[derive(Deserialize)]
struct PixelErrorJson {
    x: u32,
    y: u32,
    channel: String,
    expected: Option<f32>,
    actual: Option<f32>,
}

impl<'de> Deserialize<'de> for PixelError {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<PixelError, D::Error> {
        let json = PixelErrorJson::deserialize(deserializer)?;
        Ok(PixelError {
            x: json.x,
            y: json.y,
            channel: channel_name(&json.channel).map_err(serde::de::Error::custom)?,
            expected: json.expected.unwrap_or(f32::INFINITY),
            actual: json.actual.unwrap_or(f32::INFINITY),
        })
    }
}

impl PixelError {
    /// `|expected − actual|`, infinite when exactly one side is non-finite.
    pub fn error(&self) -> f64 {
        match difference(self.expected, self.actual, true) {
            Difference::Finite(d) => d,
            Difference::Coverage | Difference::Broken => f64::INFINITY,
        }
    }
}

/// How one value pair compares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Difference {
    /// Both finite (or the same non-finite value on both sides): the absolute difference.
    Finite(f64),
    /// A depth hit on one side and a miss (`+inf`) on the other: a silhouette moved.
    Coverage,
    /// NaN or infinity on one side only, where no valid render produces it.
    Broken,
}

pub(super) fn difference(expected: f32, actual: f32, infinity_is_a_value: bool) -> Difference {
    if expected.is_finite() && actual.is_finite() {
        return Difference::Finite((f64::from(expected) - f64::from(actual)).abs());
    }
    if expected == actual || (expected.is_nan() && actual.is_nan()) {
        return Difference::Finite(0.0);
    }
    let miss_or_hit = |v: f32| v.is_finite() || v == f32::INFINITY;
    if infinity_is_a_value && miss_or_hit(expected) && miss_or_hit(actual) {
        Difference::Coverage
    } else {
        Difference::Broken
    }
}

impl Difference {
    pub(super) fn exceeds(self, threshold: f64) -> bool {
        match self {
            Difference::Finite(d) => d > threshold,
            Difference::Coverage | Difference::Broken => true,
        }
    }
}

/// Per-channel findings, so that a report can say "the depth moved" rather than only "something".
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChannelStats {
    pub name: &'static str,
    /// Pixels where this channel differs by more than the pixel threshold.
    pub failing: usize,
    /// The largest difference (a silhouette change counts as infinite); `None` when identical.
    pub worst: Option<PixelError>,
}

#[derive(Deserialize)]
struct ChannelStatsJson {
    name: String,
    failing: usize,
    worst: Option<PixelError>,
}

impl<'de> Deserialize<'de> for ChannelStats {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<ChannelStats, D::Error> {
        let json = ChannelStatsJson::deserialize(deserializer)?;
        Ok(ChannelStats {
            name: channel_name(&json.name).map_err(serde::de::Error::custom)?,
            failing: json.failing,
            worst: json.worst,
        })
    }
}

/// Values that are NaN or infinite in one image and not in the other.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NonFinite {
    /// Channel values, not pixels: one NaN pixel in R and G counts 2.
    pub count: usize,
    pub first: PixelError,
}

/// The measurements of one image pair. MAE, RMSE, PSNR and `worst` are over colour (R, G, B) in
/// the images' units (linear values for EXR, 8-bit codes for PNG); the failing-pixel count looks
/// at every channel, AOVs included.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    pub encoding: Encoding,
    pub pixels: usize,
    pub pixel_threshold: f64,
    /// Pixels with any channel beyond `pixel_threshold`, a moved silhouette or a broken value.
    pub failing_pixels: usize,
    pub failing_fraction: f64,
    pub mae: f64,
    pub rmse: f64,
    /// In dB against the encoding's peak (1 or 255); infinite for identical colour.
    #[serde(deserialize_with = "null_is_infinite")]
    pub psnr: f64,
    /// NVIDIA's FLIP, mean over the picture of the sRGB 8-bit colour: 0 identical, 1 opposite.
    pub flip: f64,
    /// The largest colour difference; `None` when colour is identical.
    pub worst: Option<PixelError>,
    pub channels: Vec<ChannelStats>,
    pub non_finite: Option<NonFinite>,
}

/// How a colour value is held to the pixel threshold.
#[derive(Clone, Copy)]
pub(super) enum ColourRule<'a> {
    /// Every value, as any other channel.
    Threshold,
    /// A value with a σ (the statistical verdict's) is left to the statistical test: it is
    /// measured (MAE, RMSE, worst) but never counts as failing.
    Tested(&'a [[Option<f64>; 3]]),
    /// Each value's threshold is widened by its allowance (a golden's noise, in the images' units).
    Widened(&'a [[f32; 3]]),
}

impl ColourRule<'_> {
    /// Whether colour channel `c` of pixel `i` fails with `diff` under `threshold`.
    pub(super) fn fails(self, diff: Difference, threshold: f64, i: usize, c: usize) -> bool {
        match self {
            ColourRule::Threshold => diff.exceeds(threshold),
            ColourRule::Tested(tested) => tested[i][c].is_none() && diff.exceeds(threshold),
            ColourRule::Widened(allowance) => diff.exceeds(threshold + f64::from(allowance[i][c])),
        }
    }
}

/// Whether each row of `expected` and `actual` (same layout) holds equal values (`==`, so never
/// a NaN) in every channel: a row that adds nothing to a measurement or a heatmap. 8-bit pictures
/// hold their values as the preview's bytes, which are compared instead (a quarter of the
/// reading).
pub(super) fn equal_rows(expected: &Image, actual: &Image) -> Vec<bool> {
    let width = (expected.width as usize).max(1);
    if expected.encoding == Encoding::Code8 && actual.encoding == Encoding::Code8 {
        return expected
            .preview
            .as_raw()
            .chunks_exact(width * 3)
            .zip(actual.preview.as_raw().chunks_exact(width * 3))
            .map(|(e, a)| e == a)
            .collect();
    }
    (0..expected.height as usize)
        .map(|y| {
            let row = y * width..(y + 1) * width;
            expected
                .channels
                .iter()
                .zip(&actual.channels)
                .all(|(e, a)| e.values.equal_in(&a.values, row.clone()))
        })
        .collect()
}

/// Both images must have the same size and channel list (`compare` checks that first); colour
/// values are held to the threshold as `colour` says. Also returns how long FLIP took, which is
/// most of a comparison's cost.
pub(super) fn measure(
    expected: &Image,
    actual: &Image,
    pixel_threshold: f64,
    colour: ColourRule,
) -> (Metrics, Duration) {
    // At least 1, so that an empty picture has rows to iterate (none).
    let width = (expected.width as usize).max(1);
    let pixels = expected.pixels();
    let mut failing = vec![false; pixels];
    let mut channels = Vec::with_capacity(expected.channels.len());
    let mut non_finite: Option<NonFinite> = None;
    let (mut sum_abs, mut sum_sq) = (0.0_f64, 0.0_f64);
    // Equal values (`==`: NaN never is) add nothing to any measurement: a zero difference neither
    // fails a threshold that is not negative nor moves a sum or the worst. Most values of a
    // graded picture equal the golden's, so runs of them are skipped whole.
    let skip_equal = pixel_threshold >= 0.0;
    let equal_rows = equal_rows(expected, actual);

    for (e, a) in expected.channels.iter().zip(&actual.channels) {
        let color_index = COLOR_CHANNELS.iter().position(|&c| c == e.name);
        let is_color = color_index.is_some();
        let mut stats = ChannelStats {
            name: e.name,
            failing: 0,
            worst: None,
        };
        let mut worst_error = 0.0_f64;
        let mut measure_value = |i: usize, ev: f32, av: f32| {
            let at = || PixelError {
                x: (i % width) as u32,
                y: (i / width) as u32,
                channel: e.name,
                expected: ev,
                actual: av,
            };
            let diff = difference(ev, av, e.infinity_is_a_value());
            let fails = match color_index {
                Some(c) => colour.fails(diff, pixel_threshold, i, c),
                None => diff.exceeds(pixel_threshold),
            };
            if fails {
                stats.failing += 1;
                failing[i] = true;
            }
            let error = match diff {
                Difference::Finite(d) => d,
                Difference::Coverage => f64::INFINITY,
                Difference::Broken => {
                    match &mut non_finite {
                        Some(found) => found.count += 1,
                        None => non_finite = Some(NonFinite { count: 1, first: at() }),
                    }
                    return;
                }
            };
            if is_color {
                sum_abs += error;
                sum_sq += error * error;
            }
            if error > worst_error {
                worst_error = error;
                stats.worst = Some(at());
            }
        };
        for (row, &equal) in equal_rows.iter().enumerate() {
            if skip_equal && equal {
                continue;
            }
            let row = row * width..(row + 1) * width;
            match (&e.values, &a.values) {
                // Most values of a differing row are equal too: bytes are compared as bytes.
                (Plane::Code8(e), Plane::Code8(a)) if skip_equal => {
                    for ((i, &ev), &av) in row.clone().zip(&e[row.clone()]).zip(&a[row]) {
                        if ev != av {
                            measure_value(i, f32::from(ev), f32::from(av));
                        }
                    }
                }
                _ => {
                    for i in row {
                        let (ev, av) = (e.values[i], a.values[i]);
                        if !(skip_equal && ev == av) {
                            measure_value(i, ev, av);
                        }
                    }
                }
            }
        }
        channels.push(stats);
    }

    let color_values = (pixels * COLOR_CHANNELS.len()).max(1) as f64;
    let mse = sum_sq / color_values;
    let peak = expected.encoding.peak();
    let failing_pixels = failing.iter().filter(|&&f| f).count();
    let flip_started = Instant::now();
    let flip = super::flip::flip_mean(&expected.preview, &expected.flip, &actual.preview);
    let flip_time = flip_started.elapsed();
    let metrics = Metrics {
        encoding: expected.encoding,
        pixels,
        pixel_threshold,
        failing_pixels,
        failing_fraction: failing_pixels as f64 / pixels.max(1) as f64,
        mae: sum_abs / color_values,
        rmse: mse.sqrt(),
        psnr: if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (peak * peak / mse).log10()
        },
        flip,
        worst: worst_color(&channels),
        channels,
        non_finite,
    };
    (metrics, flip_time)
}

/// A channel name read back from JSON, as the `'static` name the comparator uses: JSON written by
/// goldray names only channels goldray compares.
fn channel_name(name: &str) -> Result<&'static str, String> {
    super::image::FILM_CHANNELS
        .iter()
        .find(|known| **known == name)
        .copied()
        .ok_or_else(|| format!("unknown channel {name:?}"))
}

/// JSON has no infinity: serde_json writes an infinite number (the PSNR of identical colour) as
/// `null`, so `null` reads back as infinity.
fn null_is_infinite<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(deserializer)?.unwrap_or(f64::INFINITY))
}

fn worst_color(channels: &[ChannelStats]) -> Option<PixelError> {
    largest(
        channels
            .iter()
            .filter(|c| COLOR_CHANNELS.contains(&c.name))
            .filter_map(|c| c.worst),
    )
}

/// The largest error, the earliest on a tie so that reports are stable.
pub(super) fn largest(errors: impl Iterator<Item = PixelError>) -> Option<PixelError> {
    errors.fold(None, |best, p| match best {
        Some(b) if b.error() >= p.error() => Some(b),
        _ => Some(p),
    })
}

/// The channels two images must share to be compared at all.
pub(super) fn same_layout(expected: &Image, actual: &Image) -> bool {
    let complete = |image: &Image| {
        image
            .channels
            .iter()
            .all(|c: &Channel| c.values.len() == image.pixels())
    };
    expected.width == actual.width
        && expected.height == actual.height
        && expected.encoding == actual.encoding
        && expected.channel_names() == actual.channel_names()
        && complete(expected)
        && complete(actual)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::{Rgb, RgbImage};

    /// The same values as floats, so that the byte path is checked against the float one.
    fn as_floats(image: &Image) -> Image {
        let mut floats = image.clone();
        for channel in &mut floats.channels {
            channel.values = Plane::Linear(channel.values.iter().collect());
        }
        floats
    }

    #[test]
    fn bytes_measure_as_their_floats_do() {
        let golden = RgbImage::from_fn(37, 9, |x, y| Rgb([(x * 6) as u8, (y * 20) as u8, 128]));
        let mut student = golden.clone();
        for (x, y, by) in [(0, 0, 3), (5, 1, 40), (36, 8, 200), (17, 4, 9)] {
            let Rgb([r, g, b]) = *golden.get_pixel(x, y);
            student.put_pixel(x, y, Rgb([r.wrapping_add(by), g, b.wrapping_sub(by / 2)]));
        }
        let (expected, actual) = (Image::from_rgb8(golden, "g.png"), Image::from_rgb8(student, "s.png"));
        let (bytes, _) = measure(&expected, &actual, 8.0, ColourRule::Threshold);
        let (floats, _) = measure(&as_floats(&expected), &as_floats(&actual), 8.0, ColourRule::Threshold);
        assert_eq!(bytes, floats);
        assert_eq!(bytes.failing_pixels, 3, "the change of 3 codes is within the threshold");
        assert_eq!(bytes.worst.map(|w| (w.x, w.y)), Some((36, 8)));
    }
}
