//! Throughput and end-to-end benchmarks.
//!
//! - `primary_rays/blob_1.3M`: camera rays into a 1,310,720-triangle mesh that fills the frame,
//!   on one thread (per-core figure) and on two; criterion reports rays/s as elements/s.
//! - `incoherent_rays/blob_1.3M`: closest hits of rays with random origins in the cube around the
//!   same mesh (about one in six inside it) and random directions, from a stateless hash, on one and
//!   two threads: the memory-bound case of secondary rays, with no two rays alike.
//! - `bvh_build/blob_1.3M`: the binned-SAH build over that mesh's triangle boxes, on one and two
//!   threads.
//! - `only_what_is_required/blob_1.3M/*`: the blob lit by a point light with shadows on and
//!   off, and unlit: shadows off should cost what no light costs; and 4 samples per pixel with
//!   and without the depth and normal AOVs (5 and 4 rays per pixel).
//! - `end_to_end/*`: load, build and render shipped cases (no file writes).
//! - `course_scenes/seven_at_800`: the course's seven grading commands at 800×800, one after
//!   another, each parsed, rendered and its three PNGs encoded, as `goldray mit6837` does.
//! - `stats_overhead/*`: the same render with and without ray counting (`--stats`), on one
//!   thread, for `cases/bench/blob_1m.toml` (expensive rays: 1.3M triangles; the OBJ is generated
//!   on first use) and `cases/mirrors.toml` (cheap rays, where counting weighs most). Criterion
//!   reports rays/s; `on` and `off` should agree within noise.

use std::path::Path;
use std::sync::{Arc, LazyLock};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use goldray::case::{AssignmentOptions, LoadOptions, load, load_assignment_scene};
use goldray::film::{Tonemap, color_image, depth_image, encode_png, normals_image};
use goldray::geometry::Ray;
use goldray::geometry::aabb::Aabb;
use goldray::geometry::bvh::Bvh;
use goldray::geometry::generate::{blob, write_obj};
use goldray::geometry::mesh::{Mesh, VertexNormals};
use goldray::options::{Filter, Profile, RenderOptions, Seeding, Spawn, Trace};
use goldray::pipeline::{render_case, render_options};
use goldray::progress::Silent;
use goldray::real::{Color, Real, Vec3};
use goldray::render::{render, render_counting_rays};
use goldray::scene::camera::Camera;
use goldray::scene::light::Light;
use goldray::scene::material::Material;
use goldray::scene::{Aggregate, Background, Object, Scene, Shape, build_scene};
use rayon::prelude::*;

const SIDE: u32 = 256;
/// Rays per iteration of the incoherent benchmark: enough that each thread gets many chunks.
const INCOHERENT_RAYS: usize = 1 << 16;

/// 20·4⁸ triangles: an icosahedron subdivided eight times.
const BLOB_TRIANGLES: u64 = 1_310_720;

/// The 1,310,720-triangle blob's vertices and triangles, generated on first use.
static BLOB: LazyLock<(Vec<Vec3>, Vec<[u32; 3]>)> = LazyLock::new(|| blob(8, 1));

/// The blob as a mesh with its BVH, built once and shared by every benchmark that renders it.
static BLOB_MESH: LazyLock<Arc<Mesh>> = LazyLock::new(|| {
    let (positions, triangles) = &*BLOB;
    Arc::new(Mesh::new(positions, triangles, VertexNormals::Averaged).expect("the blob is a valid mesh"))
});

/// The scenes below are cheap to make once the mesh exists, so each benchmark makes its own
/// inside its closure: criterion calls only the closures its filter selects, and a filtered run
/// (`cargo bench -- incoherent`, or one under callgrind) builds nothing it does not measure.
fn blob_scene() -> Scene {
    blob_scene_lit(Vec::new())
}

fn blob_scene_lit(lights: Vec<Light>) -> Scene {
    let object = Object {
        shape: Shape::Mesh(Arc::clone(&BLOB_MESH)),
        transform: None,
        material: 0,
    };
    Scene {
        camera: Camera::new(Profile::Native, Vec3::new(0.0, 0.0, 2.6), -Vec3::Z, Vec3::Y, 40.0),
        background: Background::Color(Color::ZERO),
        ambient: Color::ONE,
        lights,
        materials: vec![Material::default()],
        geometry: Aggregate::new(vec![object], Vec::new()),
    }
}

