//! Binned-SAH construction of a flattened binary BVH, which `collapse` then turns into the 8-wide
//! tree that is traversed.
//!
//! Every split decision is a pure function of the primitives in the node, and subtrees built in
//! parallel write their nodes into slots fixed before they are built, so the result does not
//! depend on how rayon schedules the work.
//!
//! Each node costs two passes over its primitives: binning (which also gives both children's
//! boxes, as unions of bins) and partitioning (which also gives both children's centroid
//! bounds). The largest nodes are binned in parallel.

use rayon::prelude::*;

use super::super::aabb::Aabb;
use super::super::huge_page_vec;
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
/// hand to rayon.
pub(super) const PARALLEL_THRESHOLD: usize = 4096;
/// From this many primitives a node's binning pass is itself split among threads (the first
/// levels of the tree, before there are subtrees enough to keep every thread busy).
const PARALLEL_BINNING: usize = 1 << 17;
/// From this many primitives a node is binned into two interleaved sets of bins (see
/// [`Bins::fill`]); below, the second set would cost more to clear and merge than it saves.
const INTERLEAVED_BINNING: usize = 64;
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
#[derive(Clone, Copy, Debug, bytemuck::Zeroable)]
pub(super) struct BinaryNode {
    pub bounds: Aabb,
    /// `bounds.surface_area()`, which the collapse compares many times.
    pub area: Real,
    /// Leaf: index of its first entry in the primitive order. Interior: the second child.
    pub offset: u32,
    /// Zero for an interior node.
    pub prim_count: u32,
}

impl BinaryNode {
    fn leaf(bounds: Aabb, first: usize, count: usize) -> Self {
        BinaryNode { bounds, area: bounds.surface_area(), offset: first as u32, prim_count: count as u32 }
    }

    fn interior(bounds: Aabb) -> Self {
        BinaryNode { bounds, area: bounds.surface_area(), offset: 0, prim_count: 0 }
    }

    pub fn is_leaf(&self) -> bool {
        self.prim_count > 0
    }
}

/// Returns the nodes in depth-first order and the primitive indices in leaf order, for the
/// `count` primitives whose boxes are `bounds_of(0..count)`. The nodes are `2·count − 1` slots
/// (see [`build_parallel`]), the root first; slots no node is stored in are zeroed, and no
/// node points at them.
pub(super) fn build(count: usize, bounds_of: impl Fn(usize) -> Aabb + Sync, cost: LeafCost) -> (Vec<BinaryNode>, Vec<u32>) {
    assert!(count <= super::MAX_PRIMITIVES, "a BVH holds at most 2^31 primitives, not {count}");
    if count == 0 {
        return (Vec::new(), Vec::new());
    }
    let mut prims: Vec<Prim> = huge_page_vec(count);
    prims.par_extend((0..count).into_par_iter().map(|index| Prim::new(&bounds_of(index), index)));
    let root = Extent::of_parallel(&prims);
    // Zeroed memory from the allocator: slots no subtree fills are never written, so their pages
    // never cost a fault.
    let mut nodes = bytemuck::zeroed_vec(2 * count - 1);
    build_parallel(Node { prims: &mut prims, extent: root, first: 0, depth: 0 }, &mut nodes, 0, cost);
    (nodes, prims.par_iter().map(|prim| prim.index).collect())
}

/// A primitive as the build moves it around. Partitioning these records in place, rather than
/// an index list into the caller's boxes, keeps every pass over a node sequential in memory.
/// Plain arrays of four (the fourth is zero), so that the split axis indexes them without a
/// branch and a box grows by one vector minimum and maximum.
#[derive(Clone, Copy)]
#[repr(C)]
struct Prim {
    min: [Real; 4],
    max: [Real; 4],
    index: u32,
}

impl Prim {
    fn new(bounds: &Aabb, index: usize) -> Prim {
        let (min, max) = (bounds.min, bounds.max);
        Prim { min: [min.x, min.y, min.z, 0.0], max: [max.x, max.y, max.z, 0.0], index: index as u32 }
    }

