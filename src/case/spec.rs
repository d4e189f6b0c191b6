//! The validated case: plain data with every default filled in and every number checked, so that
//! building a scene from it never has to re-validate or guess.

use std::path::PathBuf;

use glam::{DMat4, DVec3};

use crate::compare::Tolerance;
use crate::film::Tonemap;
use crate::located_toml::SourceLocation;
use crate::options::{Precision, Profile, Trace};

/// One case file: a scene, how to render it, and how far it may drift from its golden image.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// The file stem, which names the outputs and the golden snapshot.
    pub name: String,
    pub path: PathBuf,
    pub description: Option<String>,
    pub render: RenderSettings,
    pub tolerance: Tolerance,
    pub camera: CameraSpec,
    pub background: BackgroundSpec,
    pub lights: Vec<LightSpec>,
    /// In file order, so that object indices and messages are stable across runs.
    pub materials: Vec<MaterialSpec>,
    pub objects: Vec<ObjectSpec>,
}

impl Case {
    /// Every file a render of this case reads besides the case itself, in a fixed order: the
    /// OBJ meshes in object order, then the cube map's PNG faces by name. The grading cache and
    /// each output's provenance hash them, so that changing a mesh changes both.
    pub fn assets(&self) -> Vec<PathBuf> {
        fn meshes(objects: &[ObjectSpec], out: &mut Vec<PathBuf>) {
            for object in objects {
                match &object.shape {
                    ShapeSpec::Mesh { obj } => out.push(obj.clone()),
                    ShapeSpec::Group { objects } => meshes(objects, out),
                    ShapeSpec::Sphere { .. } | ShapeSpec::Plane { .. } | ShapeSpec::Triangle { .. } => {}
                }
            }
        }
        let mut files = Vec::new();
        meshes(&self.objects, &mut files);
        if let Some(dir) = &self.background.cube_map
            && let Ok(entries) = std::fs::read_dir(dir)
        {
            let mut faces: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("png")))
                .collect();
            faces.sort();
            files.extend(faces);
        }
        files
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub trace: Trace,
    /// `(min, max)` with `min < max`, mapped to black..white in the depth PNG.
    pub depth_range: Option<(f64, f64)>,
    pub normals: bool,
    pub tonemap: Tonemap,
    pub profile: Profile,
    pub precision: Precision,
}

/// `direction` and `up` have nonzero length and are not parallel; `fov` is in (0, 180) degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraSpec {
    pub center: [f64; 3],
    pub direction: [f64; 3],
    pub up: [f64; 3],
    pub fov: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct BackgroundSpec {
    pub color: [f64; 3],
    pub ambient: [f64; 3],
    /// A directory holding `left/right/up/down/front/back.png`, already resolved against the case
    /// file's directory; when present it replaces `color` for rays that miss.
    pub cube_map: Option<PathBuf>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightSpec {
    /// Intensity at distance d is `color / (falloff · d²)`; `falloff > 0`.
    Point {
        position: [f64; 3],
        color: [f64; 3],
        falloff: f64,
    },
    /// `direction` points from the light into the scene and has nonzero length.
    Directional { direction: [f64; 3], color: [f64; 3] },
}

#[derive(Clone, Debug, PartialEq)]
pub struct MaterialSpec {
    pub name: String,
    pub diffuse: [f64; 3],
    pub specular: [f64; 3],
    pub shininess: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ObjectSpec {
    pub shape: ShapeSpec,
    /// Index into `Case::materials`; `None` inherits the enclosing group's material, or the
    /// default material at the top level.
    pub material: Option<usize>,
    /// Invertible by construction (see `composite_matrix`).
    pub transform: Vec<TransformOp>,
    /// Where the object's table starts, for errors only found later (an OBJ that fails to parse).
    pub location: SourceLocation,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ShapeSpec {
    /// `radius ≥ 0`; zero is a legal, invisible sphere.
    Sphere {
        center: [f64; 3],
        radius: f64,
    },
    /// Points P with `P · normal = offset`; `normal` has nonzero length.
    Plane {
        normal: [f64; 3],
        offset: f64,
    },
    /// Optional per-vertex shading normals, each of nonzero length.
    Triangle {
        vertices: [[f64; 3]; 3],
        normals: Option<[[f64; 3]; 3]>,
    },
    /// An existing file, resolved against the case file's directory.
    Mesh {
        obj: PathBuf,
    },
    Group {
        objects: Vec<ObjectSpec>,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub enum TransformOp {
    Translate([f64; 3]),
    Scale([f64; 3]),
    UniformScale(f64),
    /// Angles in degrees, right-handed.
    RotateX(f64),
    RotateY(f64),
    RotateZ(f64),
    /// `axis` as written (nonzero length); it is normalised when the matrix is built.
    Rotate {
        axis: [f64; 3],
        degrees: f64,
    },
    /// Row-major, as written in the file.
    Matrix([f64; 16]),
}

impl TransformOp {
    pub fn matrix(&self) -> DMat4 {
        match *self {
            TransformOp::Translate(t) => DMat4::from_translation(DVec3::from(t)),
            TransformOp::Scale(s) => DMat4::from_scale(DVec3::from(s)),
            TransformOp::UniformScale(s) => DMat4::from_scale(DVec3::splat(s)),
            TransformOp::RotateX(deg) => DMat4::from_rotation_x(deg.to_radians()),
            TransformOp::RotateY(deg) => DMat4::from_rotation_y(deg.to_radians()),
            TransformOp::RotateZ(deg) => DMat4::from_rotation_z(deg.to_radians()),
            TransformOp::Rotate { axis, degrees } => {
                DMat4::from_axis_angle(DVec3::from(axis).normalize(), degrees.to_radians())
            }
            TransformOp::Matrix(m) => DMat4::from_cols_array(&m).transpose(),
        }
    }
}

/// `ops[0] · ops[1] · …`: the last op touches the object first, matching the assignment's
/// `M = M · Op`, so a list reads like the math written left to right.
pub fn composite_matrix(ops: &[TransformOp]) -> DMat4 {
    ops.iter().fold(DMat4::IDENTITY, |m, op| m * op.matrix())
}
