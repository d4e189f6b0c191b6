//! `precision = "f64"`: the same renderer in double precision. It must keep every contract of
//! the default one (bit-identical EXR on any thread count, the case file round trip) and draw
//! the same picture within the golden tolerance, while actually computing in `f64`.

mod util;

use std::path::Path;

use goldray::case::{Case, LoadOptions, case_to_toml, parse};
use goldray::compare::{Image, Tolerance, Verdict, compare};
use goldray::film::{Film, encode_exr};
use goldray::options::Precision;
use goldray::pipeline::render_case;

fn case(name: &str, precision: Precision) -> Case {
    let mut case = util::load_shipped(name);
    case.render.precision = precision;
    case
}

fn render_with_threads(case: &Case, threads: usize) -> Film {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| render_case(case).unwrap_or_else(|e| panic!("{e}")))
}

#[test]
fn f64_exr_is_bit_identical_with_one_and_two_threads() {
    for name in ["jitter_filter", "mirrors", "blob_mesh"] {
        let case = case(name, Precision::F64);
        let one = encode_exr(&render_with_threads(&case, 1)).unwrap();
        let two = encode_exr(&render_with_threads(&case, 2)).unwrap();
        assert!(one == two, "{name}: 1 and 2 threads differ in f64");
    }
}

/// Only the colour: depth compares in absolute units, and on the far floor of `mirrors` (10,850
/// units away, at a grazing angle) f32's own rounding moves it by 1e-5 relative.
fn picture(mut film: Film) -> Film {
    film.depth.fill(0.0);
    film.normal.fill([0.0; 3]);
    film
}

/// Different arithmetic, the same picture: shipped cases pass their own golden tolerance
/// against their `f32` render, and yet the films differ (the key is not ignored).
#[test]
fn f64_draws_the_f32_picture_with_different_arithmetic() {
    for name in [
        "spheres_shadows",
        "mirrors",
        "transforms",
        "vertex_normals",
        "jitter_filter",
    ] {
        let single = picture(render_with_threads(&case(name, Precision::F32), 2));
        let double = picture(render_with_threads(&case(name, Precision::F64), 2));
        let tolerance = case(name, Precision::F32).tolerance;
        let comparison = compare(
            &Image::from_film(&single, "f32.exr"),
            &Image::from_film(&double, "f64.exr"),
            &tolerance,
        );
        assert_eq!(comparison.verdict, Verdict::Pass, "{name}:\n{comparison}");
        assert!(
            single.color != double.color,
            "{name}: the f64 render is bit-identical to f32"
        );
    }
}

#[test]
fn precision_survives_the_case_file_round_trip_and_defaults_to_f32() {
    let mut case = case("mirrors", Precision::F64);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/mirrors.toml");
    let toml = case_to_toml(&case, &path);
    assert!(toml.contains("precision = \"f64\""), "{toml}");
    assert_eq!(
        parse(&toml, &path, &LoadOptions::default()).unwrap().render.precision,
        Precision::F64
    );
    case.render.precision = Precision::F32;
    let toml = case_to_toml(&case, &path);
    assert!(!toml.contains("precision"), "the default is not written: {toml}");
    assert_eq!(
        parse(&toml, &path, &LoadOptions::default()).unwrap().render.precision,
        Precision::F32
    );
}

#[test]
fn an_unknown_precision_is_an_error_listing_the_valid_ones() {
    let toml = "[render]\nprecision = \"f16\"\n[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";
    let error = parse(toml, Path::new("p.toml"), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(error.contains("p.toml:2:13"), "{error}");
    assert!(
        error.contains("f16") && error.contains("f32") && error.contains("f64"),
        "{error}"
    );
}

/// Far from the origin, a mesh file's own coordinates keep their digits only in `f64`: the
/// single-precision film is measurably further from the double-precision one there than at the
/// origin, which is what `precision = "f64"` is for.
#[test]
fn f64_keeps_the_digits_of_a_mesh_file_far_from_the_origin() {
    let dir = tempfile::tempdir().unwrap();
    let offset = 1.0e5_f64;
    let mut obj = String::new();
    let (positions, triangles) = goldray::geometry::generate::blob(4, 3);
    for p in &positions {
        obj += &format!("v {} {} {}\n", p.x as f64 + offset, p.y as f64, p.z as f64);
    }
    for t in &triangles {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(dir.path().join("far.obj"), obj).unwrap();
    let toml = format!(
        "[render]\nsize = [64, 64]\nprecision = \"f64\"\n[camera]\ncenter = [{offset}, 0, 4]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 40\n\
         [[light]]\nkind = \"directional\"\ndirection = [0.3, -0.5, -1]\ncolor = [1, 1, 1]\n[[object]]\nkind = \"mesh\"\nobj = \"far.obj\"\n"
    );
    let mut case = parse(&toml, &dir.path().join("far.toml"), &LoadOptions::default()).unwrap();
    let double = render_with_threads(&case, 2);
    case.render.precision = Precision::F32;
    let single = render_with_threads(&case, 2);
    let tolerance = Tolerance {
        pixel: 0.01,
        fail_fraction: 0.0,
        rmse: 1.0,
        max: None,
    };
    let comparison = compare(
        &Image::from_film(&double, "f64.exr"),
        &Image::from_film(&single, "f32.exr"),
        &tolerance,
    );
    assert!(
        matches!(comparison.verdict, Verdict::Fail { .. }),
        "f32 should lose the mesh's digits at 1e5:\n{comparison}"
    );
}
