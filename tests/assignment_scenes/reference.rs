//! Where the differential test (`examples/course_diff`) found goldray's pictures differing from
//! the course's reference renderer, a 3×3 scene isolates the rule, and its centre pixel must be
//! the one the course binary wrote for the same scene and flags (recorded below; the binary is
//! not part of the project).

use goldray::film::{Tonemap, color_image, normals_image};
use goldray::pipeline::render_case;

use super::*;

/// The centre pixel's colour and normal, rendered as `-size 3 3 [-bounces N] [-shadows]`.
fn centre(scene: &str, bounces: u32, shadows: bool) -> ([u8; 3], [u8; 3]) {
    let path = data_dir().join("reference.txt");
    let options = AssignmentOptions {
        width: 3,
        height: 3,
        bounces,
        shadows,
        normals: true,
        ..AssignmentOptions::default()
    };
    let case = parse_assignment_scene(scene, &path, &options).unwrap_or_else(|e| panic!("{e}"));
    let film = render_case(&case).unwrap_or_else(|e| panic!("{e}"));
    (
        color_image(&film, Tonemap::Clamp).get_pixel(1, 1).0,
        normals_image(&film, Tonemap::Clamp).get_pixel(1, 1).0,
    )
}

/// Looking straight down at `object`, lit from straight above, against a white background.
fn looking_down(light: &str, material: &str, object: &str) -> String {
    format!(
        "PerspectiveCamera {{ center 0 10 0 direction 0 -1 0 up 0 0 -1 angle 30 }}\n\
         Lights {{ numLights 1 DirectionalLight {{ direction 0 -1 0 color {light} }} }}\n\
         Background {{ color 1 1 1 ambientLight 0 0 0 }}\n\
         Materials {{ numMaterials 1 Material {{ {material} }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 {object} }}\n"
    )
}

/// `normal 0 2 0` doubles the diffuse term and shows as 1.0+ in the normals image; `0 0.5 0`
/// halves both. Under a Transform the normal is unit again.
#[test]
fn a_plane_shades_with_its_normal_as_written() {
    let diffuse = "diffuseColor 1 1 1";
    let plane = |normal: &str| format!("Plane {{ normal {normal} offset -2 }}");
    assert_eq!(
        centre(&looking_down("0.2 0.2 0.2", diffuse, &plane("0 2 0")), 0, false),
        ([0x66; 3], [0x7f, 0xff, 0x7f])
    );
    assert_eq!(
        centre(
            &looking_down("0.2 0.2 0.2", "diffuseColor 0.5 0.5 0.5", &plane("0 0.5 0")),
            0,
            false
        ),
        ([0x0c; 3], [0x7f, 0xbf, 0x7f])
    );
    let transformed = format!("Transform {{ Translate 0 0 0 {} }}", plane("0 2 0"));
    assert_eq!(
        centre(&looking_down("0.2 0.2 0.2", diffuse, &transformed), 0, false).0,
        [0x33; 3]
    );
}

/// The highlight's cosine is clamped at 0 only: R·V = 3.5 on a plane with normal `0 2 0` and
/// the light 60° off, so the highlight is 3.5² times the specular colour.
#[test]
fn the_highlight_is_not_clamped_at_one() {
    let scene = looking_down(
        "0.2 0.2 0.2",
        "diffuseColor 0 0 0 specularColor 0.02 0.02 0.02 shininess 2",
        "Plane { normal 0 2 0 offset -2 }",
    )
    .replace("direction 0 -1 0 color", "direction -0.8660254 -0.5 0 color");
    assert_eq!(centre(&scene, 0, false).0, [0x0c; 3]);
}

/// `int(c·255)` overflows past 2³¹, which the course clamps to 0: a highlight of 7²⁰ is black.
#[test]
fn an_exploding_highlight_is_black() {
    let scene = looking_down(
        "0.2 0.2 0.2",
        "diffuseColor 0 0 0 specularColor 0.2 0.2 0.2 shininess 20",
        "Plane { normal 0 2 0 offset 0 }",
    );
    assert_eq!(centre(&scene, 0, false).0, [0; 3]);
}

/// Only a specular colour longer than 0.1 reflects: |0.05·(1,1,1)| = 0.087 does not, and
/// |0.06·(1,1,1)| = 0.104 reflects the white background (0.06·255 = 15). The float 0.1 is a
/// little over the double 0.1 it is compared with, so `0.1 0 0` reflects too.
#[test]
fn only_a_specular_colour_longer_than_a_tenth_reflects() {
    let mirror = |ks: &str| {
        looking_down(
            "0 0 0",
            &format!("diffuseColor 0 0 0 specularColor {ks} shininess 1"),
            "Plane { normal 0 1 0 offset 0 }",
        )
    };
    assert_eq!(centre(&mirror("0.05 0.05 0.05"), 1, false).0, [0; 3]);
    assert_eq!(centre(&mirror("0.06 0.06 0.06"), 1, false).0, [0x0f; 3]);
    assert_eq!(centre(&mirror("0.1 0 0"), 1, false).0, [0x19, 0, 0]);
}

/// A shadow ray starts 0.01 along its direction, so a triangle 0.005 above the floor casts no
/// shadow on it (ambient 0.1 + light 0.5 = 0x99; in shadow it would be 0x19).
#[test]
fn secondary_rays_start_a_hundredth_along_their_direction() {
    let scene = "PerspectiveCamera { center 0 0.0025 0 direction 0 -1 -1 up 0 1 0 angle 30 }\n\
                 Lights { numLights 1 DirectionalLight { direction 0 -1 0 color 0.5 0.5 0.5 } }\n\
                 Background { color 0 0 0 ambientLight 0.1 0.1 0.1 }\n\
                 Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
                 Group { numObjects 2 MaterialIndex 0 Plane { normal 0 1 0 offset 0 }\n\
                   Triangle { vertex0 -5 0.005 5 vertex1 5 0.005 5 vertex2 0 0.005 -5 } }\n";
    assert_eq!(centre(scene, 0, true).0, [0x99; 3]);
}

/// A mirroring transform keeps the object-space normal's side: the triangle faces down (and is
/// unlit), where its moved vertices alone would wind it facing up.
#[test]
fn a_mirrored_triangle_keeps_its_transformed_normal() {
    let triangle = "Triangle { vertex0 -5 0 -5 vertex1 5 0 -5 vertex2 0 0 5 }";
    let mirrored = looking_down(
        "0.2 0.2 0.2",
        "diffuseColor 1 1 1",
        &format!("Transform {{ Scale 1 1 -1 {triangle} }}"),
    );
    assert_eq!(centre(&mirrored, 0, false), ([0; 3], [0x7f, 0x00, 0x7f]));
    let moved = looking_down(
        "0.2 0.2 0.2",
        "diffuseColor 1 1 1",
        "Triangle { vertex0 -5 0 5 vertex1 5 0 5 vertex2 0 0 -5 }",
    );
    assert_eq!(centre(&moved, 0, false), ([0x33; 3], [0x7f, 0xff, 0x7f]));
}
