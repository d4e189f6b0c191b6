//! `goldray autograde`: the Gradescope autograder. Grades `/autograder/submission` (running the
//! student's program first when the rubric has a `[program]` or `--program` is given) and writes
//! Gradescope's `/autograder/results/results.json`.

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::autograde::gradescope::{RESULTS, SUBMISSION, results, write_results};
use goldray::autograde::{SubmissionOptions, grade_submission};
use goldray::grade::{Diagnose, GradeOptions, load_rubric};
use goldray::sandbox::Sandbox;

use super::Failure;
use super::common::{LimitFlags, ProgramFlags, ThreadFlags, own_binary};
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
    #[command(flatten)]
    program: ProgramFlags,
    /// Folder for the HTML report (and the program's renders) [default: `report` beside
    /// --results].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Golden image cache [default: the user cache folder's goldray/goldens; fill it when the
    /// autograder image is built, so that grading renders nothing].
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Do not name the mistakes.
    #[arg(long)]
    no_diagnose: bool,
    #[command(flatten)]
    threads: ThreadFlags,
    #[command(flatten)]
    limits: LimitFlags,
}

pub fn run(args: AutogradeArgs) -> Result<ExitCode, Failure> {
    let rubric = load_rubric(&args.rubric)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| goldray::atomic_write::parent_folder(&args.results).join("report"));
    let options = SubmissionOptions {
        submission: args.submission.clone(),
        name: "submission".to_owned(),
        program: args.program.section(),
        limits: args.limits.overrides(),
        sandbox: Some(Sandbox::new(own_binary()?)),
        grade: GradeOptions {
            out,
            cache: args.cache.clone(),
            force: true,
            ..GradeOptions::default()
        },
        diagnose: if args.no_diagnose { Diagnose::No } else { Diagnose::Yes },
    };
    // The autograder's log is for the TA: a line per step.
    let reporter = Reporter::new(false);
    let graded = args
        .threads
        .install(|| grade_submission(&args.rubric, &options, &reporter))??;
    let results = results(&rubric.title, &graded.student, &rubric.gradescope, graded.run.as_ref());
    write_results(&args.results, &results)?;
    println!("{}", results.output);
    println!("results: {}", args.results.display());
    Ok(ExitCode::SUCCESS)
}
