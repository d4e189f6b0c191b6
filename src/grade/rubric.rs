//! The rubric: which files a submission must hold, which golden image each one is compared with,
//! and how the comparison becomes points.
//!
//! It is read like a case file (the same located readers), so a typo in a rubric is reported as
//! `rubric.toml:line:column` with the nearest valid key, before anything renders.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::error::RubricError;
use super::integrity::{Integrity, integrity};
use super::rubric_platform::{GradescopeSettings, ProgramSection, gradescope_section, program_section};
use super::run_limits::run_limits;
use crate::case::{self, AssignmentOptions, Case, LoadOptions, MAX_BOUNCES, load_assignment_scene};
use crate::fault::Fault;
use crate::film::Picture;
use crate::image_size::{MAX_IMAGE_SIZE, SizeLimit, check_side};
use crate::located_toml::{self, Doc, Field, ReadError, SourceLocation, Table, suggest};
use crate::named_enum::NamedEnum;
use crate::named_enum::named_enum;
use crate::sandbox::LimitOverrides;

/// A whole rubric, every path resolved and every render source loaded.
#[derive(Clone, Debug)]
pub struct Rubric {
    /// As given on the command line, for messages.
    pub path: PathBuf,
    pub title: String,
    pub renders: Vec<RenderSource>,
    /// In file order, which is the column order of every report.
    pub images: Vec<ImageSpec>,
    /// What grading checks about where submitted files come from.
    pub integrity: Integrity,
    /// `[mistake."ID"] credit = c`: the share of an image's points granted when its diagnosis
    /// is that mistake (or a pair of credited mistakes: the product), in file order.
    pub mistake_credit: Vec<(Fault, f64)>,
    /// `[limits]`: what `goldray run` allows each command of a student's program.
    pub limits: LimitOverrides,
    /// `[program]`: the student's program to build and run before grading, if the course
    /// collects source code.
    pub program: Option<ProgramSection>,
    /// `[gradescope]`: who sees which result, and when.
    pub gradescope: GradescopeSettings,
    /// `[lms] assignment`: the assignment's column in Canvas's gradebook (`Assignment 4 (1234)`),
    /// which `grades-canvas.csv` fills.
    pub lms_assignment: Option<String>,
}

/// One `[render.NAME]`: a render that one or more images are taken from.
#[derive(Clone, Debug)]
pub struct RenderSource {
    pub name: String,
    /// The loaded case (a course scene is loaded with its flags applied).
    pub case: Case,
    /// Where the table starts, for errors found only when it renders.
    pub location: SourceLocation,
    /// What the render was made from, as the rubric gives it.
    pub origin: RenderOrigin,
}

/// Where a render comes from. Only a course scene has the course's command line, which
/// `goldray run` gives a student's program.
#[derive(Clone, Debug, PartialEq)]
pub enum RenderOrigin {
    /// `scene = "…"`: the course scene at this path, with the course binary's flags (`size`,
    /// `bounces`, `shadows`, `jitter`, `filter`; never depth or normals, which are the images').
    Course { scene: PathBuf, flags: AssignmentOptions },
    /// `case = "…"`: the TOML case at this path.
    Case { path: PathBuf },
}

/// Which picture of a render an image is, as the course binary writes it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Output {
    Color,
    Normals,
    /// Distances from `min` (black) to `max` (white); a miss is black.
    Depth {
        min: f64,
        max: f64,
    },
}

impl Output {
    /// The film's picture this image is, for drawing it (goldens, diagnosis, test students).
    pub fn picture(self) -> Picture {
        match self {
            Output::Color => Picture::Color,
            Output::Normals => Picture::Normals,
            Output::Depth { min, max } => Picture::Depth {
                min: min as f32,
                max: max as f32,
            },
        }
    }
}

named_enum! {
    /// What `output = "…"` may say.
    enum OutputKind: "output" {
        Color = "color",
        Normals = "normals",
        Depth = "depth",
    }
}

