//! The course's own scene format (MIT 6.837 assignment 4), read into a `Case`.
//!
//! Students' scenes are graded against the course's reference renderer, so this accepts
//! everything that renderer's parser accepts, with its quirks (a global current material, the
//! ambient light forced to white without lights, `Matrix4f` read by columns), and rejects the
//! rest with the same `file:line:column` messages as the TOML loader. Values that both formats can
//! express are validated by the same rules, so an imported case always exports to a TOML file
//! that loads.

mod blocks;
mod lexer;
mod objects;

use std::path::Path;

use lexer::{Lexer, Result, Token, Vec3, comment_hint, quote};

use super::error::{CaseError, SourceLocation, suggest};
use super::sections::MAX_BOUNCES;
use super::spec::{BackgroundSpec, Case, MaterialSpec};
use super::value::has_usable_length;
use super::{LoadedCase, RenderSettings};
use crate::film::Tonemap;
use crate::located_toml::ReadError;
use crate::options::{Filter, Precision, Profile, Trace};

/// The course binary's command-line flags that shape a render (`-size`, `-bounces`, `-shadows`,
/// `-jitter`, `-filter`, `-depth`, `-normals`).
#[derive(Clone, Debug, PartialEq)]
pub struct AssignmentOptions {
    pub width: u32,
    pub height: u32,
    pub bounces: u32,
    pub shadows: bool,
    /// 16 jittered samples per pixel.
    pub jitter: bool,
    /// Render at 3× and down-filter with the [1 2 1] kernel.
    pub filter: bool,
    pub depth_range: Option<(f64, f64)>,
    pub normals: bool,
}

/// The course binary's defaults, so that leaving a flag out means what it means there.
impl Default for AssignmentOptions {
    fn default() -> Self {
        AssignmentOptions {
            width: 100,
            height: 100,
            bounces: 0,
            shadows: false,
            jitter: false,
            filter: false,
            depth_range: None,
            normals: false,
        }
    }
}

const BLOCKS: &[&str] = &["PerspectiveCamera", "Background", "Lights", "Materials", "Group"];

/// The course sets this when the latest `numLights` is 0 (or no Lights block was read), so that
/// unlit scenes show their colours.
const AMBIENT_WITHOUT_LIGHTS: [f64; 3] = [1.0; 3];

pub fn load_assignment_scene(path: &Path, options: &AssignmentOptions) -> Result<Case> {
    load_assignment_scene_keeping_source(path, options).map(|loaded| loaded.case)
}

/// [`load_assignment_scene`], keeping the file's bytes (see [`LoadedCase`]).
pub fn load_assignment_scene_keeping_source(path: &Path, options: &AssignmentOptions) -> Result<LoadedCase> {
    let bytes = ReadError::read(path, "case file")?;
    let source = String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let text = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
        CaseError::Invalid {
            location: SourceLocation::from_offset(path, text, valid),
            message: format!(
                "byte 0x{:02X} is not UTF-8: goldray reads scene files as UTF-8 text (the course's \
                 parser takes any bytes, which matters only in file names); save the scene as UTF-8",
                bytes[valid]
            ),
        }
    })?;
    let case = parse_assignment_scene(&source, path, options)?;
    Ok(LoadedCase {
        case,
        source: source.into_bytes(),
    })
}

