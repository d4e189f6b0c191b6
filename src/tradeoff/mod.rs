//! `goldray tradeoff`: what each setting costs and what it buys.
//!
//! A case is rendered over a sweep of settings (samples per pixel × filter, and bounces until
//! the picture stops changing), each timed and its rays counted, and each compared with a
//! converged reference (many stratified samples, no filter, as deep as the bounce sweep showed
//! the scene needs) by the project's own metrics. The report says which settings are worth
//! having at all (the Pareto front of time against error) and, given a FLIP target, the cheapest
//! setting that meets it. Timings are measurements of this machine at this moment, for choosing
//! settings; the project's speed claims come from its benchmarks.
//!
//! ```no_run
//! use goldray::tradeoff::{SweepPlan, TradeoffOptions, run_tradeoff};
//! # fn main() -> Result<(), goldray::tradeoff::TradeoffError> {
//! let options = TradeoffOptions {
//!     plan: SweepPlan { samples: vec![1, 4, 16], size: Some((64, 64)), ..SweepPlan::default() },
//!     target_flip: Some(0.05),
//!     ..TradeoffOptions::new("tradeoff/jitter")
//! };
//! let (tradeoff, written) = run_tradeoff("cases/jitter.toml".as_ref(), &options, &goldray::progress::Silent)?;
//! println!("{}", tradeoff.target_sentence().unwrap_or_default());
//! # Ok(())
//! # }
//! ```

mod error;
mod measure;
mod pareto;
mod plot;
mod report;
mod setting;
mod sweep;

use std::path::{Path, PathBuf};

pub use error::TradeoffError;
pub use measure::{Errors, Measurement, Metric, Reference};
pub use pareto::{cheapest_within, pareto_front};
pub use plot::{HEIGHT as PLOT_HEIGHT, WIDTH as PLOT_WIDTH};
pub use report::{CSV_COLUMNS, CSV_FILE, MARKDOWN_FILE, PLOT_FILE, csv, markdown, summary};
pub use setting::Setting;
pub use sweep::{BounceOutcome, DEFAULT_FILTERS, SweepPlan};

use crate::case::{self, Case, LoadOptions};
use crate::progress::Progress;
use report::{check_replaceable, significant, write_report};
use sweep::run_sweep;

/// How to run a sweep and where its report goes.
#[derive(Clone, Debug)]
pub struct TradeoffOptions {
    pub out: PathBuf,
    pub plan: SweepPlan,
    /// The error the plot and the Pareto front rank settings by.
    pub metric: Metric,
    /// Report the cheapest setting whose FLIP mean is at most this.
    pub target_flip: Option<f64>,
    /// Replace report files in `out` even when goldray did not write them.
    pub force: bool,
}

impl TradeoffOptions {
    /// The full default sweep, reported into `out`, without a target.
    pub fn new(out: impl Into<PathBuf>) -> TradeoffOptions {
        TradeoffOptions {
            out: out.into(),
            plan: SweepPlan::default(),
            metric: Metric::default(),
            target_flip: None,
            force: false,
        }
    }
}

/// Everything one sweep found.
#[derive(Clone, Debug)]
pub struct Tradeoff {
    pub case_name: String,
    pub case_path: PathBuf,
    pub width: u32,
    pub height: u32,
    /// The case's own setting.
    pub base: Setting,
    /// Worker threads the renders ran on.
    pub threads: usize,
    /// Each setting's runs added up to at least this (see [`SweepPlan::min_time`]).
    pub min_time: std::time::Duration,
    pub reference: Reference,
    pub bounces: BounceOutcome,
    /// One per distinct setting: the bounce sweep's first, then the rest of the grid.
    pub measurements: Vec<Measurement>,
    pub metric: Metric,
    /// For each measurement, whether it is on the Pareto front of time against `metric`.
    pub pareto: Vec<bool>,
    pub target: Option<Target>,
}

/// The answer to `--target-flip`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    pub flip: f64,
    /// The fastest measurement whose FLIP mean is at most `flip`, if any reached it.
    pub chosen: Option<usize>,
    /// The measurement with the lowest FLIP mean, to say how close the sweep came.
    pub best: usize,
}

impl Tradeoff {
    /// The front's measurements, fastest first.
    pub fn front(&self) -> impl Iterator<Item = &Measurement> {
        let mut front: Vec<&Measurement> = self
            .measurements
            .iter()
            .zip(&self.pareto)
            .filter(|(_, on)| **on)
            .map(|(m, _)| m)
            .collect();
        front.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
        front.into_iter()
    }

    /// The `--target-flip` answer as a sentence, or `None` without a target.
    pub fn target_sentence(&self) -> Option<String> {
        let target = self.target?;
        let describe = |m: &Measurement| {
            format!(
                "{} ({} s, FLIP {})",
                m.setting.label(),
                significant(m.seconds),
                significant(m.errors.flip)
            )
        };
        Some(match target.chosen {
            Some(index) => format!(
                "the cheapest setting with FLIP mean ≤ {} is {}.",
                target.flip,
                describe(&self.measurements[index])
            ),
            None => format!(
                "no setting reached FLIP mean ≤ {}; the lowest was {}.",
                target.flip,
                describe(&self.measurements[target.best])
            ),
        })
    }
}

/// Loads the case, checks that the report may be written, sweeps, and writes `tradeoff.csv`,
/// `tradeoff.md` and `tradeoff.png` into `options.out`, returning what it found and the paths
/// written. On any error nothing is written. Renders on the current rayon pool, reporting each
/// setting to `progress`.
pub fn run_tradeoff(
    case_path: &Path,
    options: &TradeoffOptions,
    progress: &dyn Progress,
) -> Result<(Tradeoff, Vec<PathBuf>), TradeoffError> {
    options.plan.validate()?;
    let case = case::load(case_path, &LoadOptions::default())?;
    check_replaceable(&options.out, options.force)?;
    let tradeoff = measure_tradeoff(&case, options, progress)?;
    let written = write_report(&tradeoff, &options.out)?;
    Ok((tradeoff, written))
}

/// The sweep and its analysis, without writing anything: what [`run_tradeoff`] reports.
pub fn measure_tradeoff(
    case: &Case,
    options: &TradeoffOptions,
    progress: &dyn Progress,
) -> Result<Tradeoff, TradeoffError> {
    let plan = &options.plan;
    plan.validate()?;
    let mut case = case.clone();
    if let Some((width, height)) = plan.size {
        case.render.trace.width = width;
        case.render.trace.height = height;
    }
    let sweep = run_sweep(&case, plan, progress);
    progress.finish();
    let sweep = sweep?;

    let metric = options.metric;
    let points = |value: &dyn Fn(&Measurement) -> f64| -> Vec<(f64, f64)> {
        sweep.measurements.iter().map(|m| (m.seconds, value(m))).collect()
    };
    let pareto = pareto_front(&points(&|m| metric.of(&m.errors)));
    let flips = points(&|m| m.errors.flip);
    let target = options.target_flip.map(|flip| Target {
        flip,
        chosen: cheapest_within(&flips, flip),
        best: (0..flips.len())
            .min_by(|&a, &b| flips[a].1.total_cmp(&flips[b].1))
            .unwrap_or(0),
    });
    Ok(Tradeoff {
        case_name: case.name.clone(),
        case_path: case.path.clone(),
        width: case.render.trace.width,
        height: case.render.trace.height,
        base: Setting::of(&case),
        threads: rayon::current_num_threads(),
        min_time: plan.min_time,
        reference: sweep.reference,
        bounces: sweep.bounces,
        measurements: sweep.measurements,
        metric,
        pareto,
        target,
    })
}