/// One `[image."FILE"]`: an expected file of every submission.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ImageSpec {
    pub file: String,
    pub render: String,
    /// Index into `Rubric::renders`.
    #[serde(skip)]
    pub render_index: usize,
    pub output: Output,
    pub points: f64,
    pub rule: Rule,
}

/// How a comparison becomes points: full points when both the failing-pixel fraction and the
/// FLIP mean are within the pass limits, `partial_credit × points` when within the partial limits,
/// nothing otherwise. A pixel fails when any channel differs by more than `threshold` 8-bit codes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rule {
    pub threshold: f64,
    pub pass_fraction: f64,
    pub partial_fraction: f64,
    pub pass_flip: Option<f64>,
    pub partial_flip: Option<f64>,
    pub partial_credit: f64,
    /// `statistical = true`: for a colour image of a sampled render, each pixel's threshold is
    /// widened by the golden's sampling noise (`compare::noise::png_allowance`), so that a
    /// student's jittered picture is not failed for being jittered differently.
    pub statistical: bool,
}

/// Lenient enough for an independent ray tracer's rounding and edge pixels, strict enough that a
/// missing feature (shadows, reflections) is a failure. FLIP limits are off unless asked for.
const DEFAULT_RULE: Rule = Rule {
    threshold: 8.0,
    pass_fraction: 0.01,
    partial_fraction: 0.1,
    pass_flip: None,
    partial_flip: None,
    partial_credit: 0.5,
    statistical: false,
};
const DEFAULT_POINTS: f64 = 1.0;

const TOP_KEYS: &[&str] = &[
    "title",
    "defaults",
    "render",
    "image",
    "integrity",
    "mistake",
    "limits",
    "program",
    "gradescope",
    "lms",
];
const LMS_KEYS: &[&str] = &["assignment"];
const RULE_KEYS: &[&str] = &[
    "threshold",
    "pass_fraction",
    "partial_fraction",
    "pass_flip",
    "partial_flip",
    "partial_credit",
    "statistical",
    "points",
];
const IMAGE_KEYS: &[&str] = &["render", "output", "depth"];
const RENDER_KEYS: &[&str] = &["case", "scene", "size", "bounces", "shadows", "jitter", "filter"];
/// Flags of the course binary: a TOML case sets these in its own `[render]`.
const SCENE_ONLY_KEYS: &[&str] = &["bounces", "shadows", "jitter", "filter"];

type Result<T> = std::result::Result<T, RubricError>;

pub fn load_rubric(path: &Path) -> Result<Rubric> {
    let source = ReadError::read_text(path, "the rubric")?;
    parse_rubric(&source, path)
}

