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
         Group { numObjects 2 Sphere { center -.16 .4 1e1 radius 1} Plane { normal 0 1 0 offset -2} }",
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
         Group {{ numObjects 4\n\
           {first}\n\
           MaterialIndex 0\n\
           Group {{ numObjects 2 {a} MaterialIndex 1 {b} }}\n\
           {after}\n\
           Transform {{ Translate 1 0 0 Group {{ numObjects 2 {c} MaterialIndex 2 {d} }} }}\n\
         }}",
        first = sphere("9 9 9"),
        a = sphere("1 0 0"),
        b = sphere("2 0 0"),
        after = sphere("3 0 0"),
        c = sphere("4 0 0"),
        d = sphere("5 0 0"),
    )));
    assert_eq!(case.objects[0].material, None, "before any MaterialIndex");
    let nested = group_children(&case.objects[1]);
    assert_eq!(case.objects[1].material, None, "groups hold no material");
    assert_eq!([nested[0].material, nested[1].material], [Some(0), Some(1)]);
    assert_eq!(
        case.objects[2].material,
        Some(1),
        "a MaterialIndex inside a nested group still holds after it closes, as in the course"
    );
    let transformed = group_children(&case.objects[3]);
    assert_eq!(case.objects[3].transform, [TransformOp::Translate([1.0, 0.0, 0.0])]);
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

#[test]
fn repeated_blocks_replace_or_update_the_earlier_ones_as_in_the_course() {
    let case = parse_ok(&format!(
        "Background {{ color 1 0 0 }}\n{CAMERA}Background {{ ambientLight 0.5 0.5 0.5 }}\n\
         Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 {} }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 0 1 0 }} }}\n\
         Group {{ numObjects 2 {} MaterialIndex 0 {} }}\n",
        sphere("0 0 0"),
        sphere("1 0 0"),
        sphere("2 0 0"),
    ));
    assert_eq!(case.background.color, [1.0, 0.0, 0.0]);
    assert_eq!(case.background.ambient, [0.5; 3]);
    assert_eq!(case.objects.len(), 2, "the last Group is the scene");
    assert_eq!(case.materials[1].diffuse, [0.0, 1.0, 0.0]);
    assert_eq!(case.objects[0].material, Some(0), "still the first block's material");
    assert_eq!(case.objects[1].material, Some(1), "index 0 of the latest block");
}