    /// The centre of the box on one axis, halved before adding (as `Aabb::centroid`).
    #[inline(always)]
    fn centroid(&self, axis: usize) -> Real {
        self.min[axis] * 0.5 + self.max[axis] * 0.5
    }

    #[inline(always)]
    fn centroid4(&self) -> [Real; 4] {
        std::array::from_fn(|axis| self.min[axis] * 0.5 + self.max[axis] * 0.5)
    }
}

/// A box as two arrays of four: the union of primitives' boxes in the build's inner loops.
#[derive(Clone, Copy)]
struct Bounds {
    min: [Real; 4],
    max: [Real; 4],
}

impl Bounds {
    const EMPTY: Bounds = Bounds { min: [Real::INFINITY; 4], max: [Real::NEG_INFINITY; 4] };

    /// Grows the box by `[min, max]`. Written `new < old ? new : old`, which a NaN bound leaves as
    /// it is (as `f32::min` and `f32::max` do, the accumulated bounds never being NaN), one
    /// vector instruction each.
    #[inline(always)]
    fn grow(&mut self, min: &[Real; 4], max: &[Real; 4]) {
        let (mut low, mut high) = (self.min, self.max);
        for axis in 0..4 {
            low[axis] = if min[axis] < low[axis] { min[axis] } else { low[axis] };
            high[axis] = if max[axis] > high[axis] { max[axis] } else { high[axis] };
        }
        (self.min, self.max) = (low, high);
    }

    #[inline(always)]
    fn union(mut self, other: &Bounds) -> Bounds {
        self.grow(&other.min, &other.max);
        self
    }

    /// `Aabb::surface_area`: zero for an empty box.
    #[inline(always)]
    fn area(&self) -> Real {
        if !(self.min[0] <= self.max[0] && self.min[1] <= self.max[1] && self.min[2] <= self.max[2]) {
            return 0.0;
        }
        let d = [self.max[0] - self.min[0], self.max[1] - self.min[1], self.max[2] - self.min[2]];
        2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
    }

    fn aabb(&self) -> Aabb {
        Aabb::new(
            Vec3::new(self.min[0], self.min[1], self.min[2]),
            Vec3::new(self.max[0], self.max[1], self.max[2]),
        )
    }
}

/// A node's box and the box of its primitives' centroids.
#[derive(Clone, Copy)]
struct Extent {
    bounds: Bounds,
    centroids: Bounds,
}

impl Extent {
    const EMPTY: Extent = Extent { bounds: Bounds::EMPTY, centroids: Bounds::EMPTY };

    fn add(mut self, prim: &Prim) -> Extent {
        self.bounds.grow(&prim.min, &prim.max);
        let centroid = prim.centroid4();
        self.centroids.grow(&centroid, &centroid);
        self
    }

    fn union(self, other: Extent) -> Extent {
        Extent { bounds: self.bounds.union(&other.bounds), centroids: self.centroids.union(&other.centroids) }
    }

    fn of(prims: &[Prim]) -> Extent {
        prims.iter().fold(Extent::EMPTY, Extent::add)
    }

    /// [`Extent::of`] in parallel: unions are exact, so the order of the reduction is irrelevant.
    fn of_parallel(prims: &[Prim]) -> Extent {
        prims.par_chunks(PARALLEL_THRESHOLD).map(Extent::of).reduce(|| Extent::EMPTY, Extent::union)
    }
}

/// A node to build: its primitives (in place), their extent, where they start in the primitive
/// order, and the node's depth.
struct Node<'a> {
    prims: &'a mut [Prim],
    extent: Extent,
    first: usize,
    depth: usize,
}

/// How a node was decided; for a split, its primitives have already been partitioned at `mid`
/// and the children's extents are known.
// A plan lives for one node on the stack, never in a collection: boxing the split would cost an
// allocation per node for nothing.
#[allow(clippy::large_enum_variant)]
enum Plan {
    Leaf,
    Split { mid: usize, below: Extent, above: Extent },
}

