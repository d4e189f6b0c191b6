//! Small meshes tested without their tree: up to eight boxes, each around a run of the mesh's
//! leaves, tested at once, then the packs of the boxes the ray enters, nearest box first. For a
//! mesh of a few dozen triangles (a cube is twelve) that is one slab test where the traversal
//! sets up a stack, and the result is the same: the closest hit does not depend on the order
//! in which boxes are visited (ties go to the smaller triangle index), and a box is skipped only
//! when the traversal would prune it too.

use super::super::aabb::Aabb;
use super::super::bvh::{BoxSet, LeafVisitor, Visit, WIDTH};
use super::super::real::{Real, Vec3};
use super::super::Ray;
use crate::simd::Isa;

/// Meshes of up to this many packs of four triangles are tested flat.
const FLAT_PACK_LIMIT: u32 = 16;

#[derive(Clone, Debug)]
pub(super) struct FlatLeaves {
    boxes: BoxSet,
    /// Box `lane` holds packs `first..first + count`, as `(first, count)`.
    packs: [(u32, u32); WIDTH],
}

impl FlatLeaves {
    /// `leaves` are the tree's leaves as runs `(first, count)` of `corners` (in leaf order);
    /// each leaf is packed into `count.div_ceil(4)` consecutive packs, in leaf order. `None`
    /// when the mesh has more than `FLAT_PACK_LIMIT` packs.
    pub(super) fn new(leaves: &[(u32, u32)], corners: &[[Vec3; 3]]) -> Option<FlatLeaves> {
        let total: u32 = leaves.iter().map(|&(_, count)| count.div_ceil(4)).sum();
        if total > FLAT_PACK_LIMIT || leaves.is_empty() {
            return None;
        }
        // Consecutive leaves share a box until the box holds its share of the packs.
        let share = total.div_ceil(WIDTH as u32).max(leaves.len().div_ceil(WIDTH) as u32);
        let mut bounds: Vec<Aabb> = Vec::new();
        let mut packs = [(0, 0); WIDTH];
        let mut first_pack = 0;
        for &(first, count) in leaves {
            let leaf_packs = count.div_ceil(4);
            let leaf_bounds = corners[first as usize..(first + count) as usize]
                .iter()
                .fold(Aabb::EMPTY, |b, &c| b.union(Aabb::from_points(c)));
            let lane = bounds.len();
            match lane.checked_sub(1) {
                Some(last) if packs[last].1 + leaf_packs <= share || lane == WIDTH => {
                    packs[last].1 += leaf_packs;
                    bounds[last] = bounds[last].union(leaf_bounds);
                }
                _ => {
                    packs[lane] = (first_pack, leaf_packs);
                    bounds.push(leaf_bounds);
                }
            }
            first_pack += leaf_packs;
        }
        Some(FlatLeaves { boxes: BoxSet::new(&bounds), packs })
    }

    /// A bit per box the ray enters before `t_max`, and where it enters each: the boxes
    /// [`FlatLeaves::visit`] takes. Most rays of a scene miss a small mesh, and they stop here,
    /// before anything the leaf tests need is set up.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub(super) fn entered<I: Isa>(&self, ray: &Ray, t_max: Real) -> (u32, [Real; WIDTH]) {
        self.boxes.entered::<I>(ray, t_max)
    }

    /// The leaves of the boxes `hits` (entered at `t`, from [`FlatLeaves::entered`]), nearest
    /// box first, each given to `visitor` with the limit it shrinks, as the traversal does.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub(super) fn visit<I: Isa>(&self, hits: u32, t: &[Real; WIDTH], t_max: Real, visitor: &mut impl LeafVisitor<I>) {
        let mut t_limit = t_max;
        if hits & (hits - 1) == 0 {
            let (first, count) = self.packs[hits.trailing_zeros() as usize];
            visitor.leaf(first, count, &mut t_limit);
            return;
        }
        let mut keys = [0; WIDTH];
        for &key in BoxSet::nearest_first(hits, t, &mut keys) {
            let lane = BoxSet::lane(key);
            if !BoxSet::may_hold(t[lane], t_limit) {
                break;
            }
            let (first, count) = self.packs[lane];
            if let Visit::Stop = visitor.leaf(first, count, &mut t_limit) {
                break;
            }
        }
    }
}
