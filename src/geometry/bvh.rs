//! A bounding volume hierarchy over primitives known only by their boxes.
//!
//! The BVH never sees the primitives themselves: callers pass one box per primitive to
//! [`Bvh::build`] and a closure to the traversals that tests a primitive by index. That keeps
//! one implementation for triangle meshes and for scene-level object lists; meshes replace the
//! leaves' primitive runs by runs of triangle packs ([`Bvh::remap_leaves`]) and traverse with
//! their own leaf test ([`traverse`]).

mod box_set;
mod build;
mod collapse;
mod node;
mod packet;
mod traverse;

use std::mem::MaybeUninit;
use rayon::prelude::*;

use super::Ray;
use super::aabb::Aabb;
use super::real::{MACHINE_EPSILON, R8, Real, gamma};
use crate::simd::{Isa, Kernel, dispatch};

pub use box_set::BoxSet;
pub use node::BvhNode;
pub use build::LeafCost;
pub use packet::{PACKET, PacketLanes, traverse_packet};
pub use traverse::{traverse, traverse_interleaved};

/// Children per node: eight boxes are tested at once, one per SIMD lane.
pub const WIDTH: usize = 8;

/// Boxes are pruned only when entered beyond the nearest hit so far times this: a box's entry
/// distance and a triangle's `t` are each rounded, so a triangle lying in a face of its box may
/// come out a few ulps nearer than the box's entry. Without the slack such a box could be
/// skipped once another hit a few ulps farther was known, and which of the two is found would
/// depend on the order of the traversal (a packet's, or one ray's); with it both are tested and
/// the nearest, ties to the smaller index, wins whatever the order.
const BOX_SLACK: Real = 1.0 + 64.0 * MACHINE_EPSILON;

/// Most primitives a BVH holds: the binary tree's `2n − 1` node slots are numbered with `u32`.
pub const MAX_PRIMITIVES: usize = 1 << 31;

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
pub enum Visit {
    Continue,
    Stop,
}

/// What a traversal ([`traverse`]) does at each leaf it reaches: `leaf(first, count, t_limit)`,
/// which may shrink `t_limit`. Implementations mark `leaf` `#[inline(always)]`: it is compiled
/// into the traversal's kernel, with the kernel's instructions (a closure would not be inlined
/// for certain, and one compiled on its own would run the lanes' instructions as calls).
pub trait LeafVisitor<I: Isa> {
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit;

    /// How many cache lines a leaf's primitives span from the line they start in, at most,
    /// counting from [`LeafVisitor::leaf_data`]; zero for a visitor with nothing to fetch.
    const LEAF_LINES: usize = 0;

    /// Where the primitives of the leaf starting at `first` lie, so that they can be asked for
    /// from memory while the nearer children are visited (a hint: never read through, so any
    /// address will do, and asking must change nothing).
    #[inline(always)]
    fn leaf_data(&self, _first: u32) -> *const u8 {
        std::ptr::null()
    }
}

/// A closure as a [`LeafVisitor`], for visitors that use no lanes themselves.
pub struct VisitFn<F>(pub F);

impl<I: Isa, F: FnMut(u32, u32, &mut Real) -> Visit> LeafVisitor<I> for VisitFn<F> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit {
        (self.0)(first, count, t_limit)
    }
}

/// What a packet traversal ([`traverse_packet`]) does at each leaf: `leaf(first, count, rays,
/// t_limit)` for the rays (a bit per lane) that reached it, with each ray's limit in its lane.
/// As for [`LeafVisitor`], `leaf` is `#[inline(always)]`.
///
/// The limits stay in lanes from leaf to leaf: the traversal reads all eight at once at every
/// node, and eight read back from memory just after one of them was written there wait for that
/// write to reach the cache (a wide load cannot take a narrow store's value on its way).
pub trait PacketVisitor<I: Isa> {
    fn leaf(&mut self, first: u32, count: u32, rays: u32, t_limit: &mut R8<I>);

    /// Called for each leaf the packet enters, as soon as it is found entered, so that its
    /// primitives can be asked for from memory before they are tested (a hint: it must change
    /// nothing).
    #[inline(always)]
    fn prefetch(&self, _first: u32, _count: u32) {}
}

#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    prim_indices: Vec<u32>,
    /// Box around every primitive (the root node holds only its children's boxes).
    bounds: Aabb,
}

impl Bvh {
    /// Builds a binary tree with a binned surface-area heuristic and collapses it into an 8-wide
    /// one (nodes of up to eight children), with leaves of up to four primitives each tested
    /// on its own.
    ///
    /// Deterministic: the tree depends only on `bounds`, never on the number of rayon threads
    /// that build its subtrees. Boxes may be empty or degenerate (points, identical copies);
    /// such input still yields small leaves through median splits.
    ///
    /// # Panics
    /// If there are more than [`MAX_PRIMITIVES`].
    pub fn build(bounds: &[Aabb]) -> Bvh {
        Bvh::build_for(bounds, LeafCost::PerPrimitive)
    }

    /// [`Bvh::build`] for leaves whose primitives are tested as `cost` says (a mesh tests up to
    /// four triangles at once, so a leaf of four costs what a leaf of one does).
    pub fn build_for(bounds: &[Aabb], cost: LeafCost) -> Bvh {
        Bvh::build_from(bounds.len(), |index| bounds[index], cost)
    }

