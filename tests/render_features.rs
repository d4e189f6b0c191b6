//! Each feature of the rendering model, checked on pixel values that can be worked out by hand.

use std::path::Path;

use goldray::case::{LoadOptions, parse};
use goldray::film::Film;
use goldray::pipeline::render_case;

/// 33×33 so that the centre pixel's ray is exactly the camera direction.
const CAMERA: &str = "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";

fn render_in(dir: &Path, toml: &str) -> Film {
    let case = parse(toml, &dir.join("test.toml"), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    render_case(&case).unwrap_or_else(|e| panic!("{e}"))
}

fn render(body: &str) -> Film {
    render_in(Path::new("."), &format!("[render]\nsize = [33, 33]\n{CAMERA}\n{body}"))
}

fn pixel(film: &Film, x: u32, y: u32) -> [f32; 3] {
    film.color[film.index(x, y)]
}

fn centre(film: &Film) -> [f32; 3] {
    pixel(film, film.width / 2, film.height / 2)
}

fn assert_close(actual: [f32; 3], expected: [f32; 3], what: &str) {
    let close = actual.iter().zip(expected).all(|(a, e)| (a - e).abs() <= 1e-5);
    assert!(close, "{what}: got {actual:?}, expected {expected:?}");
}

/// A flat, unlit sphere: every pixel is either the background or `ambient · diffuse`.
const FLAT_SPHERE: &str = "[background]\ncolor = [0, 0, 0]\nambient = [1, 1, 1]\n[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.3\n";

fn mixed_pixels(film: &Film) -> usize {
    film.color.iter().filter(|c| c[0] > 1e-4 && c[0] < 1.0 - 1e-4).count()
}

#[test]
fn misses_see_the_background_and_hits_get_ambient_times_diffuse() {
    let film = render(
        "[background]\ncolor = [0.1, 0.2, 0.3]\nambient = [0.2, 0.2, 0.2]\n[materials.m]\ndiffuse = [1, 0.5, 0.25]\n\
         [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
    );
    assert_close(centre(&film), [0.2, 0.1, 0.05], "ambient");
    assert_close(pixel(&film, 0, 0), [0.1, 0.2, 0.3], "background");
    let middle = film.index(16, 16);
    assert!(
        (film.depth[middle] - 9.0).abs() < 1e-5,
        "depth is the distance to the hit: {}",
        film.depth[middle]
    );
    assert_close(
        film.normal[middle],
        [0.0, 0.0, 1.0],
        "normal at the front of the sphere",
    );
    assert_eq!(film.depth[0], f32::INFINITY);
    assert_eq!(film.normal[0], [0.0; 3]);
}

#[test]
fn directional_light_is_lambertian() {
    let film = render(
        "[[light]]\nkind = \"directional\"\ndirection = [0, -1, -1]\ncolor = [1, 1, 1]\n[materials.m]\ndiffuse = [0.5, 0.5, 0.5]\n\
         [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\nmaterial = \"m\"\n",
    );
    let expected = 0.5 * std::f32::consts::FRAC_1_SQRT_2;
    assert_close(centre(&film), [expected; 3], "cos 45° · 0.5");
    assert_close(
        pixel(&film, 3, 29),
        [expected; 3],
        "a directional light is the same everywhere",
    );
}

#[test]
fn point_light_falls_off_with_falloff_times_distance_squared() {
    let plane = "[[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\n";
    let near = render(&format!(
        "[[light]]\nkind = \"point\"\nposition = [0, 0, 2]\ncolor = [1, 1, 1]\nfalloff = 0.5\n{plane}"
    ));
    assert_close(centre(&near), [0.5; 3], "1 / (0.5 · 2²)");
    let far = render(&format!(
        "[[light]]\nkind = \"point\"\nposition = [0, 0, 4]\ncolor = [1, 1, 1]\nfalloff = 0.5\n{plane}"
    ));
    assert_close(centre(&far), [0.125; 3], "1 / (0.5 · 4²)");
}

#[test]
fn phong_highlight_adds_specular_colour() {
    let film = render(
        "[[light]]\nkind = \"directional\"\ndirection = [0, 0, -1]\ncolor = [1, 1, 1]\n\
         [materials.m]\ndiffuse = [0.2, 0.2, 0.2]\nspecular = [0.5, 0.5, 0.5]\nshininess = 50\n\
         [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\nmaterial = \"m\"\n",
    );
    assert_close(centre(&film), [0.7; 3], "diffuse 0.2 + full highlight 0.5");
    assert!(
        pixel(&film, 0, 16)[0] < 0.69,
        "the highlight fades away from the mirror direction"
    );
}

#[test]
fn shadows_remove_the_light_but_keep_ambient() {
    let scene = "[background]\nambient = [0.1, 0.1, 0.1]\n\
        [[light]]\nkind = \"directional\"\ndirection = [-1, 0, -1]\ncolor = [1, 1, 1]\n\
        [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\n\
        [[object]]\nkind = \"sphere\"\ncenter = [2, 0, 2]\nradius = 0.5\n";
    let lit = render(scene);
    assert_close(
        centre(&lit),
        [0.1 + std::f32::consts::FRAC_1_SQRT_2; 3],
        "no shadow rays without shadows",
    );
    let shadowed = render_in(
        Path::new("."),
        &format!("[render]\nsize = [33, 33]\nshadows = true\n{CAMERA}\n{scene}"),
    );
    assert_close(centre(&shadowed), [0.1; 3], "ambient only in the sphere's shadow");
    assert_close(
        pixel(&shadowed, 16, 2),
        pixel(&lit, 16, 2),
        "outside the shadow nothing changes",
    );
}

#[test]
fn mirrors_reflect_up_to_the_bounce_limit() {
    // A mirror facing the camera; a red sphere behind the camera is only visible in it.
    let scene = |bounces: u32, specular: f32| {
        format!(
            "[render]\nsize = [33, 33]\nbounces = {bounces}\n{CAMERA}\n[background]\nambient = [1, 1, 1]\n\
             [materials.mirror]\ndiffuse = [0, 0, 0]\nspecular = [{specular}, {specular}, {specular}]\n\
             [materials.red]\ndiffuse = [1, 0, 0]\n\
             [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\nmaterial = \"mirror\"\n\
             [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 20]\nradius = 2\nmaterial = \"red\"\n"
        )
    };
    assert_close(
        centre(&render_in(Path::new("."), &scene(0, 1.0))),
        [0.0; 3],
        "no bounces, no reflection",
    );
    assert_close(
        centre(&render_in(Path::new("."), &scene(1, 1.0))),
        [1.0, 0.0, 0.0],
        "one bounce sees the sphere",
    );
    assert_close(
        centre(&render_in(Path::new("."), &scene(1, 0.5))),
        [0.5, 0.0, 0.0],
        "weighted by the specular colour",
    );
}

#[test]
fn facing_mirrors_terminate_at_the_bounce_limit() {
    let scene = |bounces: u32| {
        format!(
            "[render]\nsize = [9, 9]\nbounces = {bounces}\n[camera]\ncenter = [0, 0, 0]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 10\n\
             [background]\nambient = [0.5, 0.5, 0.5]\n[materials.mirror]\ndiffuse = [0.1, 0.1, 0.1]\nspecular = [0.9, 0.9, 0.9]\n\
             [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = -1\nmaterial = \"mirror\"\n\
             [[object]]\nkind = \"plane\"\nnormal = [0, 0, -1]\noffset = -1\nmaterial = \"mirror\"\n"
        )
    };
    let sum = |film: &Film| centre(film)[0];
    let (three, sixty_four) = (
        sum(&render_in(Path::new("."), &scene(3))),
        sum(&render_in(Path::new("."), &scene(64))),
    );
    // Each bounce adds 0.05 · 0.9^k: a geometric series.
    let expected = |n: i32| (0..=n).map(|k| 0.05 * 0.9f32.powi(k)).sum::<f32>();
    assert!((three - expected(3)).abs() < 1e-5, "{three} vs {}", expected(3));
    assert!(
        (sixty_four - expected(64)).abs() < 1e-4,
        "{sixty_four} vs {}",
        expected(64)
    );
}

#[test]
fn jitter_blends_edges_and_depends_only_on_the_seed() {
    let one = render(FLAT_SPHERE);
    assert_eq!(mixed_pixels(&one), 0, "one sample per pixel: hard edges");
    let jittered = |seed: u32| {
        render_in(
            Path::new("."),
            &format!("[render]\nsize = [33, 33]\nsamples = 16\nseed = {seed}\n{CAMERA}\n{FLAT_SPHERE}"),
        )
    };
    let a = jittered(1);
    assert!(
        mixed_pixels(&a) > 20,
        "16 samples blend the silhouette: {}",
        mixed_pixels(&a)
    );
    assert_eq!(a, jittered(1), "same seed, same image");
    assert_ne!(a, jittered(2), "another seed moves the samples");
}

#[test]
fn gaussian_filter_blends_edges_and_keeps_flat_regions() {
    let film = render_in(
        Path::new("."),
        &format!("[render]\nsize = [33, 33]\nfilter = \"gaussian\"\n{CAMERA}\n{FLAT_SPHERE}"),
    );
    assert!(mixed_pixels(&film) > 20, "{}", mixed_pixels(&film));
    assert_close(centre(&film), [1.0; 3], "weights sum to one");
    assert_close(pixel(&film, 0, 0), [0.0; 3], "background stays background");
}

#[test]
fn non_uniform_scale_makes_an_ellipse() {
    let film = render(&format!("{FLAT_SPHERE}transform = [{{ scale = [2, 0.5, 1] }}]\n"));
    let hits = |pixels: Vec<usize>| pixels.into_iter().filter(|&i| film.depth[i].is_finite()).count();
    let across = hits((0..33).map(|x| film.index(x, 16)).collect());
    let down = hits((0..33).map(|y| film.index(16, y)).collect());
    assert!(across >= 3 * down, "wide and flat: {across} across, {down} down");
}

#[test]
fn a_raw_matrix_equals_the_same_ops() {
    let ops = render(&format!(
        "{FLAT_SPHERE}transform = [{{ translate = [0.5, 0.2, 0] }}, {{ scale = [2, 1, 1] }}]\n"
    ));
    let matrix = render(&format!(
        "{FLAT_SPHERE}transform = [{{ matrix = [2, 0, 0, 0.5,  0, 1, 0, 0.2,  0, 0, 1, 0,  0, 0, 0, 1] }}]\n"
    ));
    assert_eq!(ops, matrix);
}

#[test]
fn groups_pass_their_material_to_children_that_have_none() {
    let film = render(
        "[background]\nambient = [1, 1, 1]\n[materials.red]\ndiffuse = [1, 0, 0]\n[materials.blue]\ndiffuse = [0, 0, 1]\n\
         [[object]]\nkind = \"group\"\nmaterial = \"red\"\nobjects = [\n\
           { kind = \"sphere\", center = [-1.5, 0, 0], radius = 0.5 },\n\
           { kind = \"sphere\", center = [1.5, 0, 0], radius = 0.5, material = \"blue\" },\n]\n",
    );
    assert_close(pixel(&film, 8, 16), [1.0, 0.0, 0.0], "inherits red");
    assert_close(pixel(&film, 24, 16), [0.0, 0.0, 1.0], "keeps its own blue");
}

#[test]
fn vertex_normals_shade_smoothly_and_plain_triangles_flat() {
    let triangle = |normals: &str| {
        render(&format!(
            "[[light]]\nkind = \"directional\"\ndirection = [0, 0, -1]\ncolor = [1, 1, 1]\n\
             [[object]]\nkind = \"triangle\"\nvertices = [[-2, -2, 0], [2, -2, 0], [0, 2, 0]]\n{normals}"
        ))
    };
    let flat = triangle("");
    let smooth = triangle("normals = [[-0.6, 0, 0.8], [0.6, 0, 0.8], [0, 0, 1]]\n");
    assert_close(
        pixel(&flat, 12, 20),
        pixel(&flat, 20, 20),
        "flat: same colour everywhere",
    );
    // Near the bottom-left corner the normal leans towards (−0.6, 0, 0.8); near the top it is +z.
    assert!(
        (pixel(&smooth, 16, 6)[0] - pixel(&smooth, 6, 27)[0]).abs() > 0.1,
        "smooth: varies across the face"
    );
}

#[test]
fn meshes_load_from_obj_and_instances_share_one_mesh() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let toml = format!(
        "[render]\nsize = [33, 33]\n{CAMERA}\n[background]\nambient = [1, 1, 1]\n\
         [[object]]\nkind = \"mesh\"\nobj = \"quad.obj\"\ntransform = [{{ translate = [-1.5, 0, 0] }}, {{ uniform_scale = 0.5 }}]\n\
         [[object]]\nkind = \"mesh\"\nobj = \"quad.obj\"\ntransform = [{{ translate = [1.5, 0, 0] }}, {{ uniform_scale = 0.5 }}]\n"
    );
    let film = render_in(dir.path(), &toml);
    assert_close(pixel(&film, 8, 16), [1.0; 3], "left instance");
    assert_close(pixel(&film, 24, 16), [1.0; 3], "right instance");
    assert_close(centre(&film), [0.0; 3], "nothing between them");

    let case = parse(&toml, &dir.path().join("test.toml"), &LoadOptions::default()).unwrap();
    let scene = goldray::scene::build_scene(&case).unwrap();
    let meshes: Vec<_> = scene
        .geometry
        .objects()
        .iter()
        .filter_map(|o| match &o.shape {
            goldray::scene::Shape::Mesh(mesh) => Some(mesh.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(meshes.len(), 2);
    assert!(
        std::sync::Arc::ptr_eq(&meshes[0], &meshes[1]),
        "one mesh, one BVH, two instances"
    );
}

#[test]
fn a_light_on_a_surface_never_produces_nan() {
    let film = render(
        "[[light]]\nkind = \"point\"\nposition = [0, 0, 0]\ncolor = [1, 1, 1]\nfalloff = 1\n\
         [materials.m]\nspecular = [1, 1, 1]\n[[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = 0\nmaterial = \"m\"\n",
    );
    assert!(film.color.iter().flatten().all(|c| c.is_finite()));
}