fn primary_rays(c: &mut Criterion) {
    let options = RenderOptions {
        trace: Trace {
            width: SIDE,
            height: SIDE,
            bounces: 0,
            shadows: false,
            samples: 1,
            seed: 0,
            filter: Filter::None,
        },
        spawn: Spawn::ErrorBounds,
        seeding: Seeding::Seeded,
        aovs: true,
    };
    let mut group = c.benchmark_group("primary_rays");
    group.sample_size(10);
    group.throughput(Throughput::Elements(u64::from(SIDE * SIDE)));
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_function(format!("blob_1.3M/{threads}_threads"), |b| {
            let scene = blob_scene();
            b.iter(|| pool.install(|| render(&scene, &options, &Silent)))
        });
    }
    group.finish();
}

/// A pool of `threads` workers, for a benchmark measured at a given thread count.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

/// SplitMix64 of a ray index and one of eight streams: every ray is a pure function of its index.
fn hash(index: u64, stream: u64) -> u64 {
    let mut z = index
        .wrapping_mul(8)
        .wrapping_add(stream)
        .wrapping_add(1)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform value in `[0, 1)` from 24 bits of the hash.
fn uniform(index: u64, stream: u64) -> Real {
    (hash(index, stream) >> 40) as Real / (1u64 << 24) as Real
}

/// Origins uniform in the cube [−1.5, 1.5]³ around the blob (radius about 0.75 to 1.25), so
/// that some start inside it (about one in six) and most outside, and directions uniform on the
/// sphere.
fn incoherent_ray(index: u64) -> Ray {
    let origin = Vec3::new(uniform(index, 0), uniform(index, 1), uniform(index, 2)) * 3.0 - Vec3::splat(1.5);
    let z = 2.0 * uniform(index, 3) - 1.0;
    let phi = std::f64::consts::TAU as Real * uniform(index, 4);
    let ring = (1.0 - z * z).max(0.0).sqrt();
    Ray::new(origin, Vec3::new(ring * phi.cos(), ring * phi.sin(), z))
}

fn incoherent_rays(c: &mut Criterion) {
    let rays: Vec<Ray> = (0..INCOHERENT_RAYS as u64).map(incoherent_ray).collect();
    let mut group = c.benchmark_group("incoherent_rays");
    group.sample_size(10);
    group.throughput(Throughput::Elements(INCOHERENT_RAYS as u64));
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_function(format!("blob_1.3M/{threads}_threads"), |b| {
            let scene = blob_scene();
            b.iter(|| {
                pool.install(|| {
                    rays.par_chunks(256)
                        .map(|chunk| {
                            chunk
                                .iter()
                                .filter(|ray| scene.geometry.intersect(ray).is_some())
                                .count()
                        })
                        .sum::<usize>()
                })
            })
        });
    }
    group.finish();
}

fn bvh_build(c: &mut Criterion) {
    let bounds = LazyLock::new(|| {
        let (positions, triangles) = &*BLOB;
        triangles
            .iter()
            .map(|corners| Aabb::from_points(corners.map(|i| positions[i as usize])))
            .collect::<Vec<_>>()
    });
    let mut group = c.benchmark_group("bvh_build");
    group.sample_size(10);
    group.throughput(Throughput::Elements(BLOB_TRIANGLES));
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_function(format!("blob_1.3M/{threads}_threads"), |b| {
            b.iter(|| pool.install(|| Bvh::build(&bounds)))
        });
    }
    group.finish();
}

fn end_to_end(c: &mut Criterion) {
    let mut group = c.benchmark_group("end_to_end");
    group.sample_size(10);
    for name in ["spheres_shadows", "blob_mesh"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join("cases")
            .join(format!("{name}.toml"));
        group.bench_function(name, |b| {
            b.iter(|| {
                let case = load(&path, &LoadOptions::default()).expect("a shipped case loads");
                render_case(&case).expect("a shipped case renders")
            })
        });
    }
    group.finish();
}

/// (scene, depth range, bounces, shadows) of the course's grading commands.
const COURSE_COMMANDS: [(&str, (f64, f64), u32, bool); 7] = [
    ("scene01_plane", (8.0, 18.0), 0, false),
    ("scene02_cube", (8.0, 18.0), 0, false),
    ("scene03_sphere", (8.0, 18.0), 0, false),
    ("scene04_axes", (8.0, 18.0), 0, false),
    ("scene05_bunny_200", (0.8, 1.0), 0, false),
    ("scene06_bunny_1k", (8.0, 18.0), 4, false),
    ("scene07_arch", (8.0, 18.0), 4, true),
];