/// `path` names the rubric in messages; its directory anchors the relative paths inside.
pub fn parse_rubric(source: &str, path: &Path) -> Result<Rubric> {
    let root = located_toml::parse(source, path)?;
    // Absolute, so that golden cache keys do not depend on the working directory.
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let dir = dir.canonicalize().unwrap_or(dir);
    let doc = Doc {
        file: path,
        text: source,
        dir: &dir,
    };
    let top = Table::new(&doc, "the rubric".to_owned(), root.span(), root.get_ref());
    top.check_keys(TOP_KEYS)?;

    let title = top.read("title", None, |f| f.string().map(|s| Some(s.to_owned())))?;
    let defaults = match top.get("defaults") {
        Some(field) => field.table("[defaults]".to_owned())?,
        None => Table::empty(&doc, "[defaults]"),
    };
    defaults.check_keys(RULE_KEYS)?;
    let base_rule = rule(&defaults, &DEFAULT_RULE)?;
    let base_points = points(&defaults, DEFAULT_POINTS)?;

    let mut renders = Vec::new();
    if let Some(field) = top.get("render") {
        for entry in field.table("[render]".to_owned())?.fields() {
            renders.push(render_source(&entry)?);
        }
    }
    let mut images = Vec::new();
    if let Some(field) = top.get("image") {
        for entry in field.table("[image]".to_owned())?.fields() {
            images.push(image_spec(&entry, &renders, &base_rule, base_points)?);
        }
    }
    let integrity = match top.get("integrity") {
        Some(field) => integrity(&field.table("[integrity]".to_owned())?)?,
        None => Integrity::default(),
    };
    let mistake_credit = match top.get("mistake") {
        Some(field) => mistake_credit(&field.table("[mistake]".to_owned())?)?,
        None => Vec::new(),
    };
    let limits = match top.get("limits") {
        Some(field) => run_limits(&field.table("[limits]".to_owned())?)?,
        None => LimitOverrides::default(),
    };
    let program = match top.get("program") {
        Some(field) => Some(program_section(&field.table("[program]".to_owned())?)?),
        None => None,
    };
    let gradescope = match top.get("gradescope") {
        Some(field) => {
            let files: Vec<&str> = images.iter().map(|i| i.file.as_str()).collect();
            gradescope_section(&field.table("[gradescope]".to_owned())?, &files)?
        }
        None => GradescopeSettings::default(),
    };
    let lms_assignment = match top.get("lms") {
        Some(field) => lms_assignment(&field.table("[lms]".to_owned())?)?,
        None => None,
    };
    if images.is_empty() {
        return Err(RubricError::Missing {
            file: path.to_path_buf(),
            message: "the rubric lists no images: add [image.\"FILE.png\"] tables".to_owned(),
        });
    }
    Ok(Rubric {
        path: path.to_path_buf(),
        title: title.unwrap_or_else(|| {
            path.file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
        }),
        renders,
        images,
        integrity,
        mistake_credit,
        limits,
        program,
        gradescope,
        lms_assignment,
    })
}

/// `[lms] assignment = "Assignment 4 (1234)"`: one line of text, as a CSV header cell.
fn lms_assignment(table: &Table) -> Result<Option<String>> {
    table.check_keys(LMS_KEYS)?;
    Ok(table.read("assignment", None, |f| match f.string()? {
        name if name.trim().is_empty() => Err(f.invalid("the assignment's name is empty")),
        name if name.contains(['\n', '\r']) => Err(f.invalid("the assignment's name must be one line")),
        name => Ok(Some(name.to_owned())),
    })?)
}

/// `[mistake."no-shadows"] credit = 0.5`, one table per catalogue id.
fn mistake_credit(table: &Table) -> Result<Vec<(Fault, f64)>> {
    let mut credits = Vec::new();
    for entry in table.fields() {
        let Some(fault) = Fault::from_name(&entry.name) else {
            let tail = suggest(&entry.name, crate::fault::ids(), "mistakes");
            return Err(entry
                .doc
                .error_at(
                    &entry.key_span,
                    format!("`{}` is not a mistake of the catalogue{tail}", entry.name),
                )
                .into());
        };
        let mistake = entry.table(format!("[mistake.\"{}\"]", entry.name))?;
        mistake.check_keys(&["credit"])?;
        let credit = mistake.require("credit")?;
        match credit.number()? {
            v if (0.0..=1.0).contains(&v) => credits.push((fault, v)),
            _ => return Err(credit.invalid("must be between 0 and 1").into()),
        }
    }
    Ok(credits)
}

