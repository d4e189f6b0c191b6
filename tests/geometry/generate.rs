//! The procedural blob is a closed, outward-wound surface that rays cannot leak out of.

use std::collections::HashMap;

use goldray::geometry::Ray;
use goldray::geometry::generate::{BLOB_MIN_RADIUS, blob, write_obj};
use goldray::geometry::mesh::{Mesh, NormalSource, VertexNormals};
use goldray::real::{Real, Vec3};

use super::Rng;

#[test]
fn blob_is_closed_and_consistently_wound_outwards() {
    for subdivisions in 0..=4 {
        let (positions, triangles) = blob(subdivisions, 11);
        assert_eq!(triangles.len(), 20 * 4usize.pow(subdivisions));
        // Closed and consistently oriented: each directed edge occurs once, and so does its
        // reverse (the neighbouring triangle walks the shared edge the other way).
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for &[a, b, c] in &triangles {
            for edge in [(a, b), (b, c), (c, a)] {
                *directed.entry(edge).or_default() += 1;
            }
        }
        for (&(a, b), &count) in &directed {
            assert_eq!(count, 1, "edge ({a}, {b}) used {count} times in the same direction");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge ({a}, {b}) has no opposite");
        }
        // Outward: the surface is star-shaped around the origin, so each face normal points
        // away from it.
        for &[a, b, c] in &triangles {
            let [a, b, c] = [a, b, c].map(|i| positions[i as usize]);
            assert!(
                (b - a).cross(c - a).dot(a) > 0.0,
                "inward face at subdivision {subdivisions}"
            );
        }
    }
}

/// Watertightness: 100,000 rays (20,000 per placement) from inside a closed, irregular,
/// 20,480-triangle mesh all hit it, also at the extremes of scale the scenes will use and moved
/// away from the origin, where coordinates carry less precision relative to the blob's size.
#[test]
fn rays_from_inside_always_hit() {
    let (unit_positions, triangles) = blob(5, 3);
    assert_eq!(triangles.len(), 20_480);
    let mut rng = Rng::new(17);
    for (scale, offset) in [(1.0, 0.0), (1e-4, 0.0), (1e6, 0.0), (1e-4, 1e-3), (1e6, -1e7)] {
        let centre = Vec3::new(offset, -0.5 * offset, 0.25 * offset);
        let positions: Vec<Vec3> = unit_positions.iter().map(|&p| centre + p * scale).collect();
        let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap();
        for i in 0..20_000 {
            let inside = rng.direction() * rng.uniform(0.0, 0.95 * BLOB_MIN_RADIUS);
            let ray = Ray::new(centre + inside * scale, rng.direction() * rng.uniform(0.1, 10.0));
            let context = format!("scale {scale}, offset {offset}, ray {i}: {ray:?}");
            let hit = mesh
                .intersect(&ray, Real::INFINITY)
                .unwrap_or_else(|| panic!("escaped at {context}"));
            assert!(mesh.occluded(&ray, Real::INFINITY), "not occluded at {context}");
            let surface = mesh.surface(&hit);
            assert!(
                surface.geometric_normal.dot(ray.direction) > 0.0,
                "back face at {context}"
            );
        }
    }
}

#[test]
fn written_obj_loads_back_identically() {
    let (positions, triangles) = blob(2, 5);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blob.obj");
    write_obj(&path, &positions, &triangles).unwrap();
    let loaded = Mesh::load_obj(&path, NormalSource::Averaged).unwrap();
    let built = Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap();
    assert_eq!(loaded.triangle_count(), built.triangle_count());
    for t in 0..built.triangle_count() as u32 {
        assert_eq!(loaded.triangle(t), built.triangle(t));
        assert_eq!(loaded.vertex_normals(t), built.vertex_normals(t));
    }
}
