//! The course's scene format: its seven scenes load with the values they spell out, its quirks
//! are honoured, malformed scenes are reported at their line and column, and every imported
//! case survives being written as TOML and loaded back.

// A test crate root resolves modules beside itself, where cargo would take them for test crates.
#[path = "assignment_scenes/errors.rs"]
mod errors;
#[path = "assignment_scenes/export.rs"]
mod export;
#[path = "assignment_scenes/fuzz.rs"]
mod fuzz;
/// The differential test's scene generator, to check here that goldray takes what it writes.
/// Only the driver reads a scene's image size, depth range and bounces.
#[path = "../examples/course_diff/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "assignment_scenes/reference.rs"]
mod reference;
#[path = "assignment_scenes/syntax.rs"]
mod syntax;

use std::path::{Path, PathBuf};

use glam::DVec3;
use goldray::case::{
    AssignmentOptions, Case, CaseError, LightSpec, ObjectSpec, ShapeSpec, SourceLocation, TransformOp,
    composite_matrix, load_assignment_scene, parse_assignment_scene,
};
use goldray::film::Tonemap;
use goldray::options::{Filter, Profile};

const SCENES: [&str; 7] = [
    "scene01_plane.txt",
    "scene02_cube.txt",
    "scene03_sphere.txt",
    "scene04_axes.txt",
    "scene05_bunny_200.txt",
    "scene06_bunny_1k.txt",
    "scene07_arch.txt",
];

/// The course's scenes, with their `models/` and `tex/`.
fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/mit6837")
}

fn course_scene(name: &str) -> Case {
    let path = data_dir().join(name);
    load_assignment_scene(&path, &AssignmentOptions::default()).unwrap_or_else(|e| panic!("{name} must load: {e}"))
}

/// Where synthetic scenes claim to live, so that `models/…` and `tex/…` resolve.
fn synthetic_path() -> PathBuf {
    data_dir().join("synthetic.txt")
}

fn try_parse(source: &str) -> Result<Case, CaseError> {
    parse_assignment_scene(source, &synthetic_path(), &AssignmentOptions::default())
}

fn parse_ok(source: &str) -> Case {
    try_parse(source).unwrap_or_else(|e| panic!("expected {source:?} to parse: {e}"))
}

/// Six lines, so that a synthetic scene's own text starts on line 7.
const CAMERA: &str = "PerspectiveCamera {\n    center 0 0 10\n    direction 0 0 -1\n    up 0 1 0\n    angle 30\n}\n";

fn with_camera(body: &str) -> String {
    format!("{CAMERA}{body}")
}

fn sphere(center: &str) -> String {
    format!("Sphere {{ center {center} radius 1 }}")
}

fn apply(ops: &[TransformOp], p: [f64; 3]) -> DVec3 {
    composite_matrix(ops).transform_point3(DVec3::from(p))
}

fn assert_close(actual: DVec3, expected: [f64; 3]) {
    assert!(
        actual.abs_diff_eq(DVec3::from(expected), 1e-12),
        "{actual} != {expected:?}"
    );
}

fn group_children(object: &ObjectSpec) -> &[ObjectSpec] {
    match &object.shape {
        ShapeSpec::Group { objects } => objects,
        other => panic!("expected a group, got {other:?}"),
    }
}

fn mesh_path(object: &ObjectSpec) -> &Path {
    match &object.shape {
        ShapeSpec::Mesh { obj } => obj,
        other => panic!("expected a mesh, got {other:?}"),
    }
}

#[test]
fn all_seven_course_scenes_load_with_the_course_defaults() {
    for name in SCENES {
        let case = course_scene(name);
        assert_eq!(case.name, name.trim_end_matches(".txt"));
        let r = &case.render;
        assert_eq!(
            (
                r.trace.width,
                r.trace.height,
                r.trace.bounces,
                r.trace.samples,
                r.trace.seed
            ),
            (100, 100, 0, 1, 0)
        );
        assert_eq!(
            (r.profile, r.tonemap, r.trace.filter),
            (Profile::Mit6837, Tonemap::Clamp, Filter::None)
        );
        assert!(!r.trace.shadows && !r.normals && r.depth_range.is_none());
        assert!(!case.objects.is_empty(), "{name}");
    }
}

