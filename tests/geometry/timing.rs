//! Rough timings of the large cases, run on demand:
//! `cargo test --release --test geometry -- --ignored --nocapture`.

use std::time::Instant;

use goldray::geometry::Ray;
use goldray::geometry::generate::{BLOB_MIN_RADIUS, blob, write_obj};
use goldray::geometry::mesh::{Mesh, NormalSource, VertexNormals};
use goldray::real::Real;
use rayon::prelude::*;

use super::Rng;

#[test]
#[ignore = "timing run; slow without --release"]
fn large_blob_timings() {
    let start = Instant::now();
    let (positions, triangles) = blob(8, 1);
    println!("generate {} triangles: {:.2?}", triangles.len(), start.elapsed());

    let start = Instant::now();
    let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap();
    let bvh = mesh.bvh();
    println!(
        "mesh + BVH build: {:.2?} ({} nodes, {} leaves, {} threads)",
        start.elapsed(),
        bvh.node_count(),
        bvh.leaf_count(),
        rayon::current_num_threads()
    );

    let mut rng = Rng::new(1);
    let rays: Vec<Ray> = (0..1_000_000)
        .map(|i| {
            if i % 2 == 0 {
                Ray::new(rng.direction() * rng.uniform(0.0, BLOB_MIN_RADIUS), rng.direction())
            } else {
                let origin = rng.direction() * 4.0;
                Ray::new(origin, rng.in_box(0.8) - origin)
            }
        })
        .collect();
    let start = Instant::now();
    let hits = rays
        .par_iter()
        .filter(|ray| mesh.intersect(ray, Real::INFINITY).is_some())
        .count();
    println!("1M closest-hit rays: {:.2?} ({hits} hits)", start.elapsed());
    let start = Instant::now();
    let blocked = rays.par_iter().filter(|ray| mesh.occluded(ray, Real::INFINITY)).count();
    println!("1M occlusion rays: {:.2?} ({blocked} blocked)", start.elapsed());
    assert_eq!(hits, blocked);

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blob8.obj");
    let start = Instant::now();
    write_obj(&path, &positions, &triangles).unwrap();
    println!("write OBJ: {:.2?}", start.elapsed());
    let start = Instant::now();
    let loaded = Mesh::load_obj(&path, NormalSource::Averaged).unwrap();
    println!("load OBJ (parse + BVH): {:.2?}", start.elapsed());
    assert_eq!(loaded.triangle_count(), triangles.len());
    assert_eq!(loaded.bounds(), mesh.bounds());
}
