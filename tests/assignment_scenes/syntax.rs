//! The corners of the course's grammar that its own scenes and students' scenes rely on.

use std::fs;

use super::*;
use crate::export::same_case;

fn one_object(object: &str) -> ObjectSpec {
    let source = with_camera(&format!(
        "Materials {{ numMaterials 1 Material {{ }} }}\nGroup {{ numObjects 1 MaterialIndex 0 {object} }}\n"
    ));
    parse_ok(&source).objects.remove(0)
}

#[test]
fn numbers_may_touch_a_closing_brace_and_drop_leading_digits() {
    let case = parse_ok(&with_camera(
        "Materials { numMaterials 1 Material { diffuseColor .4 +.5 -0 shininess 20} }\n\
         Group { numObjects 2 MaterialIndex 0 Sphere { center -.16 .4 1e1 radius 1} Plane { normal 0 1 0 offset -2} }",
    ));
    assert_eq!(case.materials[0].diffuse, [0.4, 0.5, 0.0]);
    assert_eq!(case.materials[0].shininess, 20.0);
    assert_eq!(
        case.objects[0].shape,
        ShapeSpec::Sphere {
            center: [-0.16, 0.4, 10.0],
            radius: 1.0
        }
    );
    assert_eq!(
        case.objects[1].shape,
        ShapeSpec::Plane {
            normal: [0.0, 1.0, 0.0],
            offset: -2.0
        }
    );
}

#[test]
fn crlf_and_tabs_read_like_newlines_and_spaces() {
    let path = data_dir().join("scene01_plane.txt");
    let text = fs::read_to_string(&path).unwrap();
    let windows = text.replace('\n', "\r\n").replace("    ", "\t");
    let original = parse_assignment_scene(&text, &path, &AssignmentOptions::default()).unwrap();
    let converted = parse_assignment_scene(&windows, &path, &AssignmentOptions::default()).unwrap();
    same_case(&converted, &original);
    assert_eq!(converted.objects[2].location.line, 48, "\\r\\n is one line break");
    assert_eq!(converted.objects[2].location.column, 2, "a tab is one column");
    let broken = windows.replace("radius 0.75\r\n", "radius x\r\n");
    let error = parse_assignment_scene(&broken, &path, &AssignmentOptions::default()).unwrap_err();
    let location = error.location().unwrap();
    assert_eq!((location.line, location.column), (46, 10), "{error}");
}

#[test]
fn material_index_is_one_current_material_for_the_whole_file() {
    let case = parse_ok(&with_camera(&format!(
        "Materials {{ numMaterials 3 Material {{ }} Material {{ }} Material {{ }} }}\n\
         Group {{ numObjects 3\n\
           MaterialIndex 0\n\
           Group {{ numObjects 2 {a} MaterialIndex 1 {b} }}\n\
           {after}\n\
           Transform {{ Translate 1 0 0 Group {{ numObjects 2 {c} MaterialIndex 2 {d} }} }}\n\
         }}",
        a = sphere("1 0 0"),
        b = sphere("2 0 0"),
        after = sphere("3 0 0"),
        c = sphere("4 0 0"),
        d = sphere("5 0 0"),
    )));
    let nested = group_children(&case.objects[0]);
    assert_eq!(case.objects[0].material, None, "groups hold no material");
    assert_eq!([nested[0].material, nested[1].material], [Some(0), Some(1)]);
    assert_eq!(
        case.objects[1].material,
        Some(1),
        "a MaterialIndex inside a nested group still holds after it closes, as in the course"
    );
    let transformed = group_children(&case.objects[2]);
    assert_eq!(case.objects[2].transform, [TransformOp::Translate([1.0, 0.0, 0.0])]);
    assert_eq!([transformed[0].material, transformed[1].material], [Some(1), Some(2)]);
}

#[test]
fn matrix4f_is_read_by_columns_and_multiplies_from_the_left() {
    let translate_456 = "Matrix4f { 1 0 0 0  0 1 0 0  0 0 1 0  4 5 6 1 }";
    let alone = one_object(&format!("Transform {{ {translate_456} {} }}", sphere("0 0 0")));
    assert_close(apply(&alone.transform, [0.0; 3]), [4.0, 5.0, 6.0]);
    let mixed = one_object(&format!(
        "Transform {{ UniformScale 2 {translate_456} ZRotate 90 {} }}",
        sphere("0 0 0")
    ));
    // M = (Matrix · Scale) · Rotate: the matrix is applied last although it is written second.
    assert!(matches!(mixed.transform[0], TransformOp::Matrix(_)));
    assert_eq!(
        mixed.transform[1..],
        [TransformOp::UniformScale(2.0), TransformOp::RotateZ(90.0)]
    );
    assert_close(apply(&mixed.transform, [1.0, 0.0, 0.0]), [4.0, 7.0, 6.0]);
    let TransformOp::Matrix(m) = mixed.transform[0] else {
        unreachable!()
    };
    assert_eq!(m[3], 4.0, "row-major: the translation is the last column");
}

