//! Malformed scenes: each is rejected at the line and column a person has to edit, saying what
//! was found and what would be valid.

use super::*;

/// Asserts that `source` is rejected at `line:column` with every fragment in the message.
fn assert_error(source: &str, line: usize, column: usize, fragments: &[&str]) {
    let error = match try_parse(source) {
        Ok(case) => panic!("expected an error, got {case:?}"),
        Err(e) => e,
    };
    let message = error.to_string();
    let prefix = format!("{}:{line}:{column}: ", synthetic_path().display());
    assert!(message.starts_with(&prefix), "expected {line}:{column} in: {message}");
    for fragment in fragments {
        assert!(message.contains(fragment), "expected {fragment:?} in: {message}");
    }
}

const ONE_MATERIAL: &str = "Materials { numMaterials 1 Material { } }\n";

/// A scene whose line 8 is `objects`, inside a group of `count` objects opened on line 7 after
/// one material, which is current.
fn group_of(count: usize, objects: &str) -> String {
    with_camera(&format!(
        "Materials {{ numMaterials 1 Material {{ }} }} Group {{ numObjects {count} MaterialIndex 0\n{objects}\n}}\n"
    ))
}

#[test]
fn unknown_keywords_suggest_the_nearest_valid_one() {
    assert_error(
        &group_of(1, "    Sphree { center 0 0 0 radius 1 }"),
        8,
        5,
        &[
            "unknown object `Sphree`; did you mean `Sphere`?",
            "valid objects: Group, Sphere,",
        ],
    );
    assert_error(
        &with_camera("Materails { numMaterials 0 }"),
        7,
        1,
        &["unknown block `Materails`; did you mean `Materials`?"],
    );
    assert_error(
        &with_camera("Background { colour 1 1 1 }"),
        7,
        14,
        &["unknown Background field `colour`; did you mean `color`?"],
    );
    assert_error(
        &group_of(1, "  Transform { Scael 1 2 1 Sphere { center 0 0 0 radius 1 } }"),
        8,
        15,
        &["unknown transform op or object `Scael`; did you mean `Scale`?"],
    );
}

#[test]
fn a_group_with_fewer_objects_than_announced_is_reported_at_its_closing_brace() {
    assert_error(
        &group_of(3, &format!("{}\n{}", sphere("0 0 0"), sphere("1 0 0"))),
        10,
        1,
        &["`numObjects 3` but the block closes after 2 objects"],
    );
    assert_error(
        &group_of(1, &format!("{} {}", sphere("0 0 0"), sphere("1 0 0"))),
        8,
        34,
        &["expected `}` closing Group after its 1 (numObjects) objects, found `Sphere`"],
    );
}

#[test]
fn wrong_material_and_light_counts_are_reported() {
    assert_error(
        &with_camera("Materials {\n  numMaterials 2\n  Material { }\n}\n"),
        10,
        1,
        &["`numMaterials 2` but the block closes after 1 material: add the missing material"],
    );
    assert_error(
        &with_camera(
            "Lights {\n  numLights 1\n  PointLight { position 0 0 0 color 1 1 1 falloff 1 }\n  \
             PointLight { position 0 0 0 color 1 1 1 falloff 1 }\n}\n",
        ),
        10,
        3,
        &["expected `}` closing Lights after its 1 (numLights) lights, found `PointLight`"],
    );
}

#[test]
fn material_index_must_name_a_material_of_the_block_before_it() {
    let source = format!(
        "{ONE_MATERIAL}Group {{ numObjects 1\n  MaterialIndex 1 {} }}",
        sphere("0 0 0")
    );
    assert_error(
        &with_camera(&source),
        9,
        17,
        &[
            "`MaterialIndex 1` is out of range: the latest Materials block has numMaterials 1, so indices go from 0 to 0",
        ],
    );
    let source = format!(
        "Group {{ numObjects 1 MaterialIndex 0 {} }}\n{ONE_MATERIAL}",
        sphere("0 0 0")
    );
    assert_error(
        &with_camera(&source),
        7,
        36,
        &[
            "refers to no material",
            "a Materials block with numMaterials ≥ 1 must come before the Group",
        ],
    );
    let source = format!(
        "{ONE_MATERIAL}Group {{ numObjects 1 Transform {{ MaterialIndex 0 {} }} }}",
        sphere("0 0 0")
    );
    assert_error(
        &with_camera(&source),
        8,
        34,
        &["`MaterialIndex` cannot appear inside a Transform"],
    );
}

