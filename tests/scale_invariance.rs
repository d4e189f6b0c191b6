//! The same scene at every scale from 1e-4 to 1e6, and far from the origin, must render the same
//! picture in both precisions: robust ray spawning has no length scale, and camera-world
//! coordinates keep the digits that matter wherever the scene sits. A fixed epsilon, rendered
//! from the same cases, fails at both ends of the range: the tests have teeth.

use std::fmt::Write as _;
use std::path::Path;

use goldray::case::{Case, LoadOptions, parse};
use goldray::film::{Tonemap, color_image};
use goldray::geometry::generate::{blob, write_obj};
use goldray::options::{Precision, Spawn};
use goldray::pipeline::render_options;
use goldray::progress::Silent;
use goldray::real::Vec3;
use goldray::rgb_image::RgbImage;
use goldray::with_precision;

/// The classic assignment's `tmin`.
const ASSIGNMENT_EPSILON: f64 = 1.0e-4;

/// Maps scale-1 coordinates to the test's world: `p · scale + offset`.
#[derive(Clone, Copy)]
struct Placement {
    scale: f64,
    offset: [f64; 3],
}

impl Placement {
    const UNIT: Placement = Placement {
        scale: 1.0,
        offset: [0.0; 3],
    };

    fn point(&self, p: [f64; 3]) -> String {
        let q: Vec<String> = (0..3)
            .map(|i| format!("{:e}", p[i] * self.scale + self.offset[i]))
            .collect();
        format!("[{}]", q.join(", "))
    }

    fn length(&self, l: f64) -> String {
        format!("{:e}", l * self.scale)
    }
}

/// Spheres (one a mirror), a plane, a mesh, a point and a directional light, shadows and two
/// bounces: every kind of secondary ray leaves every kind of surface. The mesh is written at
/// scale 1 and placed by its transform, as a user scales a model; the rest is written placed.
fn scene(dir: &Path, at: Placement, precision: Precision) -> Case {
    let (positions, triangles) = blob(3, 5);
    let model: Vec<Vec3> = positions
        .iter()
        .map(|p| *p * 0.8 + Vec3::new(1.4, -0.3, -0.5))
        .collect();
    write_obj(&dir.join("blob.obj"), &model, &triangles).unwrap();
    let plane_offset: f64 = at.offset[1] - at.scale;
    let mut toml = String::new();
    writeln!(
        toml,
        "[render]\nsize = [100, 100]\nshadows = true\nbounces = 2\nprecision = \"{}\"\n",
        precision.name()
    )
    .unwrap();
    writeln!(
        toml,
        "[camera]\ncenter = {}\ndirection = [0, -0.25, -1]\nup = [0, 1, 0]\nfov = 40\n",
        at.point([0.0, 1.0, 6.0])
    )
    .unwrap();
    writeln!(
        toml,
        "[background]\ncolor = [0.2, 0.3, 0.5]\nambient = [0.1, 0.1, 0.1]\n"
    )
    .unwrap();
    writeln!(
        toml,
        "[[light]]\nkind = \"point\"\nposition = {}\ncolor = [1, 1, 1]\nfalloff = {:e}\n",
        at.point([-2.0, 4.0, 3.0]),
        0.02 / (at.scale * at.scale)
    )
    .unwrap();
    writeln!(
        toml,
        "[[light]]\nkind = \"directional\"\ndirection = [0.5, -1, -0.3]\ncolor = [0.3, 0.3, 0.3]\n"
    )
    .unwrap();
    writeln!(
        toml,
        "[materials.mirror]\ndiffuse = [0.1, 0.1, 0.1]\nspecular = [0.8, 0.8, 0.8]\nshininess = 60\n"
    )
    .unwrap();
    writeln!(
        toml,
        "[materials.red]\ndiffuse = [0.8, 0.2, 0.2]\nspecular = [0.3, 0.3, 0.3]\nshininess = 20\n"
    )
    .unwrap();
    writeln!(
        toml,
        "[materials.floor]\ndiffuse = [0.7, 0.7, 0.6]\nspecular = [0.2, 0.2, 0.2]\nshininess = 5\n"
    )
    .unwrap();
    for (center, radius, material) in [([-1.2, 0.0, 0.0], 1.0, "mirror"), ([0.4, -0.6, 1.2], 0.4, "red")] {
        writeln!(
            toml,
            "[[object]]\nkind = \"sphere\"\ncenter = {}\nradius = {}\nmaterial = \"{material}\"\n",
            at.point(center),
            at.length(radius)
        )
        .unwrap();
    }
    writeln!(
        toml,
        "[[object]]\nkind = \"mesh\"\nobj = \"blob.obj\"\nmaterial = \"red\"\ntransform = [{{ translate = {} }}, {{ uniform_scale = {:e} }}]\n",
        at.point([0.0; 3]),
        at.scale
    )
    .unwrap();
    writeln!(
        toml,
        "[[object]]\nkind = \"plane\"\nnormal = [0, 1, 0]\noffset = {plane_offset:e}\nmaterial = \"floor\"\n"
    )
    .unwrap();
    parse(&toml, &dir.join("scaled.toml"), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}\n{toml}"))
}

fn render(case: &Case, spawn: Spawn) -> RgbImage {
    let options = goldray::options::RenderOptions {
        spawn,
        ..render_options(case)
    };
    let film = with_precision!(case.render.precision, p => {
        let scene = p::scene::build_scene(case).unwrap();
        p::render::render(&scene, &options, &Silent)
    });
    color_image(&film, Tonemap::Srgb)
}

