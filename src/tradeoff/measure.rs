//! Rendering one setting the way a benchmark would (timed, rays counted) and judging it against
//! the converged reference with the project's own metrics (`crate::compare`), so that an error
//! here means what it means in `goldray diff` and the golden suite.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::error::TradeoffError;
use super::setting::Setting;
use crate::build_error::BuildError;
use crate::case::Case;
use crate::compare::{Image, Tolerance, compare};
use crate::film::Film;
use crate::named_enum::named_enum;
use crate::options::{Filter, Precision, RenderOptions};
use crate::pipeline::render_options;
use crate::precision::{double, single};
use crate::progress::Silent;
use crate::stats::RayCounts;

/// A cheap setting is rendered again until its runs add up to the plan's `min_time`, but never
/// more often than this: a render of a millisecond needs no more to find its fastest run.
const MAX_RUNS: u32 = 50;

/// The precision the reference is rendered in: the more accurate one, so that an f32 setting's
/// rounding shows as error rather than being part of the truth.
pub const REFERENCE_PRECISION: Precision = Precision::F64;

/// Renders settings of one case. The scene is built once in each precision (the reference is
/// always f64, most settings are the case's f32), since no setting changes it.
pub struct Renderer<'a> {
    case: &'a Case,
    single: single::scene::Scene,
    double: double::scene::Scene,
}

/// One setting's film and what it cost.
#[derive(Clone, Debug)]
pub struct Render {
    pub setting: Setting,
    pub film: Film,
    /// Wall-clock seconds of the fastest run: the one least disturbed by other processes.
    pub seconds: f64,
    pub runs: u32,
    /// Exact, so the same for every run.
    pub rays: RayCounts,
}

/// The converged picture every setting is judged against.
#[derive(Clone, Debug)]
pub struct Reference {
    pub film: Film,
    pub samples: u32,
    pub bounces: u32,
    pub precision: Precision,
    pub seed: u64,
    pub seconds: f64,
    pub rays: RayCounts,
}

impl<'a> Renderer<'a> {
    pub fn new(case: &'a Case) -> Result<Renderer<'a>, TradeoffError> {
        let (single, double) = (single::scene::build_scene(case)?, double::scene::build_scene(case)?);
        // Cube map faces are otherwise decoded when a render first sees them.
        let decoded = single.decode_everything().and_then(|()| double.decode_everything());
        decoded.map_err(|source| BuildError::CubeMap {
            file: case.path.clone(),
            source,
        })?;
        Ok(Renderer { case, single, double })
    }

    /// One render of the film `options` describe, in `precision`, with its rays.
    fn render_once(&self, precision: Precision, options: &RenderOptions) -> (Film, RayCounts) {
        match precision {
            Precision::F32 => single::render::render_counting_rays(&self.single, options, &Silent),
            Precision::F64 => double::render::render_counting_rays(&self.double, options, &Silent),
        }
    }

    pub fn pixels(&self) -> u64 {
        u64::from(self.case.render.trace.width) * u64::from(self.case.render.trace.height)
    }

    /// Renders `setting`, again and again until the runs add up to `min_time` (at most
    /// [`MAX_RUNS`] times), and keeps the fastest time: on a machine shared with other work, the
    /// fastest run is the one least disturbed, and one run of a cheap setting may be mostly a
    /// scheduler hiccup. Every run renders the same film (rendering is deterministic), so the
    /// first is kept.
    pub fn render(&self, setting: Setting, min_time: Duration) -> Render {
        let options = render_options(&setting.apply(self.case));
        let run = || {
            let start = Instant::now();
            let (film, rays) = self.render_once(setting.precision, &options);
            (film, rays, start.elapsed())
        };
        let (film, rays, first) = run();
        let (mut fastest, mut total, mut runs) = (first, first, 1);
        while runs < MAX_RUNS && total < min_time {
            let (_, _, elapsed) = run();
            fastest = fastest.min(elapsed);
            total += elapsed;
            runs += 1;
        }
        Render {
            setting,
            film,
            seconds: fastest.as_secs_f64(),
            runs,
            rays,
        }
    }

    /// The pixel-area integral, as nearly as `samples` stratified samples get it (filter none),
    /// `bounces` deep, in [`REFERENCE_PRECISION`]. Its seed differs from the case's so that its jitter is independent of
    /// every setting's (the sampler hashes the seed, so the next seed is as good as any): with the
    /// same seed a setting's samples would partly repeat the reference's and its error would look
    /// smaller than it is.
    pub fn reference(&self, samples: u32, bounces: u32) -> Reference {
        let seed = self.case.render.trace.seed.wrapping_add(1);
        let precision = REFERENCE_PRECISION;
        let mut case = Setting {
            samples,
            filter: Filter::None,
            bounces,
            precision,
        }
        .apply(self.case);
        case.render.trace.seed = seed;
        let start = Instant::now();
        let (film, rays) = self.render_once(precision, &render_options(&case));
        Reference {
            film,
            samples,
            bounces,
            precision,
            seed,
            seconds: start.elapsed().as_secs_f64(),
            rays,
        }
    }
}

/// How far a picture is from another, by the project's metrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Root mean square over the linear R, G and B values of every pixel.
    pub rmse: f64,
    /// The largest difference of any linear colour channel of any pixel.
    pub max: f64,
    /// NVIDIA FLIP's mean over the sRGB pictures: what a viewer would notice.
    pub flip: f64,
}

