//! Binned-SAH construction of a flattened binary BVH, which `collapse` then turns into the 8-wide
//! tree that is traversed.
//!
//! Every split decision is a pure function of the primitives in the node, and subtrees built in
//! parallel are stitched together in a fixed order, so the result does not depend on how rayon
//! schedules the work.

use super::super::aabb::Aabb;
use super::super::real::{Real, Vec3};

/// Twelve bins find splits within a few percent of a full sweep at a fraction of its cost.
const BIN_COUNT: usize = 12;
/// Small leaves keep the number of primitive tests per ray low; the SAH may still stop earlier.
const MAX_LEAF_PRIMS: usize = 4;
/// Cost of visiting a node relative to testing one primitive. pbrt uses 1/2; 1 gives leaves of
/// about two triangles instead of one and 40% fewer nodes, and was no slower on large meshes,
/// whose traversal is bound by memory traffic.
const TRAVERSAL_COST: Real = 1.0;
/// Below this many primitives a subtree is cheaper to build on the current thread than to
/// hand to rayon and stitch back.
const PARALLEL_THRESHOLD: usize = 4096;
/// Depth after which only median splits are made. SAH splits may peel off one primitive at a
/// time on adversarial input; median splits guarantee the remaining depth is logarithmic.
pub(super) const SAH_DEPTH_LIMIT: usize = 32;

/// How the SAH prices a leaf.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafCost {
    /// Each primitive is tested on its own: a leaf of `n` costs `n` tests.
    PerPrimitive,
    /// Primitives are tested four at a time (a mesh's triangle packs): a leaf of `n` costs
    /// `⌈n/4⌉` tests, so leaves fill up to four.
    PerPackOfFour,
    /// Every primitive is a leaf of its own, behind its own box: for primitives whose test costs
    /// far more than a box (a scene's objects: instances move the ray into their space first).
    Single,
}

impl LeafCost {
    fn tests(self, count: usize) -> Real {
        match self {
            LeafCost::PerPrimitive | LeafCost::Single => count as Real,
            LeafCost::PerPackOfFour => count.div_ceil(4) as Real,
        }
    }

    /// The most primitives a leaf may hold.
    fn max_leaf(self) -> usize {
        match self {
            LeafCost::Single => 1,
            _ => MAX_LEAF_PRIMS,
        }
    }
}

/// One node of the binary tree. Nodes are stored depth first: an interior node's first child
/// immediately follows it, so only the second child's index needs storing.
#[derive(Clone, Copy, Debug)]
pub(super) struct BinaryNode {
    pub bounds: Aabb,
    /// Leaf: index of its first entry in the primitive order. Interior: the second child.
    pub offset: u32,
    /// Zero for an interior node.
    pub prim_count: u32,
}

impl BinaryNode {
    fn leaf(bounds: Aabb, first: usize, count: usize) -> Self {
        BinaryNode { bounds, offset: first as u32, prim_count: count as u32 }
    }

    fn interior(bounds: Aabb) -> Self {
        BinaryNode { bounds, offset: 0, prim_count: 0 }
    }

    pub fn is_leaf(&self) -> bool {
        self.prim_count > 0
    }
}

/// Returns the nodes in depth-first order and the primitive indices in leaf order.
pub(super) fn build(bounds: &[Aabb], cost: LeafCost) -> (Vec<BinaryNode>, Vec<u32>) {
    assert!(
        u32::try_from(bounds.len()).is_ok(),
        "a BVH holds at most u32::MAX primitives"
    );
    if bounds.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let mut prims: Vec<Prim> = bounds
        .iter()
        .enumerate()
        .map(|(index, &bounds)| Prim {
            bounds,
            centroid: bounds.centroid(),
            index: index as u32,
        })
        .collect();
    let subtree = build_parallel(&mut prims, 0, 0, cost);
    let mut nodes = Vec::new();
    flatten(subtree, &mut nodes);
    (nodes, prims.iter().map(|prim| prim.index).collect())
}

/// A primitive as the build moves it around. Partitioning these records in place, rather than
/// an index list into the caller's boxes, keeps every pass over a node sequential in memory.
#[derive(Clone, Copy)]
struct Prim {
    bounds: Aabb,
    centroid: Vec3,
    index: u32,
}

/// How a node was decided; for a split, its primitives have already been partitioned at `mid`.
enum Plan {
    Leaf {
        bounds: Aabb,
    },
    Split {
        bounds: Aabb,
        mid: usize,
    },
}

/// A subtree as returned by a parallel task: either a finished run of nodes (child indices
/// relative to the run's start) or a split whose children were built separately.
enum Subtree {
    Nodes(Vec<BinaryNode>),
    Split {
        bounds: Aabb,
        children: Box<(Subtree, Subtree)>,
    },
}

fn build_parallel(prims: &mut [Prim], first: usize, depth: usize, cost: LeafCost) -> Subtree {
    if prims.len() < PARALLEL_THRESHOLD {
        let mut nodes = Vec::with_capacity(prims.len());
        build_serial(prims, first, depth, cost, &mut nodes);
        return Subtree::Nodes(nodes);
    }
    match plan(prims, depth, cost) {
        Plan::Leaf { bounds } => Subtree::Nodes(vec![BinaryNode::leaf(bounds, first, prims.len())]),
        Plan::Split { bounds, mid } => {
            let (below, above) = prims.split_at_mut(mid);
            let children = rayon::join(
                || build_parallel(below, first, depth + 1, cost),
                || build_parallel(above, first + mid, depth + 1, cost),
            );
            Subtree::Split {
                bounds,
                children: Box::new(children),
            }
        }
    }
}

