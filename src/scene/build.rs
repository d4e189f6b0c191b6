//! Case → scene: flattens groups, composes transforms, loads each mesh once, and keeps only the
//! work the scene needs (no transform on untransformed shapes, no BVH for a handful of objects).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DMat4, DVec3};

use super::geometry::bvh::Bvh;
use super::geometry::mesh::{Mesh, NormalSource};
use super::geometry::plane::Plane;
use super::geometry::sphere::Sphere;
use super::geometry::transform::Transform;
use super::real::{Vec3, mat4, real, vec3};
use super::camera::Camera;
use super::light::Light;
use super::material::Material;
use super::{Aggregate, Background, CubeMap, Object, Scene, Shape, Triangle};
use crate::build_error::{BuildError, MeshError, TransformError};
use crate::case::{Case, LightSpec, ObjectSpec, ShapeSpec, composite_matrix};
use crate::options::Profile;
use crate::stats::{BuildStats, BvhStats, MeshStats};

pub fn build_scene(case: &Case) -> Result<Scene, BuildError> {
    build_scene_measured(case).map(|(scene, _)| scene)
}

/// [`build_scene`], also reporting each mesh's load and BVH build and the scene's BVH, for
/// `--stats`.
///
/// The scene is built in camera-world space (pbrt-v4's default): everything is moved, in `f64`,
/// so that the camera sits at the origin before any coordinate is rounded to `Real`. Where
/// rays start is then where precision is finest, and a scene moved far from the origin renders
/// the same picture instead of losing digits to the distance.
pub fn build_scene_measured(case: &Case) -> Result<(Scene, BuildStats), BuildError> {
    let camera_spec = &case.camera;
    let eye = DVec3::from(camera_spec.center);
    let to_camera_world = (eye != DVec3::ZERO).then(|| DMat4::from_translation(-eye));
    let camera = Camera::new(
        case.render.profile,
        Vec3::ZERO,
        vec3(camera_spec.direction),
        vec3(camera_spec.up),
        real(camera_spec.fov),
    );
    let cube_map_start = Instant::now();
    let background = match &case.background.cube_map {
        Some(dir) => Background::CubeMap(Box::new(
            CubeMap::load(dir).map_err(|source| BuildError::CubeMap { file: case.path.clone(), source })?,
        )),
        None => Background::Color(vec3(case.background.color)),
    };
    let cube_map_load_time = case.background.cube_map.as_ref().map(|_| cube_map_start.elapsed());
    let mut materials: Vec<Material> = case
        .materials
        .iter()
        .map(|m| Material { diffuse: vec3(m.diffuse), specular: vec3(m.specular), shininess: real(m.shininess) })
        .collect();
    let default_material = materials.len() as u32;
    let mut builder = Builder {
        normals: match case.render.profile {
            Profile::Native => NormalSource::FromFileOrAveraged,
            Profile::Mit6837 => NormalSource::Averaged,
        },
        written_plane_normals: case.render.profile == Profile::Mit6837,
        default_material,
        meshes: HashMap::new(),
        mesh_stats: Vec::new(),
        objects: Vec::new(),
        planes: Vec::new(),
        uses_default_material: false,
    };
    for spec in &case.objects {
        builder.add(spec, to_camera_world, None, false)?;
    }
    if builder.uses_default_material {
        materials.push(Material::default());
    }
    let bvh_start = Instant::now();
    let geometry = Aggregate::new(builder.objects, builder.planes);
    let scene_bvh = geometry.bvh().map(|bvh| bvh_stats(bvh, bvh_start.elapsed()));
    let scene = Scene {
        camera,
        background,
        ambient: vec3(case.background.ambient),
        lights: case.lights.iter().map(|spec| light(spec, eye)).collect(),
        materials,
        geometry,
    };
    Ok((scene, BuildStats { cube_map_load_time, cube_map_faces: None, meshes: builder.mesh_stats, scene_bvh }))
}

/// A BVH's shape for `--stats`. Assembled here, above both, so that the geometry does not know the
/// statistics exist.
fn bvh_stats(bvh: &Bvh, build_time: Duration) -> BvhStats {
    BvhStats { build_time, primitives: bvh.primitive_count(), nodes: bvh.node_count(), leaves: bvh.leaf_count() }
}

