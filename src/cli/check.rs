//! `goldray check`: a student's self-check. Grades one folder (or, with a program, what the
//! program renders) against the course's rubric and prints the points per image, and for each
//! image that lost points why, the mistake named and where to look. Exit code 0 at full points,
//! 1 otherwise, so that it also serves in a student's own CI.

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::autograde::grade_submission;
use goldray::grade::student_feedback;

use super::Failure;
use super::common::SubmissionFlags;
use super::progress::Reporter;

#[derive(Clone, Debug, clap::Args)]
pub struct CheckArgs {
    /// The course's rubric (TOML).
    #[arg(long)]
    rubric: PathBuf,
    /// The folder to check: your renders (a01.png …), or your sources with --program.
    #[arg(value_name = "DIR")]
    folder: PathBuf,
    /// Keep the HTML report (and, with a program, its renders) in this folder [default: a
    /// temporary folder, removed afterwards].
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    grading: SubmissionFlags,
    /// Only the exit code.
    #[arg(long)]
    quiet: bool,
}

pub fn run(args: CheckArgs) -> Result<ExitCode, Failure> {
    let temporary = match &args.out {
        Some(_) => None,
        None => Some(tempfile::Builder::new().prefix("goldray-check-").tempdir()?),
    };
    let out = args
        .out
        .clone()
        .or_else(|| temporary.as_ref().map(|t| t.path().to_path_buf()))
        .unwrap_or_default();
    let name = args
        .folder
        .file_name()
        .map_or_else(|| "submission".to_owned(), |n| n.to_string_lossy().into_owned());
    let options = args.grading.options(args.folder.clone(), name, out.clone())?;
    // Progress goes to stderr; stdout holds only what the student reads.
    let reporter = Reporter::new(args.quiet);
    let graded = args
        .grading
        .threads
        .install(|| grade_submission(&args.rubric, &options, &reporter))??;
    if !args.quiet {
        println!("{}", student_feedback(&graded.student));
        if args.out.is_some() {
            println!("report: {}", out.join(&graded.student.page).display());
        }
    }
    let full = graded.student.total >= graded.student.max_points;
    Ok(if full { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
