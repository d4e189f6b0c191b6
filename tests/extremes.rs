//! Inputs at the edges of the model: each gives a finite, sensible picture or a clear error.
//! The table of docs/extremes.md documents the same decisions.

use std::path::Path;

use goldray::case::{LoadOptions, parse};
use goldray::film::Film;
use goldray::geometry::Ray;
use goldray::geometry::plane::Plane;
use goldray::geometry::sphere::Sphere;
use goldray::options::{Profile, Spawn};
use goldray::pipeline::render_case;
use goldray::real::{Color, Real, Vec3};
use goldray::render::integrator::Whitted;
use goldray::scene::camera::Camera;
use goldray::scene::light::Light;
use goldray::scene::material::Material;
use goldray::scene::{Aggregate, Background, Object, Scene, Shape, Triangle};
use goldray::stats::RayCounts;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

const CAMERA: &str = "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";

fn render_in(dir: &Path, toml: &str) -> Result<Film, String> {
    let case = parse(toml, &dir.join("extreme.toml"), &LoadOptions::default()).map_err(|e| e.to_string())?;
    render_case(&case).map_err(|e| e.to_string())
}

fn render(toml: &str) -> Result<Film, String> {
    render_in(Path::new("."), toml)
}

/// A picture that is finite everywhere and not a single flat colour.
fn assert_sensible(film: &Film, what: &str) {
    assert!(
        film.color.iter().flatten().all(|c| c.is_finite()),
        "{what}: non-finite colour"
    );
    assert!(
        film.normal.iter().flatten().all(|c| c.is_finite()),
        "{what}: non-finite normal"
    );
    assert!(film.depth.iter().all(|d| !d.is_nan()), "{what}: NaN depth");
}

fn lit(objects: &str) -> String {
    format!(
        "[render]\nsize = [24, 24]\nshadows = true\nbounces = 2\n{CAMERA}\n[background]\ncolor = [0.2, 0.2, 0.3]\nambient = [0.1, 0.1, 0.1]\n\
         [[light]]\nkind = \"point\"\nposition = [2, 3, 4]\ncolor = [1, 1, 1]\nfalloff = 0.02\n\
         [materials.shiny]\ndiffuse = [0.5, 0.5, 0.5]\nspecular = [0.5, 0.5, 0.5]\nshininess = 20\n{objects}"
    )
}

#[test]
fn rays_parallel_to_a_plane_see_it_edge_on_as_nothing() {
    let film = render(
        "[render]\nsize = [25, 25]\n[camera]\ncenter = [0, 1, 0]\ndirection = [1, 0, 0]\nup = [0, 1, 0]\nfov = 30\n\
         [background]\ncolor = [0.5, 0.5, 0.5]\nambient = [1, 1, 1]\n[materials.black]\ndiffuse = [0, 0, 0]\n\
         [[object]]\nkind = \"plane\"\nnormal = [0, 1, 0]\noffset = 0\nmaterial = \"black\"\n",
    )
    .unwrap();
    assert_sensible(&film, "edge-on plane");
    let middle_row = film.index(12, 12);
    assert_eq!(
        film.depth[middle_row],
        f32::INFINITY,
        "the middle row's rays are parallel to the plane"
    );
    assert_eq!(film.color[film.index(12, 11)], [0.5; 3], "above: background");
    assert_eq!(film.color[film.index(12, 13)], [0.0; 3], "below: the plane");
}

#[test]
fn rays_through_a_shared_edge_and_vertex_hit_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    // Four triangles meeting at the centre vertex (0, 0, 0), which the centre pixel's ray hits,
    // with edges along both axes through it.
    std::fs::write(
        dir.path().join("fan.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\n",
    )
    .unwrap();
    let film = render_in(
        dir.path(),
        &format!("[render]\nsize = [25, 25]\n{CAMERA}\n[background]\nambient = [1, 1, 1]\n[[object]]\nkind = \"mesh\"\nobj = \"fan.obj\"\n"),
    )
    .unwrap();
    for (x, y) in [(12, 12), (12, 9), (15, 12), (12, 15), (9, 12)] {
        assert!(
            film.depth[film.index(x, y)].is_finite(),
            "pixel ({x}, {y}) on a shared edge or vertex escaped"
        );
    }
}

/// Shading is one-sided and never flips normals (the assignment's rule), so the inside of the
/// shell is shaded with its outward normal: a point whose outside faces the light is lit.
#[test]
fn camera_inside_a_sphere_sees_its_shell_shaded_with_outward_normals() {
    let film = render(&lit(
        "[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 10]\nradius = 3\nmaterial = \"shiny\"\n",
    ))
    .unwrap();
    assert_sensible(&film, "inside a sphere");
    assert!(
        film.depth.iter().all(|d| (d - 3.0).abs() < 1e-4),
        "every ray meets the sphere at its radius"
    );
    let towards_light = film.color[film.index(23, 0)][0];
    let away = film.color[film.index(0, 23)][0];
    assert!(
        towards_light > away + 0.1,
        "lit where the outward normal faces the light: {towards_light} vs {away}"
    );
}

