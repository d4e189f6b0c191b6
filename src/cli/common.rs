//! Flags and value parsers that several commands share, each written once so that every
//! command spells and checks them the same way.

use std::path::{Path, PathBuf};
use std::time::Duration;

use goldray::autograde::SubmissionOptions;
use goldray::grade::{Diagnose, GradeOptions, ProgramSection};
use goldray::image_size::{SizeLimit, check_side};
use goldray::sandbox::{LimitOverrides, Sandbox, parse_bytes, parse_duration};

/// `--threads N`, the same on every command that works in parallel.
#[derive(Clone, Debug, clap::Args)]
pub struct ThreadFlags {
    /// Worker threads (default: one per core). The output is identical for any count.
    #[arg(long, alias = "jobs", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
}

impl ThreadFlags {
    /// Runs `work` on a rayon pool of the asked size.
    pub fn install<T: Send>(&self, work: impl FnOnce() -> T + Send) -> Result<T, String> {
        let mut builder = rayon::ThreadPoolBuilder::new();
        if let Some(threads) = self.threads {
            builder = builder.num_threads(threads as usize);
        }
        let pool = builder
            .build()
            .map_err(|e| format!("cannot start worker threads: {e}"))?;
        Ok(pool.install(work))
    }
}

/// The limits of every command a student's program runs (`run`, `check --program`,
/// `autograde`); each replaces the rubric's `[limits]`, which replace the defaults.
#[derive(Clone, Debug, clap::Args)]
pub struct LimitFlags {
    /// Wall-clock time per command [default: 60s, or the rubric's [limits] wall_time].
    #[arg(long, value_parser = parse_duration, value_name = "TIME")]
    wall_time: Option<Duration>,
    /// CPU time per process [default: 60s].
    #[arg(long, value_parser = parse_duration, value_name = "TIME")]
    cpu_time: Option<Duration>,
    /// Address space per process [default: 4GiB].
    #[arg(long, value_parser = parse_bytes, value_name = "SIZE")]
    memory: Option<u64>,
    /// Size of any file written [default: 512MiB].
    #[arg(long, value_parser = parse_bytes, value_name = "SIZE")]
    file_size: Option<u64>,
    /// Processes and threads per command [default: 256].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1_000_000), value_name = "N")]
    processes: Option<u64>,
}

impl LimitFlags {
    pub fn overrides(&self) -> LimitOverrides {
        LimitOverrides {
            wall: self.wall_time,
            cpu: self.cpu_time,
            memory_bytes: self.memory,
            file_bytes: self.file_size,
            processes: self.processes,
        }
    }
}

/// How `check` and `autograde` grade one submission: from its program or its pictures, with which
/// cache, threads and limits, and whether mistakes are named.
#[derive(Clone, Debug, clap::Args)]
pub struct SubmissionFlags {
    /// Build and run the student's program first, as `goldray run` does, and grade its outputs:
    /// a path inside the submission or a command with arguments [default: the rubric's
    /// [program] command, if any; else the folder's pictures are graded].
    #[arg(long, num_args = 1.., value_name = "PROGRAM [ARGS]")]
    program: Option<Vec<String>>,
    /// The build command for --program, run with `sh -c` in a copy of the submission.
    #[arg(long, value_name = "CMD", requires = "program")]
    build: Option<String>,
    /// Golden image cache [default: the user cache folder's goldray/goldens; an autograder fills
    /// it when its image is built, so that grading renders nothing].
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Do not name the mistakes (faster: no fault renders).
    #[arg(long)]
    no_diagnose: bool,
    #[command(flatten)]
    pub threads: ThreadFlags,
    #[command(flatten)]
    limits: LimitFlags,
}

impl SubmissionFlags {
    /// The options for grading `submission` as student `name`, its report in `out`; `--program`
    /// and `--build`, when given, replace the rubric's `[program]`.
    pub fn options(&self, submission: PathBuf, name: String, out: PathBuf) -> Result<SubmissionOptions, String> {
        Ok(SubmissionOptions {
            submission,
            name,
            program: self.program.clone().map(|command| ProgramSection {
                command,
                build: self.build.clone(),
            }),
            limits: self.limits.overrides(),
            sandbox: Some(Sandbox::new(own_binary()?)),
            grade: GradeOptions {
                out,
                cache: self.cache.clone(),
                force: true,
                ..GradeOptions::default()
            },
            diagnose: if self.no_diagnose { Diagnose::No } else { Diagnose::Yes },
        })
    }
}

