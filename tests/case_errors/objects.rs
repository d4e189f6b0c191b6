//! Transforms, asset paths and nested groups.

use std::fs;

use goldray::case::{LoadOptions, ShapeSpec, load};

use super::*;

fn with_transform(transform: &str) -> String {
    format!("{CAMERA}[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = {transform}\n")
}

#[test]
fn transforms_are_checked() {
    let message = error(&with_transform("[{ rotate = { axis = [0, 0, 0], degrees = 5 } }]"));
    assert_error(
        &message,
        "10:34",
        &["axis must have a nonzero, finite length, found [0, 0, 0]"],
    );
    let message = error(&with_transform("[{ rotate_y = 45 }, { scale = [1, 0, 1] }]"));
    assert_error(
        &message,
        "10:1",
        &[
            "transform is singular",
            "zero scale",
            "found [{ rotate_y = 45 }, { scale = [1, 0, 1] }]",
        ],
    );
    let message = error(&with_transform(
        "[{ uniform_scale = 1e200 }, { uniform_scale = 1e200 }]",
    ));
    assert_error(&message, "10:1", &["transform overflows", "non-finite"]);
    let message = error(&with_transform("[{ matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0] }]"));
    assert_error(
        &message,
        "10:25",
        &["matrix must be an array of 16 numbers, row-major, but has 12 elements"],
    );
    let message = error(&with_transform(
        "[{ matrix = [1, 2, 3, 0, 2, 4, 6, 0, 0, 0, 1, 0, 0, 0, 0, 1] }]",
    ));
    assert_error(&message, "10:1", &["transform is singular"]);
    let message = error(&with_transform("[{ translate = [0, 1, 0], scale = [2, 2, 2] }]"));
    assert_error(
        &message,
        "10:14",
        &["transform[0] must hold exactly one op", "found `translate`, `scale`"],
    );
    let message = error(&with_transform("[{}]"));
    assert_error(
        &message,
        "10:14",
        &[
            "transform[0] must hold exactly one op",
            "found none",
            "valid ops: translate, scale",
        ],
    );
    let message = error(&with_transform("[{ translate = [0, 1, 0] }, { rotate_q = 5 }]"));
    assert_error(
        &message,
        "10:43",
        &[
            "unknown transform op `rotate_q`; did you mean `rotate_x`?",
            "valid ops:",
        ],
    );
    let message = error(&with_transform("[{ rotate = { axis = [1, 0, 0], degres = 5 } }]"));
    assert_error(
        &message,
        "10:45",
        &["unknown key `degres` in rotate; did you mean `degrees`?"],
    );
    let message = error(&with_transform("{ translate = [0, 1, 0] }"));
    assert_error(&message, "10:13", &["transform must be an array of ops", "found table"]);
    assert!(
        try_parse(&with_transform(
            "[{ translate = [1e6, 0, 0] }, { uniform_scale = 1e-6 }]"
        ))
        .is_ok()
    );
}

#[test]
fn mesh_files_must_exist() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "models/ok.obj", "v 0 0 0\n");
    fs::create_dir_all(dir.path().join("models/dir.obj")).unwrap();
    let case = |obj: &str| format!("{CAMERA}[[object]]\nkind = \"mesh\"\nobj = \"{obj}\"\n");
    let options = LoadOptions::default();

    let path = write(dir.path(), "missing.toml", &case("models/nope.obj"));
    let message = load(&path, &options).unwrap_err().to_string();
    let resolved = dir.path().join("models/nope.obj");
    assert!(message.starts_with(&format!("{}:8:7: ", path.display())), "{message}");
    assert!(
        message.contains(&format!("resolves to {}, which does not exist", resolved.display())),
        "{message}"
    );

    let path = write(dir.path(), "dir.toml", &case("models/dir.obj"));
    let message = load(&path, &options).unwrap_err().to_string();
    assert!(message.contains("which is not a file"), "{message}");

    let path = write(dir.path(), "ok.toml", &case("models/ok.obj"));
    let loaded = load(&path, &options).unwrap();
    assert_eq!(
        loaded.objects[0].shape,
        ShapeSpec::Mesh {
            obj: dir.path().join("models/ok.obj")
        }
    );
}

#[test]
fn cube_maps_must_exist_and_exclude_a_colour() {
    let dir = tempfile::tempdir().unwrap();
    for face in ["left", "right", "up", "down", "front"] {
        write(dir.path(), &format!("sky/{face}.png"), "");
    }
    let path = write(
        dir.path(),
        "c.toml",
        &format!("{CAMERA}[background]\ncube_map = \"sky\"\n"),
    );
    let message = load(&path, &LoadOptions::default()).unwrap_err().to_string();
    assert!(message.starts_with(&format!("{}:7:12: ", path.display())), "{message}");
    assert!(
        message.contains(&format!("{} is missing", dir.path().join("sky/back.png").display())),
        "{message}"
    );

    let message = error(&format!(
        "{CAMERA}[background]\ncolor = [1, 1, 1]\ncube_map = \"sky\"\n"
    ));
    assert_error(&message, "8:12", &["give either color or cube_map, not both"]);
}

#[test]
fn groups_nest_and_report_errors_inside() {
    let source = format!(
        "{CAMERA}[[object]]\nkind = \"group\"\nobjects = [\n  {{ kind = \"group\", objects = [\n    {{ kind = \"sphere\", center = [0, 0, 0], radius = -3 }},\n  ] }},\n]\n"
    );
    assert_error(&error(&source), "10:53", &["radius must be ≥ 0, found -3"]);
    let message = error(&format!("{CAMERA}[[object]]\nkind = \"group\"\nobjects = [3]\n"));
    assert_error(&message, "8:12", &["objects[0] must be a table, found integer 3"]);
    let message = error(&format!("{CAMERA}[[object]]\nkind = \"group\"\n"));
    assert_error(&message, "6:1", &["group is missing required key `objects`"]);
}
