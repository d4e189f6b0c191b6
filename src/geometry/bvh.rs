//! A bounding volume hierarchy over primitives known only by their boxes.
//!
//! The BVH never sees the primitives themselves: callers pass one box per primitive to
//! [`Bvh::build`] and a closure to the traversals that tests a primitive by index. That keeps
//! one implementation for triangle meshes and for scene-level object lists.

mod build;
mod collapse;

use smallvec::SmallVec;

use super::Ray;
use super::aabb::{Aabb, SlabRay, hit_lanes};
use super::real::Real;

/// Children per node: four boxes are tested at once, one per SIMD lane.
const WIDTH: usize = 4;

/// Deepest binary tree [`Bvh::build`] can produce: SAH splits are allowed up to
/// `build::SAH_DEPTH_LIMIT` levels, after which median splits at most halve `u32::MAX` primitives
/// down to a leaf. The wide tree is no deeper, and each node visited pushes at most `WIDTH − 1`
/// children (the nearest is visited next), which sizes the traversal stack so that it can never
/// overflow.
const STACK_SIZE: usize = (WIDTH - 1) * (build::SAH_DEPTH_LIMIT + 33) + 1;

/// One node of the 4-wide tree: the boxes of its (up to four) children side by side, one lane
/// per child, so that one slab test covers all four. 128 bytes with `f32` bounds, aligned to
/// two whole cache lines.
///
/// A child is either another node or a leaf, a run of primitives stored in the node itself.
/// Unused slots have an empty box, which no ray enters.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct BvhNode {
    min: [[Real; WIDTH]; 3],
    max: [[Real; WIDTH]; 3],
    /// Interior child: its node's index. Leaf: the index of its first entry in the primitive order.
    child: [u32; WIDTH],
    /// Leaf: its number of primitives (at least one). Zero for an interior child or unused slot.
    count: [u32; WIDTH],
}

impl BvhNode {
    const EMPTY: BvhNode = BvhNode {
        min: [[Real::INFINITY; WIDTH]; 3],
        max: [[Real::NEG_INFINITY; WIDTH]; 3],
        child: [0; WIDTH],
        count: [0; WIDTH],
    };

    fn set_child(&mut self, lane: usize, bounds: &Aabb, child: u32, count: u32) {
        for axis in 0..3 {
            self.min[axis][lane] = bounds.min[axis];
            self.max[axis][lane] = bounds.max[axis];
        }
        self.child[lane] = child;
        self.count[lane] = count;
    }

    /// Number of leaves among the children.
    fn leaf_count(&self) -> usize {
        self.count.iter().filter(|&&count| count > 0).count()
    }
}

/// A child waiting on the traversal stack: `count == 0` for a node, else a leaf's run of
/// primitives; `t` is where the ray enters its box, so that it is skipped once a hit nearer
/// than that is known.
#[derive(Clone, Copy)]
struct Pending {
    t: Real,
    index: u32,
    count: u32,
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
    /// Box around every primitive (the root node holds only its children's boxes).
    bounds: Aabb,
}