/// Builds `node` into `slots`, the first of which is binary node `base`: the node itself first,
/// then its first child's subtree, then its second child's. A node of `n` primitives has `2n − 1`
/// slots, as many nodes as its subtree can have (leaves are never empty), so each child's slots
/// are known before it is built: the first child of a split at `mid` takes the `2·mid − 1`
/// slots after its parent and the second child the rest. Subtrees built in parallel therefore
/// write their nodes straight into place, and the tree is the same on any number of threads.
fn build_parallel(node: Node, slots: &mut [BinaryNode], base: usize, cost: LeafCost) {
    if node.prims.len() < PARALLEL_THRESHOLD {
        build_serial(node, &mut Run { slots, base, len: 0 }, cost);
        return;
    }
    let bounds = node.extent.bounds.aabb();
    match plan(node.prims, node.extent, node.depth, cost) {
        Plan::Leaf => slots[0] = BinaryNode::leaf(bounds, node.first, node.prims.len()),
        Plan::Split { mid, below, above } => {
            slots[0] = BinaryNode::interior(bounds);
            slots[0].offset = (base + 2 * mid) as u32;
            let (below_slots, above_slots) = slots[1..].split_at_mut(2 * mid - 1);
            let (below_prims, above_prims) = node.prims.split_at_mut(mid);
            let depth = node.depth + 1;
            rayon::join(
                || build_parallel(Node { prims: below_prims, extent: below, first: node.first, depth }, below_slots, base + 1, cost),
                || build_parallel(Node { prims: above_prims, extent: above, first: node.first + mid, depth }, above_slots, base + 2 * mid, cost),
            );
        }
    }
}

/// A subtree's slots as one thread fills them, depth first from the start: the rest stay unused.
struct Run<'a> {
    slots: &'a mut [BinaryNode],
    /// The binary node index of `slots[0]`.
    base: usize,
    /// How many slots are filled.
    len: usize,
}

impl Run<'_> {
    /// Fills the next slot; returns its index among the run's slots.
    fn push(&mut self, node: BinaryNode) -> usize {
        self.slots[self.len] = node;
        self.len += 1;
        self.len - 1
    }
}

fn build_serial(node: Node, run: &mut Run, cost: LeafCost) {
    let bounds = node.extent.bounds.aabb();
    match plan(node.prims, node.extent, node.depth, cost) {
        Plan::Leaf => {
            run.push(BinaryNode::leaf(bounds, node.first, node.prims.len()));
        }
        Plan::Split { mid, below, above } => {
            let index = run.push(BinaryNode::interior(bounds));
            let (below_prims, above_prims) = node.prims.split_at_mut(mid);
            let depth = node.depth + 1;
            build_serial(Node { prims: below_prims, extent: below, first: node.first, depth }, run, cost);
            run.slots[index].offset = (run.base + run.len) as u32;
            build_serial(Node { prims: above_prims, extent: above, first: node.first + mid, depth }, run, cost);
        }
    }
}

/// Splits the list as it is at `mid`; the children's extents come from one pass over each half.
fn split_in_order(prims: &[Prim], mid: usize) -> Plan {
    let (below, above) = prims.split_at(mid);
    Plan::Split { mid, below: Extent::of(below), above: Extent::of(above) }
}

