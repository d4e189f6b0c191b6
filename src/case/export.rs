//! A `Case` written back as a TOML case file, which is how `goldray import` turns a course scene
//! into a case of the golden suite.
//!
//! The file says only what differs from the loader's defaults, so that it reads like a
//! hand-written case; numbers use Rust's shortest round-trip form, so that loading the file
//! gives back exactly the numbers that were written.

use std::path::{Path, PathBuf};

use super::spec::{BackgroundSpec, Case, LightSpec, ObjectSpec, ShapeSpec, TransformOp};
use super::{LoadOptions, parse};
use crate::options::Profile;

/// `toml_path` is where the file will live: asset paths are written relative to its directory
/// (or absolute when the two share nothing but the root), as the loader resolves them.
pub fn case_to_toml(case: &Case, toml_path: &Path) -> String {
    let base = toml_path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    write_case(case, Some(base))
}

/// [`case_to_toml`] for a file whose location is unknown (standard output, which may be
/// redirected anywhere): asset paths are absolute, so the case loads wherever it is saved.
pub fn case_to_toml_anywhere(case: &Case) -> String {
    write_case(case, None)
}

/// Asset paths relative to `base`, or absolute without one.
fn write_case(case: &Case, base: Option<&Path>) -> String {
    let writer = Writer { case, base };
    let defaults = defaults(case.render.profile);
    let paths = match base {
        Some(_) => "Paths are relative to this file",
        None => {
            "Paths are absolute (it was written to standard output; `goldray import -o FILE` writes \
             them relative to FILE)"
        }
    };
    let mut out = format!(
        "# Imported from {} by goldray.\n# {paths}; keys left out take their default values.\n",
        writer.path(&case.path)
    );
    if let Some(description) = &case.description {
        out += &format!("\ndescription = {}\n", string(description));
    }
    out += &writer.render(&defaults);
    out += &writer.tolerance(&defaults);
    let camera = &case.camera;
    out += &format!(
        "\n[camera]\ncenter = {}\ndirection = {}\nup = {}\nfov = {}  # degrees\n",
        vec3(&camera.center),
        vec3(&camera.direction),
        vec3(&camera.up),
        number(camera.fov)
    );
    out += &writer.background(&defaults.background);
    for light in &case.lights {
        out += &light_table(light);
    }
    let material_defaults = &defaults.materials[0];
    for material in &case.materials {
        out += &format!("\n[materials.{}]\n", key(&material.name));
        out += &only_changed(&[
            (
                "diffuse",
                material.diffuse != material_defaults.diffuse,
                vec3(&material.diffuse),
            ),
            (
                "specular",
                material.specular != material_defaults.specular,
                vec3(&material.specular),
            ),
            (
                "shininess",
                material.shininess != material_defaults.shininess,
                number(material.shininess),
            ),
        ]);
    }
    for object in &case.objects {
        out += &format!("\n# from {}\n[[object]]\n", writer.location(object));
        for (name, value) in writer.fields(object, 0) {
            out += &format!("{name} = {value}\n");
        }
    }
    out
}

/// The loader's defaults for `profile`, taken from the loader itself so that leaving a key out
/// of the file cannot drift from what the loader fills in.
fn defaults(profile: Profile) -> Case {
    let skeleton = format!(
        "[render]\nprofile = {}\n[camera]\ncenter = [0, 0, 0]\ndirection = [0, 0, -1]\n\
         up = [0, 1, 0]\nfov = 30\n[materials.m]\n",
        string(profile.name())
    );
    parse(&skeleton, Path::new("defaults.toml"), &LoadOptions::default())
        .expect("the skeleton case is valid for every profile")
}

struct Writer<'a> {
    case: &'a Case,
    /// Where asset paths are relative to; `None`: they are absolute.
    base: Option<&'a Path>,
}