fn light(spec: &LightSpec, eye: DVec3) -> Light {
    match *spec {
        LightSpec::Point { position, color, falloff } => Light::Point {
            position: vec3((DVec3::from(position) - eye).to_array()),
            color: vec3(color),
            falloff: real(falloff),
        },
        LightSpec::Directional { direction, color } => {
            Light::Directional { direction: vec3(direction).normalize(), color: vec3(color) }
        }
    }
}

struct Builder {
    normals: NormalSource,
    /// The course's reference renderer shades a plane outside any Transform with its normal as
    /// written (not normalised: `normal 0 2 0` doubles the diffuse term); a Transform
    /// normalises the normals it hands back.
    written_plane_normals: bool,
    default_material: u32,
    meshes: HashMap<PathBuf, Arc<Mesh>>,
    mesh_stats: Vec<MeshStats>,
    objects: Vec<Object>,
    planes: Vec<(Plane, u32)>,
    uses_default_material: bool,
}

impl Builder {
    /// `parent` is the composed transform of the enclosing groups, `None` for the identity;
    /// `transformed` whether any of them has a transform of its own (the camera-world move is
    /// not one).
    fn add(
        &mut self,
        spec: &ObjectSpec,
        parent: Option<DMat4>,
        inherited: Option<u32>,
        transformed: bool,
    ) -> Result<(), BuildError> {
        let transformed = transformed || !spec.transform.is_empty();
        let material = spec.material.map(|m| m as u32).or(inherited);
        let matrix = match (parent, spec.transform.is_empty()) {
            (parent, true) => parent,
            (None, false) => Some(composite_matrix(&spec.transform)),
            (Some(parent), false) => Some(parent * composite_matrix(&spec.transform)),
        };
        let transform_error = |source| BuildError::Transform { location: spec.location.clone(), source };
        if let ShapeSpec::Group { objects } = &spec.shape {
            for child in objects {
                self.add(child, matrix, material, transformed)?;
            }
            return Ok(());
        }
        let material = material.unwrap_or_else(|| {
            self.uses_default_material = true;
            self.default_material
        });
        match &spec.shape {
            ShapeSpec::Group { .. } => unreachable!("groups returned above"),
            ShapeSpec::Plane { normal, offset } => {
                let mut plane = transformed_plane(DVec3::from(*normal), *offset, matrix).map_err(transform_error)?;
                if self.written_plane_normals && !transformed {
                    plane.shading_normal = plane.normal * real(DVec3::from(*normal).length());
                }
                self.planes.push((plane, material));
            }
            ShapeSpec::Triangle { vertices, normals } => {
                let triangle = transformed_triangle(vertices, normals.as_ref(), matrix).map_err(transform_error)?;
                self.objects.push(Object { shape: Shape::Triangle(triangle), transform: None, material });
            }
            ShapeSpec::Sphere { center, radius } => {
                let (center, matrix) = match matrix {
                    Some(m) if is_translation(m) => (m.transform_point3(DVec3::from(*center)), None),
                    _ => (DVec3::from(*center), matrix),
                };
                let shape = Shape::Sphere(Sphere { center: vec3(center.to_array()), radius: real(*radius) });
                self.push_instanced(shape, matrix, material).map_err(transform_error)?;
            }
            ShapeSpec::Mesh { obj } => {
                let mesh = self.mesh(obj).map_err(|source| BuildError::Mesh { location: spec.location.clone(), source })?;
                self.push_instanced(Shape::Mesh(mesh), matrix, material).map_err(transform_error)?;
            }
        }
        Ok(())
    }

    fn push_instanced(&mut self, shape: Shape, matrix: Option<DMat4>, material: u32) -> Result<(), TransformError> {
        let transform = matrix.map(|m| Transform::new(mat4(m)).map(Arc::new)).transpose()?;
        self.objects.push(Object { shape, transform, material });
        Ok(())
    }

