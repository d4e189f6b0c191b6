//! Render statistics: exact ray counts on scenes counted by hand, the same counts for any
//! number of threads, and an image that does not depend on whether anything is counted.

#[path = "render_stats/cli.rs"]
mod cli;
#[path = "render_stats/required.rs"]
mod required;
mod util;

use std::path::Path;

use goldray::case::{Case, LoadOptions, parse};
use goldray::film::Film;
use goldray::pipeline::render_options;
use goldray::progress::Silent;
use goldray::render::{render, render_counting_rays};
use goldray::scene::build_scene;
use goldray::stats::RayCounts;

const CAMERA: &str = "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";

/// A sphere covering part of a 10×10 frame, so that some rays hit and some miss.
const SPHERE: &str = "[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n";

const TWO_POINT_LIGHTS: &str = "[[light]]\nkind = \"point\"\nposition = [0, 5, 5]\ncolor = [1, 1, 1]\nfalloff = 0.1\n\
                                [[light]]\nkind = \"point\"\nposition = [-5, 0, 5]\ncolor = [1, 1, 1]\nfalloff = 0.1\n";

/// A 10×10 case.
fn case(render: &str, body: &str) -> Case {
    sized_case(&format!("size = [10, 10]\n{render}"), body)
}

fn sized_case(render: &str, body: &str) -> Case {
    let toml = format!("[render]\n{render}\n{CAMERA}\n{body}");
    parse(&toml, Path::new("stats.toml"), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn counted(case: &Case) -> (Film, RayCounts) {
    let scene = build_scene(case).unwrap_or_else(|e| panic!("{e}"));
    render_counting_rays(&scene, &render_options(case), &Silent)
}

fn rays(camera: u64, aov: u64, shadow: u64, reflection: u64) -> RayCounts {
    RayCounts {
        camera,
        aov,
        shadow,
        reflection,
    }
}

fn hits(film: &Film) -> u64 {
    film.depth.iter().filter(|d| d.is_finite()).count() as u64
}

#[test]
fn four_samples_on_ten_by_ten_trace_400_camera_rays_and_100_aov_rays() {
    let (_, counts) = counted(&case("samples = 4", SPHERE));
    assert_eq!(counts, rays(400, 100, 0, 0));
}

#[test]
fn one_sample_reuses_the_camera_ray_for_the_aovs() {
    let (_, counts) = counted(&case("", SPHERE));
    assert_eq!(counts, rays(100, 0, 0, 0));
}

#[test]
fn the_gaussian_filter_traces_nine_subpixels_per_pixel() {
    let (_, counts) = counted(&case("filter = \"gaussian\"", SPHERE));
    assert_eq!(counts, rays(900, 100, 0, 0));
    let (_, counts) = counted(&case("filter = \"gaussian\"\nsamples = 4", SPHERE));
    assert_eq!(counts, rays(3600, 100, 0, 0));
}

#[test]
fn shadow_rays_are_one_per_light_per_hit() {
    let (film, counts) = counted(&case("shadows = true", &format!("{TWO_POINT_LIGHTS}{SPHERE}")));
    let hits = hits(&film);
    assert!(
        hits > 0 && hits < 100,
        "the sphere covers part of the frame: {hits} hits"
    );
    assert_eq!(counts, rays(100, 0, 2 * hits, 0));
    let (_, unshadowed) = counted(&case("", &format!("{TWO_POINT_LIGHTS}{SPHERE}")));
    assert_eq!(unshadowed, rays(100, 0, 0, 0), "no shadow rays without `shadows`");
}

/// Two facing mirrors with the camera between them: every camera ray hits the far one, and every
/// reflection bounces to the other, so each camera ray makes exactly `bounces` reflections and
/// is shaded `bounces + 1` times.
#[test]
fn rays_between_parallel_mirrors_reflect_exactly_bounces_times() {
    let mirrors = "[materials.mirror]\ndiffuse = [0.1, 0.1, 0.1]\nspecular = [0.9, 0.9, 0.9]\n\
                   [[light]]\nkind = \"point\"\nposition = [0, 0, 5]\ncolor = [1, 1, 1]\nfalloff = 0.1\n\
                   [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\nmaterial = \"mirror\"\n\
                   [[object]]\nkind = \"plane\"\nnormal = [0, 0, -1]\noffset = -20\nmaterial = \"mirror\"\n";
    let (_, counts) = counted(&case("bounces = 3", mirrors));
    assert_eq!(counts, rays(100, 0, 0, 300));
    let (_, counts) = counted(&case("bounces = 3\nshadows = true", mirrors));
    assert_eq!(counts, rays(100, 0, 400, 300));
}

/// A mirror floor under a level camera: the bottom five rows of a 10×10 image look down at it,
/// and their reflections go up into the empty sky.
#[test]
fn a_mirror_floor_reflects_the_lower_half_once_whatever_the_bounces() {
    let floor = "[materials.mirror]\nspecular = [1, 1, 1]\n\
                 [[object]]\nkind = \"plane\"\nnormal = [0, 1, 0]\noffset = -1\nmaterial = \"mirror\"\n";
    for bounces in [1, 2, 5] {
        let (film, counts) = counted(&case(&format!("bounces = {bounces}"), floor));
        assert_eq!(hits(&film), 50);
        assert_eq!(counts, rays(100, 0, 0, 50), "bounces = {bounces}");
    }
    let (_, counts) = counted(&case("", floor));
    assert_eq!(counts, rays(100, 0, 0, 0), "no reflections without bounces");
}

fn busy_case() -> Case {
    let body = format!(
        "{TWO_POINT_LIGHTS}[materials.chrome]\ndiffuse = [0.2, 0.2, 0.2]\nspecular = [0.8, 0.8, 0.8]\n\
         [[object]]\nkind = \"sphere\"\ncenter = [-0.6, 0, 0]\nradius = 0.7\nmaterial = \"chrome\"\n\
         [[object]]\nkind = \"sphere\"\ncenter = [0.7, 0.2, -1]\nradius = 0.8\nmaterial = \"chrome\"\n\
         [[object]]\nkind = \"plane\"\nnormal = [0, 1, 0]\noffset = -1\nmaterial = \"chrome\"\n"
    );
    sized_case(
        "size = [37, 23]\nsamples = 4\nbounces = 3\nshadows = true\nfilter = \"gaussian\"",
        &body,
    )
}

#[test]
fn counts_and_film_are_the_same_on_one_and_two_threads() {
    let case = busy_case();
    let results: Vec<(Film, RayCounts)> = [1, 2]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| counted(&case))
        })
        .collect();
    assert_eq!(results[0].1, results[1].1);
    assert!(results[0].0 == results[1].0, "1 and 2 threads render different films");
    let counts = results[0].1;
    assert_eq!((counts.camera, counts.aov), (37 * 23 * 9 * 4, 37 * 23));
    assert!(counts.shadow > 0 && counts.reflection > 0, "{counts:?}");
}

#[test]
fn counting_does_not_change_the_film() {
    let case = busy_case();
    let scene = build_scene(&case).unwrap();
    let plain = render(&scene, &render_options(&case), &Silent);
    assert!(counted(&case).0 == plain);
}
