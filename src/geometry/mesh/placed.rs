//! Meshes built from triangles already placed in the scene: a scene's small instanced meshes
//! moved into world space once, so that a ray is not moved into each instance's space and its
//! hit back (see `Object::placed` in `crate::scene`).

use std::time::Instant;

use super::super::aabb::Aabb;
use super::super::bvh::{Bvh, LeafCost};
use super::super::real::Vec3;
use super::{FlatLeaves, Mesh, pack_leaves};

impl Mesh {
    /// A mesh of the triangles `corners` (at least one, every corner finite), each with its
    /// corner normals or `None` (shaded with its geometric normal). The normals are kept as
    /// given, not normalised: an instance's normals mapped by its inverse transpose interpolate
    /// to the direction the instance would shade with, where unit normals would weight the
    /// corners differently.
    pub fn from_placed(corners: &[[Vec3; 3]], normals: &[Option<[Vec3; 3]>]) -> Mesh {
        assert_eq!(corners.len(), normals.len(), "one normal triple (or None) per triangle");
        assert!(!corners.is_empty(), "a mesh has at least one triangle");
        let build_start = Instant::now();
        let bounds_of = |index: usize| Aabb::from_points(corners[index]);
        let (mut bvh, order) = Bvh::build_from(corners.len(), bounds_of, LeafCost::PerPackOfFour).into_leaf_order();
        let ordered: Vec<[Vec3; 3]> = order.iter().map(|&i| corners[i as usize]).collect();
        let leaves = bvh.leaves();
        let flat = FlatLeaves::new(&leaves, &ordered);
        let packs = pack_leaves(&mut bvh, &leaves, &ordered);
        // Normal 0 is the zero normal of triangles shaded with their geometric normal.
        let mut vertex_normals = vec![Vec3::ZERO];
        let normal_indices = order
            .iter()
            .map(|&i| match normals[i as usize] {
                Some(triple) if triple.iter().all(|&n| n != Vec3::ZERO) => {
                    let first = vertex_normals.len() as u32;
                    vertex_normals.extend(triple);
                    [first, first + 1, first + 2]
                }
                _ => [0; 3],
            })
            .collect();
        Mesh {
            corners: ordered,
            normal_indices,
            normals: vertex_normals,
            packs,
            bvh,
            flat,
            bvh_build_time: build_start.elapsed(),
        }
    }
}
