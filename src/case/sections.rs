//! The scene-wide sections: `[render]`, `[tolerance]`, `[camera]`, `[background]`, `[[light]]`
//! and `[materials.NAME]`.

use std::path::Path;

use glam::DVec3;

use super::LoadOptions;
use super::error::CaseError;
use super::spec::{BackgroundSpec, CameraSpec, LightSpec, MaterialSpec, RenderSettings};
use super::value::SceneValues;
use crate::compare::Tolerance;
use crate::film::Tonemap;
use crate::image_size::{SizeLimit, check_side};
use crate::located_toml::{Doc, Field, Result, Table};
use crate::options::{Profile, Trace};

/// Deeper recursion cannot change an 8-bit image and only risks runaway render times.
pub const MAX_BOUNCES: i64 = 1024;
/// Faces of a cube-map directory, as the assignment names them.
const CUBE_FACES: [&str; 6] = ["left", "right", "up", "down", "front", "back"];

/// An optional `[name]` section as a table; an absent one reads as all defaults.
fn section<'a, 'i>(doc: &'a Doc<'a>, field: Option<Field<'a, 'i>>, what: &str) -> Result<Table<'a, 'i>> {
    field.map_or_else(|| Ok(Table::empty(doc, what)), |f| f.table(what.to_owned()))
}

pub(crate) fn render<'a>(
    doc: &'a Doc<'a>,
    field: Option<Field<'a, '_>>,
    options: &LoadOptions,
) -> Result<RenderSettings> {
    let t = section(doc, field, "[render]")?;
    t.check_keys(&[
        "size",
        "bounces",
        "shadows",
        "samples",
        "seed",
        "filter",
        "depth_range",
        "normals",
        "tonemap",
        "profile",
        "precision",
    ])?;
    let (width, height) = t.read("size", (200, 200), |f| size(f, options))?;
    let profile = t.read("profile", Profile::Native, Field::variant)?;
    // The assignment quantises with trunc(c·255) and no gamma; a mit6837 case that did not ask
    // for a tone map wants to match the reference images, not look nicer.
    let default_tonemap = match profile {
        Profile::Native => Tonemap::Srgb,
        Profile::Mit6837 => Tonemap::Clamp,
    };
    Ok(RenderSettings {
        trace: Trace {
            width,
            height,
            bounces: t.read("bounces", 0, |f| {
                f.integer_in(0..=MAX_BOUNCES, &format!("must be between 0 and {MAX_BOUNCES}"))
            })?,
            shadows: t.read("shadows", false, Field::boolean)?,
            samples: t.read("samples", 1, samples)?,
            seed: t.read("seed", 0, |f| f.integer_in(0..=i64::MAX, "must be ≥ 0"))?,
            filter: t.read("filter", Default::default(), Field::variant)?,
        },
        depth_range: t.read("depth_range", None, |f| {
            let [min, max] = f.numbers("an array of 2 numbers [min, max]")?;
            if min < max {
                Ok(Some((min, max)))
            } else {
                Err(f.invalid("must have min < max"))
            }
        })?,
        normals: t.read("normals", false, Field::boolean)?,
        tonemap: t.read("tonemap", default_tonemap, Field::variant)?,
        profile,
        precision: t.read("precision", Default::default(), Field::variant)?,
    })
}

fn size(f: &Field, options: &LoadOptions) -> Result<(u32, u32)> {
    let mut items = f.array("an array of 2 integers [width, height]")?;
    if items.len() != 2 {
        let n = items.len();
        return Err(f.invalid(format!("must be [width, height], but has {n} elements")));
    }
    items[0].name = "width".to_owned();
    items[1].name = "height".to_owned();
    let mut out = [0; 2];
    for (slot, item) in out.iter_mut().zip(&items) {
        let limit = if options.allow_huge_images {
            SizeLimit::Lifted
        } else {
            SizeLimit::Forceable
        };
        *slot = check_side(item.integer()?, limit).map_err(|error| item.invalid(error.to_string()))?;
    }
    Ok((out[0], out[1]))
}

/// Stratified jitter lays the samples on an n×n grid, so only squares can be honoured exactly.
fn samples(f: &Field) -> Result<u32> {
    const LARGEST_ROOT: i64 = u16::MAX as i64;
    let n = f.integer()?;
    if n < 1 {
        return Err(f.invalid("must be a positive perfect square (1, 4, 9, 16, …)"));
    }
    let root = n.isqrt();
    if root > LARGEST_ROOT {
        let most = LARGEST_ROOT * LARGEST_ROOT;
        return Err(f.invalid(format!("must be at most {most} ({LARGEST_ROOT}×{LARGEST_ROOT})")));
    }
    if root * root != n {
        let up = root + 1;
        return Err(f.invalid(format!(
            "must be a perfect square (an n×n grid); the nearest are {} ({root}×{root}) and {} \
             ({up}×{up})",
            root * root,
            up * up
        )));
    }
    u32::try_from(n).map_err(|_| f.invalid("must fit in 32 bits"))
}

pub(crate) fn tolerance<'a>(doc: &'a Doc<'a>, field: Option<Field<'a, '_>>) -> Result<Tolerance> {
    let t = section(doc, field, "[tolerance]")?;
    t.check_keys(&["pixel", "fail_fraction", "rmse", "max"])?;
    let default = Tolerance::DEFAULT;
    Ok(Tolerance {
        pixel: t.read("pixel", default.pixel, Field::non_negative)?,
        fail_fraction: t.read("fail_fraction", default.fail_fraction, |f| {
            let v = f.number()?;
            if (0.0..=1.0).contains(&v) {
                Ok(v)
            } else {
                Err(f.invalid("must be between 0 and 1"))
            }
        })?,
        rmse: t.read("rmse", default.rmse, Field::non_negative)?,
        max: t.read("max", default.max, |f| f.non_negative().map(Some))?,
    })
}