impl Writer<'_> {
    fn render(&self, defaults: &Case) -> String {
        let (r, d) = (&self.case.render, &defaults.render);
        let mut out = format!(
            "\n[render]\nprofile = {}\nsize = [{}, {}]\n",
            string(r.profile.name()),
            r.trace.width,
            r.trace.height
        );
        let depth = |range: Option<(f64, f64)>| {
            range.map_or_else(String::new, |(min, max)| format!("[{}, {}]", number(min), number(max)))
        };
        out += &only_changed(&[
            (
                "bounces",
                r.trace.bounces != d.trace.bounces,
                r.trace.bounces.to_string(),
            ),
            (
                "shadows",
                r.trace.shadows != d.trace.shadows,
                r.trace.shadows.to_string(),
            ),
            (
                "samples",
                r.trace.samples != d.trace.samples,
                r.trace.samples.to_string(),
            ),
            ("seed", r.trace.seed != d.trace.seed, r.trace.seed.to_string()),
            (
                "filter",
                r.trace.filter != d.trace.filter,
                string(r.trace.filter.name()),
            ),
            ("depth_range", r.depth_range != d.depth_range, depth(r.depth_range)),
            ("normals", r.normals != d.normals, r.normals.to_string()),
            ("tonemap", r.tonemap != d.tonemap, string(r.tonemap.name())),
            ("precision", r.precision != d.precision, string(r.precision.name())),
        ]);
        out
    }

    fn tolerance(&self, defaults: &Case) -> String {
        let (t, d) = (&self.case.tolerance, &defaults.tolerance);
        let keys = only_changed(&[
            ("pixel", t.pixel != d.pixel, number(t.pixel)),
            (
                "fail_fraction",
                t.fail_fraction != d.fail_fraction,
                number(t.fail_fraction),
            ),
            ("rmse", t.rmse != d.rmse, number(t.rmse)),
            ("max", t.max != d.max, t.max.map_or_else(String::new, number)),
        ]);
        section("[tolerance]", keys)
    }

    fn background(&self, d: &BackgroundSpec) -> String {
        let b = &self.case.background;
        let cube_map = b.cube_map.as_deref().map(|p| string(&self.path(p)));
        let keys = only_changed(&[
            ("color", b.color != d.color, vec3(&b.color)),
            ("ambient", b.ambient != d.ambient, vec3(&b.ambient)),
            ("cube_map", b.cube_map != d.cube_map, cube_map.unwrap_or_default()),
        ]);
        section("[background]", keys)
    }

    /// Key–value pairs in the order a person would write them: kind, shape, material, transform,
    /// and a group's children last because they run on for lines.
    fn fields(&self, object: &ObjectSpec, indent: usize) -> Vec<(&'static str, String)> {
        let mut fields = Vec::new();
        match &object.shape {
            ShapeSpec::Sphere { center, radius } => {
                fields.push(("kind", string("sphere")));
                fields.push(("center", vec3(center)));
                fields.push(("radius", number(*radius)));
            }
            ShapeSpec::Plane { normal, offset } => {
                fields.push(("kind", string("plane")));
                fields.push(("normal", vec3(normal)));
                fields.push(("offset", number(*offset)));
            }
            ShapeSpec::Triangle { vertices, normals } => {
                fields.push(("kind", string("triangle")));
                fields.push(("vertices", list(vertices.iter().map(vec3))));
                if let Some(normals) = normals {
                    fields.push(("normals", list(normals.iter().map(vec3))));
                }
            }
            ShapeSpec::Mesh { obj } => {
                fields.push(("kind", string("mesh")));
                fields.push(("obj", string(&self.path(obj))));
            }
            ShapeSpec::Group { .. } => fields.push(("kind", string("group"))),
        }
        if let Some(material) = object.material.and_then(|m| self.case.materials.get(m)) {
            fields.push(("material", string(&material.name)));
        }
        if !object.transform.is_empty() {
            fields.push(("transform", list(object.transform.iter().map(op))));
        }
        if let ShapeSpec::Group { objects } = &object.shape {
            fields.push(("objects", self.group(objects, indent)));
        }
        fields
    }

    /// One inline table per line. A group nested in a group spans lines inside its inline
    /// table, which TOML 1.1 allows; a single line would be unreadable for any real group.
    fn group(&self, objects: &[ObjectSpec], indent: usize) -> String {
        if objects.is_empty() {
            return "[]".to_owned();
        }
        let inner = indent + 4;
        let mut out = "[\n".to_owned();
        for object in objects {
            let fields: Vec<String> = self
                .fields(object, inner)
                .into_iter()
                .map(|(name, value)| format!("{name} = {value}"))
                .collect();
            out += &format!("{:inner$}{{ {} }},\n", "", fields.join(", "));
        }
        out + &format!("{:indent$}]", "")
    }

    /// Where the object came from, so that a reader can find it in the original scene.
    fn location(&self, object: &ObjectSpec) -> String {
        let at = &object.location;
        format!("{}:{}:{}", self.path(&at.file), at.line, at.column)
    }

    fn path(&self, path: &Path) -> String {
        self.base.and_then(|base| relative(path, base)).unwrap_or_else(|| {
            lexical_absolute(path)
                .unwrap_or_else(|| path.to_path_buf())
                .to_string_lossy()
                .into_owned()
        })
    }
}

