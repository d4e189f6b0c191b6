//! `goldray grade`: a class's renders against a rubric.

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::grade::{Diagnose, GradeOptions, grade_class_diagnosing, summary};

use super::Failure;
use super::common::ThreadFlags;
use super::progress::Reporter;

#[derive(Clone, Debug, clap::Args)]
pub struct GradeArgs {
    /// The rubric (TOML): expected files, their golden renders, limits and points.
    #[arg(long)]
    rubric: PathBuf,
    /// A folder holding one folder per student.
    submissions: PathBuf,
    /// Folder to write grades.csv, grades.json and index.html (with the pictures) into.
    #[arg(long, default_value = "grade-report")]
    out: PathBuf,
    #[command(flatten)]
    threads: ThreadFlags,
    /// Golden image cache [default: the user cache folder's goldray/goldens, e.g.
    /// ~/.cache/goldray/goldens]. Entries are named by content, so one cache serves every report.
    #[arg(long)]
    cache: Option<PathBuf>,
    /// No progress and no summary.
    #[arg(long)]
    quiet: bool,
    /// Do not name the mistake behind each image that lost points (faster: no fault renders).
    #[arg(long)]
    no_diagnose: bool,
}

pub fn run(args: GradeArgs) -> Result<ExitCode, Failure> {
    goldray::atomic_write::check_writable_folder(&args.out)?;
    let options = GradeOptions {
        out: args.out.clone(),
        cache: args.cache.clone(),
    };
    let reporter = Reporter::new(args.quiet);
    let diagnose = if args.no_diagnose { Diagnose::No } else { Diagnose::Yes };
    let report = args
        .threads
        .install(|| grade_class_diagnosing(&args.rubric, &args.submissions, &options, diagnose, &reporter))??;
    if !args.quiet {
        println!("{}", summary(&report, &args.out));
    }
    Ok(ExitCode::SUCCESS)
}
