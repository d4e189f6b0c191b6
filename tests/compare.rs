//! Proof that the golden comparator has teeth: it lets through what must not fail a build (ulp
//! noise, a different thread count) and catches what must (a moved edge, a missing shadow, a
//! colour drift in one object, a NaN, a size change), naming the limit that broke. The
//! `goldray diff` tests (in `compare/diff_cli.rs`) drive the binary on real files for each exit code.

#[path = "compare/diff_cli.rs"]
mod diff_cli;
mod util;

use std::path::Path;

use goldray::case::{Case, LoadOptions, parse};
use goldray::compare::{
    Comparison, EXR_DEFAULTS, FAILING, Image, Limit, NON_FINITE, Tolerance, Verdict, compare, diff_heatmap,
};
use goldray::film::Film;
use goldray::pipeline::render_case;

fn case(name: &str) -> Case {
    util::load_shipped(name)
}

fn render(case: &Case) -> Film {
    render_case(case).unwrap_or_else(|e| panic!("{e}"))
}

fn render_with_threads(case: &Case, threads: usize) -> Film {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    pool.install(|| render(case))
}

fn judge(expected: &Film, actual: &Film, tolerance: &Tolerance) -> Comparison {
    compare(
        &Image::from_film(expected, "golden.exr"),
        &Image::from_film(actual, "render.exr"),
        tolerance,
    )
}

fn breached(comparison: &Comparison) -> Vec<Limit> {
    match &comparison.verdict {
        Verdict::Fail { breaches } => breaches.iter().map(|b| b.limit).collect(),
        _ => Vec::new(),
    }
}

/// Fails unless the verdict is a failure naming `limit`, and the report a person reads says so.
fn assert_fails_on(comparison: &Comparison, limit: Limit) {
    let report = comparison.to_string();
    assert!(
        breached(comparison).contains(&limit),
        "expected {} to break:\n{report}",
        limit.name()
    );
    assert!(report.contains(&format!("broke {}", limit.name())), "{report}");
    assert_eq!(comparison.verdict.exit_code(), 2, "{report}");
}

/// The next representable value away from zero (towards +inf for zero), which is what an ulp of
/// platform drift in `powf` looks like.
fn ulp_up(v: f32) -> f32 {
    if v.is_finite() {
        f32::from_bits(v.to_bits() + 1)
    } else {
        v
    }
}

#[test]
fn passes_a_render_with_one_ulp_noise_in_every_channel() {
    let golden = render(&case("spheres_shadows"));
    let mut noisy = golden.clone();
    for (i, ((color, depth), normal)) in noisy
        .color
        .iter_mut()
        .zip(&mut noisy.depth)
        .zip(&mut noisy.normal)
        .enumerate()
    {
        if i % 3 != 0 {
            *color = color.map(ulp_up);
            *depth = ulp_up(*depth);
            *normal = normal.map(ulp_up);
        }
    }
    let comparison = judge(&golden, &noisy, &EXR_DEFAULTS);
    assert_eq!(comparison.verdict, Verdict::Pass, "{comparison}");
    let metrics = comparison.metrics.expect("metrics");
    assert!(
        metrics.rmse > 0.0 && metrics.worst.is_some(),
        "the noise was there: {metrics:?}"
    );
}

#[test]
fn passes_the_same_case_rendered_with_one_and_two_threads() {
    let case = case("jitter_filter");
    let comparison = judge(
        &render_with_threads(&case, 1),
        &render_with_threads(&case, 2),
        &EXR_DEFAULTS,
    );
    assert_eq!(comparison.verdict, Verdict::Pass, "{comparison}");
    assert_eq!(
        comparison.metrics.expect("metrics").rmse,
        0.0,
        "renders are bit-identical across thread counts"
    );
}

#[test]
fn fails_a_one_pixel_shift_of_the_edges() {
    let golden = render(&case("directional_light"));
    let mut shifted = golden.clone();
    let width = golden.width as usize;
    for row in 0..golden.height as usize {
        for x in 1..width {
            let (to, from) = (row * width + x, row * width + x - 1);
            shifted.color[to] = golden.color[from];
            shifted.depth[to] = golden.depth[from];
            shifted.normal[to] = golden.normal[from];
        }
    }
    let comparison = judge(&golden, &shifted, &EXR_DEFAULTS);
    assert_fails_on(&comparison, Limit::FailFraction);
}

#[test]
fn fails_a_missing_shadow() {
    let with = case("spheres_shadows");
    let mut without = with.clone();
    without.render.trace.shadows = false;
    let comparison = judge(&render(&with), &render(&without), &with.tolerance);
    assert_fails_on(&comparison, Limit::FailFraction);
    assert_fails_on(&comparison, Limit::Rmse);
}

#[test]
fn fails_a_colour_off_by_five_hundredths_in_one_object() {
    let golden = case("spheres_shadows");
    let mut drifted = golden.clone();
    let red = drifted
        .materials
        .iter_mut()
        .find(|m| m.name == "red")
        .expect("the red material");
    red.diffuse[1] += 0.05;
    let comparison = judge(&render(&golden), &render(&drifted), &golden.tolerance);
    assert_fails_on(&comparison, Limit::FailFraction);
    let worst = comparison
        .metrics
        .as_ref()
        .and_then(|m| m.worst)
        .expect("a worst pixel");
    assert_eq!(worst.channel, "G", "only green moved: {comparison}");
    // 0.05 times the light reaching the surface, which is a little over 1 near the light.
    assert!(worst.error() > 0.04 && worst.error() < 0.06, "{comparison}");
}

