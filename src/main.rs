use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use goldray::assignment_outputs::AssignmentOutputs;
use goldray::case::{AssignmentOptions, LoadOptions, MAX_IMAGE_SIZE};
use goldray::pipeline::{Rendered, import_assignment, render_assignment, render_case_file};

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
    Render {
        /// The case file.
        case: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        #[command(flatten)]
        run: RunFlags,
    },
    /// Drop-in replacement for the course's ray tracer binary, with its single-dash flags:
    /// goldray mit6837 -input scene.txt -output out.png [-normals n.png] [-size w h]
    /// [-depth min max d.png] [-bounces n] [-shadows] [-jitter] [-filter]
    Mit6837 {
        /// The course scene file.
        #[arg(long)]
        input: PathBuf,
        /// Colour PNG (trunc(c·255), no gamma, like the course binary).
        #[arg(long)]
        output: Option<PathBuf>,
        /// Normals PNG, (n+1)/2.
        #[arg(long)]
        normals: Option<PathBuf>,
        /// Depth PNG: distances from MIN (black) to MAX (white).
        #[arg(long, num_args = 3, value_names = ["MIN", "MAX", "FILE"], allow_negative_numbers = true)]
        depth: Option<Vec<String>>,
        /// Also write goldray's linear EXR (colour, depth, normals) here.
        #[arg(long)]
        exr: Option<PathBuf>,
        #[command(flatten)]
        course: CourseFlags,
        #[command(flatten)]
        run: RunFlags,
    },
    /// Convert a course scene file to the equivalent TOML case.
    Import {
        /// The course scene file.
        scene: PathBuf,
        /// Write the case here instead of to standard output.
        #[arg(short = 'o', long)]
        output: Option<PathBuf>,
        /// Replace the output file if it exists.
        #[arg(long)]
        force: bool,
        /// Ask the case for a depth image over MIN..MAX, like the course's `-depth`.
        #[arg(long, num_args = 2, value_names = ["MIN", "MAX"], allow_negative_numbers = true)]
        depth: Option<Vec<String>>,
        /// Ask the case for a normals image, like the course's `-normals`.
        #[arg(long)]
        normals: bool,
        #[command(flatten)]
        course: CourseFlags,
    },
    /// Compare two EXR or PNG images within a tolerance. Exit code: 0 pass, 1 warn (some pixels
    /// over --pixel, every limit kept), 2 fail, 3 size or channel mismatch, 4 unreadable file.
    Diff(goldray::compare::DiffArgs),
    /// Grade folders of student renders against a rubric's golden images: writes grades.csv,
    /// grades.json and an HTML report. Exit code 0 whenever grading ran, whatever the grades.
    Grade(goldray::grade::GradeArgs),
    /// Measure the speed-accuracy trade: render a case over samples × filter × precision and
    /// bounces, time each setting and count its rays, measure its error against a converged reference, and
    /// write tradeoff.csv, tradeoff.md and a log-log plot tradeoff.png with the Pareto front.
    Tradeoff(goldray::tradeoff::TradeoffArgs),
}

/// The course binary's rendering flags, shared by `mit6837` and `import` so that an imported
/// case renders exactly what the same course command would.
#[derive(clap::Args)]
struct CourseFlags {
    /// Image width and height.
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [100, 100])]
    size: Vec<u32>,
    /// Mirror recursion depth.
    #[arg(long, default_value_t = 0)]
    bounces: u32,
    /// Trace shadow rays.
    #[arg(long)]
    shadows: bool,
    /// 16 stratified jittered samples per pixel.
    #[arg(long)]
    jitter: bool,
    /// Render at 3× and down-filter with the 3×3 Gaussian.
    #[arg(long)]
    filter: bool,
}

#[derive(clap::Args)]
struct RunFlags {
    /// Worker threads (default: one per core). The output is identical for any count.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// No progress bar and no list of written files.
    #[arg(long)]
    quiet: bool,
    /// Allow images larger than 16384 pixels on a side.
    #[arg(long)]
    force: bool,
    /// After the render, print statistics to stderr: time per phase, BVH sizes, rays by kind
    /// with Mrays/s, threads, peak memory.
    #[arg(long)]
    stats: bool,
    /// Write the same statistics as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    stats_json: Option<PathBuf>,
}

