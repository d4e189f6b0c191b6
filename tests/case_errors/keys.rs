//! Syntax, unknown and misplaced keys, wrong types and shapes, unknown names.

use std::path::Path;

use goldray::case::{LoadOptions, load};

use super::*;

#[test]
fn malformed_toml_is_located() {
    let message = error("[render]\nsize = [1, 2\nbounces = 3\n");
    assert_error(&message, "3:1", &["invalid TOML", "expected `,`"]);
    let located = try_parse("a = 1\nb = = 2\n").unwrap_err();
    let location = located.location().expect("a syntax error has a location");
    assert_eq!(
        (location.line, location.column, location.file.as_path()),
        (2, 5, Path::new("cases/x.toml"))
    );
}

#[test]
fn an_unreadable_file_is_named() {
    let message = load(Path::new("/nonexistent/case.toml"), &LoadOptions::default()).unwrap_err();
    assert!(
        message
            .to_string()
            .starts_with("/nonexistent/case.toml: cannot read case file")
    );
}

#[test]
fn unknown_keys_suggest_the_nearest_valid_key() {
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nraduis = 1\n"
    ));
    assert_error(
        &message,
        "9:1",
        &[
            "unknown key `raduis` in sphere; did you mean `radius`?",
            "valid keys: kind, material, transform, center, radius",
        ],
    );
    let message = error(&format!("lights = []\n{CAMERA}"));
    assert_error(
        &message,
        "1:1",
        &["unknown key `lights` in the case file; did you mean `light`?"],
    );
    let message = error(&format!("[render]\n  smaples = 4\n{CAMERA}"));
    assert_error(&message, "2:3", &["`smaples` in [render]; did you mean `samples`?"]);
    let message = error(&format!("{CAMERA}[materials.red]\nshinyness = 3\n"));
    assert_error(
        &message,
        "7:1",
        &["`shinyness` in material `red`; did you mean `shininess`?"],
    );
    let message = error(&format!("{CAMERA}[tolerance]\nzzz = 3\n"));
    assert_error(
        &message,
        "7:1",
        &["unknown key `zzz` in [tolerance]; valid keys: pixel, fail_fraction, rmse, max"],
    );
}

#[test]
fn keys_of_another_kind_are_rejected() {
    let message = error(&format!("{CAMERA}[[object]]\nkind = \"sphere\"\noffset = 1\n"));
    assert_error(
        &message,
        "8:1",
        &[
            "`offset` does not apply to a sphere (it is a plane key)",
            "center, radius",
        ],
    );
    let message = error(&format!("{CAMERA}[[light]]\nkind = \"directional\"\nfalloff = 1\n"));
    assert_error(
        &message,
        "8:1",
        &["`falloff` does not apply to a directional light (it is a point key)"],
    );
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"group\"\nobjects = []\ncenter = [0, 0, 0]\n"
    ));
    assert_error(
        &message,
        "9:1",
        &[
            "`center` does not apply to a group",
            "valid keys for a group: kind, material, transform, objects",
        ],
    );
}

#[test]
fn wrong_types_name_the_expected_type_and_the_value() {
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"big\"\n"
    ));
    assert_error(&message, "9:10", &["radius must be a number, found string \"big\""]);
    let message = error(&format!("[render]\nshadows = 1\n{CAMERA}"));
    assert_error(&message, "2:11", &["shadows must be true or false, found integer 1"]);
    let message = error(&format!("[render]\nbounces = 2.5\n{CAMERA}"));
    assert_error(&message, "2:11", &["bounces must be an integer, found float 2.5"]);
    let message = error(&format!("[render]\nsize = [100, \"x\"]\n{CAMERA}"));
    assert_error(&message, "2:14", &["height must be an integer, found string \"x\""]);
    let message = error("camera = 3\n");
    assert_error(&message, "1:10", &["camera must be a table, found integer 3"]);
}

#[test]
fn wrong_array_lengths_are_reported() {
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"sphere\"\ncenter = [1, 2]\nradius = 1\n"
    ));
    assert_error(
        &message,
        "8:10",
        &["center must be an array of 3 numbers [x, y, z], but has 2 elements, found [1, 2]"],
    );
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0]]\n"
    ));
    assert_error(&message, "8:12", &["vertices must have 3 elements", "but has 2"]);
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"triangle\"\nvertices = [[0, 0, 0], [1, 0], [0, 1, 0]]\n"
    ));
    assert_error(
        &message,
        "8:24",
        &["vertices[1] must be an array of 3 numbers", "found [1, 0]"],
    );
}

#[test]
fn unknown_names_list_the_valid_ones() {
    let message = error(&format!(
        "{CAMERA}[materials.red]\n[materials.blue]\n[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"rde\"\n"
    ));
    assert_error(
        &message,
        "12:12",
        &["unknown material `rde`; did you mean `red`? valid materials: red, blue"],
    );
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"sphere\"\nmaterial = \"red\"\ncenter = [0, 0, 0]\nradius = 1\n"
    ));
    assert_error(
        &message,
        "8:12",
        &["unknown material `red`: no materials are defined; add a [materials.red] table"],
    );
    let message = error(&format!("{CAMERA}[[object]]\nkind = \"sphre\"\n"));
    assert_error(
        &message,
        "7:8",
        &["unknown object kind `sphre`; did you mean `sphere`? valid kinds: sphere, plane, triangle, mesh, group"],
    );
    let message = error(&format!("{CAMERA}[[light]]\nkind = \"spot\"\n"));
    assert_error(
        &message,
        "7:8",
        &["unknown light kind `spot`; valid kinds: point, directional"],
    );
    let message = error(&format!("{CAMERA}[[light]]\nposition = [0, 0, 0]\n"));
    assert_error(&message, "6:1", &["light is missing required key `kind`"]);
    let message = error(&format!("[render]\ntonemap = \"SRGB\"\n{CAMERA}"));
    assert_error(
        &message,
        "2:11",
        &["unknown tonemap `SRGB`; did you mean `srgb`? valid values: srgb, clamp"],
    );
    let message = error(&format!("[render]\nfilter = \"box\"\n{CAMERA}"));
    assert_error(
        &message,
        "2:10",
        &["unknown filter `box`; valid values: none, gaussian"],
    );
    let message = error(&format!("[render]\nprofile = \"mit\"\n{CAMERA}"));
    assert_error(
        &message,
        "2:11",
        &["unknown profile `mit`", "valid values: native, mit6837"],
    );
}

#[test]
fn sections_of_the_wrong_shape_are_rejected() {
    let message = error(&format!("{CAMERA}[light]\nkind = \"point\"\n"));
    assert_error(
        &message,
        "6:1",
        &["light must be an array of tables, written [[light]], found table"],
    );
    let message = error(&format!("{CAMERA}[materials]\nred = 3\n"));
    assert_error(&message, "7:7", &["materials.red must be a table, found integer 3"]);
    let message = error(&format!("description = 5\n{CAMERA}"));
    assert_error(&message, "1:15", &["description must be a string, found integer 5"]);
}
