//! `goldray run --programs`: a whole class at once. Every student's folder is built and run as
//! one submission (see [`super::run_rubric`]), its outputs and `run.json` going to a folder of
//! the student's name, so that `goldray grade` takes the whole output folder next.
//!
//! Students run in parallel beside each other's commands. A student whose inputs (sources,
//! program, build command, rubric, scenes, limits, goldray's version) are those of the last run,
//! and whose delivered files are still there, is not built or run again. Nothing one student does
//! or lacks stops the others: what keeps a student from running at all is written into the
//! student's `run.json` as the reason each command did not run, which grading then reports.

use std::fs;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::{Plan, RunError, Target, inputs_digest, plan_run, run_submission};
use crate::atomic_write::{check_writable_folder, write_file_atomic};
use crate::grade::student_folders;
use crate::progress::Progress;
use crate::sandbox::{CommandRecord, LimitOverrides, Limits, OutputRecord, RUN_RECORD, RunRecord, Sandbox};

/// What to run for a class, and where.
#[derive(Clone, Debug)]
pub struct ClassRunOptions {
    /// The program and its own arguments, as found in each student's folder (or its built copy):
    /// `raytracer`, `build/raytracer`, or a command on `PATH` with a file of the submission
    /// (`python3 rt.py`).
    pub program: Vec<String>,
    /// The class: one folder per student.
    pub programs: PathBuf,
    pub build: Option<String>,
    /// One folder per student is made here.
    pub out: PathBuf,
    pub limits: LimitOverrides,
    pub sandbox: Sandbox,
    /// Run every student again, even one whose inputs have not changed.
    pub force: bool,
}

/// One student of a class run.
#[derive(Clone, Debug)]
pub struct StudentRun {
    /// The student's folder name, which is also the output folder's.
    pub name: String,
    pub out: PathBuf,
    pub state: StudentState,
}

#[derive(Clone, Debug)]
pub enum StudentState {
    /// Built and run now.
    Ran(RunRecord),
    /// Unchanged since the last run, whose record this is.
    Reused(RunRecord),
    /// Not run, and no record could be written (the output folder refused it).
    Failed(String),
}

/// What a class run did.
#[derive(Clone, Debug)]
pub struct ClassRunReport {
    pub students: Vec<StudentRun>,
    /// Entries of the class folder that are not student folders.
    pub ignored: Vec<String>,
    pub limits: Limits,
    pub out: PathBuf,
}

/// Builds and runs every student of `options.programs` through the rubric at `rubric_path`.
pub fn run_class(
    rubric_path: &Path,
    options: &ClassRunOptions,
    progress: &dyn Progress,
) -> Result<ClassRunReport, RunError> {
    let plan = plan_run(rubric_path, &options.limits)?;
    if options.program.is_empty() {
        return Err(RunError::NoProgram);
    }
    check_writable_folder(&options.out)?;
    let (folders, ignored) = student_folders(&options.programs, &[&options.out])
        .map_err(RunError::io("list the students in", &options.programs))?;
    fs::create_dir_all(&options.out).map_err(RunError::io("create", &options.out))?;
    progress.begin("running", (folders.len() * plan.commands.len()) as u64);
    let students = folders
        .par_iter()
        .map(|(name, folder)| {
            let target = Target {
                program: &options.program,
                build: options.build.as_deref(),
                sandbox: &options.sandbox,
                student: Some(name),
            };
            let out = options.out.join(name);
            let state = run_student(&plan, &target, folder, &out, options.force, progress);
            progress.done(name);
            StudentRun {
                name: name.clone(),
                out,
                state,
            }
        })
        .collect();
    progress.finish();
    Ok(ClassRunReport {
        students,
        ignored,
        limits: plan.limits,
        out: options.out.clone(),
    })
}

fn run_student(
    plan: &Plan,
    target: &Target,
    folder: &Path,
    out: &Path,
    force: bool,
    progress: &dyn Progress,
) -> StudentState {
    let commands = plan.commands.len() as u64;
    let inputs = match inputs_digest(plan, target, Some(folder)) {
        Ok(inputs) => inputs,
        Err(e) => {
            progress.advance(commands);
            return record_not_run(plan, target, out, &e.to_string());
        }
    };
    if !force
        && let Some(record) = RunRecord::read(out)
        && record.inputs.as_deref() == Some(inputs.as_str())
        && still_delivered(&record, out)
    {
        progress.advance(commands);
        return StudentState::Reused(record);
    }
    if let Err(e) = fs::create_dir_all(out) {
        progress.advance(commands);
        return StudentState::Failed(format!("cannot create {}: {e}", out.display()));
    }
    match run_submission(plan, target, Some(folder), out, inputs, progress) {
        Ok(record) => StudentState::Ran(record),
        // The commands that had not run yet will not now.
        Err(e) => record_not_run(plan, target, out, &e.to_string()),
    }
}

/// Whether every file the record says was delivered is still in `out` (a TA may have deleted
/// one to have the student run again).
fn still_delivered(record: &RunRecord, out: &Path) -> bool {
    record
        .commands
        .iter()
        .flat_map(|command| &command.outputs)
        .filter(|output| output.delivered)
        .all(|output| out.join(&output.file).is_file())
}

/// A record in which no command ran, for `why`: what grading reports for each of the student's
/// images. Any file an earlier run delivered is removed, since this run did not make it.
fn record_not_run(plan: &Plan, target: &Target, out: &Path, why: &str) -> StudentState {
    let commands = plan
        .commands
        .iter()
        .map(|command| {
            for file in &command.outputs {
                let _ = fs::remove_file(out.join(file));
            }
            CommandRecord {
                name: command.name.clone(),
                argv: target.program.iter().chain(&command.args).cloned().collect(),
                outputs: command
                    .outputs
                    .iter()
                    .map(|file| OutputRecord {
                        file: file.clone(),
                        delivered: false,
                        problem: Some("not run".to_owned()),
                    })
                    .collect(),
                outcome: None,
                not_run: Some(format!("not run: {why}")),
            }
        })
        .collect();
    let record = RunRecord {
        goldray: env!("CARGO_PKG_VERSION").to_owned(),
        limits: plan.limits.clone(),
        inputs: None,
        build: None,
        commands,
        skipped: plan.skipped.clone(),
    };
    let written = fs::create_dir_all(out).map_err(|e| e.to_string()).and_then(|()| {
        let json = serde_json::to_vec_pretty(&record).unwrap_or_default();
        write_file_atomic(&out.join(RUN_RECORD), &json).map_err(|e| e.to_string())
    });
    match written {
        Ok(()) => StudentState::Ran(record),
        Err(e) => StudentState::Failed(format!("{why}; and its run.json could not be written: {e}")),
    }
}
