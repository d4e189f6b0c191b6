//! `goldray autograde`: the Gradescope autograder. Grades `/autograder/submission` (running the
//! student's program first when the rubric has a `[program]` or `--program` is given) and writes
//! Gradescope's `/autograder/results/results.json`.

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::autograde::grade_submission;
use goldray::autograde::gradescope::{RESULTS, SUBMISSION, results, write_results};
use goldray::grade::load_rubric;

use super::Failure;
use super::common::SubmissionFlags;
use super::progress::Reporter;

#[derive(Clone, Debug, clap::Args)]
pub struct AutogradeArgs {
    /// The rubric (TOML); its [gradescope] table sets who sees what.
    #[arg(long)]
    rubric: PathBuf,
    /// The student's submission.
    #[arg(long, default_value = SUBMISSION)]
    submission: PathBuf,
    /// Where Gradescope reads the results.
    #[arg(long, default_value = RESULTS)]
    results: PathBuf,
    /// Folder for the HTML report (and the program's renders) [default: `report` beside
    /// --results].
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    grading: SubmissionFlags,
}

pub fn run(args: AutogradeArgs) -> Result<ExitCode, Failure> {
    let rubric = load_rubric(&args.rubric)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| goldray::atomic_write::parent_folder(&args.results).join("report"));
    let options = args
        .grading
        .options(args.submission.clone(), "submission".to_owned(), out)?;
    // The autograder's log is for the TA: a line per step.
    let reporter = Reporter::new(false);
    let graded = args
        .grading
        .threads
        .install(|| grade_submission(&args.rubric, &options, &reporter))??;
    let results = results(&rubric.title, &graded.student, &rubric.gradescope, graded.run.as_ref());
    write_results(&args.results, &results)?;
    println!("{}", results.output);
    println!("results: {}", args.results.display());
    Ok(ExitCode::SUCCESS)
}
