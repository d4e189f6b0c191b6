//! What the sweep renders and in what order: the settings (one value per axis), the bounce
//! sweep that finds how many bounces the picture needs, and the grid of precision × filter ×
//! samples.
//!
//! The bounce sweep runs first because the rest depends on it. The reference must be at least as
//! deep as anything it judges, and "deep enough" is what the bounce sweep measures: an extra
//! bounce that moves no pixel by more than the threshold adds nothing. The grid renders at the
//! depth found enough, so that its errors are sampling errors; were it rendered shallower, every
//! sample count would share the same truncation error and the grid would only show that (which
//! the bounce sweep already does).

use std::time::Duration;

use super::error::TradeoffError;
use super::measure::{Measurement, Reference, Render, Renderer, errors};
use super::setting::Setting;
use crate::case::{Case, MAX_BOUNCES};
use crate::image_size::{SizeLimit, check_side};
use crate::options::{Filter, Precision};
use crate::progress::Progress;

/// The grid's filters unless told otherwise: both, since the filter is the costliest choice.
pub const DEFAULT_FILTERS: [Filter; 2] = [Filter::None, Filter::Gaussian];

/// What to sweep. The defaults are the full sweep `goldray tradeoff` runs without flags.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPlan {
    /// Samples per pixel of the grid: perfect squares, ascending, each at most once.
    pub samples: Vec<u32>,
    /// Filters of the grid, each at most once.
    pub filters: Vec<Filter>,
    /// Precisions of the grid, each at most once.
    pub precisions: Vec<Precision>,
    /// The bounce sweep stops here even if the picture is still changing.
    pub max_bounces: u32,
    /// The bounce sweep stops once one more bounce changes no colour channel of any pixel by more
    /// than this (linear units).
    pub bounce_threshold: f64,
    /// Stratified samples per pixel of the reference (filter none: the pixel-area integral).
    pub reference_samples: u32,
    /// Renders every setting and the reference at this size instead of the case's.
    pub size: Option<(u32, u32)>,
    /// Each setting is rendered until its runs add up to this (within a cap on runs), and its
    /// fastest run is its time; zero renders each setting once.
    pub min_time: Duration,
}

impl Default for SweepPlan {
    fn default() -> SweepPlan {
        SweepPlan {
            samples: vec![1, 4, 16, 64, 256],
            filters: DEFAULT_FILTERS.to_vec(),
            precisions: Precision::ALL.to_vec(),
            max_bounces: 16,
            // A thousandth of white: under half an 8-bit code anywhere but the deepest shadows.
            bounce_threshold: 1e-3,
            reference_samples: 1024,
            size: None,
            min_time: Duration::from_millis(200),
        }
    }
}

impl SweepPlan {
    /// Checks what the command line cannot check flag by flag, before anything renders.
    pub fn validate(&self) -> Result<(), TradeoffError> {
        let plan = |message: String| Err(TradeoffError::Plan(message));
        if self.samples.is_empty() || self.filters.is_empty() || self.precisions.is_empty() {
            return plan("the sweep needs at least one sample count, one filter and one precision".to_owned());
        }
        if let Some(&n) = self.samples.iter().find(|&&n| !is_square(n)) {
            return plan(format!(
                "samples {n}: every sample count must be a perfect square (1, 4, 9, 16, …)"
            ));
        }
        if !is_square(self.reference_samples) {
            return plan(format!(
                "reference samples {}: must be a perfect square",
                self.reference_samples
            ));
        }
        let most = self.samples.iter().copied().max().unwrap_or(1);
        if self.reference_samples <= most {
            return plan(format!(
                "the reference ({} samples) must have more samples than every setting it judges (up to {most})",
                self.reference_samples
            ));
        }
        if i64::from(self.max_bounces) > MAX_BOUNCES {
            return plan(format!("max bounces {}: at most {MAX_BOUNCES}", self.max_bounces));
        }
        if let Some((width, height)) = self.size {
            for side in [width, height] {
                if let Err(error) = check_side(side.into(), SizeLimit::Fixed) {
                    return plan(format!("size {width}x{height}: each side {error}"));
                }
            }
        }
        if !(self.bounce_threshold.is_finite() && self.bounce_threshold >= 0.0) {
            return plan(format!(
                "bounce threshold {}: must be a finite number ≥ 0",
                self.bounce_threshold
            ));
        }
        Ok(())
    }