fn plan(prims: &mut [Prim], extent: Extent, depth: usize, cost: LeafCost) -> Plan {
    let count = prims.len();
    // One test for the whole leaf costs no more than visiting a node would, so no split can win:
    // the SAH below would choose the leaf too, at the cost of binning.
    if count == 1 || (count <= cost.max_leaf() && cost.tests(count) <= TRAVERSAL_COST) {
        return Plan::Leaf;
    }
    let (bounds, centroid_bounds) = (extent.bounds.aabb(), extent.centroids.aabb());
    let axis = centroid_bounds.longest_axis();
    let spread = centroid_bounds.extent()[axis];
    if spread.is_nan() || spread <= 0.0 {
        // All centroids coincide (or are not finite): no position separates them, so halve
        // the list as it is.
        return if count <= cost.max_leaf() { Plan::Leaf } else { split_in_order(prims, count / 2) };
    }
    if depth >= SAH_DEPTH_LIMIT {
        return if count <= cost.max_leaf() { Plan::Leaf } else { median_split(prims, axis) };
    }
    let bins = Bins { axis, low: centroid_bounds.min[axis], per_unit: BIN_COUNT as Real / spread };
    let binned = if count >= PARALLEL_BINNING {
        prims.par_chunks(PARALLEL_THRESHOLD).map(|chunk| bins.fill(chunk)).reduce(Binned::empty, Binned::merge)
    } else {
        bins.fill(prims)
    };
    let Some((split_bin, split_cost)) = binned.best_split(count, cost) else {
        return if count <= cost.max_leaf() { Plan::Leaf } else { median_split(prims, axis) };
    };
    // Costs are kept multiplied by the node's area, so a degenerate (zero-area) node needs no
    // division and simply compares 0 with 0, which chooses a leaf.
    let area = bounds.surface_area();
    let leaf_cost = cost.tests(count) * area;
    if count <= cost.max_leaf() && TRAVERSAL_COST * area + split_cost >= leaf_cost {
        return Plan::Leaf;
    }
    let (mid, below_centroids, above_centroids) = partition(prims, |prim| bins.at_or_below(prim, split_bin));
    let side = |range: std::ops::Range<usize>| binned.boxes[range].iter().fold(Bounds::EMPTY, |b, bin| b.union(bin));
    Plan::Split {
        mid,
        below: Extent { bounds: side(0..split_bin + 1), centroids: below_centroids },
        above: Extent { bounds: side(split_bin + 1..BIN_COUNT), centroids: above_centroids },
    }
}

/// Where centroids fall along the split axis.
#[derive(Clone, Copy)]
struct Bins {
    axis: usize,
    low: Real,
    per_unit: Real,
}

impl Bins {
    /// Where `prim`'s centroid falls in units of bins from `low`: its bin is this, truncated
    /// and clamped to the bins.
    #[inline(always)]
    fn position(&self, prim: &Prim) -> Real {
        (prim.centroid(self.axis) - self.low) * self.per_unit
    }

    #[inline(always)]
    fn bin(&self, prim: &Prim) -> usize {
        // `max` turns NaN into 0, so every value lands in a bin, even when a tiny spread makes
        // `per_unit` infinite; the truncation then needs no saturation.
        self.position(prim).max(0.0).min((BIN_COUNT - 1) as Real) as i32 as usize
    }

    /// Whether `prim` falls in bin `split` or below: `bin(prim) <= split` as one comparison
    /// (the bins are monotonic in `position`, and NaN falls in bin 0).
    #[inline(always)]
    fn at_or_below(&self, prim: &Prim, split: usize) -> bool {
        let position = self.position(prim);
        position < (split + 1) as Real || position.is_nan()
    }

    /// Large nodes are binned into two interleaved sets of bins, merged at the end: consecutive
    /// primitives often fall in the same bin (a node's primitives lie in the order the
    /// partitions above left them), and one set would make each box's growth wait for the
    /// previous one's.
    fn fill(&self, prims: &[Prim]) -> Binned {
        if prims.len() < INTERLEAVED_BINNING {
            let mut binned = Binned::empty();
            for prim in prims {
                binned.add(self.bin(prim), prim);
            }
            return binned;
        }
        let (mut even, mut odd) = (Binned::empty(), Binned::empty());
        let mut pairs = prims.chunks_exact(2);
        for pair in &mut pairs {
            even.add(self.bin(&pair[0]), &pair[0]);
            odd.add(self.bin(&pair[1]), &pair[1]);
        }
        if let [last] = pairs.remainder() {
            even.add(self.bin(last), last);
        }
        even.merge(odd)
    }
}

