//! A bounding volume hierarchy over primitives known only by their boxes.
//!
//! The BVH never sees the primitives themselves: callers pass one box per primitive to
//! [`Bvh::build`] and a closure to the traversals that tests a primitive by index. That keeps
//! one implementation for triangle meshes and for scene-level object lists.

mod build;

use std::time::Duration;

use super::Ray;
use super::aabb::{Aabb, SlabRay};
use super::real::Real;
use crate::stats::BvhStats;

/// Deepest tree [`Bvh::build`] can produce: SAH splits are allowed up to `build::SAH_DEPTH_LIMIT`
/// levels, after which median splits at most halve `u32::MAX` primitives down to a leaf. Sizing
/// the traversal stack from it means the stack can never overflow.
const MAX_DEPTH: usize = build::SAH_DEPTH_LIMIT + 33;

/// One node of the flattened tree, 32 bytes with `f32` bounds so that two fit a cache line.
///
/// Nodes are stored depth first: an interior node's first child immediately follows it, so only
/// the second child's index needs storing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    pub bounds: Aabb,
    /// Leaf: index of its first entry in the primitive order. Interior: the second child.
    offset: u32,
    /// Zero for an interior node.
    prim_count: u16,
    /// The split axis of an interior node, used to visit the nearer child first.
    axis: u16,
}

impl BvhNode {
    fn leaf(bounds: Aabb, first: u32, count: u16) -> Self {
        BvhNode {
            bounds,
            offset: first,
            prim_count: count,
            axis: 0,
        }
    }

    fn interior(bounds: Aabb, axis: usize, second_child: u32) -> Self {
        BvhNode {
            bounds,
            offset: second_child,
            prim_count: 0,
            axis: axis as u16,
        }
    }

    pub fn is_leaf(&self) -> bool {
        self.prim_count > 0
    }
}

/// What a traversal visitor asks the traversal to do next.
enum Visit {
    Continue,
    Stop,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    prim_indices: Vec<u32>,
}

impl Bvh {
    /// Builds the tree with a binned surface-area heuristic.
    ///
    /// Deterministic: the tree depends only on `bounds`, never on the number of rayon threads
    /// that build its subtrees. Boxes may be empty or degenerate (points, identical copies);
    /// such input still yields small leaves through median splits.
    ///
    /// # Panics
    /// If there are more than `u32::MAX` primitives.
    pub fn build(bounds: &[Aabb]) -> Bvh {
        let (nodes, prim_indices) = build::build(bounds);
        Bvh {
            nodes,
            prim_indices,
        }
    }

    /// Hands the primitive order to the caller, who stores its primitives in that order, and
    /// returns a BVH whose traversals then report positions in the reordered storage.
    ///
    /// The point is cache locality: primitives of one leaf become neighbours in memory.
    /// `order[k]` is the original index of the primitive that belongs at position `k`.
    pub fn into_leaf_order(self) -> (Bvh, Vec<u32>) {
        let identity = (0..self.prim_indices.len() as u32).collect();
        (
            Bvh {
                nodes: self.nodes,
                prim_indices: identity,
            },
            self.prim_indices,
        )
    }

    /// The original primitive indices in leaf order.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Its shape for `--stats`.
    pub fn stats(&self, build_time: Duration) -> BvhStats {
        BvhStats { build_time, primitives: self.prim_indices().len(), nodes: self.node_count(), leaves: self.leaf_count() }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().filter(|node| node.is_leaf()).count()
    }