fn fraction_within(a: &RgbImage, b: &RgbImage, tolerance: u8) -> f64 {
    let close = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).all(|(x, y)| x.abs_diff(y) <= tolerance))
        .count();
    close as f64 / (a.width() * a.height()) as f64
}

/// The fraction of pixels within 2/255 of the scale-1 picture (rendered with robust spawning,
/// in the same precision) for each placement.
fn agreement(precision: Precision, spawn: Spawn, placements: &[(String, Placement)]) -> Vec<(String, f64)> {
    let dir = tempfile::tempdir().unwrap();
    let reference = render(&scene(dir.path(), Placement::UNIT, precision), Spawn::ErrorBounds);
    placements
        .iter()
        .map(|(label, placement)| {
            let image = render(&scene(dir.path(), *placement, precision), spawn);
            let fraction = fraction_within(&image, &reference, 2);
            eprintln!(
                "{} {spawn:?} {label}: {:.3}% of pixels within 2/255 of scale 1",
                precision.name(),
                fraction * 100.0
            );
            if fraction < 0.999 {
                // Kept to look at, inside the build's own folder rather than the system's.
                let name = format!("{}-{spawn:?}-{label}.png", precision.name()).replace(' ', "_");
                let kept = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scale-invariance");
                std::fs::create_dir_all(&kept).unwrap();
                goldray::film::write_png(&kept.join(name), &image).unwrap();
            }
            (label.clone(), fraction)
        })
        .collect()
}

fn assert_all_agree(precision: Precision, placements: &[(String, Placement)]) {
    let failures: Vec<String> = agreement(precision, Spawn::ErrorBounds, placements)
        .into_iter()
        .filter(|(_, fraction)| *fraction < 0.999)
        .map(|(label, fraction)| format!("{label}: {:.3}%", fraction * 100.0))
        .collect();
    assert!(
        failures.is_empty(),
        "{}: not the scale-1 picture: {failures:?}",
        precision.name()
    );
}

fn scales(factors: &[f64]) -> Vec<(String, Placement)> {
    factors
        .iter()
        .map(|&scale| {
            (
                format!("scale {scale:e}"),
                Placement {
                    scale,
                    offset: [0.0; 3],
                },
            )
        })
        .collect()
}

fn translations() -> Vec<(String, Placement)> {
    let mut placements = Vec::new();
    for distance in [1e2, 1e4, 1e5] {
        for axis in 0..3 {
            let mut offset = [0.0; 3];
            offset[axis] = distance;
            placements.push((
                format!("offset {distance:e} along {}", ["x", "y", "z"][axis]),
                Placement { scale: 1.0, offset },
            ));
        }
    }
    placements
}

const ALL_SCALES: [f64; 5] = [1e-4, 1e-2, 1e2, 1e4, 1e6];

#[test]
fn uniform_scale_from_1e_minus_4_to_1e6_renders_the_same_picture_in_f32() {
    assert_all_agree(Precision::F32, &scales(&ALL_SCALES));
}

#[test]
fn uniform_scale_from_1e_minus_4_to_1e6_renders_the_same_picture_in_f64() {
    assert_all_agree(Precision::F64, &scales(&ALL_SCALES));
}

#[test]
fn translation_by_up_to_1e5_along_each_axis_renders_the_same_picture_in_f32() {
    assert_all_agree(Precision::F32, &translations());
}

#[test]
fn translation_by_up_to_1e5_along_each_axis_renders_the_same_picture_in_f64() {
    assert_all_agree(Precision::F64, &translations());
}

/// The same scenes with the assignment's `tmin = 1e-4`: right at scale 1, where the epsilon was
/// tuned, wrong at both ends. Small scenes lose contact shadows and reflections to the skipped
/// distance; in `f32`, large ones self-shadow (acne) because the hit point's rounding error
/// outgrows the epsilon.
#[test]
fn a_fixed_epsilon_fails_the_same_tests_at_small_and_large_scales() {
    let fixed = Spawn::FixedEpsilon(ASSIGNMENT_EPSILON);
    let f32_results = agreement(Precision::F32, fixed, &scales(&[1.0, 1e-4, 1e-2, 1e4, 1e6]));
    let f64_results = agreement(Precision::F64, fixed, &scales(&[1.0, 1e-4]));
    let fraction = |results: &[(String, f64)], label: &str| results.iter().find(|(l, _)| l == label).unwrap().1;
    assert!(
        fraction(&f32_results, "scale 1e0") >= 0.999,
        "the fixed epsilon is fine where it was tuned"
    );
    assert!(
        fraction(&f64_results, "scale 1e0") >= 0.999,
        "the fixed epsilon is fine where it was tuned"
    );
    for label in ["scale 1e-4", "scale 1e-2", "scale 1e4", "scale 1e6"] {
        assert!(
            fraction(&f32_results, label) < 0.999,
            "f32 {label}: a fixed epsilon should fail the test"
        );
    }
    for label in ["scale 1e-4", "scale 1e4", "scale 1e6"] {
        assert!(
            fraction(&f32_results, label) < 0.95,
            "f32 {label}: a fixed epsilon should fail visibly"
        );
    }
    assert!(
        fraction(&f64_results, "scale 1e-4") < 0.95,
        "f64 scale 1e-4: a fixed epsilon should fail visibly"
    );
}