#[test]
fn scene01_has_five_spheres_a_plane_and_their_material_indices() {
    let case = course_scene("scene01_plane.txt");
    let kinds: Vec<&str> = case
        .objects
        .iter()
        .map(|o| match o.shape {
            ShapeSpec::Sphere { .. } => "sphere",
            ShapeSpec::Plane { .. } => "plane",
            _ => "other",
        })
        .collect();
    assert_eq!(kinds, ["sphere", "sphere", "sphere", "sphere", "sphere", "plane"]);
    let materials: Vec<Option<usize>> = case.objects.iter().map(|o| o.material).collect();
    assert_eq!(materials, [0, 1, 1, 2, 2, 3].map(Some));
    assert_eq!(
        case.objects[5].shape,
        ShapeSpec::Plane {
            normal: [0.0, 1.0, 0.0],
            offset: -2.0
        }
    );
    assert_eq!(
        case.objects[1].shape,
        ShapeSpec::Sphere {
            center: [1.0, 1.0, 1.0],
            radius: 0.75
        }
    );
    assert_eq!(case.materials.len(), 4);
    assert_eq!(case.materials[3].name, "material3");
    assert_eq!(case.materials[3].shininess, 20.0, "`shininess 20}}` keeps its number");
    assert_eq!(case.materials[1].diffuse, [0.0, 1.0, 0.0]);
    assert_eq!(case.materials[1].specular, [0.0; 3]);
    assert_eq!(case.camera.fov, 30.0);
    assert_eq!(case.background.color, [0.0; 3]);
    assert_eq!(case.background.ambient, [0.1; 3]);
    assert_eq!(
        case.lights,
        [LightSpec::Point {
            position: [0.0, 5.0, 5.0],
            color: [0.9; 3],
            falloff: 0.025
        }]
    );
    assert_eq!(
        case.objects[2].location,
        SourceLocation {
            file: data_dir().join("scene01_plane.txt"),
            line: 48,
            column: 5
        }
    );
}

#[test]
fn scene02_and_scene05_resolve_their_meshes_beside_the_scene() {
    let case = course_scene("scene02_cube.txt");
    let obj = mesh_path(&case.objects[0]);
    assert_eq!(obj, data_dir().join("models/cube2.obj"));
    assert!(obj.is_file());
    assert_eq!(case.background.color, [0.2, 0.0, 0.6]);
    let case = course_scene("scene05_bunny_200.txt");
    assert!(mesh_path(&case.objects[0]).ends_with("models/bunny_200.obj"));
    assert_eq!(case.lights.len(), 2);
    assert_eq!(case.materials[0].diffuse, [0.79, 0.66, 0.44]);
}

#[test]
fn scene03_lists_its_ops_in_the_written_order() {
    let case = course_scene("scene03_sphere.txt");
    let sphere = &case.objects[0];
    assert_eq!(
        sphere.transform,
        [TransformOp::RotateZ(45.0), TransformOp::Scale([1.0, 0.2, 1.0])]
    );
    assert_eq!(sphere.material, Some(0));
    assert_eq!(case.camera.fov, 20.0);
}

#[test]
fn scene04_nests_a_group_whose_transforms_apply_scale_first() {
    let case = course_scene("scene04_axes.txt");
    assert_eq!(case.camera.direction, [-0.16, -0.12, -0.5]);
    assert_eq!(case.objects.len(), 2);
    let axes = group_children(&case.objects[0]);
    assert_eq!(case.objects[0].material, None);
    assert!(case.objects[0].transform.is_empty());
    assert_eq!(axes.len(), 3);
    for (i, axis) in axes.iter().enumerate() {
        assert_eq!(axis.material, Some(i));
        assert!(mesh_path(axis).ends_with("models/cube2.obj"));
        let mut expected = [0.2; 3];
        expected[i] = 10.0;
        assert_close(apply(&axis.transform, [1.0; 3]), expected);
    }
    assert_eq!(
        axes[0].transform,
        [
            TransformOp::Translate([5.0, 0.0, 0.0]),
            TransformOp::Scale([5.0, 0.2, 0.2])
        ]
    );
    let block = &case.objects[1];
    assert_eq!(block.material, Some(3));
    assert_eq!(
        block.transform,
        [
            TransformOp::Translate([4.0, 3.0, 1.0]),
            TransformOp::RotateX(10.0),
            TransformOp::RotateY(20.0),
            TransformOp::RotateZ(30.0),
            TransformOp::Scale([2.0, 0.5, 3.0]),
        ]
    );
}

#[test]
fn scenes_06_and_07_resolve_their_cube_map_and_drop_the_colour_it_replaces() {
    for name in ["scene06_bunny_1k.txt", "scene07_arch.txt"] {
        let case = course_scene(name);
        let cube_map = case.background.cube_map.as_ref().expect("a cube map");
        assert_eq!(cube_map, &data_dir().join("tex/church"));
        assert!(cube_map.join("left.png").is_file());
        assert_eq!(case.background.color, [0.0; 3], "{name}");
        assert_eq!(case.background.ambient, [0.1; 3], "{name}");
    }
    let case = course_scene("scene06_bunny_1k.txt");
    assert_eq!(case.materials[0].diffuse, [0.2, 0.2, 0.3], "fields in any order");
    assert_eq!(case.materials[0].shininess, 30.0);
}