fn build_serial(prims: &mut [Prim], first: usize, depth: usize, cost: LeafCost, nodes: &mut Vec<BinaryNode>) {
    match plan(prims, depth, cost) {
        Plan::Leaf { bounds } => nodes.push(BinaryNode::leaf(bounds, first, prims.len())),
        Plan::Split { bounds, mid } => {
            let index = nodes.len();
            nodes.push(BinaryNode::interior(bounds));
            let (below, above) = prims.split_at_mut(mid);
            build_serial(below, first, depth + 1, cost, nodes);
            nodes[index].offset = nodes.len() as u32;
            build_serial(above, first + mid, depth + 1, cost, nodes);
        }
    }
}

/// Appends the subtree in depth-first order, rebasing the relative child indices of each
/// serially built run.
fn flatten(subtree: Subtree, nodes: &mut Vec<BinaryNode>) {
    match subtree {
        Subtree::Nodes(run) => {
            let base = nodes.len() as u32;
            nodes.extend(run.into_iter().map(|mut node| {
                if !node.is_leaf() {
                    node.offset += base;
                }
                node
            }));
        }
        Subtree::Split { bounds, children } => {
            let index = nodes.len();
            nodes.push(BinaryNode::interior(bounds));
            let (below, above) = *children;
            flatten(below, nodes);
            nodes[index].offset = nodes.len() as u32;
            flatten(above, nodes);
        }
    }
}

fn plan(prims: &mut [Prim], depth: usize, cost: LeafCost) -> Plan {
    let (bounds, centroid_bounds) = prims
        .iter()
        .fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), prim| {
            (b.union(prim.bounds), c.grow(prim.centroid))
        });
    let count = prims.len();
    if count == 1 {
        return Plan::Leaf { bounds };
    }
    let axis = centroid_bounds.longest_axis();
    let spread = centroid_bounds.extent()[axis];
    if spread.is_nan() || spread <= 0.0 {
        // All centroids coincide (or are not finite): no position separates them, so halve
        // the list as it is.
        return if count <= cost.max_leaf() {
            Plan::Leaf { bounds }
        } else {
            Plan::Split {
                bounds,
                mid: count / 2,
            }
        };
    }
    if depth >= SAH_DEPTH_LIMIT {
        return if count <= cost.max_leaf() {
            Plan::Leaf { bounds }
        } else {
            median_split(prims, bounds, axis)
        };
    }
    let (low, bins_per_unit) = (centroid_bounds.min[axis], BIN_COUNT as Real / spread);
    let bin_of = |prim: &Prim| {
        // The float-to-int cast saturates (NaN and −∞ become 0), so every value lands in a bin,
        // even when a tiny spread makes `bins_per_unit` infinite.
        (((prim.centroid[axis] - low) * bins_per_unit) as usize).min(BIN_COUNT - 1)
    };
    let Some((split_bin, split_cost)) = best_bin_split(prims, &bin_of, cost) else {
        return if count <= cost.max_leaf() {
            Plan::Leaf { bounds }
        } else {
            median_split(prims, bounds, axis)
        };
    };
    // Costs are kept multiplied by the node's area, so a degenerate (zero-area) node needs no
    // division and simply compares 0 with 0, which chooses a leaf.
    let area = bounds.surface_area();
    let leaf_cost = cost.tests(count) * area;
    if count <= cost.max_leaf() && TRAVERSAL_COST * area + split_cost >= leaf_cost {
        return Plan::Leaf { bounds };
    }
    let mid = partition(prims, |prim| bin_of(prim) <= split_bin);
    Plan::Split { bounds, mid }
}

/// The bin after which splitting is cheapest, with its cost `Σ count·area` over both sides.
/// `None` when every primitive falls into a single bin.
fn best_bin_split(prims: &[Prim], bin_of: &impl Fn(&Prim) -> usize, cost: LeafCost) -> Option<(usize, Real)> {
    let mut counts = [0usize; BIN_COUNT];
    let mut boxes = [Aabb::EMPTY; BIN_COUNT];
    for prim in prims {
        let bin = bin_of(prim);
        counts[bin] += 1;
        boxes[bin] = boxes[bin].union(prim.bounds);
    }
    let mut above_cost = [0.0; BIN_COUNT];
    let (mut above_count, mut above_box) = (0, Aabb::EMPTY);
    for bin in (1..BIN_COUNT).rev() {
        above_count += counts[bin];
        above_box = above_box.union(boxes[bin]);
        above_cost[bin - 1] = cost.tests(above_count) * above_box.surface_area();
    }
    let (mut below_count, mut below_box) = (0, Aabb::EMPTY);
    let mut best: Option<(usize, Real)> = None;
    for split in 0..BIN_COUNT - 1 {
        below_count += counts[split];
        below_box = below_box.union(boxes[split]);
        if below_count == 0 || below_count == prims.len() {
            continue;
        }
        let split_cost = cost.tests(below_count) * below_box.surface_area() + above_cost[split];
        if best.is_none_or(|(_, best_cost)| split_cost < best_cost) {
            best = Some((split, split_cost));
        }
    }
    best
}

/// Splits at the median centroid along `axis`; ties are broken by primitive index so the
/// result does not depend on the incoming order.
fn median_split(prims: &mut [Prim], bounds: Aabb, axis: usize) -> Plan {
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid[axis]
            .total_cmp(&b.centroid[axis])
            .then(a.index.cmp(&b.index))
    });
    Plan::Split { bounds, mid }
}

/// Moves the primitives satisfying `goes_below` to the front and returns how many there are.
fn partition(prims: &mut [Prim], goes_below: impl Fn(&Prim) -> bool) -> usize {
    let mut below = 0;
    for i in 0..prims.len() {
        if goes_below(&prims[i]) {
            prims.swap(below, i);
            below += 1;
        }
    }
    below
}