    /// Every combination of the grid's axes at `bounces`: by precision, then filter, then samples
    /// as listed, so that each (precision, filter) pair's settings form one curve.
    pub fn grid(&self, bounces: u32) -> Vec<Setting> {
        let mut grid = Vec::with_capacity(self.precisions.len() * self.filters.len() * self.samples.len());
        for &precision in &self.precisions {
            for &filter in &self.filters {
                grid.extend(self.samples.iter().map(|&samples| Setting {
                    samples,
                    filter,
                    bounces,
                    precision,
                }));
            }
        }
        grid
    }
}

fn is_square(n: u32) -> bool {
    n >= 1 && n.isqrt() * n.isqrt() == n
}

/// How the bounce sweep ended.
#[derive(Clone, Debug, PartialEq)]
pub struct BounceOutcome {
    /// The deepest setting rendered; the sweep covered bounces `0..=last`.
    pub last: u32,
    /// Whether the picture settled (`last` changed nothing beyond the threshold) rather than the
    /// sweep hitting `max_bounces`.
    pub settled: bool,
    /// The largest change of any colour channel from `last − 1` to `last` bounces (0 when only
    /// bounce 0 was rendered).
    pub last_change: f64,
    pub threshold: f64,
}

impl BounceOutcome {
    /// The fewest bounces whose picture the sweep found no different from deeper ones (the cap
    /// when the picture never settled).
    pub fn enough(&self) -> u32 {
        if self.settled { self.last - 1 } else { self.last }
    }

    /// Whether one more bounce that moved the picture by at most `change` ends the sweep.
    fn settles(change: f64, threshold: f64) -> bool {
        change <= threshold
    }
}

/// Everything the sweep measured.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub reference: Reference,
    /// Each distinct setting once, bounce sweep first, then the grid in [`SweepPlan::grid`] order.
    pub measurements: Vec<Measurement>,
    pub bounces: BounceOutcome,
}

