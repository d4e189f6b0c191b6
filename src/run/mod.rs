//! `goldray run`: renders a submission from its program. For each render of a rubric taken from
//! a course scene, the program runs once in the [sandbox](crate::sandbox) with the course's
//! command line, in a fresh folder holding the scene and its assets as the course's `data/`
//! folder lays them out; the files the rubric expects are then moved into the output folder
//! under the rubric's names, and nothing else the program wrote survives. `run.json` records
//! every command (see [`RunRecord`]).
//!
//! An optional build command first runs in a fresh copy of the submission, under the same
//! limits and sandbox; the program is then taken from that copy.

mod command;
mod error;
mod layout;
mod submission;

use std::fs;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

pub use command::{CourseCommand, DATA, plan};
pub use error::RunError;
pub use submission::{Program, copy_submission, resolve, submission_folder};

use crate::atomic_write::{check_writable_folder, write_file_atomic};
use crate::grade::load_rubric;
use crate::progress::Progress;
use crate::sandbox::{CommandRecord, Job, LimitOverrides, Limits, Outcome, RUN_RECORD, RunRecord, Sandbox};

/// The build's log in the output folder.
pub const BUILD_LOG: &str = "build.log";

/// What to run and where.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The program and its own arguments (the course's come after them).
    pub program: Vec<String>,
    /// The submission's folder (default: the program's folder, when the program is a path).
    pub submission: Option<PathBuf>,
    /// A build command run with `sh -c` in a fresh copy of the submission first.
    pub build: Option<String>,
    pub out: PathBuf,
    /// Limits from the command line; they replace the rubric's `[limits]`, which replace the
    /// defaults.
    pub limits: LimitOverrides,
    pub sandbox: Sandbox,
}

/// What a run did: the record written to `run.json`, and the limits it ran under.
#[derive(Clone, Debug)]
pub struct RunReport {
    pub record: RunRecord,
    pub limits: Limits,
    pub out: PathBuf,
}

/// Runs the program of `options` for every course render of the rubric at `rubric_path`, in
/// parallel on the current rayon pool (one command per worker), and writes the outputs and
/// `run.json` into `options.out`.
pub fn run_rubric(rubric_path: &Path, options: &RunOptions, progress: &dyn Progress) -> Result<RunReport, RunError> {
    let rubric = load_rubric(rubric_path)?;
    let (commands, skipped) = plan(&rubric)?;
    if commands.is_empty() {
        let reasons: Vec<String> = skipped.iter().map(|s| format!("{}: {}", s.name, s.reason)).collect();
        return Err(RunError::NothingToRun {
            rubric: rubric_path.display().to_string(),
            reasons: reasons.join("; "),
        });
    }
    let limits = rubric.limits.then(&options.limits).apply(&Limits::default());
    check_writable_folder(&options.out)?;
    fs::create_dir_all(&options.out).map_err(RunError::io("create", &options.out))?;
    let first = options.program.first().ok_or(RunError::NoProgram)?;
    let original = submission_folder(first, options.submission.as_deref());
    let scratch = tempfile::Builder::new()
        .prefix("goldray-run-")
        .tempdir()
        .map_err(RunError::io("create a temporary folder in", std::env::temp_dir()))?;

    let (program, build) = match &options.build {
        None => (resolve(&options.program, original.as_deref(), None)?, None),
        Some(command) => {
            let original = original.as_deref().ok_or(RunError::NeedsSubmission)?;
            let copy = scratch.path().join("submission");
            copy_submission(original, &copy)?;
            progress.step("build");
            let record = build_in(&copy, command, &limits, &options.sandbox);
            write_file_atomic(&options.out.join(BUILD_LOG), build_log(&record).as_bytes())?;
            progress.done("build");
            (resolve(&options.program, Some(original), Some(&copy))?, Some(record))
        }
    };
    let not_run = match &build {
        Some(record) if !record.outcome.as_ref().is_some_and(Outcome::succeeded) => {
            Some(format!("not run: the build failed (see {BUILD_LOG})"))
        }
        _ if !program.path.is_file() => Some(format!(
            "not run: the program {} does not exist{}",
            program.path.display(),
            if build.is_some() { " after the build" } else { "" }
        )),
        _ => None,
    };

    progress.begin("running", commands.len() as u64);
    let records: Vec<CommandRecord> = commands
        .par_iter()
        .map(|command| {
            let record = run_command(command, &program, not_run.as_deref(), scratch.path(), options, &limits);
            progress.advance(1);
            progress.done(&command.name);
            record
        })
        .collect();
    progress.finish();
    let record = RunRecord {
        goldray: env!("CARGO_PKG_VERSION").to_owned(),
        limits: limits.clone(),
        build,
        commands: records,
        skipped,
    };
    let json = serde_json::to_vec_pretty(&record).unwrap_or_default();
    write_file_atomic(&options.out.join(RUN_RECORD), &json)?;
    Ok(RunReport {
        record,
        limits,
        out: options.out.clone(),
    })
}