fn render_source(entry: &Field) -> Result<RenderSource> {
    let name = entry.name.clone();
    let table = entry.table(format!("[render.{name}]"))?;
    table.check_keys(RENDER_KEYS)?;
    let doc = table.doc;
    let location = doc.location(entry.key_span.start);
    let size = table.read("size", None, |f| {
        let [w, h] = f.numbers::<2>("an array [width, height]")?;
        let side = |v: f64| v.fract() == 0.0 && check_side(v as i64, SizeLimit::Fixed).is_ok();
        if side(w) && side(h) {
            Ok(Some((w as u32, h as u32)))
        } else {
            Err(f.invalid(format!("must be two whole numbers from 1 to {MAX_IMAGE_SIZE}")))
        }
    })?;
    let (loaded, origin) = match (table.get("case"), table.get("scene")) {
        (Some(case_field), None) => {
            if let Some(stray) = SCENE_ONLY_KEYS.iter().find_map(|k| table.get(k)) {
                return Err(doc
                    .error_at(
                        &stray.key_span,
                        format!(
                            "`{}` is a course-scene flag; a TOML case sets it in its own [render]",
                            stray.name
                        ),
                    )
                    .into());
            }
            let path = doc.dir.join(case_field.string()?);
            let loaded = case::load(&path, &LoadOptions::default()).map(|mut case| {
                if let Some((width, height)) = size {
                    case.render.trace.width = width;
                    case.render.trace.height = height;
                }
                case
            });
            (loaded, RenderOrigin::Case { path })
        }
        (None, Some(scene_field)) => {
            let (width, height) = size.unwrap_or((100, 100));
            let flag = |key: &str| table.read(key, false, Field::boolean);
            let options = AssignmentOptions {
                width,
                height,
                bounces: table.read("bounces", 0, |f| f.integer_in(0..=MAX_BOUNCES, "must be 0 or more"))?,
                shadows: flag("shadows")?,
                jitter: flag("jitter")?,
                filter: flag("filter")?,
                ..AssignmentOptions::default()
            };
            let scene = doc.dir.join(scene_field.string()?);
            (
                load_assignment_scene(&scene, &options),
                RenderOrigin::Course { scene, flags: options },
            )
        }
        (Some(_), Some(scene_field)) => {
            return Err(doc
                .error_at(&scene_field.key_span, "give either `case` or `scene`, not both")
                .into());
        }
        (None, None) => {
            return Err(doc
                .error_at(
                    &table.span,
                    format!(
                        "[render.{name}] needs `case = \"FILE.toml\"` or `scene = \"FILE.txt\"` \
                         (a course scene)"
                    ),
                )
                .into());
        }
    };
    let case = loaded.map_err(|source| RubricError::Source {
        location: location.clone(),
        render: name.clone(),
        source: Box::new(source),
    })?;
    Ok(RenderSource {
        name,
        case,
        location,
        origin,
    })
}

fn image_spec(entry: &Field, renders: &[RenderSource], base: &Rule, base_points: f64) -> Result<ImageSpec> {
    let file = entry.name.clone();
    let doc = entry.doc;
    if !is_plain_png_name(&file) {
        let message = format!(
            "image `{file}` must be a PNG file name of letters, digits, `.`, `_` and `-` \
             (it is used in file names and links of the report)"
        );
        return Err(doc.error_at(&entry.key_span, message).into());
    }
    let table = entry.table(format!("[image.\"{file}\"]"))?;
    let allowed: Vec<&str> = IMAGE_KEYS.iter().chain(RULE_KEYS).copied().collect();
    table.check_keys(&allowed)?;
    let render_field = table.require("render")?;
    let render = render_field.string()?;
    let Some(render_index) = renders.iter().position(|r| r.name == render) else {
        let names: Vec<&str> = renders.iter().map(|r| r.name.as_str()).collect();
        let tail = suggest(render, &names, "renders");
        return Err(render_field
            .error(format!("no [render.{render}] in the rubric{tail}"))
            .into());
    };
    let kind = table.read("output", OutputKind::Color, Field::variant)?;
    let output = match (kind, table.get("depth")) {
        (OutputKind::Depth, Some(field)) => {
            let [min, max] = field.numbers::<2>("an array [min, max]")?;
            if min >= max {
                return Err(field.invalid("must have min below max").into());
            }
            Output::Depth { min, max }
        }
        (OutputKind::Depth, None) => match renders[render_index].case.render.depth_range {
            Some((min, max)) => Output::Depth { min, max },
            None => {
                let message = format!(
                    "a depth image needs `depth = [min, max]` (the course's -depth min max), \
                     and the case of render `{render}` sets no depth_range"
                );
                return Err(doc.error_at(&table.span, message).into());
            }
        },
        (_, Some(field)) => {
            return Err(doc
                .error_at(&field.key_span, "`depth` applies only to output = \"depth\"")
                .into());
        }
        (OutputKind::Color, None) => Output::Color,
        (OutputKind::Normals, None) => Output::Normals,
    };
    let mut rule = rule(&table, base)?;
    if rule.statistical {
        let samples = renders[render_index].case.render.trace.samples;
        let problem = if output != Output::Color {
            Some(
                "applies to colour images only: depth and normals come from one ray through each pixel's centre"
                    .to_owned(),
            )
        } else if samples <= 1 {
            Some(format!(
                "needs a render with several samples per pixel (`jitter = true`, or a case with `samples`); \
                 render `{render}` takes {samples}"
            ))
        } else {
            None
        };
        match (problem, table.get("statistical")) {
            // Set on this image: a mistake to point at.
            (Some(problem), Some(field)) => {
                let message = format!("`statistical = true` {problem}");
                return Err(doc.error_at(&field.key_span, message).into());
            }
            // Inherited from [defaults]: it applies to the images it can, the others keep the threshold.
            (Some(_), None) => rule.statistical = false,
            (None, _) => {}
        }
    }
    Ok(ImageSpec {
        file,
        render: render.to_owned(),
        render_index,
        output,
        points: points(&table, base_points)?,
        rule,
    })
}