    /// A mesh used by several objects is loaded and its BVH built once.
    fn mesh(&mut self, path: &Path) -> Result<Arc<Mesh>, MeshError> {
        if let Some(mesh) = self.meshes.get(path) {
            return Ok(mesh.clone());
        }
        let start = Instant::now();
        let mesh = Arc::new(Mesh::load_obj(path, self.normals)?);
        let bvh_build_time = mesh.bvh_build_time();
        self.mesh_stats.push(MeshStats {
            path: path.to_path_buf(),
            triangles: mesh.triangle_count(),
            load_time: start.elapsed().saturating_sub(bvh_build_time),
            bvh: bvh_stats(mesh.bvh(), bvh_build_time),
        });
        self.meshes.insert(path.to_path_buf(), mesh.clone());
        Ok(mesh)
    }
}

/// A translated sphere is a sphere with another centre: moving it costs nothing per ray, where
/// instancing would transform every ray that meets its box.
fn is_translation(matrix: DMat4) -> bool {
    glam::DMat3::from_mat4(matrix) == glam::DMat3::IDENTITY && matrix.row(3) == glam::DVec4::W
}

/// Planes stay analytic under any affine transform: the normal goes by the inverse transpose
/// and a point on the plane by the matrix, so no instancing is needed.
fn transformed_plane(normal: DVec3, offset: f64, matrix: Option<DMat4>) -> Result<Plane, TransformError> {
    let Some(matrix) = matrix else {
        return Ok(Plane::new(vec3(normal.to_array()), real(offset)));
    };
    let inverse_transpose = inverse_linear(matrix)?.transpose();
    let point = matrix.transform_point3(normal * (offset / normal.length_squared()));
    let world_normal = (inverse_transpose * normal).normalize();
    Ok(Plane::new(vec3(world_normal.to_array()), real(world_normal.dot(point))))
}

/// Lone triangles are moved to world space once rather than instanced.
fn transformed_triangle(
    vertices: &[[f64; 3]; 3],
    normals: Option<&[[f64; 3]; 3]>,
    matrix: Option<DMat4>,
) -> Result<Triangle, TransformError> {
    let matrix = matrix.unwrap_or(DMat4::IDENTITY);
    let inverse_transpose = inverse_linear(matrix)?.transpose();
    let mut vertices = vertices.map(|v| vec3(matrix.transform_point3(DVec3::from(v)).to_array()));
    let mut normals =
        normals.map(|ns| ns.map(|n| vec3((inverse_transpose * DVec3::from(n)).normalize_or_zero().to_array())));
    // A mirroring matrix reverses the winding, and with it the face normal taken from the moved
    // vertices; swapping two vertices keeps the face normal the inverse transpose's, as for an
    // instanced mesh and in the course's reference renderer.
    if glam::DMat3::from_mat4(matrix).determinant() < 0.0 {
        vertices.swap(1, 2);
        if let Some(normals) = &mut normals {
            normals.swap(1, 2);
        }
    }
    Ok(Triangle { vertices, normals })
}

/// The inverse of the linear part, checked the same way instance transforms are.
fn inverse_linear(matrix: DMat4) -> Result<glam::DMat3, TransformError> {
    Transform::new(mat4(matrix))?;
    Ok(glam::DMat3::from_mat4(matrix).inverse())
}

#[cfg(test)]
mod tests {
    use super::*;


    #[test]
    fn transformed_plane_moves_with_its_matrix() {
        let lift = DMat4::from_translation(DVec3::new(0.0, 3.0, 0.0));
        let plane = transformed_plane(DVec3::Y, -2.0, Some(lift)).unwrap();
        assert!((plane.normal - Vec3::Y).length() < 1e-6);
        assert!((plane.offset - 1.0).abs() < 1e-6);
        let tilt = DMat4::from_scale(DVec3::new(1.0, 2.0, 1.0)) * DMat4::from_rotation_z(45f64.to_radians());
        let plane = transformed_plane(DVec3::Y, 1.0, Some(tilt)).unwrap();
        let on_plane = tilt.transform_point3(DVec3::new(0.0, 1.0, 0.0));
        assert!((plane.normal.dot(vec3(on_plane.to_array())) - plane.offset).abs() < 1e-5);
    }

    #[test]
    fn singular_transform_is_an_error_not_a_nan() {
        let flat = DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0));
        assert!(transformed_plane(DVec3::Y, 0.0, Some(flat)).is_err());
    }
}
