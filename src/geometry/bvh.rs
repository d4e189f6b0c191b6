//! A bounding volume hierarchy over primitives known only by their boxes.
//!
//! The BVH never sees the primitives themselves: callers pass one box per primitive to
//! [`Bvh::build`] and a closure to the traversals that tests a primitive by index. That keeps
//! one implementation for triangle meshes and for scene-level object lists; meshes replace the
//! leaves' primitive runs by runs of triangle packs ([`Bvh::remap_leaves`]) and traverse with
//! their own leaf test ([`traverse`]).

mod build;
mod collapse;

use std::mem::MaybeUninit;

use super::Ray;
use super::aabb::Aabb;
use super::real::{MACHINE_EPSILON, R8, Real, gamma};
use crate::simd::{Isa, Kernel, Lanes, MaskOps, dispatch};

pub use build::LeafCost;

/// Children per node: eight boxes are tested at once, one per SIMD lane.
pub const WIDTH: usize = 8;

/// Boxes are pruned only when entered beyond the nearest hit so far times this: a box's entry
/// distance and a triangle's `t` are each rounded, so a triangle lying in a face of its box may
/// come out a few ulps nearer than the box's entry. Without the slack such a box could be
/// skipped once another hit a few ulps farther was known, and which of the two is found would
/// depend on the order of the traversal (a packet's, or one ray's); with it both are tested and
/// the nearest, ties to the smaller index, wins whatever the order.
const BOX_SLACK: Real = 1.0 + 64.0 * MACHINE_EPSILON;

/// Deepest binary tree [`Bvh::build`] can produce: SAH splits are allowed up to
/// `build::SAH_DEPTH_LIMIT` levels, after which median splits at most halve `u32::MAX` primitives
/// down to a leaf. The wide tree is no deeper, and each node visited pushes at most `WIDTH − 1`
/// children (the nearest is visited next), which sizes the traversal stack so that it can never
/// overflow.
const STACK_SIZE: usize = (WIDTH - 1) * (build::SAH_DEPTH_LIMIT + 33) + 1;

/// One node of the 8-wide tree: the boxes of its (up to eight) children side by side, one lane
/// per child, so that one slab test covers all eight. 256 bytes with `f32` bounds, aligned to
/// whole cache lines.
///
/// A child is either another node or a leaf, a run of primitives stored in the node itself.
/// Unused slots have an empty box, which no ray enters.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct BvhNode {
    /// `bounds[0]` holds the children's minimum corners, `bounds[1]` their maximum ones, by axis
    /// and then lane.
    bounds: [[[Real; WIDTH]; 3]; 2],
    /// Interior child: its node's index. Leaf: the index of its first entry in the primitive order.
    child: [u32; WIDTH],
    /// Leaf: its number of primitives (at least one). Zero for an interior child or unused slot.
    count: [u32; WIDTH],
}

impl BvhNode {
    const EMPTY: BvhNode = BvhNode {
        bounds: [[[Real::INFINITY; WIDTH]; 3], [[Real::NEG_INFINITY; WIDTH]; 3]],
        child: [0; WIDTH],
        count: [0; WIDTH],
    };

    fn set_child(&mut self, lane: usize, bounds: &Aabb, child: u32, count: u32) {
        for axis in 0..3 {
            self.bounds[0][axis][lane] = bounds.min[axis];
            self.bounds[1][axis][lane] = bounds.max[axis];
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
/// t_limit)` for the rays (a bit per lane) that reached it. As for [`LeafVisitor`], `leaf` is
/// `#[inline(always)]`.
pub trait PacketVisitor<I: Isa> {
    fn leaf(&mut self, first: u32, count: u32, rays: u32, t_limit: &mut [Real; PACKET]);
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
    /// If there are more than `u32::MAX` primitives.
    pub fn build(bounds: &[Aabb]) -> Bvh {
        Bvh::build_for(bounds, LeafCost::PerPrimitive)
    }

    /// [`Bvh::build`] for leaves whose primitives are tested as `cost` says (a mesh tests up to
    /// four triangles at once, so a leaf of four costs what a leaf of one does).
    pub fn build_for(bounds: &[Aabb], cost: LeafCost) -> Bvh {
        let (binary, prim_indices) = build::build(bounds, cost);
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
                    count_at[node.child[lane] as usize] = node.count[lane];
                }
            }
        }
        let mut leaves = Vec::new();
        let mut first = 0;
        while first < count_at.len() {
            let count = count_at[first];
            debug_assert!(count > 0, "leaves cover the primitive order");
            leaves.push((first as u32, count));
            first += count.max(1) as usize;
        }
        leaves
    }

