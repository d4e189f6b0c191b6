//! `goldray mit6837`: the course binary's command line, flag for flag.

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::assignment_outputs::AssignmentOutputs;
use goldray::case::AssignmentOptions;
use goldray::image_size::SizeLimit;
use goldray::pipeline::render_assignment;

use super::Failure;
use super::common::{check_writable_file, parse_depth_range, size_from_values};
use super::render::RunFlags;

/// The usage line as the course spells it.
pub const USAGE: &str = "goldray mit6837 -input scene.txt -output out.png [-normals n.png] [-size w h] \
                         [-depth min max d.png] [-bounces n] [-shadows] [-jitter] [-filter] [--exr out.exr] \
                         [--threads N] [--quiet] [--force] [--stats] [--stats-json FILE] [--record-run]";

/// The flags the course binary itself takes, which help shows with one dash, as the course does.
const COURSE_FLAGS: [&str; 9] = [
    "input", "output", "normals", "depth", "size", "bounces", "shadows", "jitter", "filter",
];

/// clap's help for `mit6837` with the course's flags spelled as the course spells them
/// (`-input`, not `--input`); goldray's own additions keep their two dashes.
pub fn course_style_help(clap_help: &str) -> String {
    clap_help
        .lines()
        .map(|line| {
            let trimmed = line.trim_start();
            let indent = line.len() - trimmed.len();
            match COURSE_FLAGS.iter().find(|flag| {
                trimmed
                    .strip_prefix("--")
                    .and_then(|rest| rest.strip_prefix(**flag))
                    .is_some_and(|rest| rest.is_empty() || rest.starts_with(' '))
            }) {
                // One dash fewer, one space more: the columns stay aligned.
                Some(_) => format!("{} {}", " ".repeat(indent), &trimmed[1..]),
                None => line.to_owned(),
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[derive(clap::Args)]
pub struct Mit6837Args {
    /// The course scene file.
    #[arg(long, value_name = "scene.txt")]
    input: PathBuf,
    /// Colour PNG (trunc(c·255), no gamma, like the course binary).
    #[arg(long, value_name = "out.png")]
    output: Option<PathBuf>,
    /// Normals PNG, (n+1)/2.
    #[arg(long, value_name = "n.png")]
    normals: Option<PathBuf>,
    /// Depth PNG: distances from min (black) to max (white).
    #[arg(long, num_args = 3, value_names = ["min", "max", "d.png"], allow_negative_numbers = true)]
    depth: Option<Vec<String>>,
    /// Also write goldray's linear EXR (colour, depth, normals) here.
    #[arg(long, value_name = "out.exr")]
    exr: Option<PathBuf>,
    #[command(flatten)]
    course: CourseFlags,
    #[command(flatten)]
    run: RunFlags,
}

/// The course binary's rendering flags, shared by `mit6837` and `import` so that an imported
/// case renders exactly what the same course command would.
#[derive(clap::Args)]
pub struct CourseFlags {
    /// Image width and height (also WxH) [default: 100 100].
    #[arg(long, num_args = 1..=2, value_names = ["w", "h"], allow_negative_numbers = true)]
    size: Option<Vec<String>>,
    /// Mirror recursion depth.
    #[arg(long, value_name = "n", default_value_t = 0)]
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

impl CourseFlags {
    /// The assignment options these flags ask for; a size outside the size rule is a usage error.
    pub fn options(
        &self,
        depth_range: Option<(f64, f64)>,
        normals: bool,
        limit: SizeLimit,
    ) -> Result<AssignmentOptions, Failure> {
        let (width, height) = match &self.size {
            Some(values) => size_from_values(values, limit).map_err(Failure::Usage)?,
            None => (100, 100),
        };
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

pub fn run(args: Mit6837Args) -> Result<ExitCode, Failure> {
    let Mit6837Args {
        input,
        output,
        normals,
        depth,
        exr,
        course,
        run,
    } = args;
    let depth = depth
        .map(|values| parse_depth_range(&values[0], &values[1]).map(|(min, max)| (min, max, PathBuf::from(&values[2]))))
        .transpose()
        .map_err(Failure::Usage)?;
    let outputs = AssignmentOutputs {
        color: output,
        normals,
        depth: depth
            .as_ref()
            .map(|(min, max, path)| (*min as f32, *max as f32, path.clone())),
        exr,
    };
    let paths: Vec<&PathBuf> = [&outputs.color, &outputs.normals, &outputs.exr]
        .into_iter()
        .flatten()
        .chain(outputs.depth.as_ref().map(|(_, _, path)| path))
        .collect();
    if paths.is_empty() {
        return Err(Failure::Usage(
            "nothing to write: give -output, -normals, -depth or --exr".to_owned(),
        ));
    }
    let limit = if run.force {
        SizeLimit::Lifted
    } else {
        SizeLimit::Forceable
    };
    let options = course.options(depth.map(|(min, max, _)| (min, max)), outputs.normals.is_some(), limit)?;
    for path in paths {
        check_writable_file(path).map_err(Failure::Run)?;
    }
    let rendered = run.render(|reporter| render_assignment(&input, &options, &outputs, run.record(), reporter))?;
    run.report(&rendered)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn help_spells_the_course_flags_with_one_dash_and_keeps_the_columns() {
        let help = "Options:\n      --input <scene.txt>  The scene\n      --exr <out.exr>      EXR\n      --shadows            Shadows\n      --size <w> [h]       Size\n";
        assert_eq!(
            course_style_help(help),
            "Options:\n       -input <scene.txt>  The scene\n      --exr <out.exr>      EXR\n       -shadows            Shadows\n       -size <w> [h]       Size\n"
        );
    }
}
