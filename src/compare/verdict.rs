//! Turning measurements into pass / warn / fail against a case's `[tolerance]`.
//!
//! - **fail** when any value is NaN or infinite in one image and not the other (never excused by
//!   a tolerance), when more than `fail_fraction` of the pixels fail, when the colour RMSE is over
//!   `rmse`, or when any channel differs by more than `max` (if the case sets one);
//! - **warn** when some pixels differ by more than `pixel` but all of the above hold: a change
//!   worth a look (a silhouette that moved by a pixel, a few noisy samples) that is not a
//!   regression;
//! - **pass** when no channel of any pixel differs by more than `pixel`.
//!
//! When both images carry variance (sampled renders), colour values with variance are judged by the
//! statistical test of [`super::noise`] instead (a significant one is the `significance` breach),
//! and `rmse` and `max` are not applied to colour.
//!
//! A size, encoding or channel-set mismatch is its own verdict, decided before anything is
//! measured, because no metric means anything across it.

use std::fmt;

use serde::Serialize;

use super::image::COLOR_CHANNELS;
use super::image::{Encoding, Image};
use super::metrics::{ChannelStats, Metrics, PixelError, largest};
use super::noise::Noise;
use super::tolerance::Tolerance;

/// The limit of a [`Tolerance`] that a comparison broke.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Limit {
    NonFinite,
    FailFraction,
    Rmse,
    Max,
    /// The statistical test: a colour value differs by more than noise explains.
    Significance,
}

impl Limit {
    /// The name a person finds in the case file (or, for non-finite values, in the report).
    pub fn name(self) -> &'static str {
        match self {
            Limit::NonFinite => "non-finite",
            Limit::FailFraction => "fail_fraction",
            Limit::Rmse => "rmse",
            Limit::Max => "max",
            Limit::Significance => "significance",
        }
    }
}

/// One broken limit: what was measured against what was allowed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Breach {
    pub limit: Limit,
    pub measured: f64,
    pub allowed: f64,
    /// The pixel behind the number, for `non-finite` and `max`.
    pub at: Option<PixelError>,
}

/// Everything about an image that must agree before pixels can be compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Layout {
    pub width: u32,
    pub height: u32,
    pub encoding: Encoding,
    pub channels: Vec<&'static str>,
}

impl Layout {
    pub fn of(image: &Image) -> Layout {
        Layout {
            width: image.width,
            height: image.height,
            encoding: image.encoding,
            channels: image.channel_names(),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Verdict {
    Pass,
    Warn,
    Fail { breaches: Vec<Breach> },
    Mismatch { expected: Layout, actual: Layout },
}

impl Verdict {
    /// idiff's convention, so scripts written for OpenImageIO read these the same way.
    pub fn exit_code(&self) -> u8 {
        match self {
            Verdict::Pass => 0,
            Verdict::Warn => 1,
            Verdict::Fail { .. } => 2,
            Verdict::Mismatch { .. } => 3,
        }
    }

    /// Whether a golden test should accept the render (a warning is reported, not failed).
    pub fn accepts(&self) -> bool {
        matches!(self, Verdict::Pass | Verdict::Warn)
    }

    pub fn word(&self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::Warn => "WARN",
            Verdict::Fail { .. } => "FAIL",
            Verdict::Mismatch { .. } => "MISMATCH",
        }
    }
}

/// With `noise` (both images carry variance), colour values with variance are judged by the
/// statistical test instead of `pixel`, and `rmse` and `max` are not applied to colour: on a noisy
/// picture they measure the noise, which is what the test weighs.
pub(super) fn judge(metrics: &Metrics, tolerance: &Tolerance, noise: Option<&Noise>) -> Verdict {
    let mut breaches = Vec::new();
    if let Some(non_finite) = &metrics.non_finite {
        breaches.push(Breach {
            limit: Limit::NonFinite,
            measured: non_finite.count as f64,
            allowed: 0.0,
            at: Some(non_finite.first),
        });
    }
    if metrics.failing_fraction > tolerance.fail_fraction {
        breaches.push(Breach {
            limit: Limit::FailFraction,
            measured: metrics.failing_fraction,
            allowed: tolerance.fail_fraction,
            at: None,
        });
    }
    if let Some(noise) = noise
        && noise.significant > 0
        && let Some(strongest) = &noise.strongest
    {
        breaches.push(Breach {
            limit: Limit::Significance,
            measured: strongest.z.abs(),
            allowed: noise.z_critical,
            at: Some(strongest.at),
        });
    }
    if noise.is_none() && metrics.rmse > tolerance.rmse {
        breaches.push(Breach {
            limit: Limit::Rmse,
            measured: metrics.rmse,
            allowed: tolerance.rmse,
            at: None,
        });
    }
    if let Some(max) = tolerance.max {
        let judged = |c: &&ChannelStats| noise.is_none() || !COLOR_CHANNELS.contains(&c.name);
        let worst = largest(metrics.channels.iter().filter(judged).filter_map(|c| c.worst));
        if let Some(worst) = worst.filter(|w| w.error() > max) {
            breaches.push(Breach {
                limit: Limit::Max,
                measured: worst.error(),
                allowed: max,
                at: Some(worst),
            });
        }
    }
    if !breaches.is_empty() {
        Verdict::Fail { breaches }
    } else if metrics.failing_pixels > 0 {
        Verdict::Warn
    } else {
        Verdict::Pass
    }
}

impl fmt::Display for Breach {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (measured, allowed) = (self.measured, self.allowed);
        match self.limit {
            Limit::NonFinite => {
                let plural = if measured == 1.0 { "value is" } else { "values are" };
                write!(f, "non-finite: {measured} {plural} NaN or infinite in one image only")?;
            }
            Limit::FailFraction => write!(
                f,
                "fail_fraction: {} of pixels fail, over the {} allowed ({})",
                percent(measured),
                percent(allowed),
                times(measured, allowed)
            )?,
            Limit::Rmse => write!(
                f,
                "rmse: colour RMSE {measured:.6} is over the {allowed} allowed ({})",
                times(measured, allowed)
            )?,
            Limit::Max => write!(
                f,
                "max: a channel differs by {measured:.6}, over the {allowed} allowed ({})",
                times(measured, allowed)
            )?,
            Limit::Significance => write!(
                f,
                "significance: a colour differs by {measured:.2} σ, over the {allowed:.2} σ that noise \
                 reaches (Šidák, α = {} family-wise)",
                super::noise::FAMILY_ALPHA
            )?,
        }
        match (&self.at, self.limit) {
            (Some(at), Limit::NonFinite) => write!(f, ", the first at {at}"),
            (Some(at), _) => write!(f, ", at {at}"),
            (None, _) => Ok(()),
        }
    }
}

impl fmt::Display for PixelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "pixel ({}, {}) {}: expected {}, actual {}",
            self.x, self.y, self.channel, self.expected, self.actual
        )
    }
}

pub(super) fn percent(fraction: f64) -> String {
    format!("{:.4}%", fraction * 100.0)
}

fn times(measured: f64, allowed: f64) -> String {
    if allowed > 0.0 {
        format!("{:.1}x the limit", measured / allowed)
    } else {
        "the limit is 0".to_owned()
    }
}