#[test]
fn a_point_light_inside_a_closed_object_lights_nothing_outside_it() {
    let film = render(
        "[render]\nsize = [24, 24]\nshadows = true\n[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n\
         [background]\nambient = [0.1, 0.1, 0.1]\n[[light]]\nkind = \"point\"\nposition = [0, 0, 0]\ncolor = [1, 1, 1]\nfalloff = 0.02\n\
         [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\
         [[object]]\nkind = \"plane\"\nnormal = [0, 0, 1]\noffset = -3\n",
    )
    .unwrap();
    assert_sensible(&film, "light inside a sphere");
    assert!(
        film.color.iter().all(|c| (c[0] - 0.1).abs() < 1e-5),
        "outside the sphere everything is in its shadow"
    );
}

#[test]
fn extreme_shininess_is_finite_and_narrows_the_highlight() {
    let highlight_pixels = |shininess: &str| {
        let film = render(&format!(
            "[render]\nsize = [33, 33]\n{CAMERA}\n[[light]]\nkind = \"directional\"\ndirection = [0, 0, -1]\ncolor = [1, 1, 1]\n\
             [materials.m]\ndiffuse = [0, 0, 0]\nspecular = [1, 1, 1]\nshininess = {shininess}\n\
             [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2\nmaterial = \"m\"\n"
        ))
        .unwrap();
        assert_sensible(&film, shininess);
        film.color.iter().filter(|c| c[0] > 0.5).count()
    };
    let (zero, ten_thousand, million) = (highlight_pixels("0"), highlight_pixels("1e4"), highlight_pixels("1e6"));
    assert!(
        zero > ten_thousand && ten_thousand >= million && million >= 1,
        "{zero} {ten_thousand} {million}"
    );
}

#[test]
fn zero_falloff_is_an_error_that_says_why() {
    let error = render(&format!(
        "{CAMERA}[[light]]\nkind = \"point\"\nposition = [0, 1, 0]\ncolor = [1, 1, 1]\nfalloff = 0\n"
    ))
    .unwrap_err();
    assert!(error.contains("falloff") && error.contains("> 0"), "{error}");
}

#[test]
fn degenerate_shapes_are_invisible_not_nan() {
    let film = render(&lit(
        "[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0\nmaterial = \"shiny\"\n\
         [[object]]\nkind = \"triangle\"\nvertices = [[-1, -1, 0], [1, 1, 0], [2, 2, 0]]\nmaterial = \"shiny\"\n\
         [[object]]\nkind = \"triangle\"\nvertices = [[0, 0, 0], [0, 0, 0], [0, 0, 0]]\nmaterial = \"shiny\"\n",
    ))
    .unwrap();
    assert_sensible(&film, "degenerate shapes");
    assert!(
        film.depth.iter().all(|d| d.is_infinite()),
        "a zero-radius sphere and zero-area triangles are never hit"
    );
}

#[test]
fn unusable_obj_normals_fall_back_and_nan_coordinates_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("zero.obj"),
        "v -2 -2 0\nv 2 -2 0\nv 0 2 0\nvn 0 0 0\nvn 0 0 0\nvn 0 0 0\nf 1//1 2//2 3//3\n",
    )
    .unwrap();
    let film = render_in(
        dir.path(),
        &lit("[[object]]\nkind = \"mesh\"\nobj = \"zero.obj\"\nmaterial = \"shiny\"\n"),
    )
    .unwrap();
    assert_sensible(&film, "zero-length OBJ normals");
    assert_eq!(
        film.normal[film.index(12, 12)],
        [0.0, 0.0, 1.0],
        "falls back to the face normal"
    );
    std::fs::write(
        dir.path().join("nan.obj"),
        "v -2 -2 0\nv 2 -2 0\nv 0 2 0\nvn nan 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n",
    )
    .unwrap();
    match render_in(
        dir.path(),
        &lit("[[object]]\nkind = \"mesh\"\nobj = \"nan.obj\"\nmaterial = \"shiny\"\n"),
    ) {
        Ok(film) => assert_sensible(&film, "NaN OBJ normal"),
        Err(error) => assert!(
            error.contains("nan.obj:4"),
            "a NaN normal is reported at its line: {error}"
        ),
    }
}

