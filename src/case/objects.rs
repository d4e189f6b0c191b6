//! `[[object]]` tables: shapes, material references, transforms, and groups nested to any depth.

use std::io::ErrorKind;
use std::path::{Path, PathBuf};

use glam::{DMat3, DVec4};

use super::spec::{MaterialSpec, ObjectSpec, ShapeSpec, TransformOp, composite_matrix};
use super::value::SceneValues;
use crate::located_toml::{Field, Result, suggest};

#[derive(Clone, Copy)]
enum Kind {
    Sphere,
    Plane,
    Triangle,
    Mesh,
    Group,
}

const COMMON_KEYS: &[&str] = &["kind", "material", "transform"];

const KINDS: &[(&str, &[&str], Kind)] = &[
    ("sphere", &["center", "radius"], Kind::Sphere),
    ("plane", &["normal", "offset"], Kind::Plane),
    ("triangle", &["vertices", "normals"], Kind::Triangle),
    ("mesh", &["obj"], Kind::Mesh),
    ("group", &["objects"], Kind::Group),
];

type ReadOp = fn(&Field) -> Result<TransformOp>;

const OPS: &[(&str, ReadOp)] = &[
    ("translate", |f| Ok(TransformOp::Translate(f.vec3()?))),
    ("scale", |f| Ok(TransformOp::Scale(f.vec3()?))),
    ("uniform_scale", |f| Ok(TransformOp::UniformScale(f.number()?))),
    ("rotate_x", |f| Ok(TransformOp::RotateX(f.number()?))),
    ("rotate_y", |f| Ok(TransformOp::RotateY(f.number()?))),
    ("rotate_z", |f| Ok(TransformOp::RotateZ(f.number()?))),
    ("rotate", rotate),
    ("matrix", |f| {
        Ok(TransformOp::Matrix(f.numbers("an array of 16 numbers, row-major")?))
    }),
];

/// Below this, a determinant (of the matrix scaled to unit-sized entries) is within a few
/// thousand rounding errors of zero: the object is flattened, and its inverse, which rays and
/// normals go through, would be noise.
const SINGULAR: f64 = 1e-12;

/// The top-level `object` array of tables, or a group's `objects`.
pub(crate) fn objects(field: &Field, materials: &[MaterialSpec]) -> Result<Vec<ObjectSpec>> {
    let items = field.array("an array of object tables, like [{ kind = \"sphere\", … }]")?;
    items.iter().map(|item| object(item, materials)).collect()
}

fn object(field: &Field, materials: &[MaterialSpec]) -> Result<ObjectSpec> {
    let mut t = field.table("object".to_owned())?;
    let kind = t.kind("object", COMMON_KEYS, KINDS)?;
    let material = t.read("material", None, |f| material(f, materials).map(Some))?;
    let transform = t.read("transform", Vec::new(), transform)?;
    let shape = match kind {
        Kind::Sphere => {
            let center = t.require("center")?.vec3()?;
            let radius = t.require("radius")?.non_negative()?;
            ShapeSpec::Sphere { center, radius }
        }
        Kind::Plane => ShapeSpec::Plane {
            normal: t.require("normal")?.direction()?,
            offset: t.require("offset")?.number()?,
        },
        Kind::Triangle => ShapeSpec::Triangle {
            vertices: triple(&t.require("vertices")?, |f| f.vec3())?,
            normals: t.read("normals", None, |f| triple(f, |f| f.direction()).map(Some))?,
        },
        Kind::Mesh => ShapeSpec::Mesh {
            obj: obj_path(&t.require("obj")?)?,
        },
        Kind::Group => ShapeSpec::Group {
            objects: objects(&t.require("objects")?, materials)?,
        },
    };
    Ok(ObjectSpec {
        shape,
        material,
        transform,
        location: t.doc.location(t.span.start),
    })
}

fn material(f: &Field, materials: &[MaterialSpec]) -> Result<usize> {
    let name = f.string()?;
    materials.iter().position(|m| m.name == name).ok_or_else(|| {
        let names: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
        if names.is_empty() {
            f.error(format!(
                "unknown material `{name}`: no materials are defined; add a [materials.{name}] table"
            ))
        } else {
            f.error(format!(
                "unknown material `{name}`{}",
                suggest(name, &names, "materials")
            ))
        }
    })
}

fn triple(f: &Field, read: fn(&Field) -> Result<[f64; 3]>) -> Result<[[f64; 3]; 3]> {
    let items = f.array("an array of 3 points [[x, y, z], [x, y, z], [x, y, z]]")?;
    match items.as_slice() {
        [a, b, c] => Ok([read(a)?, read(b)?, read(c)?]),
        _ => {
            let n = items.len();
            Err(f.invalid(format!("must have 3 elements, one per vertex, but has {n}")))
        }
    }
}

