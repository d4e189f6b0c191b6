//! One ray's traversal of the 8-wide tree: the slab test of a node's eight boxes, the nearest
//! child visited first, and the stack of children waiting.

use super::super::Ray;
use super::super::real::{R8, Real};
use crate::simd::{Isa, Lanes, MaskOps};
use super::*;

/// The per-ray part of the slab test, splatted across the lanes once per ray.
pub(super) struct SlabLanes<I: Isa> {
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
    pub(super) fn new(ray: &Ray) -> Self {
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

/// Eight boxes side by side, one per lane, as the slab test reads them: a node's quantised
/// boxes, or a [`BoxSet`]'s exact ones.
pub(super) trait LaneBoxes {
    /// The lanes' planes on `axis`: the minimum corners' when `side` is 0, the maximum ones'
    /// when 1.
    fn planes<I: Isa>(&self, side: usize, axis: usize) -> R8<I>;

    /// A bit per lane that may be entered at all.
    fn used(&self) -> u32;
}

impl LaneBoxes for BvhNode {
    #[inline(always)]
    fn planes<I: Isa>(&self, side: usize, axis: usize) -> R8<I> {
        BvhNode::planes::<I>(self, side, axis)
    }

    #[inline(always)]
    fn used(&self) -> u32 {
        BvhNode::used(self)
    }
}

/// The slab test of eight boxes: each box's entry distance, and a bit per box the ray meets for
/// some `t` in `[0, t_limit·BOX_SLACK]`.
///
/// Conservative: it may report a hit the exact test would not, but never misses a box the
/// ray really touches, which is what keeps traversal from losing primitives. Two details
/// make that so. The far distance on each axis is widened by `1 + 2·gamma(3)` (pbrt-v4), which
/// covers the rounding of the inverse, the subtraction and the multiplication; it is folded
/// into the inverse once per ray, which adds one more rounding of `u`, still well inside the
/// `6u` of the widening (`(1 − u)⁴·(1 + 2·gamma(3)) > 1`). And a zero direction component
/// gives an infinite inverse, so an origin lying exactly on that slab's plane computes
/// `0 · ∞ = NaN`; `max`/`min` keep their second operand for a NaN, so that slab then constrains
/// nothing, i.e. the plane counts as inside the box, as a closed box should (and a NaN plane,
/// a node's axis that is not quantised, constrains nothing either). An empty box (`min = +∞`,
/// `max = −∞`) is never hit: its far distance is `−∞` on every axis. A node's quantised boxes
/// contain their exact ones (see `node`), and the test only widens with the box, so through
/// them the ray enters every box it would enter exactly, never later.
#[inline(always)]
pub(super) fn node_hits<I: Isa>(boxes: &impl LaneBoxes, ray: &SlabLanes<I>, t_limit: Real) -> (R8<I>, u32) {
    let mut t_enter = R8::<I>::splat(0.0);
    let mut t_exit = R8::<I>::splat(t_limit * BOX_SLACK);
    // Axis by axis, each axis's planes decoded where used: decoding all six first, as a packet's
    // `PacketLanes::entry_exit` does once per node, cost a random ray 6% more instructions in
    // the interleaved walk.
    for axis in 0..3 {
        let negative = ray.negative[axis] as usize;
        let (near, far) = (boxes.planes::<I>(negative, axis), boxes.planes::<I>(1 - negative, axis));
        let t_near = (near - ray.origin[axis]) * ray.inverse[axis];
        let t_far = (far - ray.origin[axis]) * ray.far_inverse[axis];
        t_enter = t_near.max(t_enter);
        t_exit = t_far.min(t_exit);
    }
    (t_enter, t_enter.le(t_exit).bits() & boxes.used())
}

/// A key that sorts children by the distance at which the ray enters them (non-negative and
/// never NaN, so the bits of the float order as it does) and carries the child's lane in its
/// low bits. In `f64` the distance's three lowest bits make way for the lane: the order only
/// decides how soon a child is visited, never which hit is found.
#[inline(always)]
pub(super) fn sort_key(t: Real, lane: usize) -> u64 {
    let bits = t.to_bits() as u64;
    let key = if size_of::<Real>() == 4 { bits << 3 } else { bits & !7 };
    key | lane as u64
}

/// Levels of tree whose traversals keep their stacks in their own frame: deeper trees (which
/// only the median splits past `build::SAH_DEPTH_LIMIT` make) take theirs from the heap. A
/// frame holds eight stacks for interleaved rays, and every page of it is touched on each call.
pub(super) const LOCAL_HEIGHT: usize = 12;

/// A stack's entries in the traversal's frame: each node visited pushes at most `WIDTH − 1`
/// children (the nearest is visited next), and what a node pushed is popped before the
/// traversal leaves its subtree, so a tree of `h` levels never has more than `(WIDTH − 1)·h`
/// entries waiting, plus the one being pushed.
const LOCAL_ENTRIES: usize = (WIDTH - 1) * LOCAL_HEIGHT + 1;

/// Room for `STACKS` traversal stacks' entries: in the frame for trees of up to
/// [`LOCAL_HEIGHT`] levels, else on the heap, sized by the tree's height. Not initialised
/// (zeroing the entries for every ray would cost more than most rays push), and one value
/// rather than an array of them: an array repeated from a value that is partly initialised is
/// copied in full, uninitialised bytes too (a kilobyte per stack).
pub(super) struct StackSpace<T, const STACKS: usize = 1> {
    local: [[MaybeUninit<T>; LOCAL_ENTRIES]; STACKS],
    heap: Vec<MaybeUninit<T>>,
}

impl<T, const STACKS: usize> StackSpace<T, STACKS> {
    #[inline(always)]
    pub(super) const fn new() -> Self {
        // SAFETY: an array of `MaybeUninit` needs no initialisation.
        StackSpace { local: unsafe { MaybeUninit::uninit().assume_init() }, heap: Vec::new() }
    }

    /// `STACKS` empty stacks, each with room for any traversal of the tree `nodes` (root first).
    #[inline(always)]
    pub(super) fn stacks(&mut self, nodes: &[BvhNode]) -> [Stack<'_, T>; STACKS] {
        let height = nodes.first().map_or(0, |root| root.height as usize);
        if height <= LOCAL_HEIGHT {
            return self.local.each_mut().map(|entries| Stack { entries, len: 0 });
        }
        let room = (WIDTH - 1) * height + 1;
        self.heap.resize_with(room * STACKS, MaybeUninit::uninit);
        let mut rooms = self.heap.chunks_exact_mut(room);
        std::array::from_fn(|_| Stack { entries: rooms.next().expect("a room per stack"), len: 0 })
    }
}

impl<T> StackSpace<T> {
    /// An empty stack with room for any traversal of the tree `nodes` (root first).
    #[inline(always)]
    pub(super) fn stack(&mut self, nodes: &[BvhNode]) -> Stack<'_, T> {
        let [stack] = self.stacks(nodes);
        stack
    }
}

/// A traversal stack in a [`StackSpace`] of the caller's, so that the stack itself is small
/// enough to move. A push checks for room only as slice indexing does (the room is there, see
/// [`LOCAL_ENTRIES`]) and a pop only for emptiness.
pub(super) struct Stack<'a, T> {
    entries: &'a mut [MaybeUninit<T>],
    len: usize,
}

