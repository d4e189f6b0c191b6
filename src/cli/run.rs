//! `goldray run`: a student's program run for every course render of a rubric, in the sandbox;
//! and the sandbox's hidden init (`goldray __sandbox-init`), which the library starts per command.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use goldray::run::{RunOptions, RunReport, run_rubric};
use goldray::sandbox::{LimitOverrides, Sandbox, describe_limits, parse_bytes, parse_duration, serve_init};

use super::Failure;
use super::common::ThreadFlags;
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
    /// Folder to move the rubric's files into, with run.json (and build.log).
    #[arg(long)]
    out: PathBuf,
    /// The submission's folder, which every command may read and --build copies [default: the
    /// program's folder, when the program is a path].
    #[arg(long, value_name = "DIR")]
    submission: Option<PathBuf>,
    /// A build command, run with `sh -c` in a fresh copy of the submission under the same limits
    /// and sandbox (e.g. "make", "g++ -O2 -o raytracer *.cpp"); the program is then taken from
    /// that copy.
    #[arg(long, value_name = "CMD")]
    build: Option<String>,
    #[command(flatten)]
    threads: ThreadFlags,
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
    /// No progress and no summary.
    #[arg(long)]
    quiet: bool,
}

pub fn run(args: RunArgs) -> Result<ExitCode, Failure> {
    let init = std::env::current_exe().map_err(|e| format!("cannot find goldray's own binary for the sandbox: {e}"))?;
    let options = RunOptions {
        program: args.program.clone(),
        submission: args.submission.clone(),
        build: args.build.clone(),
        out: args.out.clone(),
        limits: LimitOverrides {
            wall: args.wall_time,
            cpu: args.cpu_time,
            memory_bytes: args.memory,
            file_bytes: args.file_size,
            processes: args.processes,
        },
        sandbox: Sandbox::new(init),
    };
    let reporter = Reporter::new(args.quiet);
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
    let record = &report.record;
    let mut lines = Vec::new();
    if let Some(build) = &record.build {
        lines.push(match (&build.outcome, &build.not_run) {
            (Some(o), _) if o.succeeded() => format!("build: succeeded in {:.1} s", o.wall_seconds),
            (Some(o), _) => format!("build: FAILED: {} (build.log)", o.describe(&report.limits)),
            (None, Some(why)) => format!("build: FAILED: {why}"),
            (None, None) => "build: not run".to_owned(),
        });
    }
    let ok = record
        .commands
        .iter()
        .filter(|c| c.outcome.as_ref().is_some_and(|o| o.succeeded()) && c.outputs.iter().all(|o| o.delivered))
        .count();
    lines.push(format!(
        "ran {} of {} commands: {ok} succeeded, {} failed ({})",
        record.commands.iter().filter(|c| c.outcome.is_some()).count(),
        record.commands.len(),
        record.commands.len() - ok,
        describe_limits(&report.limits)
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
            (Some(o), _) => o.describe(&report.limits),
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
    let ran = record
        .commands
        .iter()
        .chain(&record.build)
        .filter_map(|c| c.outcome.as_ref());
    if let Some(first) = ran.clone().next() {
        lines.push(format!("sandbox: {}", first.protections.summary()));
        if !first.protections.unavailable.is_empty() {
            lines.push(format!("not in force: {}", first.protections.unavailable.join("; ")));
        }
        if ran.clone().any(|o| o.protections != first.protections) {
            lines.push("(protections differed between commands: see run.json)".to_owned());
        }
    }
    lines.push(format!("outputs and run.json: {}", report.out.display()));
    lines.join("\n")
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
