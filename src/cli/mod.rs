//! goldray's command line: every flag, every check of a flag's value, and everything printed.
//! The library below neither parses flags nor prints; each command here is one file that turns
//! flags into library options, runs the library, and reports.

mod autograde;
mod check;
mod common;
mod course_flags;
mod diff;
mod grade;
mod import;
mod mit6837;
mod progress;
mod render;
mod review;
mod run;
mod tradeoff;

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};
use goldray::texel_cache::TexelCache;

/// A deterministic Whitted ray tracer and scene-to-image regression harness.
#[derive(Parser)]
#[command(name = "goldray", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a TOML case to DIR/NAME.exr and DIR/NAME.png (plus depth and normal PNGs when the
    /// case asks for them).
    Render(render::RenderArgs),
    /// Drop-in replacement for the course's ray tracer binary, with its single-dash flags.
    #[command(override_usage = mit6837::USAGE)]
    Mit6837(mit6837::Mit6837Args),
    /// Convert a course scene file to the equivalent TOML case (takes the course's render flags).
    Import(import::ImportArgs),
    /// Compare two EXR or PNG images within a tolerance. Exit code: 0 pass, 1 warn (some pixels
    /// over --pixel, every limit kept), 2 fail, 3 size or channel mismatch, 4 unreadable file.
    Diff(diff::DiffArgs),
    /// Grade folders of student renders against a rubric's golden images: writes grades.csv,
    /// grades.json and an HTML report. Exit code 0 whenever grading ran, whatever the grades.
    Grade(grade::GradeArgs),
    /// Measure the speed-accuracy trade: render a case over samples × filter × precision and
    /// bounces, time each setting and count its rays, measure its error against a converged
    /// reference, and write tradeoff.csv, tradeoff.md and a log-log plot tradeoff.png with the
    /// Pareto front.
    Tradeoff(tradeoff::TradeoffArgs),
    /// Review the golden suite's pending snapshots (golden/*.snap.new): a local page with the
    /// pictures and numbers to accept or reject each, or --list, --accept, --reject,
    /// --accept-all, --static DIR. Accepting writes what `cargo insta accept` writes.
    Review(review::ReviewArgs),
    /// Run a student's program for every course render of a rubric, each command in a sandbox
    /// with limits, moving the rubric's files into --out with run.json (what each command did).
    Run(run::RunArgs),
    /// A student's self-check: grade one folder (or what its program renders) against the
    /// course's rubric and print the points, the mistakes named and where to look. Exit code 0
    /// at full points, 1 otherwise.
    Check(check::CheckArgs),
    /// Gradescope's autograder: grade /autograder/submission (building and running the program
    /// first when the rubric has a [program]) and write /autograder/results/results.json.
    Autograde(autograde::AutogradeArgs),
}

/// Why a command stopped: a command line that cannot be right (exit code 2, like clap's own
/// errors) or a failure while running (exit code 1).
pub enum Failure {
    Usage(String),
    Run(String),
}

impl<E: std::fmt::Display> From<E> for Failure {
    fn from(error: E) -> Failure {
        Failure::Run(error.to_string())
    }
}

/// `goldray mit6837 --help` (or `-help`, or `goldray help mit6837`).
fn asks_for_course_help(args: &[std::ffi::OsString]) -> bool {
    match args.get(1).and_then(|a| a.to_str()) {
        Some("mit6837") => true,
        Some("help") => args.get(2).is_some_and(|a| a == "mit6837"),
        _ => false,
    }
}

/// Asks glibc's allocator to keep memory the process frees for its next allocations instead of
/// handing it back to the kernel at once. goldray allocates and frees pictures of megabytes by
/// the thousand (a class's PNGs, the mistakes' pictures of a diagnosis); with glibc's defaults
/// many went back to the kernel on free, and every page came back zeroed on the next use.
/// - Blocks up to 32 MB (the largest glibc takes) come from the heap, which keeps up to 1 GB of
///   free space at its top: a warm diagnosed grading of a 20-student class at 800×800 went from
///   1.6–2.3 s of its 8–9 s of processor time in the kernel to 1.1–1.2 s.
/// - One heap for all threads: glibc gives threads heaps of their own and deletes such a heap
///   whenever it empties, whatever the trim threshold (its grading run created and deleted about
///   a thousand 64 MB heaps). With one it creates none, and the same grading went from 2.5–2.7 s
///   of kernel time to 1.9–2.6 s and from 4.7–5.0 s of wall time to 4.5–4.7 s (alternated on a
///   busy machine), with the same peak memory. The shared lock is taken only for blocks too large
///   for each thread's cache of small ones, a few per picture.
/// - The heap grows in large steps, advised to use huge pages before blocks are carved from it
///   (see `allocator::grow_heap_in_large_steps`).
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets allocator parameters; it is called before any thread starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
    crate::allocator::grow_heap_in_large_steps();
}

/// Keeps decoded cube-map faces between runs (see `goldray::texel_cache`) in the folder
/// `GOLDRAY_TEXEL_CACHE` names, or in the user's cache folder when it is unset; `off` (or empty)
/// keeps none. Read here, once, so that the library itself writes nothing unasked.
fn install_texel_cache() {
    let dir = match std::env::var_os("GOLDRAY_TEXEL_CACHE") {
        Some(value) if value.is_empty() || value == "off" => None,
        Some(value) => Some(std::path::PathBuf::from(value)),
        None => TexelCache::default_dir(),
    };
    if let Some(dir) = dir {
        TexelCache::new(dir, goldray::texel_cache::DEFAULT_LIMIT_BYTES).install();
    }
}

/// Parses the command line (rewriting the course's single-dash flags first), runs the command
/// and turns its outcome into the process's exit code.
pub fn main() -> ExitCode {
    // The sandbox's init, started by the library for each command it runs: first thing, before
    // anything could start a thread (see goldray::sandbox).
    if std::env::args_os()
        .nth(1)
        .is_some_and(|a| a == goldray::sandbox::INIT_COMMAND)
    {
        return run::serve_sandbox_init();
    }
    keep_freed_memory();
    install_texel_cache();
    let args = course_flags::rewrite(std::env::args_os());
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(error) if error.kind() == clap::error::ErrorKind::DisplayHelp && asks_for_course_help(&args) => {
            let help = Cli::command()
                .find_subcommand_mut("mit6837")
                .map(|command| command.render_help().to_string())
                .unwrap_or_default();
            print!("{}", mit6837::course_style_help(&help));
            return ExitCode::SUCCESS;
        }
        Err(error) => error.exit(),
    };
    let outcome = match cli.command {
        Command::Render(args) => render::run(args),
        Command::Mit6837(args) => mit6837::run(args),
        Command::Import(args) => import::run(args),
        Command::Diff(args) => Ok(diff::run(args)),
        Command::Grade(args) => grade::run(args),
        Command::Tradeoff(args) => tradeoff::run(args),
        Command::Run(args) => run::run(args),
        Command::Check(args) => check::run(args),
        Command::Autograde(args) => autograde::run(args),
        Command::Review(args) => review::run(args),
    };
    match outcome {
        Ok(code) => code,
        Err(Failure::Usage(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
        Err(Failure::Run(message)) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
