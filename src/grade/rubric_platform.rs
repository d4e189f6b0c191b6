//! What a rubric says about where it is used: `[program]`, the student's program that `goldray
//! autograde` and `goldray check --program` build and run before grading (so a course that
//! collects source code is graded end to end), and `[gradescope]`, who sees which result on
//! Gradescope and when.
//!
//! ```toml
//! [program]
//! build = "g++ -O2 -o raytracer *.cpp"
//! command = "raytracer"            # or ["python3", "rt.py"]
//!
//! [gradescope]
//! visibility = "after_due_date"    # the whole result
//! images = { "a07.png" = "hidden" } # single images
//! ```

use super::error::RubricError;
use crate::located_toml::{Field, LocatedError, Table};
use crate::named_enum::named_enum;

named_enum! {
    /// When a student sees a Gradescope result (Gradescope's own words).
    pub enum Visibility: "visibility" {
        Visible = "visible",
        AfterDueDate = "after_due_date",
        AfterPublished = "after_published",
        Hidden = "hidden",
    }
}

/// `[program]`: the student's program, found in their submission (or in its built copy).
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramSection {
    /// The program and its own arguments; the course's arguments follow them.
    pub command: Vec<String>,
    /// Run with `sh -c` in a copy of the submission first.
    pub build: Option<String>,
}

/// `[gradescope]`: visibility of the whole result and of single images.
#[derive(Clone, Debug, PartialEq)]
pub struct GradescopeSettings {
    pub visibility: Visibility,
    /// Images whose result has its own visibility, by file name.
    pub images: Vec<(String, Visibility)>,
}

impl Default for GradescopeSettings {
    fn default() -> GradescopeSettings {
        GradescopeSettings {
            visibility: Visibility::Visible,
            images: Vec::new(),
        }
    }
}

impl GradescopeSettings {
    /// The visibility of `file`'s result: its own, else the whole result's.
    pub fn visibility_of(&self, file: &str) -> Visibility {
        self.images
            .iter()
            .find(|(name, _)| name == file)
            .map_or(self.visibility, |(_, visibility)| *visibility)
    }
}

const PROGRAM_KEYS: &[&str] = &["command", "build"];
const GRADESCOPE_KEYS: &[&str] = &["visibility", "images"];

/// `command = "raytracer"` (split at spaces) or `["python3", "rt.py"]`; `build = "make"`.
pub fn program_section(table: &Table) -> Result<ProgramSection, RubricError> {
    table.check_keys(PROGRAM_KEYS)?;
    let command = table.require("command")?;
    let words = match command.string() {
        Ok(text) => text.split_whitespace().map(str::to_owned).collect(),
        Err(_) => command
            .array("a command line: a string, or an array of strings")?
            .iter()
            .map(|word| word.string().map(str::to_owned))
            .collect::<Result<Vec<String>, LocatedError>>()?,
    };
    if words.is_empty() {
        return Err(command.invalid("must name the program: e.g. \"raytracer\"").into());
    }
    let build = table.read("build", None, |f: &Field| {
        let text = f.string()?;
        if text.trim().is_empty() {
            return Err(f.invalid("must be a command, e.g. \"make\""));
        }
        Ok(Some(text.to_owned()))
    })?;
    Ok(ProgramSection { command: words, build })
}

/// `visibility = "…"` and `images = { "a01.png" = "…" }`, each image one of the rubric's
/// (`files`).
pub fn gradescope_section(table: &Table, files: &[&str]) -> Result<GradescopeSettings, RubricError> {
    table.check_keys(GRADESCOPE_KEYS)?;
    let visibility = table.read("visibility", Visibility::Visible, |f: &Field| f.variant())?;
    let mut images = Vec::new();
    if let Some(field) = table.get("images") {
        let per_image = field.table("[gradescope] images".to_owned())?;
        per_image.check_keys(files)?;
        for entry in per_image.fields() {
            images.push((entry.name.clone(), entry.variant()?));
        }
    }
    Ok(GradescopeSettings { visibility, images })
}