impl Bvh {
    /// Builds a binary tree with a binned surface-area heuristic and collapses it into a 4-wide
    /// one (nodes of up to four children).
    ///
    /// Deterministic: the tree depends only on `bounds`, never on the number of rayon threads
    /// that build its subtrees. Boxes may be empty or degenerate (points, identical copies);
    /// such input still yields small leaves through median splits.
    ///
    /// # Panics
    /// If there are more than `u32::MAX` primitives.
    pub fn build(bounds: &[Aabb]) -> Bvh {
        let (binary, prim_indices) = build::build(bounds);
        Bvh {
            bounds: binary.first().map_or(Aabb::EMPTY, |root| root.bounds),
            nodes: collapse::collapse(&binary),
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
                bounds: self.bounds,
            },
            self.prim_indices,
        )
    }

    /// The original primitive indices in leaf order.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Number of primitives, each in exactly one leaf.
    pub fn primitive_count(&self) -> usize {
        self.prim_indices.len()
    }

    /// Number of (4-wide) nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of leaves, each a run of at most four primitives.
    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().map(BvhNode::leaf_count).sum()
    }

    /// Box around every primitive; empty when there are none.
    pub fn bounds(&self) -> Aabb {
        self.bounds
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

    /// Depth-first traversal with an explicit stack, nearest child first: each node's four boxes
    /// are tested at once, the children hit are ordered by where the ray enters them, the
    /// nearest is visited next and the others wait on the stack with their entry distance. The
    /// visitor may shrink `t_limit`, which prunes every box entered beyond it.
    fn traverse(&self, ray: &Ray, t_max: Real, mut visit: impl FnMut(u32, &mut Real) -> Visit) {
        if self.nodes.is_empty() || !(ray.origin.is_finite() && ray.direction.is_finite()) {
            return;
        }
        let slab_ray = SlabRay::new(ray);
        let mut t_limit = t_max;
        // Inline storage that is never spilled (see `STACK_SIZE`) and, unlike an array, not
        // initialised: zeroing the whole bound for every ray would cost more than most rays push.
        let mut stack: SmallVec<[Pending; STACK_SIZE]> = SmallVec::new();
        let mut current = Pending { t: 0.0, index: 0, count: 0 };
        loop {
            if current.count == 0 {
                let node = &self.nodes[current.index as usize];
                let (t_enter, hit) = hit_lanes(&node.min, &node.max, &slab_ray, t_limit);
                // Insertion sort of the (at most four) children hit, nearest first.
                let mut near = [current; WIDTH];
                let mut near_len = 0;
                for lane in 0..WIDTH {
                    if hit[lane] {
                        let child = Pending { t: t_enter[lane], index: node.child[lane], count: node.count[lane] };
                        let mut k = near_len;
                        while k > 0 && near[k - 1].t > child.t {
                            near[k] = near[k - 1];
                            k -= 1;
                        }
                        near[k] = child;
                        near_len += 1;
                    }
                }
                if near_len > 0 {
                    for &farther in near[1..near_len].iter().rev() {
                        stack.push(farther);
                    }
                    current = near[0];
                    continue;
                }
            } else {
                let first = current.index as usize;
                for &prim in &self.prim_indices[first..first + current.count as usize] {
                    if let Visit::Stop = visit(prim, &mut t_limit) {
                        return;
                    }
                }
            }
            loop {
                let Some(pending) = stack.pop() else { return };
                // The box was hit before `t_limit` shrank; entered beyond it, it holds nothing nearer.
                if pending.t <= t_limit {
                    current = pending;
                    break;
                }
            }
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
    fn node_is_two_cache_lines_with_f32() {
        if size_of::<Real>() == 4 {
            assert_eq!((size_of::<BvhNode>(), align_of::<BvhNode>()), (128, 64));
        }
    }

    #[test]
    fn wide_nodes_have_two_to_four_children_and_keep_every_leaf() {
        let points: Vec<Vec3> = (0..2000)
            .map(|i| Vec3::new((i * 37 % 101) as Real, (i * 11 % 13) as Real, (i % 7) as Real))
            .collect();
        let boxes = point_boxes(&points);
        let (binary, _) = build::build(&boxes);
        let bvh = Bvh::build(&boxes);
        let binary_leaves = binary.iter().filter(|node| node.is_leaf()).count();
        assert_eq!(bvh.leaf_count(), binary_leaves);
        for node in &bvh.nodes {
            let used = (0..WIDTH).filter(|&lane| node.min[0][lane] <= node.max[0][lane]).count();
            assert!((2..=WIDTH).contains(&used), "{used} children");
            assert!(node.count.iter().all(|&count| count <= 4));
        }
        assert!(bvh.node_count() * 2 < binary.len(), "{} wide nodes for {} binary ones", bvh.node_count(), binary.len());
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
        let leaf_sizes: Vec<u32> = bvh
            .nodes
            .iter()
            .flat_map(|n| n.count)
            .filter(|&count| count > 0)
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
