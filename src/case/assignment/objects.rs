//! Groups, shapes and transforms: the scene graph of the course's format.
//!
//! A course `Transform { ops… object }` wraps one object; here it becomes that object with the
//! ops in front of its own, which is the same matrix because the outer transform is applied last.

use super::lexer::{Result, Token};
use super::{Parser, usable_in_single_precision};
use crate::case::objects::{file_problem, singularity};
use crate::case::spec::{ObjectSpec, ShapeSpec, TransformOp};

/// What a group or a transform may hold.
const OBJECT_WORDS: [&str; 6] = ["Group", "Sphere", "Plane", "Triangle", "TriangleMesh", "Transform"];
/// What may come in a group: an object, or the material of what follows.
const GROUP_WORDS: [&str; 7] = concat(OBJECT_WORDS, ["MaterialIndex"]);
/// What may come in a transform: its ops, then its object.
const TRANSFORM_WORDS: [&str; 14] = concat(
    [
        "Scale",
        "UniformScale",
        "Translate",
        "XRotate",
        "YRotate",
        "ZRotate",
        "Rotate",
        "Matrix4f",
    ],
    OBJECT_WORDS,
);

/// `first` then `second`, for keyword lists that share a part (`N` must be `A + B`).
const fn concat<const A: usize, const B: usize, const N: usize>(
    first: [&'static str; A],
    second: [&'static str; B],
) -> [&'static str; N] {
    assert!(A + B == N, "the lengths must add up");
    let mut all = [""; N];
    let mut i = 0;
    while i < N {
        all[i] = if i < A { first[i] } else { second[i - A] };
        i += 1;
    }
    all
}

/// Far deeper than any real scene, and shallow enough that neither this recursive parser nor
/// the TOML written by `case_to_toml` (toml's own limit is 80 levels) can run out of depth.
const MAX_NESTING: usize = 32;

impl<'a> Parser<'a> {
    /// The objects of a group whose `Group` keyword has just been read.
    pub(super) fn group(&mut self) -> Result<Vec<ObjectSpec>> {
        self.lex.expect("{", "after `Group`")?;
        self.lex.expect("numObjects", "first in Group")?;
        let (count, _) = self.lex.count("numObjects")?;
        let mut objects = Vec::new();
        while objects.len() < count {
            let token = self.lex.word_for("an object or `MaterialIndex`")?;
            match token.text {
                "MaterialIndex" => self.material_index()?,
                "}" => {
                    let given = objects.len();
                    return Err(self.too_few(token, "numObjects", count, given, "object"));
                }
                _ => objects.push(self.object(token, "object", &GROUP_WORDS, "objects")?),
            }
        }
        self.lex
            .expect("}", &format!("closing Group after its {count} (numObjects) objects"))?;
        Ok(objects)
    }

    /// `MaterialIndex k` names the k-th material read so far, counting every Materials block,
    /// and must be below the latest block's `numMaterials`: the course asserts exactly that.
    fn material_index(&mut self) -> Result<()> {
        let (k, token) = self.lex.count("MaterialIndex")?;
        if k < self.material_count {
            self.current_material = Some(k);
            return Ok(());
        }
        let message = match self.material_count {
            0 => format!(
                "`MaterialIndex {k}` refers to no material: no materials are defined before it \
                 (a Materials block with numMaterials ≥ 1 must come before the Group)"
            ),
            n => format!(
                "`MaterialIndex {k}` is out of range: the latest Materials block has numMaterials \
                 {n}, so indices go from 0 to {}",
                n - 1
            ),
        };
        Err(self.lex.error_at(token.start, message))
    }

    /// The object whose keyword is `token`; primitives take the current material, as the
    /// course's parser gives each primitive the material current when it is read.
    fn object(&mut self, token: Token<'a>, what: &str, valid: &[&str], noun: &str) -> Result<ObjectSpec> {
        let shape = match token.text {
            "Group" => ShapeSpec::Group {
                objects: self.nested(token, Self::group)?,
            },
            "Transform" => return self.nested(token, |p| p.transform(token)),
            "Sphere" => self.sphere()?,
            "Plane" => self.plane()?,
            "Triangle" => self.triangle()?,
            "TriangleMesh" => self.mesh()?,
            _ => return Err(self.unknown(token, what, valid, noun)),
        };
        let material = match shape {
            ShapeSpec::Group { .. } => None,
            // The course asserts a material for a sphere, plane or triangle, and dereferences
            // a mesh's null material as soon as a ray hits the mesh.
            _ => match self.current_material {
                Some(material) => Some(material),
                None => {
                    let message = format!(
                        "this {} has no material: put `MaterialIndex k` before it (the course \
                         stops on a shape without one)",
                        token.text
                    );
                    return Err(self.lex.error_at(token.start, message));
                }
            },
        };
        Ok(ObjectSpec {
            shape,
            material,
            transform: Vec::new(),
            location: self.lex.location(token.start),
        })
    }

    fn nested<T>(&mut self, token: Token, read: impl FnOnce(&mut Self) -> Result<T>) -> Result<T> {
        if self.depth >= MAX_NESTING {
            let message = format!("Group and Transform blocks nest more than {MAX_NESTING} deep");
            return Err(self.lex.error_at(token.start, message));
        }
        self.depth += 1;
        let result = read(self);
        self.depth -= 1;
        result
    }

    fn sphere(&mut self) -> Result<ShapeSpec> {
        self.lex.expect("{", "after `Sphere`")?;
        self.lex.expect("center", "first in Sphere")?;
        let center = self.lex.vec3("3 numbers after `center`")?.value;
        self.lex.expect("radius", "after the sphere's center")?;
        let (radius, _) = self.lex.number("a number after `radius`")?;
        self.lex.expect("}", "closing Sphere")?;
        // The course's sphere test uses only r² and normalises `p − center`, so a negative
        // radius draws the sphere of radius |r|, normals and all.
        Ok(ShapeSpec::Sphere {
            center,
            radius: radius.abs(),
        })
    }

    fn plane(&mut self) -> Result<ShapeSpec> {
        self.lex.expect("{", "after `Plane`")?;
        self.lex.expect("normal", "first in Plane")?;
        let normal = self.direction("normal")?.value;
        self.lex.expect("offset", "after the plane's normal")?;
        let (offset, _) = self.lex.number("a number after `offset`")?;
        self.lex.expect("}", "closing Plane")?;
        Ok(ShapeSpec::Plane { normal, offset })
    }

    /// No normals: the course shades a lone triangle with its face normal.
    fn triangle(&mut self) -> Result<ShapeSpec> {
        self.lex.expect("{", "after `Triangle`")?;
        let mut vertices = [[0.0; 3]; 3];
        for (i, vertex) in vertices.iter_mut().enumerate() {
            let label = format!("vertex{i}");
            let context = if i == 0 {
                "first in Triangle".to_owned()
            } else {
                format!("after the triangle's vertex{}", i - 1)
            };
            self.lex.expect(&label, &context)?;
            *vertex = self.lex.vec3(&format!("3 numbers after `{label}`"))?.value;
        }
        self.lex.expect("}", "closing Triangle")?;
        Ok(ShapeSpec::Triangle {
            vertices,
            normals: None,
        })
    }

    /// Only existence is checked here, as for TOML cases; the scene builder parses the OBJ.
    fn mesh(&mut self) -> Result<ShapeSpec> {
        self.lex.expect("{", "after `TriangleMesh`")?;
        self.lex.expect("obj_file", "first in TriangleMesh")?;
        let written = self.lex.word_for("a file name after `obj_file`")?;
        if !written.text.ends_with(".obj") {
            let rule = "must name a file ending in `.obj` (the course asserts that extension)";
            return Err(self.invalid(written, "`obj_file`", rule));
        }
        let obj = self.dir.join(written.text);
        if let Some(problem) = file_problem(&obj) {
            let message = format!("`obj_file {}` resolves to {}, {problem}", written.text, obj.display());
            return Err(self.lex.error_at(written.start, message));
        }
        self.lex.expect("}", "closing TriangleMesh")?;
        Ok(ShapeSpec::Mesh { obj })
    }

    /// Ops build `M = M · Op`, so they keep their written order in the op list (whose first op
    /// is applied last); `Matrix4f` builds `M = Op · M` and so goes to the front.
    fn transform(&mut self, keyword: Token) -> Result<ObjectSpec> {
        self.lex.expect("{", "after `Transform`")?;
        let mut ops = Vec::new();
        let mut object = loop {
            let token = self.lex.word_for("a transform op or the object it transforms")?;
            let op = match token.text {
                "Scale" => TransformOp::Scale(self.lex.vec3("3 numbers after `Scale`")?.value),
                "UniformScale" => TransformOp::UniformScale(self.lex.number("a number after `UniformScale`")?.0),
                "Translate" => TransformOp::Translate(self.lex.vec3("3 numbers after `Translate`")?.value),
                "XRotate" => TransformOp::RotateX(self.degrees("XRotate")?),
                "YRotate" => TransformOp::RotateY(self.degrees("YRotate")?),
                "ZRotate" => TransformOp::RotateZ(self.degrees("ZRotate")?),
                "Rotate" => self.rotate()?,
                "Matrix4f" => {
                    let matrix = self.matrix()?;
                    ops.insert(0, matrix);
                    continue;
                }
                "MaterialIndex" => {
                    let message = "`MaterialIndex` cannot appear inside a Transform; put it \
                                   before the Transform, in the enclosing Group";
                    return Err(self.lex.error_at(token.start, message));
                }
                _ => {
                    break self.object(token, "transform op or object", &TRANSFORM_WORDS, "ops and objects")?;
                }
            };
            ops.push(op);
        };
        self.lex.expect(
            "}",
            "closing Transform (a Transform holds its ops and then exactly one object)",
        )?;
        ops.append(&mut object.transform);
        if let Some(problem) = singularity(&ops) {
            let message = format!("this Transform {problem}");
            return Err(self.lex.error_at(keyword.start, message));
        }
        object.transform = ops;
        Ok(object)
    }

    fn degrees(&mut self, op: &str) -> Result<f64> {
        Ok(self.lex.number(&format!("a number of degrees after `{op}`"))?.0)
    }

    fn rotate(&mut self) -> Result<TransformOp> {
        self.lex.expect("{", "after `Rotate`")?;
        let axis = self.lex.vec3("3 numbers (the axis) after `Rotate {`")?;
        if !usable_in_single_precision(axis.value) {
            let rule = "must have a nonzero, finite length";
            return Err(self.invalid_vec(&axis, "the rotation axis", rule));
        }
        let (degrees, _) = self.lex.number("a number of degrees after the axis of `Rotate`")?;
        self.lex.expect("}", "closing Rotate { axis degrees }")?;
        Ok(TransformOp::Rotate {
            axis: axis.value,
            degrees,
        })
    }

    /// Read column by column, stored row-major as `TransformOp::Matrix` wants.
    fn matrix(&mut self) -> Result<TransformOp> {
        self.lex.expect("{", "after `Matrix4f`")?;
        let mut m = [0.0; 16];
        for column in 0..4 {
            for row in 0..4 {
                m[row * 4 + column] = self.lex.number("16 numbers (column by column) after `Matrix4f {`")?.0;
            }
        }
        self.lex.expect("}", "closing Matrix4f after its 16 numbers")?;
        Ok(TransformOp::Matrix(m))
    }
}