    /// Box around every primitive; empty when there are none.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |root| root.bounds)
    }

    /// Finds the nearest primitive along the ray in `(0, t_max]`.
    ///
    /// `test(prim, t_limit)` must return `Some(t)` only for a hit with `t <= t_limit`; the limit
    /// then shrinks to `t`, so later boxes and primitives beyond it are skipped. The caller
    /// records whatever it needs about the hit inside `test`; the final `t` is returned.
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: Real,
        mut test: impl FnMut(u32, Real) -> Option<Real>,
    ) -> Option<Real> {
        let mut nearest = None;
        self.traverse(ray, t_max, |prim, t_limit| {
            if let Some(t) = test(prim, *t_limit) {
                debug_assert!(
                    t <= *t_limit,
                    "closest: test returned a hit beyond its limit"
                );
                *t_limit = t;
                nearest = Some(t);
            }
            Visit::Continue
        });
        nearest
    }

    /// Whether any primitive is hit in `(0, t_max]`; stops at the first one `test` accepts.
    pub fn any(&self, ray: &Ray, t_max: Real, mut test: impl FnMut(u32, Real) -> bool) -> bool {
        let mut found = false;
        self.traverse(ray, t_max, |prim, t_limit| {
            if test(prim, *t_limit) {
                found = true;
                Visit::Stop
            } else {
                Visit::Continue
            }
        });
        found
    }

    /// Depth-first traversal with an explicit stack, nearer child first: with the ray heading
    /// towards −axis the second child (the upper half of the split) is the nearer one. The
    /// visitor may shrink `t_limit`, which prunes every box entered afterwards.
    fn traverse(&self, ray: &Ray, t_max: Real, mut visit: impl FnMut(u32, &mut Real) -> Visit) {
        if self.nodes.is_empty() || !(ray.origin.is_finite() && ray.direction.is_finite()) {
            return;
        }
        let slab_ray = SlabRay::new(ray);
        let mut t_limit = t_max;
        let mut stack = [0u32; MAX_DEPTH];
        let mut stack_len = 0;
        let mut node_index = 0usize;
        loop {
            let node = &self.nodes[node_index];
            if node.bounds.hit_by(&slab_ray, t_limit) {
                if node.is_leaf() {
                    let first = node.offset as usize;
                    for &prim in &self.prim_indices[first..first + node.prim_count as usize] {
                        if let Visit::Stop = visit(prim, &mut t_limit) {
                            return;
                        }
                    }
                } else {
                    let first_child = node_index as u32 + 1;
                    let (near, far) = if slab_ray.direction_is_negative[node.axis as usize] {
                        (node.offset, first_child)
                    } else {
                        (first_child, node.offset)
                    };
                    stack[stack_len] = far;
                    stack_len += 1;
                    node_index = near as usize;
                    continue;
                }
            }
            if stack_len == 0 {
                return;
            }
            stack_len -= 1;
            node_index = stack[stack_len] as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use super::super::real::Vec3;

    fn point_boxes(points: &[Vec3]) -> Vec<Aabb> {
        points
            .iter()
            .map(|&p| Aabb::new(p, p + Vec3::splat(0.1)))
            .collect()
    }

    fn all_hits(bvh: &Bvh, ray: &Ray) -> Vec<u32> {
        let mut hit = Vec::new();
        bvh.any(ray, Real::INFINITY, |prim, _| {
            hit.push(prim);
            false
        });
        hit.sort_unstable();
        hit
    }

    #[test]
    fn node_is_32_bytes_with_f32() {
        if size_of::<Real>() == 4 {
            assert_eq!(size_of::<BvhNode>(), 32);
        }
    }

    #[test]
    fn zero_prims_never_hit() {
        let bvh = Bvh::build(&[]);
        assert_eq!(bvh.node_count(), 0);
        assert!(bvh.bounds().is_empty());
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(bvh.closest(&ray, Real::INFINITY, |_, _| Some(1.0)), None);
        assert!(!bvh.any(&ray, Real::INFINITY, |_, _| true));
    }

    #[test]
    fn single_prim() {
        let bvh = Bvh::build(&point_boxes(&[Vec3::new(1.0, 0.0, 0.0)]));
        assert_eq!((bvh.node_count(), bvh.leaf_count()), (1, 1));
        let ray = Ray::new(Vec3::new(0.0, 0.05, 0.05), Vec3::X);
        assert_eq!(
            bvh.closest(&ray, Real::INFINITY, |prim, _| Some(prim as Real + 1.0)),
            Some(1.0)
        );
        assert!(
            !bvh.any(&ray, 0.5, |_, _| true),
            "the box starts beyond t_max"
        );
    }

    #[test]
    fn coincident_centroids_split_into_small_leaves() {
        let bvh = Bvh::build(&point_boxes(&vec![Vec3::ONE; 1000]));
        let leaf_sizes: Vec<u16> = bvh
            .nodes()
            .iter()
            .filter(|n| n.is_leaf())
            .map(|n| n.prim_count)
            .collect();
        assert!(leaf_sizes.iter().all(|&count| count <= 4), "{leaf_sizes:?}");
        assert_eq!(leaf_sizes.iter().map(|&c| c as usize).sum::<usize>(), 1000);
        let ray = Ray::new(Vec3::new(1.05, 1.05, -5.0), Vec3::Z);
        assert_eq!(all_hits(&bvh, &ray), (0..1000).collect::<Vec<u32>>());
    }

    #[test]
    fn every_primitive_is_in_exactly_one_leaf() {
        let points: Vec<Vec3> = (0..500)
            .map(|i| Vec3::new((i * 37 % 101) as Real, (i % 7) as Real, 0.0))
            .collect();
        let bvh = Bvh::build(&point_boxes(&points));
        let mut order = bvh.prim_indices().to_vec();
        order.sort_unstable();
        assert_eq!(order, (0..500).collect::<Vec<u32>>());
    }

    #[test]
    fn leaf_order_renumbers_primitives() {
        let points: Vec<Vec3> = (0..50)
            .map(|i| Vec3::splat((i * 13 % 50) as Real))
            .collect();
        let (bvh, order) = Bvh::build(&point_boxes(&points)).into_leaf_order();
        let reordered: Vec<Vec3> = order.iter().map(|&i| points[i as usize]).collect();
        let target = points[7];
        let ray = Ray::new(target + Vec3::new(0.05, 0.05, -1.0), Vec3::Z);
        let mut seen = Vec::new();
        bvh.any(&ray, Real::INFINITY, |slot, _| {
            seen.push(reordered[slot as usize]);
            false
        });
        assert_eq!(seen, vec![target]);
    }
}
