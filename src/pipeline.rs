//! The whole path from a case file to files on disk, as the `render` command runs it.

use std::path::{Path, PathBuf};

use crate::assignment_outputs::AssignmentOutputs;
use crate::case::{self, AssignmentOptions, Case, LoadOptions, case_to_toml, load_assignment_scene};
use crate::error::Error;
use crate::film::{Film, OutputOptions, write_outputs};
use crate::render::{Progress, RenderOptions, render};
use crate::scene::build_scene;

/// Renders a loaded case to a film, showing progress when asked.
pub fn render_case(case: &Case, show_progress: bool) -> Result<Film, Error> {
    let scene = build_scene(case)?;
    let settings = &case.render;
    let options = RenderOptions {
        width: settings.width,
        height: settings.height,
        bounces: settings.bounces,
        shadows: settings.shadows,
        samples: settings.samples,
        seed: settings.seed,
        filter: settings.filter,
    };
    let progress = Progress::new(u64::from(settings.height), &case.name, show_progress);
    Ok(render(&scene, &options, &progress))
}

/// The files a case's render writes, as its options ask.
pub fn output_options(case: &Case) -> OutputOptions {
    OutputOptions {
        tonemap: case.render.tonemap,
        depth_range: case.render.depth_range.map(|(min, max)| (min as f32, max as f32)),
        normals: case.render.normals,
    }
}

/// Loads, renders and writes `DIR/NAME.exr` and its PNGs. Nothing is written unless every
/// stage succeeds, and existing outputs are replaced atomically.
pub fn render_case_file(
    path: &Path,
    out_dir: &Path,
    load: &LoadOptions,
    show_progress: bool,
) -> Result<Vec<PathBuf>, Error> {
    let case = case::load(path, load)?;
    let film = render_case(&case, show_progress)?;
    Ok(write_outputs(out_dir, &case.name, &film, &output_options(&case))?)
}

/// `goldray mit6837`: renders a course scene file as the course binary would and writes the
/// files its flags name.
pub fn render_assignment(
    scene: &Path,
    options: &AssignmentOptions,
    outputs: &AssignmentOutputs,
    show_progress: bool,
) -> Result<Vec<PathBuf>, Error> {
    let case = load_assignment_scene(scene, options)?;
    let film = render_case(&case, show_progress)?;
    Ok(outputs.write(&film)?)
}

/// `goldray import`: the TOML case equivalent to a course scene file, with asset paths
/// relative to where the TOML will live.
pub fn import_assignment(scene: &Path, options: &AssignmentOptions, toml_path: &Path) -> Result<String, Error> {
    let case = load_assignment_scene(scene, options)?;
    Ok(case_to_toml(&case, toml_path))
}