/// The one section a case cannot do without, hence the one that can be missing.
pub(crate) fn camera(doc: &Doc, field: Option<Field>) -> std::result::Result<CameraSpec, CaseError> {
    let Some(field) = field else {
        return Err(CaseError::Missing {
            file: doc.file.to_path_buf(),
            message: "missing the required [camera] table (center, direction, up, fov)".to_owned(),
        });
    };
    let t = field.table("[camera]".to_owned())?;
    t.check_keys(&["center", "direction", "up", "fov"])?;
    let center = t.require("center")?.vec3()?;
    let direction_field = t.require("direction")?;
    let direction = direction_field.direction()?;
    let up_field = t.require("up")?;
    let up = up_field.direction()?;
    if is_parallel(direction, up) {
        let d = direction_field.excerpt();
        return Err(up_field
            .invalid(format!("must not be parallel to direction {d}"))
            .into());
    }
    let fov_field = t.require("fov")?;
    let fov = fov_field.number()?;
    if fov <= 0.0 || fov >= 180.0 {
        return Err(fov_field.invalid("must be strictly between 0 and 180 degrees").into());
    }
    Ok(CameraSpec {
        center,
        direction,
        up,
        fov,
    })
}

/// The camera basis is cross(direction, up); parallel vectors leave it undefined. Shared with the
/// assignment importer so that both formats accept the same cameras.
pub(crate) fn is_parallel(direction: [f64; 3], up: [f64; 3]) -> bool {
    let sine = DVec3::from(direction)
        .normalize()
        .cross(DVec3::from(up).normalize())
        .length();
    sine < 1e-9
}

pub(crate) fn background<'a>(doc: &'a Doc<'a>, field: Option<Field<'a, '_>>) -> Result<BackgroundSpec> {
    let t = section(doc, field, "[background]")?;
    t.check_keys(&["color", "ambient", "cube_map"])?;
    let cube_map = t.read("cube_map", None, |f| {
        if t.get("color").is_some() {
            return Err(f.error("give either color or cube_map, not both: a cube map replaces the colour"));
        }
        let path = doc.dir.join(f.string()?);
        match cube_map_problem(&path) {
            None => Ok(Some(path)),
            Some(problem) => Err(f.invalid(problem)),
        }
    })?;
    Ok(BackgroundSpec {
        color: t.read("color", [0.0; 3], Field::color)?,
        ambient: t.read("ambient", [0.0; 3], Field::color)?,
        cube_map,
    })
}

/// What a cube-map directory lacks, phrased as a requirement ("must …"), if anything. Shared
/// with the assignment importer so that both formats accept the same cube maps.
pub(crate) fn cube_map_problem(path: &Path) -> Option<String> {
    let shown = path.display();
    if !path.is_dir() {
        return Some(format!("must name a directory, but {shown} is not one"));
    }
    let missing = CUBE_FACES
        .iter()
        .map(|face| path.join(format!("{face}.png")))
        .find(|p| !p.is_file())?;
    Some(format!(
        "must hold the six faces {}.png; {} is missing",
        CUBE_FACES.join("/"),
        missing.display()
    ))
}

#[derive(Clone, Copy)]
enum LightKind {
    Point,
    Directional,
}

const LIGHT_KINDS: &[(&str, &[&str], LightKind)] = &[
    ("point", &["position", "color", "falloff"], LightKind::Point),
    ("directional", &["direction", "color"], LightKind::Directional),
];

pub(crate) fn lights(field: Option<Field>) -> Result<Vec<LightSpec>> {
    let Some(field) = field else {
        return Ok(Vec::new());
    };
    field
        .array("an array of tables, written [[light]]")?
        .iter()
        .map(light)
        .collect()
}

fn light(field: &Field) -> Result<LightSpec> {
    let mut t = field.table("light".to_owned())?;
    Ok(match t.kind("light", &["kind"], LIGHT_KINDS)? {
        LightKind::Point => {
            let position = t.require("position")?.vec3()?;
            let color = t.require("color")?.color()?;
            let falloff_field = t.require("falloff")?;
            let falloff = falloff_field.number()?;
            if falloff <= 0.0 {
                let rule = "must be > 0 (intensity is color / (falloff · d²))";
                return Err(falloff_field.invalid(rule));
            }
            LightSpec::Point {
                position,
                color,
                falloff,
            }
        }
        LightKind::Directional => LightSpec::Directional {
            direction: t.require("direction")?.direction()?,
            color: t.require("color")?.color()?,
        },
    })
}

pub(crate) fn materials(field: Option<Field>) -> Result<Vec<MaterialSpec>> {
    let Some(field) = field else {
        return Ok(Vec::new());
    };
    let table = field.table("[materials]".to_owned())?;
    table
        .fields()
        .map(|mut f| {
            let name = std::mem::take(&mut f.name);
            f.name = format!("materials.{name}");
            let t = f.table(format!("material `{name}`"))?;
            t.check_keys(&["diffuse", "specular", "shininess"])?;
            Ok(MaterialSpec {
                diffuse: t.read("diffuse", [1.0; 3], Field::color)?,
                specular: t.read("specular", [0.0; 3], Field::color)?,
                shininess: t.read("shininess", 0.0, Field::non_negative)?,
                name,
            })
        })
        .collect()
}
