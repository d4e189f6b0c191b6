//! The course's command lines for a rubric: one per render of a course scene, with exactly the
//! flags and output names the course binary takes.

use std::path::{Component, Path, PathBuf};

use super::error::RunError;
use crate::grade::{Output, RenderOrigin, Rubric};
use crate::sandbox::Skipped;

/// The folder the scene and its assets are laid out in, inside a command's working folder, as
/// the course's starter folder has it (`-input data/scene01_plane.txt`).
pub const DATA: &str = "data";

/// One command of the course's binary.
#[derive(Clone, Debug, PartialEq)]
pub struct CourseCommand {
    /// The render's name (`scene01`; `scene01-2` for a second command of one render).
    pub name: String,
    /// The scene file, and each asset with its path relative to the scene's folder.
    pub scene: PathBuf,
    pub assets: Vec<(PathBuf, PathBuf)>,
    /// The course's arguments: `-input data/scene.txt -size W H … -output a01.png …`.
    pub args: Vec<String>,
    /// The files it is to write, by the rubric's names.
    pub outputs: Vec<String>,
}

/// The commands that make the rubric's images, in rubric order, and the renders that no
/// student program can make.
pub fn plan(rubric: &Rubric) -> Result<(Vec<CourseCommand>, Vec<Skipped>), RunError> {
    let mut commands = Vec::new();
    let mut skipped = Vec::new();
    for (index, render) in rubric.renders.iter().enumerate() {
        let images: Vec<_> = rubric.images.iter().filter(|i| i.render_index == index).collect();
        let (scene, flags) = match &render.origin {
            _ if images.is_empty() => {
                skipped.push(Skipped {
                    name: render.name.clone(),
                    reason: "no image of the rubric is taken from it".to_owned(),
                });
                continue;
            }
            RenderOrigin::Case { path } => {
                skipped.push(Skipped {
                    name: render.name.clone(),
                    reason: format!(
                        "it is a TOML case ({}), which has no course command line: a student's program \
                         takes `-input scene.txt`, so only `scene = \"…\"` renders can be run",
                        path.display()
                    ),
                });
                continue;
            }
            RenderOrigin::Course { scene, flags } => (scene, flags),
        };
        let scene_dir = scene.parent().unwrap_or(Path::new(""));
        let mut assets = Vec::new();
        for asset in render.case.assets() {
            let relative = asset
                .strip_prefix(scene_dir)
                .ok()
                .filter(|r| r.components().all(|c| matches!(c, Component::Normal(_))))
                .ok_or_else(|| RunError::AssetOutside {
                    render: render.name.clone(),
                    asset: asset.clone(),
                })?;
            assets.push((asset.clone(), relative.to_path_buf()));
        }
        let scene_name = scene
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let mut base = vec![
            "-input".to_owned(),
            format!("{DATA}/{scene_name}"),
            "-size".to_owned(),
            flags.width.to_string(),
            flags.height.to_string(),
        ];
        if flags.bounces > 0 {
            base.extend(["-bounces".to_owned(), flags.bounces.to_string()]);
        }
        for (on, flag) in [
            (flags.shadows, "-shadows"),
            (flags.jitter, "-jitter"),
            (flags.filter, "-filter"),
        ] {
            if on {
                base.push(flag.to_owned());
            }
        }
        // The course binary writes one picture of each kind: a render whose images ask for two
        // of a kind (two depth ranges) takes one command per round.
        let of_kind = |kind: fn(&Output) -> bool| -> Vec<_> { images.iter().filter(|i| kind(&i.output)).collect() };
        let colors = of_kind(|o| matches!(o, Output::Color));
        let normals = of_kind(|o| matches!(o, Output::Normals));
        let depths = of_kind(|o| matches!(o, Output::Depth { .. }));
        let rounds = colors.len().max(normals.len()).max(depths.len());
        for round in 0..rounds {
            let mut args = base.clone();
            let mut outputs = Vec::new();
            if let Some(image) = colors.get(round) {
                args.extend(["-output".to_owned(), image.file.clone()]);
                outputs.push(image.file.clone());
            }
            if let Some(image) = normals.get(round) {
                args.extend(["-normals".to_owned(), image.file.clone()]);
                outputs.push(image.file.clone());
            }
            if let Some(image) = depths.get(round)
                && let Output::Depth { min, max } = image.output
            {
                args.extend([
                    "-depth".to_owned(),
                    min.to_string(),
                    max.to_string(),
                    image.file.clone(),
                ]);
                outputs.push(image.file.clone());
            }
            let name = match round {
                0 => render.name.clone(),
                n => format!("{}-{}", render.name, n + 1),
            };
            commands.push(CourseCommand {
                name,
                scene: scene.clone(),
                assets: assets.clone(),
                args,
                outputs,
            });
        }
    }
    Ok((commands, skipped))
}
