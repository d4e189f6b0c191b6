//! `goldray import scene.txt`: the TOML case equivalent to a course scene and its flags.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use goldray::atomic_write::{check_writable, write_file_atomic};
use goldray::image_size::SizeLimit;
use goldray::pipeline::import_assignment;

use super::Failure;
use super::common::parse_depth_range;
use super::mit6837::CourseFlags;

#[derive(clap::Args)]
pub struct ImportArgs {
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
}

pub fn run(args: ImportArgs) -> Result<ExitCode, Failure> {
    let ImportArgs {
        scene,
        output,
        force,
        depth,
        normals,
        course,
    } = args;
    let depth_range = depth
        .map(|values| parse_depth_range(&values[0], &values[1]))
        .transpose()
        .map_err(Failure::Usage)?;
    let options = course.options(depth_range, normals, SizeLimit::Lifted)?;
    if let Some(path) = &output {
        if path.exists() && !force {
            return Err(Failure::Run(format!(
                "{} exists; pass --force to replace it",
                path.display()
            )));
        }
        check_writable(path)?;
    }
    let text = import_assignment(&scene, &options, output.as_deref())?;
    match output {
        Some(path) => write_file_atomic(&path, text.as_bytes())?,
        None => std::io::stdout()
            .write_all(text.as_bytes())
            .map_err(|e| format!("cannot write to standard output: {e}"))?,
    }
    Ok(ExitCode::SUCCESS)
}
