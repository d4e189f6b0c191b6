//! Comparing a render against its golden image: metrics, tolerance verdicts and diff heatmaps.
//!
//! EXR films are compared on linear values, channel by channel (colour, depth and normals); PNGs
//! on 8-bit code values. The golden suite (`tests/golden.rs`) and `goldray diff` both go through
//! [`compare`], so a verdict in CI and one at the shell always agree.
//!
//! ```no_run
//! use goldray::compare::{Image, compare, EXR_DEFAULTS};
//! # fn main() -> Result<(), goldray::compare::CompareError> {
//! let expected = Image::read("golden/spheres_shadows.snap.exr".as_ref())?;
//! let actual = Image::read("out/spheres_shadows.exr".as_ref())?;
//! let comparison = compare(&expected, &actual, &EXR_DEFAULTS);
//! println!("{comparison}");
//! # Ok(())
//! # }
//! ```

mod comparison;
mod error;
mod files;
mod flip;
mod heatmap;
mod image;
mod metrics;
pub mod noise;
mod normal;
mod power;
mod tolerance;
mod verdict;

pub use comparison::{Comparison, compare, compare_timed, compare_widened};
pub use error::CompareError;
pub use files::{FileComparison, ToleranceOverrides, compare_files};
pub use heatmap::{FAILING, NON_FINITE, comparison_heatmap, diff_heatmap, diff_heatmap_widened, evidence_heatmap};
pub use image::{COLOR_CHANNELS, Channel, Encoding, Image, Plane};
pub use metrics::{ChannelStats, Metrics, NonFinite, PixelError};
pub use noise::{Evidence, Noise};
pub use power::{POWER_PROBABILITY, POWER_WINDOW, Power};
pub use tolerance::{EXR_DEFAULTS, PNG_DEFAULTS, Tolerance};
pub use verdict::{Breach, Layout, Limit, Verdict};