    /// [`Bvh::build_for`] of the `count` boxes `bounds_of(0..count)`, computed as the build
    /// needs them (in parallel), for a caller that would otherwise make a list of them only
    /// to hand it over.
    pub fn build_from(count: usize, bounds_of: impl Fn(usize) -> Aabb + Sync, cost: LeafCost) -> Bvh {
        let (binary, prim_indices) = build::build(count, bounds_of, cost);
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

    /// Every leaf as `(first, count)` in primitive order (leaves hold consecutive runs of the
    /// primitive order, and together all of it).
    pub fn leaves(&self) -> Vec<(u32, u32)> {
        let mut count_at = vec![0u32; self.prim_indices.len()];
        for node in &self.nodes {
            for lane in 0..WIDTH {
                if node.count[lane] > 0 {
                    count_at[node.child[lane] as usize] = node.count[lane] as u32;
                }
            }
        }
        // Only leaves' first primitives have a count, so a filter finds them all at once, where
        // stepping from each leaf to the next would wait for every count in turn.
        let leaves: Vec<(u32, u32)> = count_at
            .par_iter()
            .enumerate()
            .filter(|&(_, &count)| count > 0)
            .map(|(first, &count)| (first as u32, count))
            .collect();
        debug_assert!(
            leaves.iter().try_fold(0, |next, &(first, count)| (first == next).then_some(first + count))
                == Some(self.prim_indices.len() as u32),
            "leaves cover the primitive order"
        );
        leaves
    }

    /// Replaces each leaf's `(first, count)` by `remap(first, count)`: how a mesh points its
    /// leaves at the packs of triangles it made of them. Only [`traverse`] with the caller's own
    /// leaf test makes sense afterwards.
    pub fn remap_leaves(&mut self, remap: impl Fn(u32, u32) -> (u32, u32) + Sync) {
        self.nodes.par_iter_mut().for_each(|node| {
            for lane in 0..WIDTH {
                if node.count[lane] > 0 {
                    let (first, count) = remap(node.child[lane], node.count[lane] as u32);
                    assert!((1..=255).contains(&count), "a leaf keeps one to 255 entries, not {count}");
                    (node.child[lane], node.count[lane]) = (first, count as u8);
                }
            }
        });
    }

    /// The original primitive indices in leaf order.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Number of primitives, each in exactly one leaf.
    pub fn primitive_count(&self) -> usize {
        self.prim_indices.len()
    }

    /// Number of (8-wide) nodes.
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

    /// The nodes, for [`traverse`].
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Finds the nearest primitive along the ray in `(0, t_max]`.
    ///
    /// `test(prim, t_limit)` must return `Some(t)` only for a hit with `t <= t_limit`; the limit
    /// then shrinks to `t`, so later boxes and primitives beyond it are skipped. The caller
    /// records whatever it needs about the hit inside `test`; the final `t` is returned.
    ///
    /// Boxes entered exactly at the limit are still visited, so a test that also breaks ties of
    /// `t` by a fixed rule (as `scene::Aggregate` does, by object index) finds the same hit
    /// whatever order the boxes are visited in.
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: Real,
        mut test: impl FnMut(u32, Real) -> Option<Real>,
    ) -> Option<Real> {
        let mut nearest = None;
        let prims = &self.prim_indices;
        self.traverse(ray, t_max, |first, count, t_limit| {
            for &prim in &prims[first as usize..(first + count) as usize] {
                if let Some(t) = test(prim, *t_limit) {
                    debug_assert!(t <= *t_limit, "closest: test returned a hit beyond its limit");
                    *t_limit = t;
                    nearest = Some(t);
                }
            }
            Visit::Continue
        });
        nearest
    }

    /// Whether any primitive is hit in `(0, t_max]`; stops at the first one `test` accepts.
    pub fn any(&self, ray: &Ray, t_max: Real, mut test: impl FnMut(u32, Real) -> bool) -> bool {
        let mut found = false;
        let prims = &self.prim_indices;
        self.traverse(ray, t_max, |first, count, t_limit| {
            if prims[first as usize..(first + count) as usize].iter().any(|&prim| test(prim, *t_limit)) {
                found = true;
                Visit::Stop
            } else {
                Visit::Continue
            }
        });
        found
    }

    /// [`traverse`] on the current SIMD path.
    fn traverse(&self, ray: &Ray, t_max: Real, visit: impl FnMut(u32, u32, &mut Real) -> Visit) {
        struct Traversal<'a, V> {
            nodes: &'a [BvhNode],
            ray: &'a Ray,
            t_max: Real,
            visit: V,
        }
        impl<V: FnMut(u32, u32, &mut Real) -> Visit> Kernel for Traversal<'_, V> {
            type Output = ();
            #[inline(always)]
            fn run<I: Isa>(self) {
                traverse::<I>(self.nodes, self.ray, self.t_max, &mut VisitFn(self.visit));
            }
        }
        dispatch(Traversal { nodes: &self.nodes, ray, t_max, visit });
    }
}

#[cfg(test)]
mod tests;
