use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use goldray::case::LoadOptions;
use goldray::pipeline::render_case_file;

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
        /// Worker threads (default: one per core). The output is identical for any count.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Allow images larger than 16384 pixels on a side.
        #[arg(long)]
        force: bool,
    },
    /// Compare two EXR or PNG images within a tolerance. Exit code: 0 pass, 1 warn (some pixels
    /// over --pixel, every limit kept), 2 fail, 3 size or channel mismatch, 4 unreadable file.
    Diff(goldray::compare::DiffArgs),
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Render { case, out, threads, quiet, force } => {
            let pool = thread_pool(threads)?;
            let load = LoadOptions { allow_huge_images: force };
            let written = pool.install(|| render_case_file(&case, &out, &load, !quiet)).map_err(|e| e.to_string())?;
            if !quiet {
                for path in written {
                    eprintln!("wrote {}", path.display());
                }
            }
            Ok(())
        }
        Command::Diff(args) => std::process::exit(i32::from(goldray::compare::run_diff(&args))),
    }
}

fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, String> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = threads {
        if threads == 0 {
            return Err("--threads must be at least 1".to_string());
        }
        builder = builder.num_threads(threads);
    }
    builder.build().map_err(|e| format!("cannot start worker threads: {e}"))
}