fn course_scenes(c: &mut Criterion) {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("cases/mit6837");
    let mut group = c.benchmark_group("course_scenes");
    group.sample_size(10);
    group.bench_function("seven_at_800", |b| {
        b.iter(|| {
            for (scene, depth_range, bounces, shadows) in COURSE_COMMANDS {
                let options = AssignmentOptions {
                    width: 800,
                    height: 800,
                    bounces,
                    shadows,
                    depth_range: Some(depth_range),
                    normals: true,
                    ..AssignmentOptions::default()
                };
                let case =
                    load_assignment_scene(&data.join(format!("{scene}.txt")), &options).expect("a course scene loads");
                let film = render_case(&case).expect("a course scene renders");
                let (min, max) = (depth_range.0 as f32, depth_range.1 as f32);
                for image in [
                    color_image(&film, Tonemap::Clamp),
                    normals_image(&film, Tonemap::Clamp),
                    depth_image(&film, min, max, Tonemap::Clamp),
                ] {
                    encode_png(&image).expect("PNG encoding");
                }
            }
        })
    });
    group.finish();
}

/// The 1.3M-triangle OBJ is 50 MB, so it is generated rather than committed; this is what
/// `cargo run --release --example blob -- 8 1 cases/bench/assets/blob_1m.obj` writes.
fn ensure_blob_1m(path: &Path) {
    if !path.exists() {
        let (positions, triangles) = &*BLOB;
        std::fs::create_dir_all(path.parent().expect("the asset has a directory"))
            .expect("cases/bench/assets is writable");
        write_obj(path, positions, triangles).expect("the blob OBJ is written");
    }
}

fn stats_overhead(c: &mut Criterion) {
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("cases");
    ensure_blob_1m(&cases.join("bench/assets/blob_1m.obj"));
    let pool = pool(1);
    let mut group = c.benchmark_group("stats_overhead");
    group.sample_size(10);
    for path in [cases.join("bench/blob_1m.toml"), cases.join("mirrors.toml")] {
        let case = load(&path, &LoadOptions::default()).expect("a shipped case loads");
        let scene = build_scene(&case).expect("a shipped case builds");
        let options = render_options(&case);
        let (_, rays) = pool.install(|| render_counting_rays(&scene, &options, &Silent));
        group.throughput(Throughput::Elements(rays.total()));
        group.bench_function(format!("{}/off", case.name), |b| {
            b.iter(|| pool.install(|| render(&scene, &options, &Silent)))
        });
        group.bench_function(format!("{}/on", case.name), |b| {
            b.iter(|| pool.install(|| render_counting_rays(&scene, &options, &Silent)))
        });
    }
    group.finish();
}

/// Work a scene does not ask for is not done: the blob lit by one point light renders as fast
/// with shadows off as with no light at all (both trace only camera rays), and with shadows on
/// pays for one shadow ray per hit. With 4 samples per pixel, the AOVs cost one more ray per
/// pixel (5 instead of 4) when they are written and nothing when they are not.
fn only_what_is_required(c: &mut Criterion) {
    let light = Light::Point {
        position: Vec3::new(2.0, 3.0, 5.0),
        color: Color::ONE,
        falloff: 0.05,
    };
    let options = |shadows, samples, aovs| RenderOptions {
        trace: Trace {
            width: SIDE,
            height: SIDE,
            bounces: 0,
            shadows,
            samples,
            seed: 0,
            filter: Filter::None,
        },
        spawn: Spawn::ErrorBounds,
        seeding: Seeding::Seeded,
        aovs,
    };
    let renders = [
        ("shadows_on", vec![light], options(true, 1, true)),
        ("shadows_off", vec![light], options(false, 1, true)),
        ("no_lights", Vec::new(), options(false, 1, true)),
        ("4_samples_with_aovs", Vec::new(), options(false, 4, true)),
        ("4_samples_without_aovs", Vec::new(), options(false, 4, false)),
    ];
    let pool = pool(1);
    let mut group = c.benchmark_group("only_what_is_required");
    group.sample_size(10);
    for (name, lights, options) in &renders {
        group.bench_function(format!("blob_1.3M/{name}"), |b| {
            let scene = blob_scene_lit(lights.clone());
            b.iter(|| pool.install(|| render(&scene, options, &Silent)))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    primary_rays,
    incoherent_rays,
    bvh_build,
    only_what_is_required,
    end_to_end,
    course_scenes,
    stats_overhead
);
criterion_main!(benches);
