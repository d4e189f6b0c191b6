//! Numbers that parse but mean nothing: non-finite, out of range, degenerate.

use std::path::Path;

use goldray::case::{LoadOptions, parse};

use super::*;

#[test]
fn nan_and_infinity_are_rejected_everywhere() {
    let message = error(&format!("{CAMERA}[background]\nambient = [0, nan, 0]\n"));
    assert_error(&message, "7:15", &["ambient[1] must be a finite number, found nan"]);
    let message = error("[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = -inf\n");
    assert_error(&message, "5:7", &["fov must be a finite number, found -inf"]);
    let message = error(&format!("[tolerance]\nrmse = +inf\n{CAMERA}"));
    assert_error(&message, "2:8", &["rmse must be a finite number, found +inf"]);
}

#[test]
fn image_size_is_bounded_unless_forced() {
    let message = error(&format!("[render]\nsize = [0, 100]\n{CAMERA}"));
    assert_error(&message, "2:9", &["width must be between 1 and 16384", "found 0"]);
    let huge = format!("[render]\nsize = [100, 20000]\n{CAMERA}");
    let message = error(&huge);
    assert_error(
        &message,
        "2:14",
        &["height must be between 1 and 16384 (pass --force to render larger images), found 20000"],
    );
    let forced = parse(
        &huge,
        Path::new("cases/x.toml"),
        &LoadOptions {
            allow_huge_images: true,
        },
    )
    .unwrap();
    assert_eq!((forced.render.trace.width, forced.render.trace.height), (100, 20000));
    let message = error(&format!("[render]\nsize = [1, 2, 3]\n{CAMERA}"));
    assert_error(&message, "2:8", &["size must be [width, height], but has 3 elements"]);
}

#[test]
fn samples_must_be_a_positive_square() {
    let message = error(&format!("[render]\nsamples = 10\n{CAMERA}"));
    assert_error(
        &message,
        "2:11",
        &["samples must be a perfect square", "9 (3×3) and 16 (4×4)", "found 10"],
    );
    let message = error(&format!("[render]\nsamples = 0\n{CAMERA}"));
    assert_error(
        &message,
        "2:11",
        &["samples must be a positive perfect square", "found 0"],
    );
    let message = error(&format!("[render]\nbounces = 1025\n{CAMERA}"));
    assert_error(&message, "2:11", &["bounces must be between 0 and 1024, found 1025"]);
    let message = error(&format!("[render]\nseed = -1\n{CAMERA}"));
    assert_error(&message, "2:8", &["seed must be ≥ 0, found -1"]);
}

#[test]
fn physically_meaningless_numbers_are_rejected() {
    let sphere =
        |radius: &str| format!("{CAMERA}[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = {radius}\n");
    assert_error(&error(&sphere("-1")), "9:10", &["radius must be ≥ 0, found -1"]);
    assert!(try_parse(&sphere("0")).is_ok(), "a zero radius is allowed");

    let message = error(&format!("{CAMERA}[materials.red]\ndiffuse = [1, -0.5, 0]\n"));
    assert_error(&message, "7:15", &["diffuse[1]", "must be ≥ 0", "found -0.5"]);
    let message = error(&format!("{CAMERA}[materials.red]\nspecular = [-1, 0, 0]\n"));
    assert_error(&message, "7:13", &["specular[0] must be ≥ 0", "found -1"]);
    let message = error(&format!("{CAMERA}[materials.red]\nshininess = -2\n"));
    assert_error(&message, "7:13", &["shininess must be ≥ 0, found -2"]);
    let message = error(&format!("{CAMERA}[background]\ncolor = [0, 0, -0.1]\n"));
    assert_error(&message, "7:16", &["color[2] must be ≥ 0", "found -0.1"]);
    let light = |extra: &str| format!("{CAMERA}[[light]]\nkind = \"point\"\nposition = [0, 0, 0]\n{extra}\n");
    let message = error(&light("color = [1, 1, 1]\nfalloff = 0"));
    assert_error(
        &message,
        "10:11",
        &["falloff must be > 0 (intensity is color / (falloff · d²)), found 0"],
    );
    let message = error(&light("color = [1, -1, 1]\nfalloff = 1"));
    assert_error(&message, "9:13", &["color[1] must be ≥ 0", "found -1"]);
    let message = error(&light("falloff = 1"));
    assert_error(&message, "6:1", &["point light is missing required key `color`"]);
}

