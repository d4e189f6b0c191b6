//! Collapsing the binary SAH tree into the 8-wide tree that is traversed.
//!
//! A wide node takes the two children of a binary node and keeps replacing its interior child
//! with the largest surface area (the one a ray is likeliest to enter) by that child's own two
//! children, until it has eight children or only leaves are left (the usual BVH2 → BVH8
//! collapse, as in Embree). Every binary leaf becomes one leaf slot of a wide node, with the
//! same primitives; children keep their left-to-right order. A pure function of the binary
//! tree, so the wide tree is as deterministic as the binary one.

use super::build::{BinaryNode, SAH_DEPTH_LIMIT};
use super::node::{BvhNode, Child};
use super::WIDTH;
use super::super::huge_page_vec;
use super::super::real::Real;
use rayon::prelude::*;

/// Wide nodes this many levels below the root start subtrees laid out each on its own task:
/// up to 8² = 64 of them, enough to share among threads, few enough to cost nothing to join.
const PARALLEL_DEPTH: usize = 2;
/// Trees of fewer binary nodes are laid out on one thread.
const PARALLEL_NODES: usize = 1 << 15;

/// The wide nodes in depth-first order (a node's first interior child follows it), root first.
///
/// The tree is laid out first: for each wide node, the binary nodes its children are and where
/// the wide nodes of its interior children are, relative to itself. Subtrees below the first
/// levels are laid out in parallel, each on its own, and relative positions do not change when
/// they are put side by side, so the layout is the same on any number of threads. The wide
/// nodes, with their children's boxes quantised, are then made node by node in parallel (a
/// node's quantisation depends on its children's boxes only). A layout entry is a few indices
/// rather than the children's boxes: a fraction of the memory to write and read back, which for
/// large meshes was most of the collapse's time.
pub(super) fn collapse(binary: &[BinaryNode]) -> Vec<BvhNode> {
    let parallel_depth = if binary.len() >= PARALLEL_NODES { PARALLEL_DEPTH } else { 0 };
    collapse_in_parallel_to(binary, parallel_depth)
}

/// [`collapse`], with subtrees laid out in parallel from `parallel_depth` levels below the root
/// (0: the whole tree on this thread).
pub(super) fn collapse_in_parallel_to(binary: &[BinaryNode], parallel_depth: usize) -> Vec<BvhNode> {
    if binary.is_empty() {
        return Vec::new();
    }
    let pieces = lay_out(binary, 0, parallel_depth);
    // Where each piece starts among the wide nodes.
    let (mut starts, mut total) = (Vec::with_capacity(pieces.len()), 0);
    for piece in &pieces {
        starts.push(total);
        total += piece.len();
    }
    let mut nodes = huge_page_vec(total);
    nodes.par_extend((0..total).into_par_iter().map(|wide| {
        let piece = starts.partition_point(|&start| start <= wide) - 1;
        let entry = &pieces[piece][wide - starts[piece]];
        let children = entry.slots.map(|slot| &binary[slot as usize]);
        let children: [Child; WIDTH] = std::array::from_fn(|k| {
            let node = children[k];
            let index = if node.is_leaf() { node.offset } else { wide as u32 + entry.below[k] };
            Child { bounds: node.bounds, index, count: node.prim_count }
        });
        BvhNode::new(&children[..entry.len as usize])
    }));
    set_heights(&mut nodes);
    nodes
}

/// Heights fit a node's byte: SAH splits are allowed up to `SAH_DEPTH_LIMIT` levels, after
/// which median splits at most halve `u32::MAX` primitives down to a leaf, and the wide tree is
/// no deeper than the binary one.
const _: () = assert!(SAH_DEPTH_LIMIT + 33 <= u8::MAX as usize);

/// Gives each node the height of its subtree: nodes are laid out depth first, each after its
/// parent, so going from the last node to the first meets every child before its parent.
fn set_heights(nodes: &mut [BvhNode]) {
    for index in (0..nodes.len()).rev() {
        let node = &nodes[index];
        let mut height = 1u8;
        for lane in 0..WIDTH {
            if node.used() >> lane & 1 != 0 && node.count[lane] == 0 {
                height = height.max(nodes[node.child[lane] as usize].height.saturating_add(1));
            }
        }
        nodes[index].height = height;
    }
}

/// One wide node as laid out: the binary nodes that are its children, in order, how many there
/// are, and for each interior child how far after this node its wide node is.
struct Entry {
    slots: [u32; WIDTH],
    below: [u32; WIDTH],
    len: u8,
}

/// The wide subtree of binary node `index`, depth first, as pieces to be put side by side: at
/// `parallel_depth` levels below, one piece a subtree, each laid out on its own task.
fn lay_out(binary: &[BinaryNode], index: usize, parallel_depth: usize) -> Vec<Vec<Entry>> {
    if parallel_depth == 0 {
        let mut piece = Vec::new();
        lay_out_serial(binary, index, &mut piece);
        return vec![piece];
    }
    let mut entry = entry(binary, index);
    let interior: Vec<usize> = (0..entry.len as usize).filter(|&k| !binary[entry.slots[k] as usize].is_leaf()).collect();
    let subtrees: Vec<Vec<Vec<Entry>>> =
        interior.par_iter().map(|&k| lay_out(binary, entry.slots[k] as usize, parallel_depth - 1)).collect();
    let mut next = 1;
    for (&k, subtree) in interior.iter().zip(&subtrees) {
        entry.below[k] = next;
        next += subtree.iter().map(Vec::len).sum::<usize>() as u32;
    }
    let mut pieces = vec![vec![entry]];
    pieces.extend(subtrees.into_iter().flatten());
    pieces
}

/// Appends the wide node standing for binary node `index` and then, depth first, the wide
/// nodes of its interior children.
fn lay_out_serial(binary: &[BinaryNode], index: usize, piece: &mut Vec<Entry>) {
    let own = piece.len();
    piece.push(entry(binary, index));
    for k in 0..piece[own].len as usize {
        let slot = piece[own].slots[k] as usize;
        if !binary[slot].is_leaf() {
            piece[own].below[k] = (piece.len() - own) as u32;
            lay_out_serial(binary, slot, piece);
        }
    }
}

/// The entry for binary node `index`, its children found but not yet placed.
fn entry(binary: &[BinaryNode], index: usize) -> Entry {
    let (slots, len) = children(binary, index);
    Entry { slots: slots.map(|slot| slot as u32), below: [0; WIDTH], len: len as u8 }
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
