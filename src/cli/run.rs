//! `goldray run`: a student's program run for every course render of a rubric, in the sandbox;
//! and the sandbox's hidden init (`goldray __sandbox-init`), which the library starts per command.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use goldray::run::{ClassRunOptions, ClassRunReport, RunOptions, RunReport, StudentState, run_class, run_rubric};
use goldray::sandbox::{CommandRecord, Limits, RunRecord};
use goldray::sandbox::{Sandbox, describe_limits, serve_init};

use super::Failure;
use super::common::{LimitFlags, ThreadFlags, own_binary};
use super::progress::Reporter;

#[derive(Clone, Debug, clap::Args)]
pub struct RunArgs {
    /// The rubric (TOML): each `[render.NAME]` of a course scene is one command.
    #[arg(long)]
    rubric: PathBuf,
    /// The student's program: a path, or a command with its arguments (`--program python3
    /// /path/rt.py`); the course's arguments follow them.
    #[arg(long, required = true, num_args = 1.., value_name = "PROGRAM [ARGS]")]
    program: Vec<String>,
    /// Folder to move the rubric's files into, with run.json (and build.log); with --programs,
    /// one such folder per student, ready for `goldray grade`.
    #[arg(long)]
    out: PathBuf,
    /// The submission's folder, which every command may read and --build copies [default: the
    /// program's folder, when the program is a path].
    #[arg(long, value_name = "DIR", conflicts_with = "programs")]
    submission: Option<PathBuf>,
    /// A whole class: one folder per student, each built (with --build) and run; --program then
    /// names the program inside each student's folder. A student whose sources and rubric have
    /// not changed since the last run into --out is not run again.
    #[arg(long, value_name = "SUBMISSIONS_DIR")]
    programs: Option<PathBuf>,
    /// With --programs: run every student again, changed or not.
    #[arg(long, requires = "programs")]
    force: bool,
    /// A build command, run with `sh -c` in a fresh copy of the submission under the same limits
    /// and sandbox (e.g. "make", "g++ -O2 -o raytracer *.cpp"); the program is then taken from
    /// that copy.
    #[arg(long, value_name = "CMD")]
    build: Option<String>,
    #[command(flatten)]
    threads: ThreadFlags,
    #[command(flatten)]
    limits: LimitFlags,
    /// No progress and no summary.
    #[arg(long)]
    quiet: bool,
}

pub fn run(args: RunArgs) -> Result<ExitCode, Failure> {
    let init = own_binary()?;
    let limits = args.limits.overrides();
    let reporter = Reporter::new(args.quiet);
    if let Some(programs) = &args.programs {
        let options = ClassRunOptions {
            program: args.program.clone(),
            programs: programs.clone(),
            build: args.build.clone(),
            out: args.out.clone(),
            limits,
            sandbox: Sandbox::new(init),
            force: args.force,
        };
        let report = args
            .threads
            .install(|| run_class(&args.rubric, &options, &reporter))??;
        if !args.quiet {
            println!("{}", class_summary(&report));
        }
        let failed = report
            .students
            .iter()
            .any(|s| matches!(s.state, StudentState::Failed(_)));
        return Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS });
    }
    let options = RunOptions {
        program: args.program.clone(),
        submission: args.submission.clone(),
        build: args.build.clone(),
        out: args.out.clone(),
        limits,
        sandbox: Sandbox::new(init),
    };
    let report = args
        .threads
        .install(|| run_rubric(&args.rubric, &options, &reporter))??;
    if !args.quiet {
        println!("{}", summary(&report));
    }
    Ok(ExitCode::SUCCESS)
}

/// What a TA reads after a run: how many commands succeeded, why each other one failed, what is
/// missing, which protections held.
fn summary(report: &RunReport) -> String {
    let mut lines = record_lines(&report.record, &report.limits, "");
    lines.extend(sandbox_lines(std::iter::once(&report.record)));
    lines.push(format!("outputs and run.json: {}", report.out.display()));
    lines.join("\n")
}