impl<'a, T: Copy> Stack<'a, T> {
    #[inline(always)]
    pub(super) fn push(&mut self, entry: T) {
        // In bounds: each node visited pushes at most `WIDTH - 1` entries (see `LOCAL_ENTRIES`).
        self.entries[self.len] = MaybeUninit::new(entry);
        self.len += 1;
    }

    /// Pushes `entry` when `keep`, without a branch: the entry is written either way, in the
    /// room the next push would use.
    #[inline(always)]
    pub(super) fn push_if(&mut self, entry: T, keep: bool) {
        self.entries[self.len] = MaybeUninit::new(entry);
        self.len += keep as usize;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were written by `push`.
        Some(unsafe { self.entries[self.len].assume_init() })
    }
}

/// A child that waits on the stack is fetched from memory meanwhile: a node, or the start of a
/// leaf's primitives (where the visitor says they lie). The address is chosen by a select, not
/// a branch (whether a child is a node or a leaf is not predictable), and the same number of
/// lines asked for either way: a node's or a leaf's, whichever is more. A visitor with nothing
/// to fetch has its leaves passed over (its null address is not asked for).
#[inline(always)]
fn fetch<I: Isa, V: LeafVisitor<I>>(nodes: &[BvhNode], pending: &Pending, visitor: &V) {
    if V::LEAF_LINES == 0 {
        if pending.count == 0 {
            prefetch_node::<I>(nodes, pending.index);
        }
        return;
    }
    let node = node_data(nodes, pending.index);
    let leaf = visitor.leaf_data(pending.index);
    let start = if pending.count == 0 { node } else { leaf };
    prefetch_lines::<I>(start, NODE_LINES.max(V::LEAF_LINES));
}

