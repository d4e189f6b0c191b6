//! `goldray tradeoff`'s command line: flags, their checks (a bad value is refused before
//! anything renders or is written), and what the command prints.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use goldray::case::{MAX_BOUNCES, case_name};
use goldray::options::{Filter, Precision};
use goldray::tradeoff::{Metric, SweepPlan, TradeoffOptions, run_tradeoff, summary};

use super::Failure;
use super::common::{ThreadFlags, parse_named, parse_threshold, size_from_values};
use super::progress::Reporter;
use goldray::image_size::SizeLimit;

// The list defaults as the flags accept them (help shows them as written); a test checks they
// are the library's defaults.
const DEFAULT_SAMPLES: &str = "1,4,16,64,256";
const DEFAULT_FILTER_LIST: &str = "none,gaussian";
const DEFAULT_PRECISIONS: &str = "f32,f64";

/// Render a case over a sweep of samples, filters, precisions and bounces; measure each setting's time, rays
/// and error against a converged reference; write tradeoff.csv, tradeoff.md and a log-log plot
/// tradeoff.png with the Pareto front marked.
#[derive(Clone, Debug, clap::Args)]
pub struct TradeoffArgs {
    /// The case file.
    pub case: PathBuf,
    /// Where to write tradeoff.csv, tradeoff.md and tradeoff.png [default: tradeoff/NAME].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print (and record in tradeoff.md) the fastest setting whose FLIP mean is at most X
    /// (0 = identical to the reference, 1 = as different as can be).
    #[arg(long, value_name = "X", value_parser = parse_flip)]
    pub target_flip: Option<f64>,
    /// Samples per pixel of the grid: comma-separated perfect squares (e.g. 1,4,16).
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_square,
          default_value = DEFAULT_SAMPLES)]
    pub samples: Vec<u32>,
    /// Filters of the grid: comma-separated, from none and gaussian (3× supersampling, 9× the rays).
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_named::<Filter>,
          default_value = DEFAULT_FILTER_LIST)]
    pub filters: Vec<Filter>,
    /// Precisions of the grid: comma-separated, from f32 and f64 (the reference is always f64).
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_named::<Precision>,
          default_value = DEFAULT_PRECISIONS)]
    pub precisions: Vec<Precision>,
    /// Render every setting and the reference at this size instead of the case's (W H or WxH,
    /// e.g. 64x48): a quicker sweep.
    #[arg(long, num_args = 1..=2, value_names = ["W", "H"], allow_negative_numbers = true)]
    pub size: Option<Vec<String>>,
    /// Stratified samples per pixel of the reference: a perfect square above every --samples.
    #[arg(long, value_name = "N", value_parser = parse_square,
          default_value_t = SweepPlan::default().reference_samples)]
    pub reference_samples: u32,
    /// The bounce sweep stops at this many bounces even if the picture is still changing.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=MAX_BOUNCES),
          default_value_t = SweepPlan::default().max_bounces)]
    pub max_bounces: u32,
    /// The bounce sweep stops once one more bounce changes no pixel's colour by more than this
    /// (linear units, 1 = white).
    #[arg(long, value_name = "T", value_parser = parse_threshold,
          default_value_t = SweepPlan::default().bounce_threshold)]
    pub bounce_threshold: f64,
    /// Render each setting again until its runs add up to S seconds (at most 50 runs) and keep
    /// the fastest run; 0 renders each setting once (quicker, noisier times).
    #[arg(long, value_name = "S", value_parser = parse_seconds,
          default_value_t = SweepPlan::default().min_time.as_secs_f64())]
    pub min_time: f64,
    /// The error the plot and the Pareto front rank settings by: rmse (RMSE on linear colour; its
    /// log-log slope against samples is the convergence rate), max (the largest error of any
    /// channel of any pixel) or flip (the FLIP mean: what a viewer would notice).
    #[arg(long, value_name = "METRIC", value_parser = parse_named::<Metric>, default_value = "rmse")]
    pub metric: Metric,
    #[command(flatten)]
    pub threads: ThreadFlags,
    /// No progress bar and no summary (the --target-flip answer is still printed).
    #[arg(long)]
    pub quiet: bool,
    /// Replace tradeoff.csv, tradeoff.md or tradeoff.png in DIR even when goldray did not write them.
    #[arg(long)]
    pub force: bool,
}

