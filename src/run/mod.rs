//! `goldray run`: renders a submission from its program. For each render of a rubric taken from
//! a course scene, the program runs once in the [sandbox](crate::sandbox) with the course's
//! command line, in a fresh folder holding the scene and its assets as the course's `data/`
//! folder lays them out; the files the rubric expects are then moved into the output folder
//! under the rubric's names, and nothing else the program wrote survives. `run.json` records
//! every command (see [`RunRecord`]).
//!
//! An optional build command first runs in a fresh copy of the submission, under the same
//! limits and sandbox; the program is then taken from that copy.

mod class;
mod command;
mod error;
mod layout;
mod submission;

use std::fs;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

pub use class::{ClassRunOptions, ClassRunReport, StudentRun, StudentState, run_class};
pub use command::{CourseCommand, DATA, plan};
pub use error::RunError;
pub use submission::{Program, copy_submission, hash_submission, resolve, submission_folder};

use crate::atomic_write::{check_writable_folder, write_file_atomic};
use crate::grade::load_rubric;
use crate::progress::Progress;
use crate::sandbox::{CommandRecord, Job, LimitOverrides, Limits, Outcome, RUN_RECORD, RunRecord, Sandbox, Skipped};

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

/// A rubric's commands, ready to run for any number of submissions.
#[derive(Clone, Debug)]
pub struct Plan {
    pub commands: Vec<CourseCommand>,
    pub skipped: Vec<Skipped>,
    pub limits: Limits,
    /// The digest of everything of the rubric's that a run depends on: the commands, the
    /// limits, and the bytes of every scene and asset laid out.
    digest: blake3::Hash,
}

/// The commands of the rubric at `rubric_path` and the limits they run under (`overrides`, then
/// the rubric's `[limits]`, then the defaults).
pub fn plan_run(rubric_path: &Path, overrides: &LimitOverrides) -> Result<Plan, RunError> {
    let rubric = load_rubric(rubric_path)?;
    let (commands, skipped) = plan(&rubric)?;
    if commands.is_empty() {
        let reasons: Vec<String> = skipped.iter().map(|s| format!("{}: {}", s.name, s.reason)).collect();
        return Err(RunError::NothingToRun {
            rubric: rubric_path.display().to_string(),
            reasons: reasons.join("; "),
        });
    }
    let limits = rubric.limits.then(overrides).apply(&Limits::default());
    let mut hasher = blake3::Hasher::new();
    hasher.update(env!("CARGO_PKG_VERSION").as_bytes());
    hasher.update(serde_json::to_string(&limits).unwrap_or_default().as_bytes());
    for command in &commands {
        hasher.update(format!("{:?}", (&command.args, &command.outputs)).as_bytes());
        let files = std::iter::once(&command.scene).chain(command.assets.iter().map(|(source, _)| source));
        for file in files {
            hash_file(&mut hasher, file);
        }
    }
    Ok(Plan {
        commands,
        skipped,
        limits,
        digest: hasher.finalize(),
    })
}

fn hash_file(hasher: &mut blake3::Hasher, path: &Path) {
    hasher.update(path.as_os_str().as_encoded_bytes());
    match fs::read(path) {
        Ok(bytes) => hasher.update(&[1]).update(blake3::hash(&bytes).as_bytes()),
        Err(_) => hasher.update(&[0]),
    };
}

/// Runs the program of `options` for every course render of the rubric at `rubric_path`, in
/// parallel on the current rayon pool (one command per worker), and writes the outputs and
/// `run.json` into `options.out`.
pub fn run_rubric(rubric_path: &Path, options: &RunOptions, progress: &dyn Progress) -> Result<RunReport, RunError> {
    let plan = plan_run(rubric_path, &options.limits)?;
    check_writable_folder(&options.out)?;
    fs::create_dir_all(&options.out).map_err(RunError::io("create", &options.out))?;
    let first = options.program.first().ok_or(RunError::NoProgram)?;
    let original = submission_folder(first, options.submission.as_deref());
    if options.build.is_some() && original.is_none() {
        return Err(RunError::NeedsSubmission);
    }
    // Without a build the program is found before anything runs: a mistyped path is the TA's
    // error, not a verdict on the student.
    if options.build.is_none() {
        resolve(&options.program, original.as_deref(), None)?;
    }
    let target = Target {
        program: &options.program,
        build: options.build.as_deref(),
        sandbox: &options.sandbox,
        student: None,
    };
    let inputs = inputs_digest(&plan, &target, original.as_deref())?;
    progress.begin("running", plan.commands.len() as u64);
    let record = run_submission(&plan, &target, original.as_deref(), &options.out, inputs, progress);
    progress.finish();
    let record = record?;
    Ok(RunReport {
        record,
        limits: plan.limits,
        out: options.out.clone(),
    })
}