/// Asks for `lines` cache lines from the one `start` lies in.
#[inline(always)]
fn prefetch_lines<I: Isa>(start: *const u8, lines: usize) {
    let line = start.wrapping_sub(start as usize % 64);
    for k in 0..lines {
        I::prefetch(line.wrapping_add(64 * k));
    }
}

/// The cache lines of a node.
const NODE_LINES: usize = size_of::<BvhNode>().div_ceil(64);

/// Where node `index` lies, for asking for it from memory (computed without indexing: it is
/// never read through).
#[inline(always)]
fn node_data(nodes: &[BvhNode], index: u32) -> *const u8 {
    nodes.as_ptr().wrapping_add(index as usize).cast()
}

/// Asks for the cache lines of node `index`.
#[inline(always)]
pub(super) fn prefetch_node<I: Isa>(nodes: &[BvhNode], index: u32) {
    prefetch_lines::<I>(node_data(nodes, index), NODE_LINES);
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
    let mut space = StackSpace::new();
    let Some(mut walk) = Walk::<I>::new(nodes, ray, t_max, space.stack(nodes)) else { return };
    while walk.step::<false>(nodes, visitor) {}
}

/// [`traverse`] for up to [`PACKET`] rays that need not have anything in common (the random
/// rays of a path, the reflections off a bumpy surface), ray `k` with its own `t_max[k]` and
/// `visitors[k]`. Their traversals are interleaved, a node or leaf of each in turn, and each
/// asks for the next node or leaf it will visit from memory before the others take their
/// turn: where one ray's traversal would wait for each node to arrive, several rays' nodes are
/// on their way at once. Each ray visits exactly the nodes and leaves, in the same order, that
/// [`traverse`] visits for it alone, so its visitor sees the same calls.
///
/// A kernel: compile it only inside one (see `crate::simd`).
///
/// # Panics
/// If there are more than [`PACKET`] rays, or fewer visitors than rays.
#[inline(always)]
pub fn traverse_interleaved<I: Isa, V: LeafVisitor<I>>(
    nodes: &[BvhNode],
    rays: &[Ray],
    t_max: &[Real; PACKET],
    visitors: &mut [V],
) {
    assert!(rays.len() <= PACKET && visitors.len() >= rays.len(), "up to {PACKET} rays, a visitor each");
    let mut space = StackSpace::<Pending, PACKET>::new();
    // Uninitialised until a ray's walk starts, its bit then set in `active`: an array of
    // `None`s would be written in full (three kilobytes) for every call.
    let mut walks = [const { MaybeUninit::<Walk<'_, I>>::uninit() }; PACKET];
    let mut active = 0u32;
    // Loops rather than `array::from_fn`: a closure may be compiled outside the kernel,
    // without its instructions.
    for (k, (stack, ray)) in space.stacks(nodes).into_iter().zip(rays).enumerate() {
        if let Some(walk) = Walk::<I>::new(nodes, ray, t_max[k], stack) {
            walks[k].write(walk);
            active |= 1 << k;
        }
    }
    while active != 0 {
        let mut turn = active;
        while turn != 0 {
            let k = turn.trailing_zeros() as usize;
            turn &= turn - 1;
            // SAFETY: bit `k` of `active` (and so of `turn`) is set only once `walks[k]` is
            // written. A walk owns nothing to drop, so leaving them uninitialised leaks nothing.
            let walk = unsafe { walks[k].assume_init_mut() };
            if !walk.step::<true>(nodes, &mut visitors[k]) {
                active &= !(1 << k);
            }
        }
    }
}

/// One ray's traversal under way: the ray's slab terms, its limit, what it visits next and the
/// children waiting.
struct Walk<'a, I: Isa> {
    slab: SlabLanes<I>,
    t_limit: Real,
    current: Pending,
    stack: Stack<'a, Pending>,
}

impl<'a, I: Isa> Walk<'a, I> {
    /// `None` when there is nothing to traverse or the ray is not finite.
    #[inline(always)]
    fn new(nodes: &[BvhNode], ray: &Ray, t_max: Real, stack: Stack<'a, Pending>) -> Option<Self> {
        if nodes.is_empty() || !(ray.origin.is_finite() && ray.direction.is_finite()) {
            return None;
        }
        Some(Walk {
            slab: SlabLanes::<I>::new(ray),
            t_limit: t_max,
            current: Pending { t: 0.0, index: 0, count: 0 },
            stack,
        })
    }

    /// Visits the current node or leaf and moves on to the next; `false` when the traversal is
    /// over. With `AHEAD`, the next node or leaf is asked for from memory, for a caller that
    /// has other work to do before the next step.
    #[inline(always)]
    fn step<const AHEAD: bool>(&mut self, nodes: &[BvhNode], visitor: &mut impl LeafVisitor<I>) -> bool {
        let current = self.current;
        if current.count == 0 {
            let node = &nodes[current.index as usize];
            let (t_enter, hits) = node_hits::<I>(node, &self.slab, self.t_limit);
            if hits != 0 {
                self.current = nearest_child::<I>(node, t_enter, hits, nodes, &mut self.stack, visitor);
                if AHEAD {
                    fetch::<I, _>(nodes, &self.current, visitor);
                }
                return true;
            }
        } else if let Visit::Stop = visitor.leaf(current.index, current.count, &mut self.t_limit) {
            return false;
        }
        loop {
            let Some(pending) = self.stack.pop() else { return false };
            // The box was hit before `t_limit` shrank; entered beyond it, it holds nothing nearer.
            if pending.t <= self.t_limit * BOX_SLACK {
                self.current = pending;
                return true;
            }
        }
    }
}

/// Of a node's children the ray enters (`hits`, entered at `t_enter`), the nearest, which is
/// visited next; the others are pushed on the stack, farthest first, and fetched meanwhile.
#[inline(always)]
fn nearest_child<I: Isa>(
    node: &BvhNode,
    t_enter: R8<I>,
    hits: u32,
    nodes: &[BvhNode],
    stack: &mut Stack<'_, Pending>,
    visitor: &impl LeafVisitor<I>,
) -> Pending {
    let mut t = [0.0; WIDTH];
    t_enter.store(&mut t);
    let child = |lane: usize| Pending { t: t[lane], index: node.child[lane], count: node.count[lane] as u32 };
    let first = hits.trailing_zeros() as usize;
    let rest = hits & (hits - 1);
    if rest & rest.wrapping_sub(1) == 0 {
        // One child or two, the common cases, without a branch between them (which is which
        // is as unpredictable as a coin): with one, `last` is `first` and nothing waits.
        let last = (u32::BITS - 1 - hits.leading_zeros()) as usize;
        let (near, far) = if t[last] < t[first] { (last, first) } else { (first, last) };
        fetch::<I, _>(nodes, &child(far), visitor);
        stack.push_if(child(far), rest != 0);
        return child(near);
    }
    // More: sort keys that order by entry distance and carry the lane, nearest first.
    let mut keys = [0; WIDTH];
    let keys = BoxSet::nearest_first(hits, &t, &mut keys);
    for &key in keys[1..].iter().rev() {
        let waiting = child(BoxSet::lane(key));
        fetch::<I, _>(nodes, &waiting, visitor);
        stack.push(waiting);
    }
    child(BoxSet::lane(keys[0]))
}