#[test]
fn an_unclosed_block_is_reported_at_the_end_of_the_file() {
    assert_error(
        &with_camera("Group { numObjects 1\n  Sphere { center 0 0 0 radius 1\n"),
        9,
        1,
        &["expected `}` closing Sphere, found the end of the file"],
    );
    assert_error(
        &with_camera("Group { numObjects 1"),
        7,
        21,
        &["expected an object or `MaterialIndex`, found the end of the file"],
    );
    assert_error(
        &with_camera("Group { numObjects 1 Sphere{ center 0 0 0 radius 1 } }"),
        7,
        22,
        &["unknown object `Sphere{`; did you mean `Sphere`?"],
    );
    assert_error(
        &with_camera("Group { numObjects 1 Sphere {center 0 0 0 radius 1 } }"),
        7,
        29,
        &["expected `{` after `Sphere`", "braces need whitespace around them"],
    );
}

#[test]
fn values_that_are_not_numbers_are_quoted() {
    assert_error(
        &group_of(1, "  Sphere { center 0 0 0 radius }"),
        8,
        32,
        &["expected a number after `radius`, found `}`"],
    );
    assert_error(
        &group_of(1, "  Sphere { center 0 zero 0 radius 1 }"),
        8,
        21,
        &["expected 3 numbers after `center`, found `zero`"],
    );
    assert_error(
        &with_camera("Group { numObjects two }"),
        7,
        20,
        &["expected a whole number after `numObjects`, found `two`"],
    );
    assert_error(
        &with_camera("Group { numObjects 1.5 }"),
        7,
        20,
        &["expected a whole number after `numObjects`, found `1.5`"],
    );
}

#[test]
fn nan_and_infinity_are_rejected() {
    assert_error(
        &group_of(1, "  Sphere { center 0 nan 0 radius 1 }"),
        8,
        21,
        &["expected a finite number, found `nan`"],
    );
    assert_error(
        &group_of(1, "  Plane { normal 0 1 0 offset -inf }"),
        8,
        31,
        &["found `-inf`"],
    );
    assert_error(
        &group_of(1, "  Sphere { center 0 0 0 radius 1e999 }"),
        8,
        32,
        &["`1e999` is beyond single precision"],
    );
    // Finite as a double, infinite as the course's float.
    assert_error(
        &group_of(1, "  Sphere { center 0 0 0 radius 4e38 }"),
        8,
        32,
        &["`4e38` is beyond single precision: the course reads numbers as `float`"],
    );
}

#[test]
fn values_are_held_to_the_toml_loaders_rules() {
    assert_error(
        &group_of(1, "  Plane { normal 0 0 0 offset 1 }"),
        8,
        18,
        &["`normal` must have a nonzero, finite length, found `0 0 0`"],
    );
    assert_error(
        &group_of(
            1,
            "  Transform { Rotate { 0 0 0 45 } Sphere { center 0 0 0 radius 1 } }",
        ),
        8,
        24,
        &["the rotation axis must have a nonzero, finite length, found `0 0 0`"],
    );
    assert_error(
        &with_camera("Materials { numMaterials 1 Material { diffuseColor 1 -0.5 0 } }"),
        7,
        54,
        &["`diffuseColor` must be ≥ 0 (colours are non-negative), found `-0.5`"],
    );
    assert_error(
        &with_camera("Lights { numLights 1 PointLight { position 0 0 0 color 1 1 1 falloff 0 } }"),
        7,
        70,
        &["`falloff` must be > 0"],
    );
    assert_error(
        "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 0 2 angle 30 }",
        1,
        55,
        &["`up` must not be parallel to direction, found `0 0 2`"],
    );
    assert_error(
        "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 180 }",
        1,
        67,
        &["`angle` must be strictly between 0 and 180 degrees, found `180`"],
    );
}

#[test]
fn a_singular_transform_is_reported_at_its_keyword() {
    assert_error(
        &group_of(
            1,
            "  Transform { YRotate 45 Scale 1 0 1 Sphere { center 0 0 0 radius 1 } }",
        ),
        8,
        3,
        &["this Transform is singular", "zero scale"],
    );
    assert_error(
        &group_of(
            1,
            "  Transform { Scale 1 1 1e-7\n  Transform { Scale 1 1 1e-7 Sphere { center 0 0 0 radius 1 } } }",
        ),
        8,
        3,
        &["this Transform is singular"],
    );
}

#[test]
fn missing_assets_name_the_resolved_path() {
    let missing = data_dir().join("models/nope.obj");
    assert_error(
        &group_of(1, "  TriangleMesh { obj_file models/nope.obj }"),
        8,
        27,
        &[&format!(
            "`obj_file models/nope.obj` resolves to {}, which does not exist",
            missing.display()
        )],
    );
    assert_error(
        &with_camera("Background { cubeMap tex/nowhere }"),
        7,
        22,
        &[&format!(
            "must name a directory, but {} is not one",
            data_dir().join("tex/nowhere").display()
        )],
    );
}

