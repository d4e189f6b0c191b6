//! The eight-lane integrator draws every shipped case exactly as rays traced one at a time do:
//! colour, variance, depth and normals, bit for bit, under every spawn rule and sampling the
//! renderer offers. Compiled in both precisions, so each holds for `f32` and `f64`.

use std::path::{Path, PathBuf};

use super::{render, render_one_ray_at_a_time};
use super::super::scene::build_scene;
use crate::case::{Case, LoadOptions, load};
use crate::film::Film;
use crate::options::{Filter, Profile, RenderOptions, Seeding, Spawn};
use crate::progress::Silent;

fn shipped_cases() -> Vec<Case> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .expect("cases/ is readable")
        .map(|entry| entry.expect("entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "the shipped cases: {files:?}");
    files.iter().map(|path| load(path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))).collect()
}

/// The case's options at a small size whose rows are not a multiple of eight pixels, so that
/// runs of pixels wrap from one row to the next and the last run is partial.
fn small(case: &Case) -> RenderOptions {
    let mut trace = case.render.trace;
    (trace.width, trace.height) = (29, 21);
    let spawn = match case.render.profile {
        Profile::Native => Spawn::ErrorBounds,
        Profile::Mit6837 => Spawn::Course,
    };
    RenderOptions { trace, spawn, seeding: Seeding::Seeded, aovs: true }
}

fn assert_same_film(lanes: &Film, alone: &Film, what: &str) {
    let bits = |values: &[[f32; 3]]| values.iter().flat_map(|v| v.map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&lanes.color), bits(&alone.color), "{what}: colour");
    assert_eq!(
        lanes.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
        alone.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
        "{what}: depth"
    );
    assert_eq!(bits(&lanes.normal), bits(&alone.normal), "{what}: normals");
    assert_eq!(lanes.variance.as_deref().map(bits), alone.variance.as_deref().map(bits), "{what}: variance");
}

#[test]
fn every_shipped_case_is_drawn_as_by_rays_traced_alone() {
    for case in shipped_cases() {
        let scene = build_scene(&case).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let options = small(&case);
        assert_same_film(&render(&scene, &options, &Silent), &render_one_ray_at_a_time(&scene, &options), &case.name);
    }
}

/// The spawn rules and samplings that no shipped case uses on its own: a fixed epsilon, the
/// course's rules on a native scene, a pixel-seeded sampler, nine samples (a full packet and one
/// more), the filter with one sample per sub-pixel, and no AOVs.
#[test]
fn every_spawn_rule_and_sampling_is_drawn_as_by_rays_traced_alone() {
    let cases = shipped_cases();
    for name in ["spheres_shadows", "mirrors", "transforms", "course_scene07_arch", "vertex_normals"] {
        let case = cases.iter().find(|case| case.name == name).unwrap_or_else(|| panic!("no case {name}"));
        let scene = build_scene(case).expect("builds");
        let base = small(case);
        let variants = [
            RenderOptions { spawn: Spawn::FixedEpsilon(1e-4), ..base },
            RenderOptions { spawn: Spawn::Course, ..base },
            RenderOptions { spawn: Spawn::ErrorBounds, ..base },
            RenderOptions { seeding: Seeding::PixelIndex, trace: crate::options::Trace { samples: 4, ..base.trace }, ..base },
            RenderOptions { trace: crate::options::Trace { samples: 9, ..base.trace }, ..base },
            RenderOptions { trace: crate::options::Trace { samples: 1, filter: Filter::Gaussian, ..base.trace }, ..base },
            RenderOptions { trace: crate::options::Trace { samples: 1, filter: Filter::None, ..base.trace }, aovs: false, ..base },
        ];
        for (k, options) in variants.iter().enumerate() {
            let what = format!("{name}, variant {k}");
            assert_same_film(&render(&scene, options, &Silent), &render_one_ray_at_a_time(&scene, options), &what);
        }
    }
}

/// The probe that decodes a render's cube-map faces before it starts finds, when it traces
/// every pixel, exactly the faces that rendering decodes when they are first seen (by rays
/// traced alone, so without the probe); and a render after the probe is the same picture.
#[test]
fn the_cube_map_probe_finds_the_faces_a_render_decodes() {
    use super::super::packet::WhittedLanes;
    use super::super::scene::Background;
    use super::pixel_centre;
    let cases = shipped_cases();
    for name in ["course_scene06_bunny_1k", "course_scene07_arch"] {
        let case = cases.iter().find(|case| case.name == name).unwrap_or_else(|| panic!("no case {name}"));
        let options = small(case);
        let cube_map = |scene: &super::Scene| match &scene.background {
            Background::CubeMap(map) => map.undecoded_faces(),
            Background::Color(_) => panic!("{name} has a cube map"),
        };
        let alone = build_scene(case).expect("builds");
        let picture = render_one_ray_at_a_time(&alone, &options);
        let decoded = !cube_map(&alone) & 0b11_1111;
        assert!(decoded.count_ones() >= 2, "{name}: {decoded:06b}");

        let probed = build_scene(case).expect("builds");
        let (width, height) = (options.trace.width, options.trace.height);
        let centres: Vec<_> = (0..height).flat_map(|y| (0..width).map(move |x| pixel_centre(x, y))).collect();
        let trace = &options.trace;
        let lanes = WhittedLanes::new(&probed, trace.bounces, trace.shadows, options.spawn);
        assert_eq!(lanes.cube_map_faces_seen(&centres, (width, height)), decoded, "{name}");
        assert_eq!(cube_map(&probed), 0b11_1111, "{name}: the probe decodes nothing");
        assert_same_film(&render(&probed, &options, &Silent), &picture, name);
    }
}