impl TradeoffArgs {
    /// The library's options; a size outside the size rule is a usage error.
    fn options(&self) -> Result<TradeoffOptions, Failure> {
        let size = self
            .size
            .as_ref()
            .map(|values| size_from_values(values, SizeLimit::Fixed))
            .transpose()
            .map_err(Failure::Usage)?;
        Ok(TradeoffOptions {
            out: self
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("tradeoff").join(case_name(&self.case))),
            plan: SweepPlan {
                samples: self.samples.clone(),
                filters: self.filters.clone(),
                precisions: self.precisions.clone(),
                max_bounces: self.max_bounces,
                bounce_threshold: self.bounce_threshold,
                reference_samples: self.reference_samples,
                size,
                min_time: Duration::from_secs_f64(self.min_time),
            },
            metric: self.metric,
            target_flip: self.target_flip,
            force: self.force,
        })
    }
}

/// Runs `goldray tradeoff` on its own thread pool and prints the summary to standard output.
pub fn run(args: TradeoffArgs) -> Result<ExitCode, Failure> {
    let options = args.options()?;
    let reporter = Reporter::new(args.quiet);
    let (tradeoff, written) = args
        .threads
        .install(|| run_tradeoff(&args.case, &options, &reporter))??;
    if !args.quiet {
        println!("{}", summary(&tradeoff));
        for path in &written {
            println!("wrote {}", path.display());
        }
    }
    if let Some(sentence) = tradeoff.target_sentence() {
        println!("target: {sentence}");
    }
    Ok(ExitCode::SUCCESS)
}

fn parse_square(text: &str) -> Result<u32, String> {
    let n: u32 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a whole number"))?;
    let root = n.isqrt();
    if n == 0 || root * root != n {
        let up = root + 1;
        return Err(format!(
            "{n} is not a perfect square: samples lie on an n×n grid (the nearest are {} and {})",
            (root * root).max(1),
            up * up
        ));
    }
    Ok(n)
}

fn parse_flip(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if (0.0..=1.0).contains(&x) => Ok(x),
        _ => Err(format!("`{text}` is not a FLIP mean: a number from 0 to 1")),
    }
}

fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if (0.0..=3600.0).contains(&x) => Ok(x),
        _ => Err(format!("`{text}` is not a time: a number of seconds from 0 to 3600")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use goldray::tradeoff::DEFAULT_FILTERS;

    #[test]
    fn list_defaults_are_the_library_defaults_in_the_syntax_the_flags_take() {
        let split = |list: &str| list.split(',').map(str::to_owned).collect::<Vec<_>>();
        let samples: Vec<u32> = split(DEFAULT_SAMPLES)
            .iter()
            .map(|s| parse_square(s).unwrap())
            .collect();
        assert_eq!(samples, SweepPlan::default().samples);
        let filters: Vec<Filter> = split(DEFAULT_FILTER_LIST)
            .iter()
            .map(|s| parse_named::<Filter>(s).unwrap())
            .collect();
        assert_eq!(filters, DEFAULT_FILTERS);
        let precisions: Vec<Precision> = split(DEFAULT_PRECISIONS)
            .iter()
            .map(|s| parse_named::<Precision>(s).unwrap())
            .collect();
        assert_eq!(precisions, Precision::ALL);
    }

    #[test]
    fn flag_values_are_checked_with_reasons() {
        assert_eq!(parse_square("16"), Ok(16));
        assert!(parse_square("8").unwrap_err().contains("nearest are 4 and 9"));
        assert!(parse_square("0").unwrap_err().contains("perfect square"));
        assert!(parse_square("four").unwrap_err().contains("whole number"));
        assert_eq!(parse_named::<Filter>("gaussian"), Ok(Filter::Gaussian));
        assert!(parse_named::<Filter>("box").unwrap_err().contains("none or gaussian"));
        assert_eq!(parse_named::<Precision>("f64"), Ok(Precision::F64));
        assert!(parse_named::<Precision>("f16").unwrap_err().contains("f32 or f64"));
        assert_eq!(parse_flip("0.05"), Ok(0.05));
        assert!(parse_flip("1.5").is_err() && parse_flip("nan").is_err());
        assert_eq!(parse_seconds("0"), Ok(0.0));
        assert!(parse_seconds("-0.5").is_err() && parse_seconds("nan").is_err());
    }
}