#[test]
fn a_scene_without_a_camera_or_group_is_rejected() {
    for (source, fragment) in [
        (
            format!(
                "Materials {{ numMaterials 1 Material {{ }} }} Group {{ numObjects 1 MaterialIndex 0 {} }}",
                sphere("0 0 0")
            ),
            "no PerspectiveCamera",
        ),
        (CAMERA.to_owned(), "no top-level Group"),
    ] {
        let error = try_parse(&source).unwrap_err();
        assert!(error.location().is_none(), "nothing to point at: {error}");
        let message = error.to_string();
        assert!(
            message.starts_with(&format!("{}: ", synthetic_path().display())),
            "{message}"
        );
        assert!(message.contains(fragment), "{message}");
    }
}

#[test]
fn nesting_is_bounded_instead_of_overflowing_the_stack() {
    let mut object = sphere("0 0 0");
    for _ in 0..40 {
        object = format!("Group {{ numObjects 1 {object} }}");
    }
    let message = try_parse(&with_camera(&format!("Group {{ numObjects 1 {object} }}")))
        .unwrap_err()
        .to_string();
    assert!(message.contains("nest more than 32 deep"), "{message}");
}

/// Where the course binary asserts, crashes or reads nonsense, goldray says why at the spot. Each
/// of these was run through the course binary; what it did is in docs/course-grammar.md.
#[test]
fn what_crashes_the_course_is_a_located_error() {
    let no_material = "Materials { numMaterials 1 Material { } }\nGroup { numObjects 2\n";
    assert_error(
        &with_camera(&format!(
            "{no_material}  Sphere {{ center 0 0 0 radius 1 }} MaterialIndex 0 }}"
        )),
        9,
        3,
        &["this Sphere has no material: put `MaterialIndex k` before it"],
    );
    assert_error(
        &with_camera(&format!(
            "{no_material}  TriangleMesh {{ obj_file models/cube.obj }} MaterialIndex 0 }}"
        )),
        9,
        3,
        &["this TriangleMesh has no material"],
    );
    assert_error(
        &group_of(1, "  TriangleMesh { obj_file models/cube.OBJ }"),
        8,
        27,
        &[
            "`obj_file` must name a file ending in `.obj`",
            "found `models/cube.OBJ`",
        ],
    );
    assert_error(
        &with_camera("Lights { numLights 1\n  PointLight { position 0 5 5 color 1 1 1 } }"),
        8,
        3,
        &["this PointLight has no `falloff`", "render every lit surface black"],
    );
    assert_error(
        &with_camera("Lights { numLights 1 PointLight { falloff 1e-300 } }"),
        7,
        43,
        &["`falloff` must be > 0 in single precision", "found `1e-300`"],
    );
    assert_error(
        &with_camera("Lights { numLights 1 PointLight { falloff 1 colour 1 1 1 } }"),
        7,
        45,
        &["unknown PointLight field `colour`; did you mean `color`?"],
    );
    assert_error(
        "PerspectiveCamera { center 0 0 10 direction 1e-30 0 0 up 0 1 0 angle 30 }",
        1,
        45,
        &["`direction` must have a nonzero, finite length, found `1e-30 0 0`"],
    );
}

/// The course reads a count with `%d` into an `int`: a negative one means none, a larger one
/// wraps around.
#[test]
fn counts_must_fit_the_course_int() {
    assert_error(
        &with_camera("Group { numObjects -1 }"),
        7,
        20,
        &["`numObjects` must be a whole number from 0 to 2147483647 (a C `int`), found `-1`"],
    );
    assert_error(
        &with_camera("Lights { numLights 4294967297 }"),
        7,
        20,
        &["found `4294967297`"],
    );
}

#[test]
fn comments_are_not_part_of_the_format() {
    assert_error(
        &with_camera("# the floor\nGroup { numObjects 0 }"),
        7,
        1,
        &["unknown block `#`", "(the course's scene format has no comments)"],
    );
    assert_error(
        &group_of(1, "  Sphere { // unit\n center 0 0 0 radius 1 }"),
        8,
        12,
        &["expected `center` first in Sphere, found `//`", "no comments"],
    );
}

#[test]
fn a_byte_order_mark_or_text_that_is_not_utf8_is_located() {
    assert_error(
        &format!("\u{feff}{CAMERA}Group {{ numObjects 0 }}"),
        1,
        1,
        &["starts with a byte-order mark"],
    );
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let path = dir.path().join("latin1.txt");
    let mut bytes = format!("{CAMERA}Group {{ numObjects 0 }}\nBackground {{ cubeMap tex/").into_bytes();
    bytes.extend_from_slice(b"\xE9glise }");
    std::fs::write(&path, bytes).unwrap();
    let message = load_assignment_scene(&path, &AssignmentOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with(&format!("{}:8:26: byte 0xE9 is not UTF-8", path.display())),
        "{message}"
    );
}
