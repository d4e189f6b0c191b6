//! "Do only what a scene requires", checked by counting: each test fails if the renderer traces a
//! ray, or builds a tree, that nothing in the scene or its outputs asks for.

use goldray::options::RenderOptions;
use goldray::pipeline::render_options;
use goldray::progress::Silent;
use goldray::render::render_counting_rays;
use goldray::scene::build_scene;
use goldray::stats::RayCounts;

use super::{SPHERE, TWO_POINT_LIGHTS, case, counted, hits};

/// Two lights, but `shadows` off: every light is shaded as visible and no ray goes towards one.
#[test]
fn no_shadow_rays_without_shadows() {
    let scene = format!("{TWO_POINT_LIGHTS}{SPHERE}");
    for render in ["", "bounces = 3", "samples = 4\nfilter = \"gaussian\""] {
        let (_, counts) = counted(&case(render, &scene));
        assert_eq!(counts.shadow, 0, "{render:?}: {counts:?}");
    }
    let (film, counts) = counted(&case("shadows = true", &scene));
    assert_eq!(counts.shadow, 2 * hits(&film), "with shadows, one per light per hit");
}

/// Materials whose specular colour is zero reflect nothing, so however many bounces are allowed
/// they spawn no reflection ray; a single mirror among them does.
#[test]
fn no_reflection_rays_from_materials_without_a_specular_colour() {
    let matte = "[materials.matte]\ndiffuse = [0.5, 0.5, 0.5]\nspecular = [0, 0, 0]\nshininess = 20\n\
                 [[object]]\nkind = \"plane\"\nnormal = [0, 1, 0]\noffset = -1\nmaterial = \"matte\"\n";
    let scene = format!("{TWO_POINT_LIGHTS}{SPHERE}{matte}");
    let (film, counts) = counted(&case("bounces = 5\nshadows = true", &scene));
    assert!(
        hits(&film) > 50,
        "the sphere and the floor are shaded: {} hits",
        hits(&film)
    );
    assert_eq!(counts.reflection, 0, "{counts:?}");
    let mirror = "[materials.mirror]\nspecular = [1, 1, 1]\n\
                  [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"mirror\"\n";
    let (_, counts) = counted(&case("bounces = 5", &format!("{matte}{mirror}")));
    assert!(counts.reflection > 0, "a mirror sphere reflects: {counts:?}");
}

/// The extra pixel-centre ray for depth and normals is traced only when they are written: the
/// colour is the same without it, and the film's AOVs stay all misses.
#[test]
fn no_aov_rays_when_no_aov_is_written() {
    for render in [
        "samples = 4",
        "filter = \"gaussian\"",
        "samples = 4\nfilter = \"gaussian\"",
        "",
    ] {
        let case = case(render, SPHERE);
        let scene = build_scene(&case).unwrap_or_else(|e| panic!("{e}"));
        let with = render_options(&case);
        assert!(with.aovs, "a case always writes its EXR, with depth and normals");
        let without = RenderOptions { aovs: false, ..with };
        let (film, counts) = render_counting_rays(&scene, &with, &Silent);
        let (bare, bare_counts) = render_counting_rays(&scene, &without, &Silent);
        assert_eq!(bare_counts.aov, 0, "{render:?}");
        assert_eq!(bare_counts, RayCounts { aov: 0, ..counts }, "{render:?}");
        assert!(bare.color == film.color, "{render:?}: the AOVs changed the colour");
        assert!(hits(&film) > 0 && hits(&bare) == 0, "{render:?}: AOVs were written");
        assert!(bare.normal.iter().all(|n| *n == [0.0; 3]), "{render:?}");
    }
}

/// Infinite planes are tested beside the tree, and a handful of plain spheres side by side:
/// neither a scene of planes nor one of a few spheres builds (or traverses) a scene BVH.
#[test]
fn no_scene_bvh_for_planes_or_a_single_object() {
    let plane = |offset: i32| format!("[[object]]\nkind = \"plane\"\nnormal = [0, 1, 0]\noffset = {offset}\n");
    let sphere = |x: i32| format!("[[object]]\nkind = \"sphere\"\ncenter = [{x}, 0, 0]\nradius = 0.4\n");
    let scene_bvh = |body: &str| {
        build_scene(&case("", body))
            .unwrap_or_else(|e| panic!("{e}"))
            .geometry
            .bvh()
            .is_some()
    };
    assert!(!scene_bvh(&(-3..3).map(plane).collect::<String>()), "planes only");
    assert!(!scene_bvh(&sphere(0)), "one sphere");
    assert!(
        !scene_bvh(&format!("{}{}", sphere(0), plane(-1))),
        "one sphere over a plane"
    );
    assert!(
        !scene_bvh(&(-3..3).map(sphere).collect::<String>()),
        "six spheres are tested side by side"
    );
    assert!(
        scene_bvh(&(-6..6).map(sphere).collect::<String>()),
        "twelve spheres do get a tree"
    );
}