/// What runs for a submission.
struct Target<'a> {
    program: &'a [String],
    build: Option<&'a str>,
    sandbox: &'a Sandbox,
    /// In a class, the student's name: the program then names a file of the student's own
    /// submission (not a path from the current folder), and progress names the student.
    student: Option<&'a str>,
}

impl Target<'_> {
    fn label(&self, what: &str) -> String {
        match self.student {
            Some(student) => format!("{student}: {what}"),
            None => what.to_owned(),
        }
    }
}

/// Builds (when asked) and runs one submission's program for every command of `plan`, delivers
/// the outputs into `out` and writes `run.json` there, with `inputs` (see [`inputs_digest`]).
fn run_submission(
    plan: &Plan,
    target: &Target,
    original: Option<&Path>,
    out: &Path,
    inputs: String,
    progress: &dyn Progress,
) -> Result<RunRecord, RunError> {
    let scratch = tempfile::Builder::new()
        .prefix("goldray-run-")
        .tempdir()
        .map_err(RunError::io("create a temporary folder in", std::env::temp_dir()))?;
    let (program, build) = match (target.build, original) {
        (Some(command), Some(original)) => {
            let copy = scratch.path().join("submission");
            copy_submission(original, &copy)?;
            progress.step(&target.label("build"));
            let record = build_in(&copy, command, &plan.limits, target.sandbox);
            write_file_atomic(&out.join(BUILD_LOG), build_log(&record).as_bytes())?;
            progress.done(&target.label("build"));
            (resolve(target.program, Some(original), Some(&copy))?, Some(record))
        }
        (Some(_), None) => return Err(RunError::NeedsSubmission),
        (None, Some(original)) if target.student.is_some() => {
            (resolve(target.program, Some(original), Some(original))?, None)
        }
        (None, _) => (resolve(target.program, original, None)?, None),
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
    let records: Vec<CommandRecord> = plan
        .commands
        .par_iter()
        .map(|command| {
            let record = run_command(
                command,
                &program,
                not_run.as_deref(),
                scratch.path(),
                target,
                out,
                &plan.limits,
            );
            progress.advance(1);
            progress.done(&target.label(&command.name));
            record
        })
        .collect();
    let record = RunRecord {
        goldray: env!("CARGO_PKG_VERSION").to_owned(),
        limits: plan.limits.clone(),
        inputs: Some(inputs),
        build,
        commands: records,
        skipped: plan.skipped.clone(),
    };
    let json = serde_json::to_vec_pretty(&record).unwrap_or_default();
    write_file_atomic(&out.join(RUN_RECORD), &json)?;
    Ok(record)
}

/// What a submission's run depends on, as hex: the plan, the program and build command, and
/// every file of the submission (a student whose sources and rubric have not changed need not be
/// built and run again).
fn inputs_digest(plan: &Plan, target: &Target, original: Option<&Path>) -> Result<String, RunError> {
    let mut hasher = blake3::Hasher::new();
    hasher.update(plan.digest.as_bytes());
    hasher.update(format!("{:?}", (target.program, target.build, target.student.is_some())).as_bytes());
    if let Some(folder) = original {
        hash_submission(folder, &mut hasher)?;
    }
    Ok(hasher.finalize().to_hex().to_string())
}

/// One course command: a fresh folder, the program in the sandbox, the outputs delivered, the
/// folder removed.
fn run_command(
    command: &CourseCommand,
    program: &Program,
    not_run: Option<&str>,
    scratch: &Path,
    target: &Target,
    out: &Path,
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
        match prepared.map(|()| target.sandbox.run(&job, limits)) {
            Ok(Ok(outcome)) => record.outcome = Some(outcome),
            Ok(Err(e)) => record.not_run = Some(format!("the sandbox failed: {e}")),
            Err(e) => record.not_run = Some(format!("not run: {e}")),
        }
    }
    record.outputs = command
        .outputs
        .iter()
        .map(|file| layout::deliver(&work, file, out, limits.file_bytes))
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