/// A class run: per student, how the run went (and why each failing command failed), then the
/// protections and what to do next.
fn class_summary(report: &ClassRunReport) -> String {
    let mut lines = Vec::new();
    let (mut ran, mut reused, mut failed) = (0, 0, 0);
    for student in &report.students {
        match &student.state {
            StudentState::Ran(record) => {
                ran += 1;
                let mut own = record_lines(record, &report.limits, "  ");
                if let Some(first) = own.first_mut() {
                    *first = format!("{}: {}", student.name, first.trim_start());
                }
                lines.extend(own);
            }
            StudentState::Reused(record) => {
                reused += 1;
                let ok = succeeded(record);
                lines.push(format!(
                    "{}: unchanged since the last run ({ok} of {} commands succeeded)",
                    student.name,
                    record.commands.len()
                ));
            }
            StudentState::Failed(why) => {
                failed += 1;
                lines.push(format!("{}: FAILED: {why}", student.name));
            }
        }
    }
    if !report.ignored.is_empty() {
        lines.push(format!("not student folders, ignored: {}", report.ignored.join(", ")));
    }
    lines.push(format!(
        "{} students: {ran} run, {reused} unchanged, {failed} failed ({})",
        report.students.len(),
        describe_limits(&report.limits)
    ));
    let records = report.students.iter().filter_map(|s| match &s.state {
        StudentState::Ran(record) | StudentState::Reused(record) => Some(record),
        StudentState::Failed(_) => None,
    });
    lines.extend(sandbox_lines(records));
    lines.push(format!(
        "outputs: one folder per student in {}; grade them with `goldray grade --rubric RUBRIC {}`",
        report.out.display(),
        report.out.display()
    ));
    lines.join("\n")
}

fn succeeded(record: &RunRecord) -> usize {
    record.commands.iter().filter(|c| command_succeeded(c)).count()
}

fn command_succeeded(command: &CommandRecord) -> bool {
    command.outcome.as_ref().is_some_and(|o| o.succeeded()) && command.outputs.iter().all(|o| o.delivered)
}

/// The build's line, the count of commands, and a line (with the last line of stderr) per
/// command that failed, each after `indent` but the first.
fn record_lines(record: &RunRecord, limits: &Limits, indent: &str) -> Vec<String> {
    let mut lines = Vec::new();
    if let Some(build) = &record.build {
        lines.push(match (&build.outcome, &build.not_run) {
            (Some(o), _) if o.succeeded() => format!("build: succeeded in {:.1} s", o.wall_seconds),
            (Some(o), _) => format!("build: FAILED: {} (build.log)", o.describe(limits)),
            (None, Some(why)) => format!("build: FAILED: {why}"),
            (None, None) => "build: not run".to_owned(),
        });
    }
    let ok = succeeded(record);
    lines.push(format!(
        "ran {} of {} commands: {ok} succeeded, {} failed ({})",
        record.commands.iter().filter(|c| c.outcome.is_some()).count(),
        record.commands.len(),
        record.commands.len() - ok,
        describe_limits(limits)
    ));
    for command in &record.commands {
        let missing: Vec<&str> = command
            .outputs
            .iter()
            .filter(|o| !o.delivered)
            .map(|o| o.file.as_str())
            .collect();
        let how = match (&command.outcome, &command.not_run) {
            (Some(o), _) if o.succeeded() && missing.is_empty() => continue,
            (Some(o), _) => o.describe(limits),
            (None, Some(why)) => why.clone(),
            (None, None) => "not run".to_owned(),
        };
        let missing = if missing.is_empty() {
            String::new()
        } else {
            format!("; missing {}", missing.join(", "))
        };
        lines.push(format!("  {}: {how}{missing}", command.name));
        if let Some(last) = command
            .outcome
            .as_ref()
            .and_then(|o| o.stderr_tail.lines().rev().find(|l| !l.trim().is_empty()))
        {
            let last: String = last.chars().take(160).collect();
            lines.push(format!("    stderr: {last}"));
        }
    }
    for skipped in &record.skipped {
        lines.push(format!("  {}: skipped: {}", skipped.name, skipped.reason));
    }
    lines.iter().map(|line| format!("{indent}{line}")).collect()
}

/// Which protections held, from the first command that ran; and whether any other differed.
fn sandbox_lines<'a>(records: impl Iterator<Item = &'a RunRecord>) -> Vec<String> {
    let mut ran = records.flat_map(|r| r.commands.iter().chain(&r.build).filter_map(|c| c.outcome.as_ref()));
    let Some(first) = ran.next() else {
        return Vec::new();
    };
    let mut lines = vec![format!("sandbox: {}", first.protections.summary())];
    if !first.protections.unavailable.is_empty() {
        lines.push(format!("not in force: {}", first.protections.unavailable.join("; ")));
    }
    if ran.any(|o| o.protections != first.protections) {
        lines.push("(protections differed between commands: see run.json)".to_owned());
    }
    lines
}

/// `goldray __sandbox-init`: reads the job from stdin, runs it, writes the reply to stdout.
pub fn serve_sandbox_init() -> ExitCode {
    let reply = serve_init(std::io::stdin().lock());
    let mut stdout = std::io::stdout().lock();
    match serde_json::to_writer(&mut stdout, &reply).map(|()| stdout.flush()) {
        Ok(Ok(())) => ExitCode::SUCCESS,
        _ => ExitCode::FAILURE,
    }
}