/// Only existence is checked here, so a typo fails at load time with the line that has it;
/// parsing the OBJ is the scene builder's job.
fn obj_path(f: &Field) -> Result<PathBuf> {
    let path = f.doc.dir.join(f.string()?);
    match file_problem(&path) {
        None => Ok(path),
        Some(problem) => Err(f.error(format!(
            "obj = {} resolves to {}, {problem}",
            f.excerpt(),
            path.display()
        ))),
    }
}

/// Why `path` cannot serve as an OBJ file, phrased to follow "resolves to PATH, ". Shared with
/// the assignment importer so that both formats accept the same files.
pub(crate) fn file_problem(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_file() => None,
        Ok(_) => Some("which is not a file".to_owned()),
        Err(e) if e.kind() == ErrorKind::NotFound => Some("which does not exist".to_owned()),
        Err(e) => Some(format!("which cannot be read: {e}")),
    }
}

fn transform(f: &Field) -> Result<Vec<TransformOp>> {
    let entries = f.array("an array of ops, like [{ translate = [0, 1, 0] }, { rotate_y = 45 }]")?;
    let ops = entries.iter().map(op).collect::<Result<Vec<_>>>()?;
    check_invertible(f, &ops)?;
    Ok(ops)
}

fn op(entry: &Field) -> Result<TransformOp> {
    let names: Vec<&str> = OPS.iter().map(|(name, _)| *name).collect();
    let t = entry.table("transform op".to_owned())?;
    let fields: Vec<Field> = t.fields().collect();
    let [field] = fields.as_slice() else {
        let found: Vec<String> = fields.iter().map(|f| format!("`{}`", f.name)).collect();
        let found = if found.is_empty() {
            "none".to_owned()
        } else {
            found.join(", ")
        };
        return Err(entry.error(format!(
            "{} must hold exactly one op (each op is its own {{ … }} entry, applied last to \
             first), found {found}; valid ops: {}",
            entry.name,
            names.join(", ")
        )));
    };
    match OPS.iter().find(|(name, _)| *name == field.name) {
        Some((_, read)) => read(field),
        None => Err(field.doc.error_at(
            &field.key_span,
            format!(
                "unknown transform op `{}`{}",
                field.name,
                suggest(&field.name, &names, "ops")
            ),
        )),
    }
}

fn rotate(f: &Field) -> Result<TransformOp> {
    let t = f.table("rotate".to_owned())?;
    t.check_keys(&["axis", "degrees"])?;
    Ok(TransformOp::Rotate {
        axis: t.require("axis")?.direction()?,
        degrees: t.require("degrees")?.number()?,
    })
}

fn check_invertible(f: &Field, ops: &[TransformOp]) -> Result<()> {
    match singularity(ops) {
        None => Ok(()),
        Some(problem) => Err(f
            .doc
            .error_at(&f.key_span, format!("{} {problem}; found {}", f.name, f.excerpt()))),
    }
}

/// Why the composite of `ops` is not comfortably invertible, if it is not. Rays are intersected
/// in object space through the inverse and normals come back through its transpose.
/// `DMat4::inverse` never fails (it returns infinities or NaN), hence the explicit checks.
/// Shared with the assignment importer so that both formats accept the same transforms.
pub(crate) fn singularity(ops: &[TransformOp]) -> Option<String> {
    let m = composite_matrix(ops);
    if !m.is_finite() {
        return Some("overflows: the composite matrix has non-finite entries".to_owned());
    }
    // Translation does not affect invertibility but would dominate the scale of an affine
    // matrix, so only its linear part is judged; a projective `matrix` is judged whole.
    let (determinant, scale, relative) = if m.row(3) == DVec4::W {
        let linear = DMat3::from_mat4(m);
        let scale = linear.to_cols_array().iter().fold(0.0, |a: f64, b| a.max(b.abs()));
        (linear.determinant(), scale, (linear * scale.recip()).determinant())
    } else {
        let scale = m.to_cols_array().iter().fold(0.0, |a: f64, b| a.max(b.abs()));
        (m.determinant(), scale, (m * scale.recip()).determinant())
    };
    let invertible = relative.abs() > SINGULAR && m.inverse().is_finite();
    (!invertible).then(|| {
        format!(
            "is singular (determinant {determinant:.3e} for entries up to {scale:.3e}), which \
             flattens the object: check for a zero scale or a degenerate matrix"
        )
    })
}