/// `path` is not read: it names the scene in messages and anchors its relative asset paths.
pub fn parse_assignment_scene(source: &str, path: &Path, options: &AssignmentOptions) -> Result<Case> {
    let render = render_settings(path, options)?;
    if source.starts_with('\u{feff}') {
        return Err(CaseError::Invalid {
            location: SourceLocation::from_offset(path, source, 0),
            message: "the file starts with a byte-order mark, which the course's parser reads as part \
                      of the first word (and stops: \"Unknown token\"); save the scene without it"
                .to_owned(),
        });
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut parser = Parser {
        lex: Lexer::new(path, source),
        dir,
        materials: Vec::new(),
        material_count: 0,
        current_material: None,
        depth: 0,
    };
    let mut camera = None;
    // The course's defaults: grey background, no ambient light.
    let mut background = BackgroundSpec {
        color: [0.5; 3],
        ambient: [0.0; 3],
        cube_map: None,
    };
    let mut lights = Vec::new();
    // `numLights` of the latest Lights block; the course starts from 0.
    let mut light_count = 0;
    let mut objects = None;
    // As in the course, a repeated PerspectiveCamera or Group replaces the earlier one, a
    // Background updates the fields it names, and Lights and Materials blocks add up.
    while let Some(token) = parser.lex.word() {
        match token.text {
            "PerspectiveCamera" => camera = Some(parser.camera()?),
            "Background" => parser.background(&mut background)?,
            "Lights" => {
                let (block, count) = parser.lights()?;
                lights.extend(block);
                light_count = count;
            }
            "Materials" => parser.materials()?,
            "Group" => objects = Some(parser.group()?),
            _ => return Err(parser.unknown(token, "block", BLOCKS, "blocks")),
        }
    }
    let missing = |message: &str| CaseError::Missing {
        file: path.to_path_buf(),
        message: message.to_owned(),
    };
    let camera = camera
        .ok_or_else(|| missing("the scene has no PerspectiveCamera { center … direction … up … angle … } block"))?;
    let objects = objects
        .ok_or_else(|| missing("the scene has no top-level Group { numObjects N … } block, so nothing to render"))?;
    // The course tests the latest count, not the lights it holds: `numLights 0` after a block
    // of lights still makes the ambient light white, and every light still shines.
    if light_count == 0 {
        background.ambient = AMBIENT_WITHOUT_LIGHTS;
    }
    // The TOML schema forbids a colour beside a cube map, which replaces it; keeping the unused
    // colour would make the imported case impossible to write back.
    if background.cube_map.is_some() {
        background.color = [0.0; 3];
    }
    Ok(Case {
        name: super::case_name(path),
        path: path.to_path_buf(),
        description: None,
        render,
        tolerance: crate::compare::Tolerance::DEFAULT,
        camera,
        background,
        lights,
        materials: parser.materials,
        objects,
    })
}

/// Whether `v` survives normalisation both as written and as the course's `float`s, in which
/// a length like 1e-30 squares to zero and normalising gives NaN.
fn usable_in_single_precision(v: [f64; 3]) -> bool {
    let [x, y, z] = v.map(|c| c as f32);
    let length = (x * x + y * y + z * z).sqrt();
    has_usable_length(v) && length > 0.0 && length.is_finite() && (1.0 / length).is_finite()
}

/// The options come from the command line, not the file, so their errors have no line.
fn render_settings(path: &Path, o: &AssignmentOptions) -> Result<RenderSettings> {
    let invalid = |message: String| CaseError::Missing {
        file: path.to_path_buf(),
        message,
    };
    if o.width == 0 || o.height == 0 {
        let (w, h) = (o.width, o.height);
        return Err(invalid(format!("-size {w} {h}: the image needs at least one pixel")));
    }
    if i64::from(o.bounces) > MAX_BOUNCES {
        let n = o.bounces;
        return Err(invalid(format!("-bounces {n}: at most {MAX_BOUNCES} are allowed")));
    }
    if let Some((min, max)) = o.depth_range
        && !(min.is_finite() && max.is_finite() && min < max)
    {
        return Err(invalid(format!("-depth {min} {max}: needs finite min < max")));
    }
    Ok(RenderSettings {
        trace: Trace {
            width: o.width,
            height: o.height,
            bounces: o.bounces,
            shadows: o.shadows,
            samples: if o.jitter { 16 } else { 1 },
            seed: 0,
            filter: if o.filter { Filter::Gaussian } else { Filter::None },
        },
        depth_range: o.depth_range,
        normals: o.normals,
        tonemap: Tonemap::Clamp,
        profile: Profile::Mit6837,
        precision: Precision::F32,
    })
}

struct Parser<'a> {
    lex: Lexer<'a>,
    dir: &'a Path,
    /// Every material of every Materials block, named `material0`, `material1`, … in order.
    materials: Vec<MaterialSpec>,
    /// The latest Materials block's count: `MaterialIndex k` must be below it (and means the
    /// k-th of `materials`, whichever block defined it).
    material_count: usize,
    /// The course keeps one current material for the whole file and ignores group nesting:
    /// `MaterialIndex` inside a nested group still applies after the group closes.
    current_material: Option<usize>,
    /// How many Group and Transform blocks enclose the cursor.
    depth: usize,
}

impl<'a> Parser<'a> {
    /// Non-negative, as the TOML loader requires of every colour.
    fn color(&mut self, label: &str) -> Result<[f64; 3]> {
        let v = self.lex.vec3(&format!("3 numbers after `{label}`"))?;
        match v.value.iter().position(|c| *c < 0.0) {
            Some(i) => {
                let rule = "must be ≥ 0 (colours are non-negative)";
                Err(self.invalid(v.tokens[i], &format!("`{label}`"), rule))
            }
            None => Ok(v.value),
        }
    }

    /// A vector that will be normalised downstream.
    fn direction(&mut self, label: &str) -> Result<Vec3<'a>> {
        let v = self.lex.vec3(&format!("3 numbers after `{label}`"))?;
        if usable_in_single_precision(v.value) {
            Ok(v)
        } else {
            let rule = "must have a nonzero, finite length";
            Err(self.invalid_vec(&v, &format!("`{label}`"), rule))
        }
    }

    /// "SUBJECT RULE, found `token`": a value that reads fine but breaks a rule.
    fn invalid(&self, token: Token, subject: &str, rule: &str) -> CaseError {
        let found = quote(token.text);
        self.lex
            .error_at(token.start, format!("{subject} {rule}, found {found}"))
    }

    fn invalid_vec(&self, v: &Vec3, subject: &str, rule: &str) -> CaseError {
        let written = self.lex.span_text(v.tokens[0], v.tokens[2]);
        let found = quote(&written.split_whitespace().collect::<Vec<_>>().join(" "));
        self.lex
            .error_at(v.tokens[0].start, format!("{subject} {rule}, found {found}"))
    }

    /// "unknown WHAT `word`", with the nearest of `valid` suggested and all of them listed as
    /// `noun`.
    fn unknown(&self, token: Token, what: &str, valid: &[&str], noun: &str) -> CaseError {
        let tail = suggest(token.text, valid, noun);
        let found = quote(token.text);
        let hint = comment_hint(token.text);
        self.lex
            .error_at(token.start, format!("unknown {what} {found}{tail}{hint}"))
    }

    /// A block closed before the count it announced; pointed at the closing brace.
    fn too_few(&self, brace: Token, label: &str, count: usize, given: usize, noun: &str) -> CaseError {
        let plural = |n: usize| {
            if n == 1 { noun.to_owned() } else { format!("{noun}s") }
        };
        self.lex.error_at(
            brace.start,
            format!(
                "`{label} {count}` but the block closes after {given} {}: add the missing {} or \
                 change the count",
                plural(given),
                plural(count.saturating_sub(given)),
            ),
        )
    }
}
