//! A full case parses to exactly the expected values, and omitted settings get their defaults.

use goldray::case::{BackgroundSpec, CameraSpec, LightSpec, LoadOptions, MaterialSpec, ShapeSpec, TransformOp, load};
use goldray::compare::Tolerance;
use goldray::film::Tonemap;
use goldray::options::{Filter, Profile};

use super::*;

const FULL: &str = r#"description = "every kind of object, light and transform op"

[render]
size = [320, 240]
bounces = 3
shadows = true
samples = 16
seed = 7
filter = "gaussian"
depth_range = [8.0, 18]
normals = true
profile = "mit6837"

[tolerance]
pixel = 0.02
max = 0.5

[camera]
center = [0, 0, 10]
direction = [0, 0, -1]
up = [0, 1, 0]
fov = 30

[background]
ambient = [0.1, 0.1, 0.1]
cube_map = "tex/church"

[[light]]
kind = "point"
position = [0, 5, 5]
color = [0.9, 0.9, 0.9]
falloff = 0.025

[[light]]
kind = "directional"
direction = [-1, -1, -1]
color = [0.5, 0.5, 0.5]

[materials.red]
diffuse = [1, 0, 0]
specular = [1, 1, 1]
shininess = 20

[materials.blank]

[[object]]
kind = "sphere"
center = [0, 0, 0]
radius = 1
material = "red"
transform = [{ translate = [0, 1, 0] }, { rotate_y = 45 }, { scale = [1, 0.2, 1] }]

[[object]]
kind = "plane"
normal = [0, 1, 0]
offset = -2
transform = [{ uniform_scale = 2 }, { rotate_x = 10 }, { rotate_z = -5 },
             { rotate = { axis = [1, 1, 0], degrees = 30 } },
             { matrix = [1, 0, 0, 4, 0, 1, 0, 5, 0, 0, 1, 6, 0, 0, 0, 1] }]

[[object]]
kind = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
normals = [[0, 0, 1], [0, 0, 1], [0, 0.1, 1]]

[[object]]
kind = "mesh"
obj = "models/tri.obj"
material = "blank"

[[object]]
kind = "group"
material = "red"
objects = [
  { kind = "sphere", center = [1, 2, 3], radius = 0 },
  { kind = "group", material = "blank", objects = [
      { kind = "sphere", center = [0, 0, 0], radius = 0.5, material = "red" },
  ] },
]
"#;