#[test]
fn fails_a_single_nan_pixel_whatever_the_tolerance() {
    let golden = render(&case("vertex_normals"));
    let mut broken = golden.clone();
    let at = broken.index(17, 23);
    broken.color[at][0] = f32::NAN;
    let lenient = Tolerance {
        pixel: 1e9,
        fail_fraction: 1.0,
        rmse: 1e9,
        max: None,
    };
    for tolerance in [EXR_DEFAULTS, lenient] {
        let comparison = judge(&golden, &broken, &tolerance);
        assert_fails_on(&comparison, Limit::NonFinite);
        assert!(
            comparison.to_string().contains("pixel (17, 23) R: expected"),
            "{comparison}"
        );
        assert!(comparison.to_string().contains("actual NaN"), "{comparison}");
    }
    let reversed = judge(&broken, &golden, &EXR_DEFAULTS);
    assert_fails_on(&reversed, Limit::NonFinite);
}

#[test]
fn an_infinite_colour_fails_but_a_depth_that_turns_into_a_miss_is_only_a_failing_pixel() {
    let golden = render(&case("vertex_normals"));
    let mut infinite = golden.clone();
    infinite.color[5][2] = f32::INFINITY;
    assert_fails_on(&judge(&golden, &infinite, &EXR_DEFAULTS), Limit::NonFinite);

    let hit = golden
        .depth
        .iter()
        .position(|d| d.is_finite())
        .expect("some pixel hits");
    let mut missed = golden.clone();
    missed.depth[hit] = f32::INFINITY;
    let comparison = judge(&golden, &missed, &EXR_DEFAULTS);
    assert_eq!(comparison.verdict, Verdict::Warn, "{comparison}");
    assert!(comparison.to_string().contains("Z fails on 1 pixels"), "{comparison}");
}

#[test]
fn reports_a_size_change_as_a_mismatch() {
    let golden = case("directional_light");
    let mut wider = golden.clone();
    wider.render.trace.width += 1;
    let comparison = judge(&render(&golden), &render(&wider), &EXR_DEFAULTS);
    assert!(matches!(comparison.verdict, Verdict::Mismatch { .. }), "{comparison}");
    assert_eq!(comparison.verdict.exit_code(), 3);
    assert!(comparison.metrics.is_none());
    assert!(
        comparison.to_string().contains("size differ: expected 160x120"),
        "{comparison}"
    );
}

#[test]
fn a_few_pixels_over_the_threshold_warn_and_a_hard_max_fails_them() {
    let golden = render(&case("directional_light"));
    let mut touched = golden.clone();
    let at = touched.index(80, 60);
    touched.color[at][1] += 0.05;
    let comparison = judge(&golden, &touched, &EXR_DEFAULTS);
    assert_eq!(comparison.verdict, Verdict::Warn, "{comparison}");
    assert!(comparison.verdict.accepts());
    assert!(comparison.to_string().contains("pixel (80, 60) G"), "{comparison}");

    let capped = Tolerance {
        max: Some(0.02),
        ..EXR_DEFAULTS
    };
    let comparison = judge(&golden, &touched, &capped);
    assert_fails_on(&comparison, Limit::Max);
}

#[test]
fn the_heatmap_marks_failing_pixels_and_non_finite_values_in_their_own_colours() {
    let golden = render(&case("vertex_normals"));
    let mut changed = golden.clone();
    let (failing, nan, tiny) = (golden.index(3, 4), golden.index(10, 4), golden.index(20, 4));
    changed.color[failing][0] += 0.5;
    changed.color[nan][1] = f32::NAN;
    changed.color[tiny][2] += 0.001;
    let heatmap =
        diff_heatmap(&Image::from_film(&golden, "a"), &Image::from_film(&changed, "b"), 0.01).expect("same size");
    assert_eq!(heatmap.get_pixel(3, 4).0, FAILING);
    assert_eq!(heatmap.get_pixel(10, 4).0, NON_FINITE);
    let [r, g, b] = heatmap.get_pixel(20, 4).0;
    assert!(
        r > g && g > b,
        "an error under the threshold is on the red-yellow scale: {:?}",
        [r, g, b]
    );
    let [r, g, b] = heatmap.get_pixel(30, 4).0;
    assert!(r == g && g == b, "an unchanged pixel is grey: {:?}", [r, g, b]);
}

#[test]
fn a_nan_limit_is_the_strictest_rather_than_no_limit() {
    let golden = render(&case("directional_light"));
    let mut touched = golden.clone();
    touched.color[0][0] += 0.001;
    let nan = Tolerance {
        pixel: f64::NAN,
        fail_fraction: f64::NAN,
        rmse: f64::NAN,
        max: None,
    };
    let comparison = judge(&golden, &touched, &nan);
    assert_fails_on(&comparison, Limit::FailFraction);
}

#[test]
fn the_command_line_defaults_are_the_case_file_defaults() {
    let minimal = "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";
    let case = parse(minimal, Path::new("x.toml"), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(case.tolerance, EXR_DEFAULTS);
}