/// The absolute form of `path` with `.` and `..` resolved as written, not through symlinks: a
/// `../shared` that is a link stays `../shared` in the case, as the user wrote it, instead of
/// becoming the link's target, which only exists on this machine.
fn lexical_absolute(path: &Path) -> Option<PathBuf> {
    let mut resolved = PathBuf::new();
    for component in std::path::absolute(path).ok()?.components() {
        match component {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                resolved.pop();
            }
            other => resolved.push(other),
        }
    }
    Some(resolved)
}

/// `target` relative to the directory `base`, with `/` separators so that the case file works on
/// every platform; `None` when either cannot be resolved or they share nothing below the root,
/// where a chain of `..` would be more fragile than an absolute path.
fn relative(target: &Path, base: &Path) -> Option<String> {
    let target = lexical_absolute(target)?;
    let base = lexical_absolute(base)?;
    let common = target
        .components()
        .zip(base.components())
        .take_while(|(a, b)| a == b)
        .count();
    let root = target
        .components()
        .take_while(|c| !matches!(c, std::path::Component::Normal(_)))
        .count();
    if common <= root {
        return None;
    }
    let ups = base.components().count() - common;
    let rest: PathBuf = target.components().skip(common).collect();
    let parts: Vec<String> = std::iter::repeat_n("..".to_owned(), ups)
        .chain(rest.iter().map(|p| p.to_string_lossy().into_owned()))
        .collect();
    Some(if parts.is_empty() {
        ".".to_owned()
    } else {
        parts.join("/")
    })
}

fn light_table(light: &LightSpec) -> String {
    match light {
        LightSpec::Point {
            position,
            color,
            falloff,
        } => format!(
            "\n[[light]]\nkind = \"point\"\nposition = {}\ncolor = {}\n\
             falloff = {}  # intensity = color / (falloff · d²)\n",
            vec3(position),
            vec3(color),
            number(*falloff)
        ),
        LightSpec::Directional { direction, color } => format!(
            "\n[[light]]\nkind = \"directional\"\ndirection = {}\ncolor = {}\n",
            vec3(direction),
            vec3(color)
        ),
    }
}

fn op(op: &TransformOp) -> String {
    let (name, value) = match op {
        TransformOp::Translate(v) => ("translate", vec3(v)),
        TransformOp::Scale(v) => ("scale", vec3(v)),
        TransformOp::UniformScale(s) => ("uniform_scale", number(*s)),
        TransformOp::RotateX(d) => ("rotate_x", number(*d)),
        TransformOp::RotateY(d) => ("rotate_y", number(*d)),
        TransformOp::RotateZ(d) => ("rotate_z", number(*d)),
        TransformOp::Rotate { axis, degrees } => (
            "rotate",
            format!("{{ axis = {}, degrees = {} }}", vec3(axis), number(*degrees)),
        ),
        TransformOp::Matrix(m) => ("matrix", list(m.iter().map(|v| number(*v)))),
    };
    format!("{{ {name} = {value} }}")
}

/// `name = value` lines for the entries whose flag says they differ from the default.
fn only_changed(entries: &[(&str, bool, String)]) -> String {
    entries
        .iter()
        .filter(|(_, changed, _)| *changed)
        .map(|(name, _, value)| format!("{name} = {value}\n"))
        .collect()
}

/// A table header over `keys`, or nothing when every key has its default.
fn section(header: &str, keys: String) -> String {
    if keys.is_empty() {
        keys
    } else {
        format!("\n{header}\n{keys}")
    }
}

/// Integers print without a fraction (`radius = 1`); everything else in the shortest form that
/// parses back to the same bits, with an exponent where that is shorter.
fn number(v: f64) -> String {
    if v == 0.0 && v.is_sign_negative() {
        "-0.0".to_owned()
    } else if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v:?}")
    }
}

fn vec3(v: &[f64; 3]) -> String {
    list(v.iter().map(|c| number(*c)))
}

fn list(items: impl Iterator<Item = String>) -> String {
    format!("[{}]", items.collect::<Vec<_>>().join(", "))
}

fn string(s: &str) -> String {
    toml::Value::String(s.to_owned()).to_string()
}

/// Bare when TOML allows it, quoted otherwise.
fn key(name: &str) -> String {
    let bare = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare { name.to_owned() } else { string(name) }
}