/// The difference of `film` from `reference`, measured as `goldray diff` measures it.
pub fn errors(reference: &Film, film: &Film, setting: &Setting) -> Result<Errors, TradeoffError> {
    let expected = Image::from_film(reference, "reference");
    let actual = Image::from_film(film, PathBuf::from(setting.label()));
    let metrics = compare(&expected, &actual, &Tolerance::DEFAULT)
        .metrics
        .ok_or_else(|| TradeoffError::Mismatch {
            setting: setting.label(),
        })?;
    Ok(Errors {
        rmse: metrics.rmse,
        max: metrics.worst.map_or(0.0, |w| w.error()),
        flip: metrics.flip,
    })
}

named_enum! {
    /// Which error the plot and the Pareto front rank settings by; named as `--metric` names it.
    #[derive(Default)]
    pub enum Metric: "metric" {
        /// RMSE on linear colour: its log-log slope against samples is the convergence rate
        #[default]
        Rmse = "rmse",
        /// The largest error of any colour channel of any pixel
        Max = "max",
        /// The FLIP mean: what a viewer would notice
        Flip = "flip",
    }
}

impl Metric {
    pub fn of(self, errors: &Errors) -> f64 {
        match self {
            Metric::Rmse => errors.rmse,
            Metric::Max => errors.max,
            Metric::Flip => errors.flip,
        }
    }

    /// The error's column in the report (`max_error` where the flag says `max`).
    pub fn column(self) -> &'static str {
        match self {
            Metric::Rmse => "rmse",
            Metric::Max => "max_error",
            Metric::Flip => "flip",
        }
    }

    /// How a person reads it: the plot's axis and the report's prose.
    pub fn title(self) -> &'static str {
        match self {
            Metric::Rmse => "RMSE (linear colour)",
            Metric::Max => "largest pixel error (linear colour)",
            Metric::Flip => "FLIP mean",
        }
    }
}

/// One setting's cost and error: a row of the report and a point of the plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    pub setting: Setting,
    pub seconds: f64,
    pub runs: u32,
    pub rays: RayCounts,
    pub errors: Errors,
    /// Part of the samples × filter grid.
    pub in_grid: bool,
    /// Part of the bounce sweep.
    pub in_bounce_sweep: bool,
}

impl Measurement {
    pub fn of(
        render: &Render,
        reference: &Reference,
        in_grid: bool,
        in_bounce_sweep: bool,
    ) -> Result<Measurement, TradeoffError> {
        Ok(Measurement {
            setting: render.setting,
            seconds: render.seconds,
            runs: render.runs,
            rays: render.rays,
            errors: errors(&reference.film, &render.film, &render.setting)?,
            in_grid,
            in_bounce_sweep,
        })
    }

    /// Millions of rays (all kinds) per second of the fastest run.
    pub fn mrays_per_second(&self) -> f64 {
        if self.seconds > 0.0 {
            self.rays.total() as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}