#[test]
fn a_full_case_parses_to_the_expected_values() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(dir.path(), "models/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for face in ["left", "right", "up", "down", "front", "back"] {
        write(dir.path(), &format!("tex/church/{face}.png"), "");
    }
    let path = write(dir.path(), "full.toml", FULL);
    let case = load(&path, &LoadOptions::default()).unwrap();

    assert_eq!(case.name, "full");
    assert_eq!(case.path, path);
    assert_eq!(
        case.description.as_deref(),
        Some("every kind of object, light and transform op")
    );
    let r = &case.render;
    assert_eq!(
        (
            r.trace.width,
            r.trace.height,
            r.trace.bounces,
            r.trace.samples,
            r.trace.seed
        ),
        (320, 240, 3, 16, 7)
    );
    assert!(r.trace.shadows && r.normals);
    assert_eq!(r.trace.filter, Filter::Gaussian);
    assert_eq!(r.depth_range, Some((8.0, 18.0)));
    assert_eq!(r.profile, Profile::Mit6837);
    assert_eq!(
        r.tonemap,
        Tonemap::Clamp,
        "mit6837 defaults to the assignment's quantiser"
    );
    assert_eq!(
        case.tolerance,
        Tolerance {
            pixel: 0.02,
            fail_fraction: 0.001,
            rmse: 0.002,
            max: Some(0.5)
        }
    );
    assert_eq!(
        case.camera,
        CameraSpec {
            center: [0.0, 0.0, 10.0],
            direction: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            fov: 30.0
        }
    );
    assert_eq!(
        case.background,
        BackgroundSpec {
            color: [0.0; 3],
            ambient: [0.1; 3],
            cube_map: Some(dir.path().join("tex/church")),
        }
    );
    assert_eq!(
        case.lights,
        vec![
            LightSpec::Point {
                position: [0.0, 5.0, 5.0],
                color: [0.9; 3],
                falloff: 0.025
            },
            LightSpec::Directional {
                direction: [-1.0; 3],
                color: [0.5; 3]
            },
        ]
    );
    assert_eq!(
        case.materials,
        vec![
            MaterialSpec {
                name: "red".into(),
                diffuse: [1.0, 0.0, 0.0],
                specular: [1.0; 3],
                shininess: 20.0
            },
            MaterialSpec {
                name: "blank".into(),
                diffuse: [1.0; 3],
                specular: [0.0; 3],
                shininess: 0.0
            },
        ],
        "file order and defaults"
    );

    let [sphere, plane, triangle, mesh, group] = case.objects.as_slice() else {
        panic!("expected 5 objects, got {:?}", case.objects)
    };
    assert_eq!(
        sphere.shape,
        ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 1.0
        }
    );
    assert_eq!(sphere.material, Some(0));
    assert_eq!(
        sphere.transform,
        vec![
            TransformOp::Translate([0.0, 1.0, 0.0]),
            TransformOp::RotateY(45.0),
            TransformOp::Scale([1.0, 0.2, 1.0])
        ]
    );
    assert_eq!((sphere.location.line, sphere.location.column), (46, 1));
    assert_eq!(sphere.location.file, path);

    assert_eq!(
        plane.shape,
        ShapeSpec::Plane {
            normal: [0.0, 1.0, 0.0],
            offset: -2.0
        }
    );
    assert_eq!(plane.material, None);
    let mut matrix = [0.0; 16];
    for (i, v) in [(0, 1.0), (3, 4.0), (5, 1.0), (7, 5.0), (10, 1.0), (11, 6.0), (15, 1.0)] {
        matrix[i] = v;
    }
    assert_eq!(
        plane.transform,
        vec![
            TransformOp::UniformScale(2.0),
            TransformOp::RotateX(10.0),
            TransformOp::RotateZ(-5.0),
            TransformOp::Rotate {
                axis: [1.0, 1.0, 0.0],
                degrees: 30.0
            },
            TransformOp::Matrix(matrix),
        ]
    );

    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let n = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.1, 1.0]];
    assert_eq!(
        triangle.shape,
        ShapeSpec::Triangle {
            vertices: v,
            normals: Some(n)
        }
    );
    assert!(triangle.transform.is_empty());

    assert_eq!(mesh.shape, ShapeSpec::Mesh { obj });
    assert_eq!(mesh.material, Some(1));

    assert_eq!(group.material, Some(0));
    let ShapeSpec::Group { objects } = &group.shape else {
        panic!("not a group: {group:?}")
    };
    assert_eq!(
        objects[0].shape,
        ShapeSpec::Sphere {
            center: [1.0, 2.0, 3.0],
            radius: 0.0
        }
    );
    assert_eq!(objects[0].material, None, "inherits from the group");
    assert_eq!((objects[0].location.line, objects[0].location.column), (75, 3));
    assert_eq!(objects[1].material, Some(1));
    let ShapeSpec::Group { objects: inner } = &objects[1].shape else {
        panic!("not a group")
    };
    assert_eq!(inner[0].material, Some(0));
    assert_eq!(
        inner[0].shape,
        ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 0.5
        }
    );
}

#[test]
fn a_minimal_case_gets_every_default() {
    let case = try_parse(CAMERA).unwrap();
    let r = &case.render;
    assert_eq!(
        (
            r.trace.width,
            r.trace.height,
            r.trace.bounces,
            r.trace.samples,
            r.trace.seed
        ),
        (200, 200, 0, 1, 0)
    );
    assert!(!r.trace.shadows && !r.normals);
    assert_eq!(
        (r.trace.filter, r.profile, r.tonemap),
        (Filter::None, Profile::Native, Tonemap::Srgb)
    );
    assert_eq!(r.depth_range, None);
    assert_eq!(
        case.tolerance,
        Tolerance {
            pixel: 0.01,
            fail_fraction: 0.001,
            rmse: 0.002,
            max: None
        }
    );
    assert_eq!(
        case.background,
        BackgroundSpec {
            color: [0.0; 3],
            ambient: [0.0; 3],
            cube_map: None
        }
    );
    assert!(case.lights.is_empty() && case.materials.is_empty() && case.objects.is_empty());
    assert_eq!((case.name.as_str(), case.description), ("x", None));
}

#[test]
fn an_explicit_tonemap_overrides_the_profile_default() {
    let case = try_parse(&format!(
        "[render]\nprofile = \"mit6837\"\ntonemap = \"srgb\"\n{CAMERA}"
    ))
    .unwrap();
    assert_eq!(case.render.tonemap, Tonemap::Srgb);
}