#[test]
fn coincident_surfaces_render_the_same_on_any_thread_count() {
    let toml = lit("[materials.red]\ndiffuse = [1, 0, 0]\n\
         [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.5\nmaterial = \"shiny\"\n\
         [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.5\nmaterial = \"red\"\n");
    let films: Vec<Film> = [1, 2]
        .iter()
        .map(|&threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| render(&toml).unwrap())
        })
        .collect();
    assert_sensible(&films[0], "coincident spheres");
    assert_eq!(
        films[0], films[1],
        "which coincident surface wins never depends on scheduling"
    );
}

#[test]
fn singular_transforms_are_errors_and_nearly_singular_ones_render() {
    let squash = |factor: &str| {
        render(&lit(&format!(
            "[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.5\nmaterial = \"shiny\"\ntransform = [{{ scale = [1, {factor}, 1] }}]\n"
        )))
    };
    let error = squash("0").unwrap_err();
    assert!(error.contains("singular"), "{error}");
    let thin = squash("1e-4").unwrap();
    assert_sensible(&thin, "a sphere squashed to 1e-4");
}

#[test]
fn one_pixel_and_one_row_images_render() {
    for size in ["[1, 1]", "[1, 10000]", "[10000, 1]"] {
        // Radius 5: a 10000×1 image's pixels are 0.27 wide at unit distance.
        let film = render(&format!(
            "[render]\nsize = {size}\n{CAMERA}\n[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 5\n"
        ))
        .unwrap();
        assert_sensible(&film, size);
        assert!(
            film.depth.iter().any(|d| d.is_finite()),
            "{size}: the sphere in the middle is seen"
        );
    }
}

fn config() -> Config {
    Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x5afe),
        failure_persistence: None,
        ..Config::default()
    }
}

fn vector(range: std::ops::Range<Real>) -> impl Strategy<Value = Vec3> {
    (range.clone(), range.clone(), range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn material() -> impl Strategy<Value = Material> {
    (
        vector(0.0..1.0),
        vector(0.0..1.0),
        prop_oneof![Just(0.0), 0.0..100.0 as Real, Just(1e6)],
    )
        .prop_map(|(diffuse, specular, shininess)| Material {
            diffuse,
            specular,
            shininess,
        })
}

fn object(materials: u32) -> impl Strategy<Value = Object> {
    prop_oneof![
        (vector(-3.0..3.0), 0.0..2.0 as Real).prop_map(|(center, radius)| Shape::Sphere(Sphere { center, radius })),
        (vector(-3.0..3.0), vector(-3.0..3.0), vector(-3.0..3.0)).prop_map(|(a, b, c)| Shape::Triangle(Triangle {
            vertices: [a, b, c],
            normals: Some([a, b - a, Vec3::ZERO])
        })),
    ]
    .prop_flat_map(move |shape| (Just(shape), 0..materials))
    .prop_map(|(shape, material)| Object {
        shape,
        transform: None,
        material,
    })
}

fn light() -> impl Strategy<Value = Light> {
    prop_oneof![
        (
            vector(-3.0..3.0),
            vector(0.0..2.0),
            prop_oneof![Just(1e-30 as Real), 1e-3..1.0 as Real]
        )
            .prop_map(|(position, color, falloff)| Light::Point {
                position,
                color,
                falloff
            }),
        (vector(-1.0..1.0), vector(0.0..2.0)).prop_filter_map("a direction", |(direction, color)| {
            direction
                .try_normalize()
                .map(|direction| Light::Directional { direction, color })
        }),
    ]
}

proptest! {
    #![proptest_config(config())]

    /// The integrator's own output, before the film's last-line sanitising, is finite for random
    /// scenes (degenerate shapes, zero-length vertex normals, lights on surfaces, shininess 0 and
    /// 1e6, a near-zero fall-off) and random rays, with shadows and bounces.
    #[test]
    fn radiance_is_always_finite(
        materials in prop::collection::vec(material(), 1..4),
        objects in prop::collection::vec(object(3), 0..12),
        lights in prop::collection::vec(light(), 0..4),
        rays in prop::collection::vec((vector(-4.0..4.0), vector(-1.0..1.0)), 32),
    ) {
        let count = materials.len() as u32;
        let objects: Vec<Object> = objects.into_iter().map(|mut o| { o.material %= count; o }).collect();
        let scene = Scene {
            camera: Camera::new(Profile::Native, Vec3::Z * 10.0, -Vec3::Z, Vec3::Y, 30.0),
            background: Background::Color(Color::splat(0.2)),
            ambient: Color::splat(0.1),
            lights,
            materials,
            geometry: Aggregate::new(objects, vec![(Plane::new(Vec3::Y, -3.0), 0)]),
        };
        let integrator = Whitted::new(&scene, 8, true, Spawn::ErrorBounds);
        let mut counts = RayCounts::default();
        for (origin, direction) in rays {
            let (color, _) = integrator.trace(Ray::new(origin, direction), &mut counts);
            prop_assert!(color.is_finite(), "{color} along {origin} + t{direction}");
        }
    }
}