fn main() -> ExitCode {
    match run(Cli::parse_from(course_style_flags(std::env::args_os()))) {
        Ok(code) => code,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// The course binary takes single-dash long flags (`-input`); after `mit6837` they are
/// rewritten to clap's `--input`, leaving negative numbers (`-depth -1 5 d.png`) alone.
fn course_style_flags(args: impl Iterator<Item = OsString>) -> Vec<OsString> {
    let args: Vec<OsString> = args.collect();
    if args.get(1).is_none_or(|a| a != "mit6837") {
        return args;
    }
    args.into_iter()
        .enumerate()
        .map(|(index, arg)| match arg.to_str() {
            Some(flag)
                if index > 1
                    && flag.len() > 2
                    && flag.starts_with('-')
                    && !flag.starts_with("--")
                    && flag.parse::<f64>().is_err() =>
            {
                OsString::from(format!("-{flag}"))
            }
            _ => arg,
        })
        .collect()
}

/// The exit code on success: 0, except `diff`, whose code is its verdict.
fn run(cli: Cli) -> Result<ExitCode, String> {
    match cli.command {
        Command::Render { case, out, run } => {
            let load = LoadOptions {
                allow_huge_images: run.force,
            };
            let rendered = run.install(|| render_case_file(&case, &out, &load, !run.quiet))?;
            run.report(&rendered).map(|()| ExitCode::SUCCESS)
        }
        Command::Mit6837 {
            input,
            output,
            normals,
            depth,
            exr,
            course,
            run,
        } => {
            let depth = depth
                .map(|values| parse_depth(&values[..2]).map(|(min, max)| (min, max, PathBuf::from(&values[2]))))
                .transpose()?;
            let outputs = AssignmentOutputs {
                color: output,
                normals,
                depth: depth
                    .as_ref()
                    .map(|(min, max, path)| (*min as f32, *max as f32, path.clone())),
                exr,
            };
            if outputs.color.is_none() && outputs.normals.is_none() && outputs.depth.is_none() && outputs.exr.is_none()
            {
                return Err("nothing to write: give -output, -normals, -depth or --exr".to_string());
            }
            let depth_range = depth.map(|(min, max, _)| (min, max));
            let options = course.options(depth_range, outputs.normals.is_some(), run.force)?;
            let rendered = run.install(|| render_assignment(&input, &options, &outputs, !run.quiet))?;
            run.report(&rendered).map(|()| ExitCode::SUCCESS)
        }
        Command::Import {
            scene,
            output,
            force,
            depth,
            normals,
            course,
        } => {
            let depth_range = depth.map(|values| parse_depth(&values)).transpose()?;
            let options = course.options(depth_range, normals, true)?;
            let toml_path = output.clone().unwrap_or_else(|| PathBuf::from("imported.toml"));
            let text = import_assignment(&scene, &options, &toml_path).map_err(|e| e.to_string())?;
            match output {
                Some(path) if path.exists() && !force => {
                    Err(format!("{} exists; pass --force to replace it", path.display()))
                }
                Some(path) => {
                    goldray::atomic_write::write_file_atomic(&path, text.as_bytes()).map_err(|e| e.to_string())
                }
                None => std::io::stdout()
                    .write_all(text.as_bytes())
                    .map_err(|e| format!("cannot write to standard output: {e}")),
            }
            .map(|()| ExitCode::SUCCESS)
        }
        Command::Diff(args) => Ok(ExitCode::from(goldray::compare::run_diff(&args))),
        Command::Grade(args) => goldray::grade::run_grade(&args)
            .map(|_| ExitCode::SUCCESS)
            .map_err(|e| e.to_string()),
        Command::Tradeoff(args) => goldray::tradeoff::run_tradeoff_command(&args)
            .map(|_| ExitCode::SUCCESS)
            .map_err(|e| e.to_string()),
    }
}

/// The `MIN MAX` of `-depth`, checked before anything renders.
fn parse_depth(values: &[String]) -> Result<(f64, f64), String> {
    let number = |text: &str| {
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("depth: `{text}` is not a finite number"))
    };
    let (min, max) = (number(&values[0])?, number(&values[1])?);
    if min >= max {
        return Err(format!("depth {min} {max}: the minimum must be below the maximum"));
    }
    Ok((min, max))
}

impl CourseFlags {
    fn options(
        &self,
        depth_range: Option<(f64, f64)>,
        normals: bool,
        allow_huge: bool,
    ) -> Result<AssignmentOptions, String> {
        let (width, height) = (self.size[0], self.size[1]);
        let limit = if allow_huge { u32::MAX } else { MAX_IMAGE_SIZE as u32 };
        if width == 0 || height == 0 || width > limit || height > limit {
            return Err(format!(
                "size {width} {height}: each side must be between 1 and {MAX_IMAGE_SIZE} (pass --force for larger)"
            ));
        }
        Ok(AssignmentOptions {
            width,
            height,
            bounces: self.bounces,
            shadows: self.shadows,
            jitter: self.jitter,
            filter: self.filter,
            depth_range,
            normals,
        })
    }
}

impl RunFlags {
    fn install<T>(&self, work: impl FnOnce() -> Result<T, goldray::Error> + Send) -> Result<T, String>
    where
        T: Send,
    {
        let mut builder = rayon::ThreadPoolBuilder::new();
        if let Some(threads) = self.threads {
            builder = builder.num_threads(threads as usize);
        }
        let pool = builder
            .build()
            .map_err(|e| format!("cannot start worker threads: {e}"))?;
        pool.install(work).map_err(|e| e.to_string())
    }

    fn report(&self, rendered: &Rendered) -> Result<(), String> {
        if !self.quiet {
            for path in &rendered.written {
                eprintln!("wrote {}", path.display());
            }
        }
        if self.stats {
            eprint!("{}", rendered.stats);
        }
        match &self.stats_json {
            Some(path) => rendered.stats.write_json(path).map_err(|e| e.to_string()),
            None => Ok(()),
        }
    }
}