#[test]
fn the_camera_is_checked() {
    let camera = |direction: &str, up: &str, fov: &str| {
        format!("[camera]\ncenter = [0, 0, 10]\ndirection = {direction}\nup = {up}\nfov = {fov}\n")
    };
    let message = error(&camera("[0, 0, 0]", "[0, 1, 0]", "30"));
    assert_error(
        &message,
        "3:13",
        &["direction must have a nonzero, finite length, found [0, 0, 0]"],
    );
    let message = error(&camera("[0, 0, -1]", "[0, 0, 0]", "30"));
    assert_error(&message, "4:6", &["up must have a nonzero, finite length"]);
    let message = error(&camera("[0, 0, -1]", "[0, 0, 2]", "30"));
    assert_error(
        &message,
        "4:6",
        &["up must not be parallel to direction [0, 0, -1], found [0, 0, 2]"],
    );
    for fov in ["0", "180", "-5", "200.5"] {
        let message = error(&camera("[0, 0, -1]", "[0, 1, 0]", fov));
        assert_error(
            &message,
            "5:7",
            &[
                "fov must be strictly between 0 and 180 degrees",
                &format!("found {fov}"),
            ],
        );
    }
    let message = error("description = \"no camera\"\n");
    assert_eq!(
        message,
        "cases/x.toml: missing the required [camera] table (center, direction, up, fov)"
    );
    let message = error("[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\n");
    assert_error(&message, "1:1", &["[camera] is missing required key `fov`"]);
}

#[test]
fn degenerate_directions_are_rejected() {
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"plane\"\nnormal = [0, 0, 0]\noffset = 1\n"
    ));
    assert_error(
        &message,
        "8:10",
        &["normal must have a nonzero, finite length, found [0, 0, 0]"],
    );
    let message = error(&format!(
        "{CAMERA}[[object]]\nkind = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nnormals = [[0, 0, 1], [0, 0, 0], [0, 0, 1]]\n"
    ));
    assert_error(
        &message,
        "9:23",
        &["normals[1] must have a nonzero, finite length, found [0, 0, 0]"],
    );
    let message = error(&format!(
        "{CAMERA}[[light]]\nkind = \"directional\"\ndirection = [0, 0, 0]\ncolor = [1, 1, 1]\n"
    ));
    assert_error(&message, "8:13", &["direction must have a nonzero, finite length"]);
}

#[test]
fn ranges_and_tolerances_are_checked() {
    let message = error(&format!("[render]\ndepth_range = [18, 8]\n{CAMERA}"));
    assert_error(&message, "2:15", &["depth_range must have min < max, found [18, 8]"]);
    let message = error(&format!("[render]\ndepth_range = [8, 8]\n{CAMERA}"));
    assert_error(&message, "2:15", &["depth_range must have min < max"]);
    let message = error(&format!("[tolerance]\npixel = -0.01\n{CAMERA}"));
    assert_error(&message, "2:9", &["pixel must be ≥ 0, found -0.01"]);
    let message = error(&format!("[tolerance]\nfail_fraction = 1.5\n{CAMERA}"));
    assert_error(&message, "2:17", &["fail_fraction must be between 0 and 1, found 1.5"]);
    let message = error(&format!("[tolerance]\nmax = -1\n{CAMERA}"));
    assert_error(&message, "2:7", &["max must be ≥ 0, found -1"]);
}