/// Runs the bounce sweep, renders the reference, then the grid at the depth the bounce sweep
/// found enough, advancing `progress` by each render's camera rays (its total is the estimate; the
/// bounce sweep adds to it as it goes deeper).
pub fn run_sweep(case: &Case, plan: &SweepPlan, progress: &dyn Progress) -> Result<Sweep, TradeoffError> {
    let renderer = Renderer::new(case)?;
    let base = Setting::of(case);
    let pixels = renderer.pixels();
    let cost = |setting: &Setting| setting.camera_rays_per_pixel() * pixels;
    // The grid's camera rays do not depend on its bounces, so its cost is known before they are.
    progress.begin(
        "tradeoff",
        plan.grid(0).iter().map(cost).sum::<u64>() + u64::from(plan.reference_samples) * pixels + cost(&base),
    );
    let render = |setting: Setting| {
        progress.step(&setting.label());
        let rendered = renderer.render(setting, plan.min_time);
        progress.advance(cost(&setting));
        rendered
    };

    let mut bounce_renders: Vec<Render> = Vec::new();
    let mut outcome = BounceOutcome {
        last: 0,
        settled: false,
        last_change: 0.0,
        threshold: plan.bounce_threshold,
    };
    for bounces in 0..=plan.max_bounces {
        if bounces > 0 {
            progress.grow(cost(&base));
        }
        let next = render(Setting { bounces, ..base });
        outcome.last = bounces;
        if let Some(previous) = bounce_renders.last() {
            outcome.last_change = errors(&previous.film, &next.film, &next.setting)?.max;
            outcome.settled = BounceOutcome::settles(outcome.last_change, plan.bounce_threshold);
        }
        bounce_renders.push(next);
        if outcome.settled {
            break;
        }
    }

    progress.step(&format!("reference ({} spp)", plan.reference_samples));
    let reference = renderer.reference(plan.reference_samples, outcome.last);
    progress.advance(u64::from(plan.reference_samples) * pixels);

    let grid = plan.grid(outcome.enough());
    let mut measurements: Vec<Measurement> = bounce_renders
        .iter()
        .map(|r| Measurement::of(r, &reference, grid.contains(&r.setting), true))
        .collect::<Result<_, _>>()?;
    drop(bounce_renders);
    for setting in grid {
        if measurements.iter().any(|m| m.setting == setting) {
            // Rendered by the bounce sweep, and already marked as part of the grid.
            progress.advance(cost(&setting));
            continue;
        }
        measurements.push(Measurement::of(&render(setting), &reference, true, false)?);
    }
    Ok(Sweep {
        reference,
        measurements,
        bounces: outcome,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(samples: &[u32], reference: u32) -> SweepPlan {
        SweepPlan {
            samples: samples.to_vec(),
            reference_samples: reference,
            ..SweepPlan::default()
        }
    }

    #[test]
    fn the_grid_is_every_precision_filter_and_sample_count_at_the_given_bounces() {
        let grid = plan(&[1, 4], 16).grid(3);
        let mut expected = Vec::new();
        for precision in [Precision::F32, Precision::F64] {
            for filter in [Filter::None, Filter::Gaussian] {
                for samples in [1, 4] {
                    expected.push(Setting {
                        samples,
                        filter,
                        bounces: 3,
                        precision,
                    });
                }
            }
        }
        assert_eq!(grid, expected);
        let single = SweepPlan {
            precisions: vec![Precision::F64],
            filters: vec![Filter::None],
            ..plan(&[9], 16)
        };
        assert_eq!(
            single.grid(0),
            [Setting {
                samples: 9,
                filter: Filter::None,
                bounces: 0,
                precision: Precision::F64
            }]
        );
    }

    #[test]
    fn the_default_plan_is_valid_and_bad_plans_say_why() {
        assert!(SweepPlan::default().validate().is_ok());
        let message = |p: SweepPlan| p.validate().unwrap_err().to_string();
        assert!(message(plan(&[1, 8], 1024)).contains("samples 8"));
        assert!(message(plan(&[1, 4], 4)).contains("more samples than every setting"));
        assert!(message(plan(&[1], 10)).contains("reference samples 10"));
        assert!(message(plan(&[], 16)).contains("at least one"));
        assert!(
            message(SweepPlan {
                precisions: Vec::new(),
                ..SweepPlan::default()
            })
            .contains("one precision")
        );
        let deep = SweepPlan {
            max_bounces: 5000,
            ..SweepPlan::default()
        };
        assert!(message(deep).contains("at most 1024"));
        let nan = SweepPlan {
            bounce_threshold: f64::NAN,
            ..SweepPlan::default()
        };
        assert!(message(nan).contains("bounce threshold"));
    }

    #[test]
    fn labels_name_every_axis_without_commas() {
        let setting = Setting {
            samples: 16,
            filter: Filter::Gaussian,
            bounces: 2,
            precision: Precision::F64,
        };
        assert_eq!(setting.label(), "16spp gaussian 2b f64");
        assert_eq!(setting.camera_rays_per_pixel(), 144);
    }

    #[test]
    fn the_bounce_sweep_settles_at_the_threshold_inclusive() {
        assert!(BounceOutcome::settles(0.0, 0.0));
        assert!(BounceOutcome::settles(1e-3, 1e-3));
        assert!(!BounceOutcome::settles(1.1e-3, 1e-3));
    }
}