/// goldray's own binary, which the sandbox starts as the init of every command it runs.
pub fn own_binary() -> Result<PathBuf, String> {
    std::env::current_exe().map_err(|e| format!("cannot find goldray's own binary for the sandbox: {e}"))
}

/// A limit: a finite number ≥ 0 (a NaN limit would pass everything, because every comparison
/// with NaN is false).
pub fn parse_threshold(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}` is not a finite number at least 0")),
    }
}

/// A fraction: a number in [0, 1].
pub fn parse_fraction(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("`{text}` is not a number between 0 and 1")),
    }
}

/// A named option (`gaussian`, `f64`, `rmse`) through the option's own `FromStr`, whose error
/// lists the valid names.
pub fn parse_named<T>(text: &str) -> Result<T, String>
where
    T: std::str::FromStr,
    T::Err: std::fmt::Display,
{
    text.trim().parse().map_err(|error: T::Err| error.to_string())
}

/// An image size given as two arguments, `W H`, or as one, `WxH`, checked against the size rule.
pub fn size_from_values(values: &[String], limit: SizeLimit) -> Result<(u32, u32), String> {
    match values {
        [one] => {
            let (width, height) = one
                .split_once(['x', 'X', '×'])
                .ok_or_else(|| format!("size `{one}`: give WIDTH HEIGHT or WIDTHxHEIGHT"))?;
            size_from_sides(width, height, limit)
        }
        [width, height] => size_from_sides(width, height, limit),
        _ => Err("size: give WIDTH HEIGHT or WIDTHxHEIGHT".to_owned()),
    }
}

fn size_from_sides(width: &str, height: &str, limit: SizeLimit) -> Result<(u32, u32), String> {
    let (width, height) = (width.trim(), height.trim());
    let side = |text: &str| {
        let value: i64 = text
            .parse()
            .map_err(|_| format!("size {width} {height}: `{text}` is not a whole number"))?;
        check_side(value, limit).map_err(|error| format!("size {width} {height}: each side {error}"))
    };
    Ok((side(width)?, side(height)?))
}

/// The `MIN MAX` of a depth range, checked before anything renders.
pub fn parse_depth_range(min: &str, max: &str) -> Result<(f64, f64), String> {
    let number = |text: &str| {
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("depth: `{text}` is not a finite number"))
    };
    let (min, max) = (number(min)?, number(max)?);
    if min >= max {
        return Err(format!("depth {min} {max}: the minimum must be below the maximum"));
    }
    Ok((min, max))
}

/// Fails unless `path`'s folder exists and a file can be created in it, so that a render is not
/// wasted on an output it cannot write. Says which path the user gave.
pub fn check_writable_file(path: &Path) -> Result<(), String> {
    goldray::atomic_write::check_writable(path).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_accepted_as_two_values_or_one_and_checked_by_the_size_rule() {
        let values = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(
            size_from_values(&values(&["800", "600"]), SizeLimit::Forceable),
            Ok((800, 600))
        );
        assert_eq!(
            size_from_values(&values(&["800x600"]), SizeLimit::Forceable),
            Ok((800, 600))
        );
        assert!(
            size_from_values(&values(&["64"]), SizeLimit::Fixed)
                .unwrap_err()
                .contains("WIDTHxHEIGHT")
        );
        assert!(
            size_from_values(&values(&["0x10"]), SizeLimit::Fixed)
                .unwrap_err()
                .contains("between 1")
        );
        let fixed = size_from_values(&values(&["99999x10"]), SizeLimit::Fixed).unwrap_err();
        assert!(fixed.contains("16384") && !fixed.contains("--force"), "{fixed}");
        let negative = size_from_values(&values(&["-400", "400"]), SizeLimit::Forceable).unwrap_err();
        assert!(negative.contains("must be between 1 and 16384"), "{negative}");
        let big = size_from_values(&values(&["20000", "10"]), SizeLimit::Forceable).unwrap_err();
        assert!(big.contains("--force"), "{big}");
        assert_eq!(
            size_from_values(&values(&["20000", "10"]), SizeLimit::Lifted),
            Ok((20000, 10))
        );
    }

    #[test]
    fn thresholds_and_fractions_refuse_what_would_pass_everything() {
        assert_eq!(parse_threshold("0.5"), Ok(0.5));
        assert!(parse_threshold("-1").is_err() && parse_threshold("inf").is_err() && parse_threshold("nan").is_err());
        assert_eq!(parse_fraction("1"), Ok(1.0));
        assert!(parse_fraction("1.5").is_err());
        assert_eq!(parse_depth_range("8", "18"), Ok((8.0, 18.0)));
        assert!(parse_depth_range("18", "8").unwrap_err().contains("below the maximum"));
    }
}