/// One course command: a fresh folder, the program in the sandbox, the outputs delivered, the
/// folder removed.
fn run_command(
    command: &CourseCommand,
    program: &Program,
    not_run: Option<&str>,
    scratch: &Path,
    options: &RunOptions,
    limits: &Limits,
) -> CommandRecord {
    let mut job_args = program.args.clone();
    job_args.extend(command.args.iter().cloned());
    let work = scratch.join(format!("run-{}", command.name));
    let mut job = Job::new(&program.path, job_args, &work);
    job.readable.extend(program.folder.iter().cloned());
    let mut record = CommandRecord {
        name: command.name.clone(),
        argv: job.argv(),
        outputs: Vec::new(),
        outcome: None,
        not_run: not_run.map(str::to_owned),
    };
    if record.not_run.is_none() {
        let prepared = fs::create_dir(&work)
            .map_err(RunError::io("create", &work))
            .and_then(|()| layout::lay_out(&work, command));
        match prepared.map(|()| options.sandbox.run(&job, limits)) {
            Ok(Ok(outcome)) => record.outcome = Some(outcome),
            Ok(Err(e)) => record.not_run = Some(format!("the sandbox failed: {e}")),
            Err(e) => record.not_run = Some(format!("not run: {e}")),
        }
    }
    record.outputs = command
        .outputs
        .iter()
        .map(|file| layout::deliver(&work, file, &options.out, limits.file_bytes))
        .collect();
    let _ = fs::remove_dir_all(&work);
    record
}

fn build_in(copy: &Path, command: &str, limits: &Limits, sandbox: &Sandbox) -> CommandRecord {
    let job = Job::new("/bin/sh", vec!["-c".to_owned(), command.to_owned()], copy);
    let (outcome, not_run) = match sandbox.run(&job, limits) {
        Ok(outcome) => (Some(outcome), None),
        Err(e) => (None, Some(format!("the sandbox failed: {e}"))),
    };
    CommandRecord {
        name: "build".to_owned(),
        argv: vec!["sh".to_owned(), "-c".to_owned(), command.to_owned()],
        outputs: Vec::new(),
        outcome,
        not_run,
    }
}

/// The build's command, how it ended, and the tails of what it printed.
fn build_log(record: &CommandRecord) -> String {
    let mut log = format!("$ {}\n", record.argv.join(" "));
    match (&record.outcome, &record.not_run) {
        (Some(outcome), _) => {
            log += &format!(
                "# {}; {:.1} s, CPU {:.1} s, peak memory {}\n",
                if outcome.succeeded() { "succeeded" } else { "FAILED" },
                outcome.wall_seconds,
                outcome.cpu_seconds,
                crate::sandbox::show_bytes(outcome.peak_memory_bytes)
            );
            log += &format!("# exit: {}; limit: {:?}\n", outcome.exit, outcome.limit);
            log += &format!(
                "\n## stdout (last {} bytes)\n{}\n",
                outcome.stdout_tail.len(),
                outcome.stdout_tail
            );
            log += &format!(
                "\n## stderr (last {} bytes)\n{}\n",
                outcome.stderr_tail.len(),
                outcome.stderr_tail
            );
        }
        (None, Some(reason)) => log += &format!("# {reason}\n"),
        (None, None) => {}
    }
    log
}
