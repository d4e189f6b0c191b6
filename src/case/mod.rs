//! Case files: the TOML schema, loading with located errors, and validation.
//!
//! A case is validated completely here, once, so that everything downstream can take its numbers
//! at face value; and every rejection names the file, line and column, what was found and what
//! would be valid, because a case file is edited by hand.

mod assignment;
mod error;
mod export;
mod objects;
mod sections;
mod spec;
mod value;

#[cfg(test)]
mod tests;

use std::path::Path;

pub use crate::located_toml::SourceLocation;
pub use assignment::{
    AssignmentOptions, load_assignment_scene, load_assignment_scene_keeping_source, parse_assignment_scene,
};
pub use error::CaseError;
pub use export::{case_to_toml, case_to_toml_anywhere};
pub use sections::MAX_BOUNCES;
pub use spec::{
    BackgroundSpec, CameraSpec, Case, LightSpec, MaterialSpec, ObjectSpec, RenderSettings, ShapeSpec, TransformOp,
    composite_matrix,
};

use crate::located_toml::{self, Doc, ReadError, Table};

#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Lifts the [`crate::image_size::MAX_IMAGE_SIZE`] guard (the CLI's `--force`).
    pub allow_huge_images: bool,
}

const TOP_LEVEL_KEYS: &[&str] = &[
    "description",
    "render",
    "tolerance",
    "camera",
    "background",
    "light",
    "materials",
    "object",
];

pub fn load(path: &Path, options: &LoadOptions) -> Result<Case, CaseError> {
    load_keeping_source(path, options).map(|loaded| loaded.case)
}

/// A case and its file's bytes as they were read and parsed, so that a render's provenance
/// hashes the very text it rendered, read once.
pub struct LoadedCase {
    pub case: Case,
    pub source: Vec<u8>,
}

/// [`load`], keeping the file's bytes.
pub fn load_keeping_source(path: &Path, options: &LoadOptions) -> Result<LoadedCase, CaseError> {
    let source = ReadError::read_text(path, "case file")?;
    let case = parse(&source, path, options)?;
    Ok(LoadedCase {
        case,
        source: source.into_bytes(),
    })
}

/// `path` is not read: it names the case in messages and anchors its relative asset paths.
pub fn parse(source: &str, path: &Path, options: &LoadOptions) -> Result<Case, CaseError> {
    let root = located_toml::parse(source, path)?;
    let doc = Doc {
        file: path,
        text: source,
        dir: path.parent().unwrap_or(Path::new("")),
    };
    let top = Table::new(&doc, "the case file".to_owned(), root.span(), root.get_ref());
    top.check_keys(TOP_LEVEL_KEYS)?;
    let materials = sections::materials(top.get("materials"))?;
    Ok(Case {
        name: case_name(path),
        path: path.to_path_buf(),
        description: top.read("description", None, |f| f.string().map(|s| Some(s.to_owned())))?,
        render: sections::render(&doc, top.get("render"), options)?,
        tolerance: sections::tolerance(&doc, top.get("tolerance"))?,
        camera: sections::camera(&doc, top.get("camera"))?,
        background: sections::background(&doc, top.get("background"))?,
        lights: sections::lights(top.get("light"))?,
        objects: top.read("object", Vec::new(), |f| objects::objects(f, &materials))?,
        materials,
    })
}

/// A case is named after its file's stem: `cases/spheres.toml` renders `spheres.exr`.
pub fn case_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}
