//! Collapsing the binary SAH tree into the 8-wide tree that is traversed.
//!
//! A wide node takes the two children of a binary node and keeps replacing its interior child
//! with the largest surface area (the one a ray is likeliest to enter) by that child's own two
//! children, until it has eight children or only leaves are left (the usual BVH2 → BVH8
//! collapse, as in Embree). Every binary leaf becomes one leaf slot of a wide node, with the
//! same primitives; children keep their left-to-right order. A pure function of the binary
//! tree, so the wide tree is as deterministic as the binary one.

use super::build::BinaryNode;
use super::node::{BvhNode, Child};
use super::WIDTH;
use super::super::huge_page_vec;
use super::super::real::Real;
use rayon::prelude::*;

/// The wide nodes in depth-first order (a node's first interior child follows it), root first.
///
/// The tree is laid out first as the binary nodes each wide node's children are, and the wide
/// node each interior binary child became; the wide nodes, with their children's boxes
/// quantised, are then made node by node in parallel (a node's quantisation depends on its
/// children's boxes only, so the result is the same on any number of threads). A layout entry
/// is a few indices rather than the children's boxes: a tenth of the memory to write and read
/// back, which for large meshes was most of the collapse's time.
pub(super) fn collapse(binary: &[BinaryNode]) -> Vec<BvhNode> {
    let mut layout = Vec::with_capacity(binary.len() / 4 + 1);
    let mut wide = vec![0; binary.len()];
    if !binary.is_empty() {
        emit(binary, 0, &mut layout, &mut wide);
    }
    let mut nodes = huge_page_vec(layout.len());
    nodes.par_extend(layout.par_iter().map(|(slots, len)| {
        let children = slots.map(|slot| {
            let node = &binary[slot as usize];
            let index = if node.is_leaf() { node.offset } else { wide[slot as usize] };
            Child { bounds: node.bounds, index, count: node.prim_count }
        });
        BvhNode::new(&children[..*len as usize])
    }));
    nodes
}

/// The binary nodes that are a wide node's children, in order, and how many there are.
type Slots = ([u32; WIDTH], u8);

/// Appends the wide node standing for binary node `index` and then, depth first, the wide
/// nodes of its interior children, recording in `wide` the wide node each interior binary
/// node became.
fn emit(binary: &[BinaryNode], index: usize, layout: &mut Vec<Slots>, wide: &mut [u32]) {
    let (slots, len) = children(binary, index);
    wide[index] = layout.len() as u32;
    layout.push((slots.map(|slot| slot as u32), len as u8));
    for &slot in &slots[..len] {
        if !binary[slot].is_leaf() {
            emit(binary, slot, layout, wide);
        }
    }
}

/// The binary nodes that become the children of the wide node for `index`, in tree order. A
/// binary tree that is a single leaf becomes one wide node with that leaf as its only child.
fn children(binary: &[BinaryNode], index: usize) -> ([usize; WIDTH], usize) {
    let mut slots = [index; WIDTH];
    let node = &binary[index];
    if node.is_leaf() {
        return (slots, 1);
    }
    // Depth-first storage: the first child follows its parent, `offset` is the second.
    (slots[0], slots[1]) = (index + 1, node.offset as usize);
    let mut len = 2;
    while len < WIDTH {
        let widest = (0..len)
            .filter(|&k| !binary[slots[k]].is_leaf())
            .max_by(|&a, &b| area(binary, slots[a]).total_cmp(&area(binary, slots[b])).then(b.cmp(&a)));
        let Some(k) = widest else { break };
        let opened = slots[k];
        slots.copy_within(k + 1..len, k + 2);
        (slots[k], slots[k + 1]) = (opened + 1, binary[opened].offset as usize);
        len += 1;
    }
    (slots, len)
}

fn area(binary: &[BinaryNode], index: usize) -> Real {
    binary[index].area
}