    /// Replaces each leaf's `(first, count)` by `remap(first, count)`: how a mesh points its
    /// leaves at the packs of triangles it made of them. Only [`traverse`] with the caller's own
    /// leaf test makes sense afterwards.
    pub fn remap_leaves(&mut self, mut remap: impl FnMut(u32, u32) -> (u32, u32)) {
        for node in &mut self.nodes {
            for lane in 0..WIDTH {
                if node.count[lane] > 0 {
                    (node.child[lane], node.count[lane]) = remap(node.child[lane], node.count[lane]);
                    debug_assert!(node.count[lane] > 0, "a leaf keeps at least one entry");
                }
            }
        }
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

/// The per-ray part of the slab test, splatted across the lanes once per ray.
struct SlabLanes<I: Isa> {
    origin: [R8<I>; 3],
    /// `1 / direction` per component; ±∞ where the direction component is ±0.
    inverse: [R8<I>; 3],
    /// The inverse widened by `1 + 2·gamma(3)`, for the far planes (see [`node_hits`]).
    far_inverse: [R8<I>; 3],
    /// Chooses the near and far plane of each slab. Taken from the inverse so that a direction
    /// of −0.0 counts as negative, consistently with its −∞ inverse.
    negative: [bool; 3],
}

impl<I: Isa> SlabLanes<I> {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        // Spelled out rather than mapped: a closure passed to `map` may be compiled outside the
        // kernel, without its instructions.
        let inverse = ray.direction.recip();
        let far_inverse = inverse * (1.0 + 2.0 * gamma(3));
        let (o, i, f) = (ray.origin, inverse, far_inverse);
        SlabLanes {
            origin: [R8::<I>::splat(o.x), R8::<I>::splat(o.y), R8::<I>::splat(o.z)],
            inverse: [R8::<I>::splat(i.x), R8::<I>::splat(i.y), R8::<I>::splat(i.z)],
            far_inverse: [R8::<I>::splat(f.x), R8::<I>::splat(f.y), R8::<I>::splat(f.z)],
            negative: [inverse.x < 0.0, inverse.y < 0.0, inverse.z < 0.0],
        }
    }
}

/// The slab test of a node's eight boxes: each box's entry distance, and a bit per box the ray
/// meets for some `t` in `[0, t_limit·BOX_SLACK]`.
///
/// Conservative: it may report a hit the exact test would not, but never misses a box the
/// ray really touches, which is what keeps traversal from losing primitives. Two details
/// make that so. The far distance on each axis is widened by `1 + 2·gamma(3)` (pbrt-v4), which
/// covers the rounding of the inverse, the subtraction and the multiplication; it is folded
/// into the inverse once per ray, which adds one more rounding of `u`, still well inside the
/// `6u` of the widening (`(1 − u)⁴·(1 + 2·gamma(3)) > 1`). And a zero direction component
/// gives an infinite inverse, so an origin lying exactly on that slab's plane computes
/// `0 · ∞ = NaN`; `max`/`min` keep their second operand for a NaN, so that slab then constrains
/// nothing, i.e. the plane counts as inside the box, as a closed box should. An empty box
/// (`min = +∞`, `max = −∞`) is never hit: its far distance is `−∞` on every axis.
#[inline(always)]
fn node_hits<I: Isa>(node: &BvhNode, ray: &SlabLanes<I>, t_limit: Real) -> (R8<I>, u32) {
    let mut t_enter = R8::<I>::splat(0.0);
    let mut t_exit = R8::<I>::splat(t_limit * BOX_SLACK);
    for axis in 0..3 {
        let negative = ray.negative[axis];
        let (near, far) = (&node.bounds[negative as usize][axis], &node.bounds[!negative as usize][axis]);
        let t_near = (R8::<I>::load(near) - ray.origin[axis]) * ray.inverse[axis];
        let t_far = (R8::<I>::load(far) - ray.origin[axis]) * ray.far_inverse[axis];
        t_enter = t_near.max(t_enter);
        t_exit = t_far.min(t_exit);
    }
    (t_enter, t_enter.le(t_exit).bits())
}

/// A key that sorts children by the distance at which the ray enters them (non-negative and
/// never NaN, so the bits of the float order as it does) and carries the child's lane in its
/// low bits. In `f64` the distance's three lowest bits make way for the lane: the order only
/// decides how soon a child is visited, never which hit is found.
#[inline(always)]
fn sort_key(t: Real, lane: usize) -> u64 {
    let bits = t.to_bits() as u64;
    let key = if size_of::<Real>() == 4 { bits << 3 } else { bits & !7 };
    key | lane as u64
}

/// Entries the traversal stack holds in place before it spills to the heap. Rays rarely need
/// more than a few dozen, and a small frame keeps the kernels that do not traverse cheap.
const INLINE_STACK: usize = 64;

/// The traversal stack: `INLINE_STACK` entries inline and, unlike an array, not initialised
/// (zeroing them for every ray would cost more than most rays push), then a vector for the
/// deepest trees (at most `STACK_SIZE` entries in all), allocated only if ever needed.
struct Stack {
    entries: [MaybeUninit<Pending>; INLINE_STACK],
    len: usize,
    spilled: Vec<Pending>,
}

impl Stack {
    #[inline(always)]
    fn new() -> Self {
        Stack { entries: [const { MaybeUninit::uninit() }; INLINE_STACK], len: 0, spilled: Vec::new() }
    }

