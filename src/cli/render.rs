//! `goldray render CASE.toml`, and the flags every rendering command shares.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use goldray::case::LoadOptions;
use goldray::pipeline::{RecordRun, Rendered, render_case_file};

use super::Failure;
use super::common::{ThreadFlags, check_writable_file};
use super::progress::Reporter;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The case file.
    case: PathBuf,
    /// Output folder (created if missing).
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    run: RunFlags,
}

/// What every rendering command (`render`, `mit6837`) takes besides its inputs and outputs.
#[derive(clap::Args)]
pub struct RunFlags {
    #[command(flatten)]
    threads: ThreadFlags,
    /// No progress bar (or progress lines) and no list of written files.
    #[arg(long)]
    pub quiet: bool,
    /// Allow images larger than 16384 pixels on a side.
    #[arg(long)]
    pub force: bool,
    /// After the render, print statistics to stderr: time per phase, BVH sizes, rays by kind
    /// with Mrays/s, threads, peak memory.
    #[arg(long)]
    stats: bool,
    /// Write the same statistics as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    stats_json: Option<PathBuf>,
    /// Also write this run's record (render time, thread count, host) into every output, as
    /// `goldray.run.*`. Without it, the same case and binary give byte-identical files.
    #[arg(long)]
    record_run: bool,
}

pub fn run(args: RenderArgs) -> Result<ExitCode, Failure> {
    let RenderArgs { case, out, run } = args;
    goldray::atomic_write::check_writable_folder(&out)?;
    let load = LoadOptions {
        allow_huge_images: run.force,
    };
    let rendered = run
        .render(|reporter| render_case_file(&case, &out, &load, run.record(), reporter))
        .map_err(|failure| match failure {
            Failure::Run(_) if looks_like_course_scene(&case) => Failure::Run(format!(
                "{0} is a course scene file, not a TOML case: render it with `goldray mit6837 -input {0} \
                 -output out.png`, or convert it with `goldray import {0} -o case.toml`",
                case.display()
            )),
            other => other,
        })?;
    run.report(&rendered)
}

impl RunFlags {
    /// Whether the outputs carry the run's record.
    pub fn record(&self) -> RecordRun {
        if self.record_run {
            RecordRun::InOutputs
        } else {
            RecordRun::Omitted
        }
    }

    /// Checks the statistics file can be written, then renders on the asked pool with a
    /// progress reporter.
    pub fn render(
        &self,
        work: impl FnOnce(&Reporter) -> Result<Rendered, goldray::Error> + Send,
    ) -> Result<Rendered, Failure> {
        if let Some(path) = &self.stats_json {
            check_writable_file(path).map_err(Failure::Run)?;
        }
        let reporter = Reporter::new(self.quiet);
        Ok(self.threads.install(|| work(&reporter))??)
    }

    /// Lists what was written (unless quiet) and the statistics when asked.
    pub fn report(&self, rendered: &Rendered) -> Result<ExitCode, Failure> {
        if !self.quiet {
            for path in &rendered.written {
                eprintln!("wrote {}", path.display());
            }
        }
        if self.stats {
            eprint!("{}", rendered.stats);
        }
        if let Some(path) = &self.stats_json {
            rendered.stats.write_json(path)?;
        }
        Ok(ExitCode::SUCCESS)
    }
}

/// Whether `path` holds a course scene rather than a TOML case: its first word is one of the
/// course format's opening blocks. Used to point a user who gives one to `render` at the right
/// command.
fn looks_like_course_scene(path: &Path) -> bool {
    let Ok(text) = std::fs::read_to_string(path) else {
        return false;
    };
    let first_word = text
        .lines()
        .map(|line| line.split("//").next().unwrap_or("").trim())
        .find(|line| !line.is_empty())
        .and_then(|line| line.split_whitespace().next());
    matches!(
        first_word,
        Some("OrthographicCamera" | "PerspectiveCamera" | "Background" | "Lights" | "Materials" | "Group")
    )
}
