//! Internals of case loading: transform algebra, and robustness against arbitrary input (parse
//! will be fuzzed).

use std::path::Path;

use glam::{DMat4, DVec3};
use proptest::prelude::*;

use super::*;

fn apply(ops: &[TransformOp], p: [f64; 3]) -> DVec3 {
    composite_matrix(ops).transform_point3(DVec3::from(p))
}

fn close(a: DVec3, b: [f64; 3]) -> bool {
    a.abs_diff_eq(DVec3::from(b), 1e-12)
}

#[test]
fn the_last_op_is_applied_first() {
    let ops = [TransformOp::Translate([1.0, 0.0, 0.0]), TransformOp::UniformScale(2.0)];
    assert!(close(apply(&ops, [1.0, 0.0, 0.0]), [3.0, 0.0, 0.0]));
    let ops = [TransformOp::UniformScale(2.0), TransformOp::Translate([1.0, 0.0, 0.0])];
    assert!(close(apply(&ops, [1.0, 0.0, 0.0]), [4.0, 0.0, 0.0]));
    assert_eq!(composite_matrix(&[]), DMat4::IDENTITY);
}

#[test]
fn rotations_are_right_handed_degrees_and_normalise_their_axis() {
    assert!(close(
        apply(&[TransformOp::RotateZ(90.0)], [1.0, 0.0, 0.0]),
        [0.0, 1.0, 0.0]
    ));
    assert!(close(
        apply(&[TransformOp::RotateX(90.0)], [0.0, 1.0, 0.0]),
        [0.0, 0.0, 1.0]
    ));
    assert!(close(
        apply(&[TransformOp::RotateY(90.0)], [0.0, 0.0, 1.0]),
        [1.0, 0.0, 0.0]
    ));
    let about_z = TransformOp::Rotate {
        axis: [0.0, 0.0, 5.0],
        degrees: 90.0,
    };
    assert!(close(apply(&[about_z], [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
    let scale = TransformOp::Scale([1.0, 2.0, 3.0]);
    assert!(close(apply(&[scale], [1.0, 1.0, 1.0]), [1.0, 2.0, 3.0]));
}

#[test]
fn matrices_are_row_major_as_written() {
    let mut m = [0.0; 16];
    m[0] = 1.0;
    m[5] = 1.0;
    m[10] = 1.0;
    m[15] = 1.0;
    m[3] = 4.0;
    m[1] = 2.0;
    let op = TransformOp::Matrix(m);
    assert!(close(
        apply(std::slice::from_ref(&op), [0.0, 0.0, 0.0]),
        [4.0, 0.0, 0.0]
    ));
    assert!(close(apply(&[op], [0.0, 1.0, 0.0]), [6.0, 1.0, 0.0]), "x' = x + 2y + 4");
}

const CAMERA: &str = "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";

fn transform_result(transform: &str) -> Result<Case, CaseError> {
    let source =
        format!("{CAMERA}[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = {transform}\n");
    parse(&source, Path::new("t.toml"), &LoadOptions::default())
}

#[test]
fn invertibility_ignores_translation_and_uniform_scale_but_not_flattening() {
    assert!(transform_result("[{ translate = [1e12, 0, 0] }]").is_ok());
    assert!(transform_result("[{ uniform_scale = 1e-9 }]").is_ok());
    assert!(transform_result("[{ uniform_scale = 1e9 }, { rotate = { axis = [1, 2, 3], degrees = 17 } }]").is_ok());
    let projective = "[{ matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0.5, 1] }]";
    assert!(transform_result(projective).is_ok());
    let flat = "[{ matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0] }]";
    assert!(transform_result(flat).unwrap_err().to_string().contains("singular"));
    assert!(
        transform_result("[{ scale = [1, 1e-14, 1] }]")
            .unwrap_err()
            .to_string()
            .contains("singular")
    );
    assert!(
        transform_result("[{ uniform_scale = 1e-200 }]")
            .unwrap_err()
            .to_string()
            .contains("singular")
    );
    assert!(transform_result("[{ uniform_scale = 0 }]").is_err());
}

#[test]
fn long_values_are_shortened_in_messages() {
    let many = vec!["1"; 100].join(", ");
    let message = transform_result(&format!("[{{ matrix = [{many}] }}]"))
        .unwrap_err()
        .to_string();
    assert!(message.contains("but has 100 elements, found [1, 1,"), "{message}");
    assert!(message.ends_with('…'), "{message}");
    assert!(message.chars().count() < 200, "{message}");
}

#[test]
fn integers_too_large_for_64_bits_are_an_error_not_a_panic() {
    let source = format!("[render]\nseed = 99999999999999999999\n{CAMERA}");
    let message = parse(&source, Path::new("t.toml"), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with("t.toml:2:8: seed must be an integer that fits in 64 bits"),
        "{message}"
    );
}

#[test]
fn deeply_nested_groups_parse() {
    let mut object = "{ kind = \"sphere\", center = [0, 0, 0], radius = 1 }".to_owned();
    for _ in 0..30 {
        object = format!("{{ kind = \"group\", objects = [{object}] }}");
    }
    let source = format!("object = [{object}]\n{CAMERA}");
    let mut case = parse(&source, Path::new("t.toml"), &LoadOptions::default()).unwrap();
    let mut depth = 0;
    while let ShapeSpec::Group { mut objects } = case.objects.remove(0).shape {
        case.objects = std::mem::take(&mut objects);
        depth += 1;
    }
    assert_eq!(depth, 30);
}

const VALID: &str = r#"[render]
size = [20, 10]
samples = 4
[camera]
center = [0, 0, 10]
direction = [0, 0, -1]
up = [0, 1, 0]
fov = 30
[materials.red]
diffuse = [1, 0, 0]
[[light]]
kind = "point"
position = [0, 5, 5]
color = [1, 1, 1]
falloff = 1
[[object]]
kind = "group"
material = "red"
transform = [{ rotate = { axis = [1, 0, 0], degrees = 3 } }, { matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] }]
objects = [{ kind = "plane", normal = [0, 1, 0], offset = -1 }, { kind = "triangle", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]] }]
"#;

proptest! {
    #[test]
    fn arbitrary_text_never_panics(source in "\\PC{0,200}") {
        let _ = parse(&source, Path::new("f.toml"), &LoadOptions::default());
    }

    #[test]
    fn mutated_cases_never_panic(
        position in 0..VALID.len(),
        cut in 0usize..8,
        insert in prop::sample::select(vec![
            "", "nan", "-inf", "0", "-1", "1e308", "\"", "[", "]", "{", "}", "=", "\n", "é",
            "[0, 0]", "\"x\"", "99999999999999999999", "0x7fffffffffffffff", "[[object]]\n",
        ]),
    ) {
        let mut source = VALID.to_owned();
        let end = (position + cut).min(source.len());
        source.replace_range(position..end, insert);
        let _ = parse(&source, Path::new("f.toml"), &LoadOptions { allow_huge_images: cut % 2 == 0 });
    }
}

#[test]
fn the_mutation_base_is_valid() {
    assert!(parse(VALID, Path::new("f.toml"), &LoadOptions::default()).is_ok());
}