    #[inline(always)]
    fn push(&mut self, entry: Pending) {
        if self.len < INLINE_STACK {
            self.entries[self.len] = MaybeUninit::new(entry);
            self.len += 1;
        } else {
            self.spill(entry);
        }
    }

    #[cold]
    #[inline(never)]
    fn spill(&mut self, entry: Pending) {
        debug_assert!(self.spilled.len() + INLINE_STACK < STACK_SIZE);
        self.spilled.push(entry);
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Pending> {
        if !self.spilled.is_empty() {
            return self.spilled.pop();
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were written by `push`.
        Some(unsafe { self.entries[self.len].assume_init() })
    }
}

/// A child that waits on the stack is fetched from memory meanwhile.
#[inline(always)]
fn fetch_node<I: Isa>(nodes: &[BvhNode], pending: &Pending) {
    if pending.count == 0 {
        let waiting: *const BvhNode = &nodes[pending.index as usize];
        for line in 0..size_of::<BvhNode>().div_ceil(64) {
            I::prefetch(waiting.cast::<u8>().wrapping_add(64 * line));
        }
    }
}

/// Depth-first traversal with an explicit stack, nearest child first: each node's eight boxes
/// are tested at once, the children hit are ordered by where the ray enters them, the nearest
/// is visited next and the others wait on the stack with their entry distance. `visit(first,
/// count, t_limit)` is called for each leaf reached; it may shrink `t_limit`, which prunes every
/// box entered beyond it (a box entered exactly at the limit is still visited).
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn traverse<I: Isa>(nodes: &[BvhNode], ray: &Ray, t_max: Real, visitor: &mut impl LeafVisitor<I>) {
    if nodes.is_empty() || !(ray.origin.is_finite() && ray.direction.is_finite()) {
        return;
    }
    let slab = SlabLanes::<I>::new(ray);
    let mut t_limit = t_max;
    let mut stack = Stack::new();
    let mut current = Pending { t: 0.0, index: 0, count: 0 };
    loop {
        if current.count == 0 {
            let node = &nodes[current.index as usize];
            let (t_enter, hits) = node_hits::<I>(node, &slab, t_limit);
            if hits != 0 {
                let first = hits.trailing_zeros() as usize;
                let rest = hits & (hits - 1);
                if rest == 0 {
                    current = Pending { t: 0.0, index: node.child[first], count: node.count[first] };
                    continue;
                }
                let mut t = [0.0; WIDTH];
                t_enter.store(&mut t);
                let child = |lane: usize| Pending { t: t[lane], index: node.child[lane], count: node.count[lane] };
                let fetch = |pending: &Pending| fetch_node::<I>(nodes, pending);
                if rest & (rest - 1) == 0 {
                    // Two children, the common case: the farther one waits.
                    let second = rest.trailing_zeros() as usize;
                    let (near, far) = if t[second] < t[first] { (second, first) } else { (first, second) };
                    fetch(&child(far));
                    stack.push(child(far));
                    current = child(near);
                    continue;
                }
                // More: sort keys that order by entry distance and carry the lane, nearest first.
                let mut keys = [0u64; WIDTH];
                let mut len = 0;
                let mut remaining = hits;
                while remaining != 0 {
                    let lane = remaining.trailing_zeros() as usize;
                    remaining &= remaining - 1;
                    let key = sort_key(t[lane], lane);
                    let mut k = len;
                    while k > 0 && keys[k - 1] > key {
                        keys[k] = keys[k - 1];
                        k -= 1;
                    }
                    keys[k] = key;
                    len += 1;
                }
                for &key in keys[1..len].iter().rev() {
                    let waiting = child(key as usize & (WIDTH - 1));
                    fetch(&waiting);
                    stack.push(waiting);
                }
                current = child(keys[0] as usize & (WIDTH - 1));
                continue;
            }
        } else if let Visit::Stop = visitor.leaf(current.index, current.count, &mut t_limit) {
            return;
        }
        loop {
            let Some(pending) = stack.pop() else { return };
            // The box was hit before `t_limit` shrank; entered beyond it, it holds nothing nearer.
            if pending.t <= t_limit * BOX_SLACK {
                current = pending;
                break;
            }
        }
    }
}

/// Up to eight boxes side by side, tested at once with the traversal's slab test: a handful of
/// objects that need no tree.
#[derive(Clone, Debug)]
pub struct BoxSet {
    node: BvhNode,
    len: usize,
}

impl BoxSet {
    /// # Panics
    /// With more than [`WIDTH`] boxes.
    pub fn new(bounds: &[Aabb]) -> BoxSet {
        assert!(bounds.len() <= WIDTH, "a box set holds at most {WIDTH} boxes");
        let mut node = BvhNode::EMPTY;
        for (lane, bounds) in bounds.iter().enumerate() {
            node.set_child(lane, bounds, lane as u32, 1);
        }
        BoxSet { node, len: bounds.len() }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// A bit per box the ray enters by `t_limit` (with the traversal's slack), and where it enters
    /// each (meaningful for those bits).
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn entered<I: Isa>(&self, ray: &Ray, t_limit: Real) -> (u32, [Real; WIDTH]) {
        let mut t = [0.0; WIDTH];
        if !(ray.origin.is_finite() && ray.direction.is_finite()) {
            return (0, t);
        }
        let (t_enter, hits) = node_hits::<I>(&self.node, &SlabLanes::<I>::new(ray), t_limit);
        t_enter.store(&mut t);
        (hits, t)
    }

    /// The boxes of `hits` (from [`BoxSet::entered`]) nearest first, in the low bits of keys
    /// that sort by entry distance; `count` of them.
    #[inline(always)]
    pub fn nearest_first(hits: u32, t: &[Real; WIDTH]) -> ([u64; WIDTH], usize) {
        let mut keys = [0u64; WIDTH];
        let mut count = 0;
        let mut remaining = hits;
        while remaining != 0 {
            let lane = remaining.trailing_zeros() as usize;
            remaining &= remaining - 1;
            let key = sort_key(t[lane], lane);
            let mut k = count;
            while k > 0 && keys[k - 1] > key {
                keys[k] = keys[k - 1];
                k -= 1;
            }
            keys[k] = key;
            count += 1;
        }
        (keys, count)
    }

    /// The box a key of [`BoxSet::nearest_first`] stands for.
    #[inline(always)]
    pub fn lane(key: u64) -> usize {
        key as usize & (WIDTH - 1)
    }

    /// Whether a box entered at `t` may hold a hit nearer than `t_limit` (the traversal's pruning).
    #[inline(always)]
    pub fn may_hold(t: Real, t_limit: Real) -> bool {
        t <= t_limit * BOX_SLACK
    }
}

/// Rays traversed together by [`traverse_packet`].
pub const PACKET: usize = 8;

/// The per-ray part of the slab test for a packet of up to eight rays, one per lane, which
/// share the signs of their directions.
pub struct PacketLanes<I: Isa> {
    origin: [R8<I>; 3],
    inverse: [R8<I>; 3],
    far_inverse: [R8<I>; 3],
    negative: [bool; 3],
}

impl<I: Isa> PacketLanes<I> {
    /// `None` unless there are one to eight rays, all finite, whose direction components share
    /// their signs (as camera rays through a small tile do). Lanes past the last ray repeat it.
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Option<Self> {
        if rays.is_empty() || rays.len() > PACKET {
            return None;
        }
        let mut values = [[0.0; PACKET]; 9];
        let mut signs = None;
        for lane in 0..PACKET {
            let ray = &rays[lane.min(rays.len() - 1)];
            if !(ray.origin.is_finite() && ray.direction.is_finite()) {
                return None;
            }
            let inverse = ray.direction.recip();
            let negative = [inverse.x < 0.0, inverse.y < 0.0, inverse.z < 0.0];
            if *signs.get_or_insert(negative) != negative {
                return None;
            }
            // As `SlabLanes::new` computes them for one ray.
            let far_inverse = inverse * (1.0 + 2.0 * gamma(3));
            let (o, i, f) = (ray.origin, inverse, far_inverse);
            for (k, value) in [o.x, o.y, o.z, i.x, i.y, i.z, f.x, f.y, f.z].into_iter().enumerate() {
                values[k][lane] = value;
            }
        }
        let v = &values;
        Some(PacketLanes {
            origin: [R8::<I>::load(&v[0]), R8::<I>::load(&v[1]), R8::<I>::load(&v[2])],
            inverse: [R8::<I>::load(&v[3]), R8::<I>::load(&v[4]), R8::<I>::load(&v[5])],
            far_inverse: [R8::<I>::load(&v[6]), R8::<I>::load(&v[7]), R8::<I>::load(&v[8])],
            negative: signs.expect("at least one ray"),
        })
    }
}

/// A child waiting on a packet's stack: a [`Pending`] and the rays (a bit per lane) that entered
/// its box, the nearest at `t`.
#[derive(Clone, Copy)]
struct PacketPending {
    t: Real,
    index: u32,
    count: u32,
    rays: u32,
}

/// [`traverse`] for a packet of rays, each node visited once for all the rays that enter it:
/// each child box is tested against every ray at once (a ray per lane), with the same slab test
/// as one ray's traversal, so each ray enters exactly the boxes it would enter alone (given its
/// own `t_limit`). Children are visited nearest first (by the nearest ray's entry). `visit(first,
/// count, rays, t_limit)` is called for each leaf with the rays (bits) that reached it; it may
/// shrink the rays' entries of `t_limit`, which prunes, ray by ray, every box entered beyond.
///
/// A kernel: compile it only inside one (see `crate::simd`).
#[inline(always)]
pub fn traverse_packet<I: Isa>(
    nodes: &[BvhNode],
    lanes: &PacketLanes<I>,
    rays: u32,
    t_limit: &mut [Real; PACKET],
    visitor: &mut impl PacketVisitor<I>,
) {
    if nodes.is_empty() || rays == 0 {
        return;
    }
    let mut stack: Vec<PacketPending> = Vec::with_capacity(64);
    let mut current = PacketPending { t: 0.0, index: 0, count: 0, rays };
    loop {
        if current.count == 0 {
            let node = &nodes[current.index as usize];
            let limit = R8::<I>::load(&t_limit[..]) * R8::<I>::splat(BOX_SLACK);
            let mut children = [(0u64, 0u32); WIDTH];
            let mut hit = 0;
            for slot in 0..WIDTH {
                // The collapse fills slots from the first; the root is no node's child.
                if node.child[slot] == 0 && node.count[slot] == 0 {
                    break;
                }
                let mut t_enter = R8::<I>::splat(0.0);
                let mut t_exit = limit;
                for axis in 0..3 {
                    let negative = lanes.negative[axis] as usize;
                    let near = R8::<I>::splat(node.bounds[negative][axis][slot]);
                    let far = R8::<I>::splat(node.bounds[1 - negative][axis][slot]);
                    let t_near = (near - lanes.origin[axis]) * lanes.inverse[axis];
                    let t_far = (far - lanes.origin[axis]) * lanes.far_inverse[axis];
                    t_enter = t_near.max(t_enter);
                    t_exit = t_far.min(t_exit);
                }
                let entered = t_enter.le(t_exit).bits() & current.rays;
                if entered != 0 {
                    let mut t = [0.0; PACKET];
                    t_enter.store(&mut t);
                    let mut nearest = Real::INFINITY;
                    let mut remaining = entered;
                    while remaining != 0 {
                        let lane = remaining.trailing_zeros() as usize;
                        remaining &= remaining - 1;
                        nearest = nearest.min(t[lane]);
                    }
                    // Sorted by the key, nearest first; the low bits carry the slot.
                    let mut k = hit;
                    let key = sort_key(nearest, slot);
                    while k > 0 && children[k - 1].0 > key {
                        children[k] = children[k - 1];
                        k -= 1;
                    }
                    children[k] = (key, entered);
                    hit += 1;
                }
            }
            if hit > 0 {
                let pending = |(key, rays): (u64, u32)| {
                    let slot = key as usize & (WIDTH - 1);
                    let t = Real::from_bits_key(key);
                    PacketPending { t, index: node.child[slot], count: node.count[slot], rays }
                };
                for &child in children[1..hit].iter().rev() {
                    stack.push(pending(child));
                }
                current = pending(children[0]);
                continue;
            }
        } else {
            visitor.leaf(current.index, current.count, current.rays, t_limit);
        }
        loop {
            let Some(pending) = stack.pop() else { return };
            // Only the rays that have found nothing nearer than where the box is entered go on.
            let mut rays = 0;
            let mut remaining = pending.rays;
            while remaining != 0 {
                let lane = remaining.trailing_zeros();
                remaining &= remaining - 1;
                if pending.t <= t_limit[lane as usize] * BOX_SLACK {
                    rays |= 1 << lane;
                }
            }
            if rays != 0 {
                current = PacketPending { rays, ..pending };
                break;
            }
        }
    }
}

/// The distance a [`sort_key`] was made from, to within its dropped low bits (rounded down, so
/// never beyond the true entry distance).
trait FromBitsKey {
    fn from_bits_key(key: u64) -> Self;
}

impl FromBitsKey for Real {
    #[inline(always)]
    fn from_bits_key(key: u64) -> Real {
        if size_of::<Real>() == 4 { Real::from_bits((key >> 3) as _) } else { Real::from_bits((key & !7) as _) }
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
    fn node_is_four_cache_lines_with_f32() {
        if size_of::<Real>() == 4 {
            assert_eq!((size_of::<BvhNode>(), align_of::<BvhNode>()), (256, 64));
        }
    }

    #[test]
    fn wide_nodes_have_two_to_eight_children_and_keep_every_leaf() {
        let points: Vec<Vec3> = (0..2000)
            .map(|i| Vec3::new((i * 37 % 101) as Real, (i * 11 % 13) as Real, (i % 7) as Real))
            .collect();
        let boxes = point_boxes(&points);
        let (binary, _) = build::build(&boxes, LeafCost::PerPrimitive);
        let bvh = Bvh::build(&boxes);
        let binary_leaves = binary.iter().filter(|node| node.is_leaf()).count();
        assert_eq!(bvh.leaf_count(), binary_leaves);
        for node in &bvh.nodes {
            let used = (0..WIDTH).filter(|&lane| node.bounds[0][0][lane] <= node.bounds[1][0][lane]).count();
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