/// Each bin's primitive count and box.
struct Binned {
    counts: [usize; BIN_COUNT],
    boxes: [Bounds; BIN_COUNT],
}

impl Binned {
    fn empty() -> Binned {
        Binned { counts: [0; BIN_COUNT], boxes: [Bounds::EMPTY; BIN_COUNT] }
    }

    #[inline(always)]
    fn add(&mut self, bin: usize, prim: &Prim) {
        self.counts[bin] += 1;
        self.boxes[bin].grow(&prim.min, &prim.max);
    }

    /// Counts add and boxes unite exactly, so merging partial binnings in any order gives the
    /// binning of the whole.
    fn merge(mut self, other: Binned) -> Binned {
        for bin in 0..BIN_COUNT {
            self.counts[bin] += other.counts[bin];
            self.boxes[bin] = self.boxes[bin].union(&other.boxes[bin]);
        }
        self
    }

    /// The bin after which splitting is cheapest, with its cost `Σ tests·area` over both sides.
    /// `None` when every primitive falls into a single bin.
    fn best_split(&self, count: usize, cost: LeafCost) -> Option<(usize, Real)> {
        let mut above_cost = [0.0; BIN_COUNT];
        let (mut above_count, mut above_box) = (0, Bounds::EMPTY);
        for bin in (1..BIN_COUNT).rev() {
            above_count += self.counts[bin];
            above_box = above_box.union(&self.boxes[bin]);
            above_cost[bin - 1] = cost.tests(above_count) * above_box.area();
        }
        let (mut below_count, mut below_box) = (0, Bounds::EMPTY);
        let mut best: Option<(usize, Real)> = None;
        for (split, &above) in above_cost.iter().enumerate().take(BIN_COUNT - 1) {
            below_count += self.counts[split];
            below_box = below_box.union(&self.boxes[split]);
            if below_count == 0 || below_count == count {
                continue;
            }
            let split_cost = cost.tests(below_count) * below_box.area() + above;
            if best.is_none_or(|(_, best_cost)| split_cost < best_cost) {
                best = Some((split, split_cost));
            }
        }
        best
    }
}

/// Splits at the median centroid along `axis`; ties are broken by primitive index so the
/// result does not depend on the incoming order.
fn median_split(prims: &mut [Prim], axis: usize) -> Plan {
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid(axis).total_cmp(&b.centroid(axis)).then(a.index.cmp(&b.index))
    });
    split_in_order(prims, mid)
}

/// Moves the primitives satisfying `goes_below` to the front; returns how many there are and
/// the centroid bounds of each side. Hoare's scheme: each primitive is tested once, and only
/// pairs on the wrong sides are swapped.
fn partition(prims: &mut [Prim], goes_below: impl Fn(&Prim) -> bool) -> (usize, Bounds, Bounds) {
    let (mut below_centroids, mut above_centroids) = (Bounds::EMPTY, Bounds::EMPTY);
    let grow = |bounds: &mut Bounds, prim: &Prim| {
        let centroid = prim.centroid4();
        bounds.grow(&centroid, &centroid);
    };
    let (mut low, mut high) = (0, prims.len());
    loop {
        while low < high && goes_below(&prims[low]) {
            grow(&mut below_centroids, &prims[low]);
            low += 1;
        }
        while low < high && !goes_below(&prims[high - 1]) {
            grow(&mut above_centroids, &prims[high - 1]);
            high -= 1;
        }
        if low >= high {
            return (low, below_centroids, above_centroids);
        }
        // `prims[low]` belongs above and `prims[high − 1]` below.
        prims.swap(low, high - 1);
        grow(&mut below_centroids, &prims[low]);
        grow(&mut above_centroids, &prims[high - 1]);
        low += 1;
        high -= 1;
    }
}