#[test]
fn rotate_takes_an_unnormalised_axis_and_degrees() {
    let object = one_object(&format!("Transform {{ Rotate {{ 0 0 5 90 }} {} }}", sphere("0 0 0")));
    assert_eq!(
        object.transform,
        [TransformOp::Rotate {
            axis: [0.0, 0.0, 5.0],
            degrees: 90.0
        }]
    );
    assert_close(apply(&object.transform, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
}

#[test]
fn nested_transforms_put_the_outer_ops_first() {
    let object = one_object(&format!(
        "Transform {{ Translate 1 0 0 Transform {{ UniformScale 3 {} }} }}",
        sphere("0 0 0")
    ));
    assert_eq!(
        object.transform,
        [TransformOp::Translate([1.0, 0.0, 0.0]), TransformOp::UniformScale(3.0)]
    );
    assert_close(apply(&object.transform, [1.0, 0.0, 0.0]), [4.0, 0.0, 0.0]);
}

#[test]
fn triangles_have_no_normals_and_meshes_resolve_beside_the_scene() {
    let triangle = one_object("Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }");
    assert_eq!(
        triangle.shape,
        ShapeSpec::Triangle {
            vertices: [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: None
        }
    );
    let mesh = one_object("TriangleMesh { obj_file models/cube.obj }");
    assert_eq!(mesh_path(&mesh), data_dir().join("models/cube.obj"));
    assert_eq!(mesh.material, Some(0));
}

/// Checked against the course binary: its material and light lists grow with every block while
/// `numMaterials` and `numLights` are replaced, so `MaterialIndex k` counts from the first
/// material of the file and must stay below the latest count.
#[test]
fn repeated_blocks_replace_update_or_add_up_as_in_the_course() {
    let case = parse_ok(&format!(
        "Background {{ color 1 0 0 }}\n{CAMERA}Background {{ ambientLight 0.5 0.5 0.5 }}\n\
         Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 {} }}\n\
         Lights {{ numLights 1 PointLight {{ position 0 5 0 color 1 1 1 falloff 1 }} }}\n\
         Materials {{ numMaterials 2 Material {{ diffuseColor 0 1 0 }} Material {{ diffuseColor 0 0 1 }} }}\n\
         Group {{ numObjects 2 MaterialIndex 0 {} MaterialIndex 1 {} }}\n",
        sphere("0 0 0"),
        sphere("1 0 0"),
        sphere("2 0 0"),
    ));
    assert_eq!(case.background.color, [1.0, 0.0, 0.0]);
    assert_eq!(case.background.ambient, [0.5; 3]);
    assert_eq!(case.objects.len(), 2, "the last Group is the scene");
    assert_eq!(case.materials.len(), 3);
    assert_eq!(case.materials[1].diffuse, [0.0, 1.0, 0.0]);
    assert_eq!(
        [case.objects[0].material, case.objects[1].material],
        [Some(0), Some(1)],
        "MaterialIndex 0 and 1 are the file's first and second materials, from two blocks"
    );
    assert_eq!(case.lights.len(), 2, "both Lights blocks shine");
    let error = try_parse(&format!(
        "{CAMERA}Materials {{ numMaterials 2 Material {{ }} Material {{ }} }}\n\
         Materials {{ numMaterials 1 Material {{ }} }}\n\
         Group {{ numObjects 1 MaterialIndex 2 {} }}\n",
        sphere("0 0 0")
    ))
    .unwrap_err()
    .to_string();
    assert!(
        error.contains("`MaterialIndex 2` is out of range: the latest Materials block has numMaterials 1"),
        "{error}"
    );
}

/// The issue's own example: the course reads PointLight fields in a loop, in any order, each
/// optional (position and color default to 0) and the last of a repeated one winning.
#[test]
fn point_light_fields_come_in_any_order() {
    let light = |fields: &str| {
        let case = parse_ok(&with_camera(&format!(
            "Lights {{ numLights 1 PointLight {{ {fields} }} }}\nGroup {{ numObjects 0 }}"
        )));
        case.lights[0].clone()
    };
    let expected = LightSpec::Point {
        position: [0.0, 5.0, 5.0],
        color: [0.9; 3],
        falloff: 0.025,
    };
    assert_eq!(light("falloff 0.025 color 0.9 0.9 0.9 position 0 5 5"), expected);
    assert_eq!(light("color 0.9 0.9 0.9 position 0 5 5 falloff 0.025"), expected);
    assert_eq!(
        light("falloff 1 position 0 5 5 falloff 0.025 color 0.9 0.9 0.9"),
        expected,
        "the last falloff counts"
    );
    assert_eq!(
        light("falloff 0.5"),
        LightSpec::Point {
            position: [0.0; 3],
            color: [0.0; 3],
            falloff: 0.5
        },
        "position and color default to zero"
    );
}

/// Every row was read by the course binary (glibc's `fscanf("%f")`) to the same picture as the
/// plain decimal.
#[test]
fn numbers_are_read_as_c_reads_them() {
    let case = parse_ok(&with_camera(
        "Materials { numMaterials 1 Material { diffuseColor 0x.8 0X1p-1 +5e-1 shininess 0x1.4p4} }\n\
         Group { numObjects 3 MaterialIndex 0\n\
           Sphere { center 1e 2e+ -3E- radius 1e}\n\
           Sphere { center 1-2-3 radius -0x1p1 }\n\
           Sphere { center 0 0 0radius +2. }\n\
         }",
    ));
    assert_eq!(case.materials[0].diffuse, [0.5; 3]);
    assert_eq!(case.materials[0].shininess, 20.0);
    let spheres: Vec<&ShapeSpec> = case.objects.iter().map(|o| &o.shape).collect();
    assert_eq!(
        spheres,
        [
            &ShapeSpec::Sphere {
                center: [1.0, 2.0, -3.0],
                radius: 1.0
            },
            &ShapeSpec::Sphere {
                center: [1.0, -2.0, -3.0],
                radius: 2.0
            },
            &ShapeSpec::Sphere {
                center: [0.0; 3],
                radius: 2.0
            },
        ],
        "an exponent without digits reads as nothing, a sign starts a new number, a word may touch \
         a number, and a negative radius is its absolute value"
    );
}

/// `%d` takes a sign and leading zeros, and stops before what cannot continue a number.
#[test]
fn counts_are_read_as_c_reads_them() {
    let case = parse_ok(&with_camera(&format!(
        "Materials {{ numMaterials +02 Material {{ }} Material {{ }} }}\n\
         Group {{ numObjects 02 MaterialIndex +1{} MaterialIndex -0 Group {{ numObjects -0}} }}",
        sphere("0 0 0")
    )));
    assert_eq!(case.materials.len(), 2);
    assert_eq!(case.objects[0].material, Some(1));
    assert_eq!(case.objects[1].shape, ShapeSpec::Group { objects: Vec::new() });
}

/// The course's keyword aliases and its ignored `bump` field.
#[test]
fn phong_material_is_material_and_bump_is_read_and_ignored() {
    let case = parse_ok(&with_camera(
        "Materials { numMaterials 2 PhongMaterial { bump tex/none.png shininess 3 } \
         Material { shininess 3 bump whatever } }\nGroup { numObjects 0 }",
    ));
    assert_eq!(case.materials[0].shininess, 3.0);
    assert_eq!(
        (case.materials[0].diffuse, case.materials[0].specular),
        (case.materials[1].diffuse, case.materials[1].specular)
    );
}

/// The generated scenes of the differential test (`examples/course_diff`), which the course
/// binary renders, all load here and survive the trip through TOML.
#[test]
fn generated_scenes_are_accepted_and_round_trip() {
    let path = data_dir().join("generated.txt");
    for seed in 1..=200 {
        let scene = generate::scene(seed);
        let case = parse_assignment_scene(&scene.text, &path, &AssignmentOptions::default())
            .unwrap_or_else(|e| panic!("seed {seed}: {e}\n{}", scene.text));
        let text = goldray::case::case_to_toml(&case, &path.with_extension("toml"));
        let loaded = goldray::case::parse(&text, &path.with_extension("toml"), &Default::default())
            .unwrap_or_else(|e| panic!("seed {seed}: {e}\n{text}"));
        same_case(&loaded, &case);
    }
}