#[test]
fn scene07_has_a_point_light_with_falloff_and_four_coloured_parts() {
    let case = course_scene("scene07_arch.txt");
    assert_eq!(
        case.lights[1],
        LightSpec::Point {
            position: [-2.0, 4.0, -2.0],
            color: [1.4; 3],
            falloff: 0.7
        }
    );
    assert_eq!(case.camera.direction, [0.4, -0.5, -0.75]);
    let materials: Vec<Option<usize>> = case.objects.iter().map(|o| o.material).collect();
    assert_eq!(materials, [0, 1, 2, 3].map(Some));
    assert_eq!(case.materials[0].shininess, 1.0);
    assert_eq!(
        case.objects[1].transform,
        [
            TransformOp::Translate([-0.8, 0.0, -2.0]),
            TransformOp::Scale([0.25, 1.0, 0.25]),
            TransformOp::RotateY(45.0),
            TransformOp::Translate([0.0, 1.0, 0.0]),
        ]
    );
}

/// One material and a group of one sphere that uses it.
const ONE_SPHERE: &str = "Materials { numMaterials 1 Material { } }\nGroup { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n";

/// The course tests `numLights` of the latest Lights block, not the lights it holds.
#[test]
fn without_lights_the_ambient_light_is_white_whatever_the_file_says() {
    let background = "Background { color 0 0 0 ambientLight 0.1 0.2 0.3 }\n";
    let no_block = parse_ok(&with_camera(&format!("{background}{ONE_SPHERE}")));
    assert_eq!(no_block.background.ambient, [1.0; 3]);
    assert!(no_block.lights.is_empty());
    let zero = parse_ok(&with_camera(&format!(
        "Lights {{ numLights 0 }}\n{background}{ONE_SPHERE}"
    )));
    assert_eq!(zero.background.ambient, [1.0; 3]);
    let light = "Lights { numLights 1 DirectionalLight { direction 0 0 -1 color 1 1 1 } }\n";
    let lit = parse_ok(&with_camera(&format!("{light}{background}{ONE_SPHERE}")));
    assert_eq!(lit.background.ambient, [0.1, 0.2, 0.3]);
    let zero_after = parse_ok(&with_camera(&format!(
        "{light}Lights {{ numLights 0 }}\n{background}{ONE_SPHERE}"
    )));
    assert_eq!(zero_after.background.ambient, [1.0; 3], "the latest count is 0");
    assert_eq!(zero_after.lights.len(), 1, "and the earlier light still shines");
}

#[test]
fn missing_optional_blocks_take_the_course_defaults() {
    let case = parse_ok(&with_camera(ONE_SPHERE));
    assert_eq!(case.background.color, [0.5; 3]);
    assert_eq!(case.materials[0].diffuse, [1.0; 3]);
    let case = parse_ok(&with_camera(
        "Materials { numMaterials 1 PhongMaterial { bump tex/none.png } }\nGroup { numObjects 0 }",
    ));
    assert_eq!(case.materials[0].diffuse, [1.0; 3]);
    assert_eq!(case.materials[0].specular, [0.0; 3]);
    assert_eq!(case.materials[0].shininess, 0.0);
}

#[test]
fn the_flags_become_render_settings() {
    let options = AssignmentOptions {
        width: 800,
        height: 600,
        bounces: 4,
        shadows: true,
        jitter: true,
        filter: true,
        depth_range: Some((8.0, 18.0)),
        normals: true,
    };
    let path = data_dir().join("scene07_arch.txt");
    let case = load_assignment_scene(&path, &options).unwrap();
    let r = &case.render;
    assert_eq!(
        (r.trace.width, r.trace.height, r.trace.bounces, r.trace.samples),
        (800, 600, 4, 16)
    );
    assert!(r.trace.shadows && r.normals);
    assert_eq!(r.trace.filter, Filter::Gaussian);
    assert_eq!(r.depth_range, Some((8.0, 18.0)));
    assert_eq!(case.tolerance, course_scene("scene01_plane.txt").tolerance);
    let bad = AssignmentOptions {
        depth_range: Some((18.0, 8.0)),
        ..options.clone()
    };
    let message = load_assignment_scene(&path, &bad).unwrap_err().to_string();
    assert!(message.contains("-depth 18 8: needs finite min < max"), "{message}");
    let bad = AssignmentOptions { width: 0, ..options };
    assert!(load_assignment_scene(&path, &bad).is_err());
}
