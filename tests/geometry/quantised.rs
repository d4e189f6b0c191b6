//! The tree's child boxes are stored a byte per plane, rounded outward; if a stored box ever
//! fell short of its exact box, rays touching the exact box's faces, edges and corners would
//! lose their hit. These meshes put triangles in those faces (axis-aligned squares, whose boxes
//! are flat), at scales from 1/1024 to 8 and far from the origin, where the quantisation's steps
//! are coarsest against the coordinates; rays through their corners and edges and rays lying in
//! their planes must find exactly what testing every triangle alone finds.

use goldray::geometry::Ray;
use goldray::geometry::bvh::PACKET;
use goldray::geometry::mesh::{Mesh, VertexNormals};
use goldray::real::{Real, Vec3};
use proptest::prelude::*;

use super::packs::brute_force;
use super::{Rng, ray_through};

/// Axis-aligned squares (two triangles each, in a plane x, y or z = const) of sizes 2^-10 to 8
/// around `offset`, with their corner points.
fn squares(rng: &mut Rng, count: usize, offset: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for _ in 0..count {
        let size = (2.0 as Real).powi((rng.next_u64() % 14) as i32 - 10);
        let corner = offset + rng.in_box(20.0);
        let normal_axis = (rng.next_u64() % 3) as usize;
        let (u, v) = ((normal_axis + 1) % 3, (normal_axis + 2) % 3);
        let mut a = Vec3::ZERO;
        a[u] = size;
        let mut b = Vec3::ZERO;
        b[v] = size * rng.uniform(0.25, 2.0);
        let first = positions.len() as u32;
        positions.extend([corner, corner + a, corner + a + b, corner + b]);
        triangles.push([first, first + 1, first + 2]);
        triangles.push([first, first + 2, first + 3]);
    }
    (positions, triangles)
}

/// Rays at the squares' corners and edge midpoints from random points, and rays along an axis
/// lying in a square's plane through its corner; each tested alone, in packets of eight from
/// one origin, and all in one call of [`Mesh::intersect_packets`]. Returns the number of hits.
fn check(seed: u64, offset: Vec3) -> usize {
    let mut rng = Rng::new(seed);
    let (positions, triangles) = squares(&mut rng, 300, offset);
    let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).expect("valid");
    let mut hits = 0;
    let mut every_ray = Vec::new();
    for fan in 0..40 {
        let origin = offset + rng.in_box(40.0);
        let rays: Vec<Ray> = (0..PACKET)
            .map(|k| {
                let p = positions[(rng.next_u64() % positions.len() as u64) as usize];
                let q = positions[(rng.next_u64() % positions.len() as u64) as usize];
                match (fan + k) % 4 {
                    0 => ray_through(origin, p),
                    1 => ray_through(origin, p * 0.5 + q * 0.5),
                    2 => {
                        // Along an axis, lying in the planes through `p`.
                        let axis = k % 3;
                        let mut start = p;
                        start[axis] -= 50.0;
                        let mut direction = Vec3::ZERO;
                        direction[axis] = 1.0;
                        Ray::new(start, direction)
                    }
                    _ => ray_through(origin, p + rng.in_box(1e-3)),
                }
            })
            .collect();
        let packet = mesh.intersect_packet(&rays, Real::INFINITY);
        for (ray, from_packet) in rays.iter().zip(packet) {
            let expected = brute_force(&mesh, ray, Real::INFINITY);
            assert_eq!(mesh.intersect(ray, Real::INFINITY), expected, "one ray {ray:?}");
            assert_eq!(from_packet, expected, "in a packet {ray:?}");
            hits += expected.is_some() as usize;
            every_ray.push((*ray, expected));
        }
    }
    // All of them in one call, three rays in: the packets then straddle the fans (rays from two
    // origins, traced each its own way) but for the fans' own, and the last is short.
    let batch = &every_ray[3..];
    let rays: Vec<Ray> = batch.iter().map(|&(ray, _)| ray).collect();
    let mut found = vec![None; rays.len() + 5];
    mesh.intersect_packets(&rays, Real::INFINITY, &mut found);
    assert_eq!(found[rays.len()..], [None; 5], "hits past the rays are left alone");
    for (&(ray, expected), from_batch) in batch.iter().zip(found) {
        assert_eq!(from_batch, expected, "in a batch of packets {ray:?}");
    }
    hits
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]
    #[test]
    fn rays_touching_flat_boxes_find_what_every_triangle_finds(seed in any::<u64>()) {
        prop_assert!(check(seed, Vec3::ZERO) > 50);
        prop_assert!(check(seed, Vec3::new(3000.0, -1000.5, 777.25)) > 50);
    }
}