/// `base` with whatever `table` overrides, checked as a whole: a partial limit looser than the
/// pass limit, or a FLIP limit for one grade only, would make the rule contradict itself.
fn rule(table: &Table, base: &Rule) -> Result<Rule> {
    let fraction = |f: &Field| match f.number()? {
        v if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(f.invalid("must be between 0 and 1")),
    };
    let rule = Rule {
        threshold: table.read("threshold", base.threshold, |f| match f.number()? {
            v if (0.0..=255.0).contains(&v) => Ok(v),
            _ => Err(f.invalid("must be between 0 and 255 (8-bit codes)")),
        })?,
        pass_fraction: table.read("pass_fraction", base.pass_fraction, fraction)?,
        partial_fraction: table.read("partial_fraction", base.partial_fraction, fraction)?,
        pass_flip: table.read("pass_flip", base.pass_flip, |f| fraction(f).map(Some))?,
        partial_flip: table.read("partial_flip", base.partial_flip, |f| fraction(f).map(Some))?,
        partial_credit: table.read("partial_credit", base.partial_credit, fraction)?,
        statistical: table.read("statistical", base.statistical, Field::boolean)?,
    };
    let what = &table.what;
    let problem = if rule.partial_fraction < rule.pass_fraction {
        Some(format!(
            "{what}: partial_fraction {} is below pass_fraction {}",
            rule.partial_fraction, rule.pass_fraction
        ))
    } else {
        match (rule.pass_flip, rule.partial_flip) {
            (Some(pass), Some(partial)) if partial < pass => {
                Some(format!("{what}: partial_flip {partial} is below pass_flip {pass}"))
            }
            (Some(_), None) | (None, Some(_)) => {
                Some(format!("{what}: give both pass_flip and partial_flip, or neither"))
            }
            _ => None,
        }
    };
    match problem {
        Some(message) => Err(table.doc.error_at(&table.span, message).into()),
        None => Ok(rule),
    }
}

fn points(table: &Table, default: f64) -> Result<f64> {
    Ok(table.read("points", default, Field::non_negative)?)
}

/// Letters, digits, `.`, `_`, `-`, ending in `.png`: safe as a file name on every system and in an
/// unescaped link, so the report never has to encode a rubric name.
fn is_plain_png_name(name: &str) -> bool {
    name.len() > 4
        && !name.starts_with('.')
        && name.to_ascii_lowercase().ends_with(".png")
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'))
}
