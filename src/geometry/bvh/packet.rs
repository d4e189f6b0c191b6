//! Packets of up to eight coherent rays traversing the tree together.

use super::super::Ray;
use super::super::lanes::RayLanes;
use super::super::real::{R8, Real, lane_pair};
use crate::simd::{Isa, Lanes, MaskOps};
use super::*;
use super::traverse::{StackSpace, prefetch_node, sort_key};

pub const PACKET: usize = 8;

/// The per-ray part of the slab test for a packet of up to eight rays, one per lane, which
/// share the signs of their directions.
pub struct PacketLanes<I: Isa> {
    origin: [R8<I>; 3],
    inverse: [R8<I>; 3],
    far_inverse: [R8<I>; 3],
    negative: [bool; 3],
    /// The rays' ranges, when every inverse is finite (see [`Frustum`]).
    frustum: Option<Frustum>,
}

/// The range of each of the packet's slab terms over its rays, for a test of a node's eight
/// boxes at once against the whole packet before each box is tested against each ray. The test
/// is interval arithmetic over the per-ray test's own roundings: a rounded subtraction or
/// product moves monotonically with each operand, so the per-ray entry distance of every ray is
/// no nearer than the range's nearest and its exit no farther than the range's farthest. A box
/// that no ray can enter by that bound is one that no ray enters by its own test: the pre-test
/// only spares tests whose answer is "no", and changes no result.
///
/// Not made when a direction component is zero: its infinite inverse times a plane through the
/// origin is NaN, which the per-ray test reads as "no constraint" on that ray alone.
/// Kept as numbers, splatted where used: lanes of them would be copied with the packet.
#[derive(Clone, Copy)]
struct Frustum {
    /// Per axis: the smallest and largest origin component.
    origin: [[Real; 2]; 3],
    /// Per axis: the smallest and largest inverse, and the same of the widened far inverse.
    inverse: [[Real; 2]; 3],
    far_inverse: [[Real; 2]; 3],
}

impl Frustum {
    /// From the packet's lanes; `None` when an inverse is not finite.
    #[inline(always)]
    fn new<I: Isa>(origin: &[R8<I>; 3], inverse: &[R8<I>; 3]) -> Option<Self> {
        let infinity = R8::<I>::splat(Real::INFINITY);
        // The far inverse is the inverse times a positive constant, and a rounded product
        // moves with its operand: its range is its ends' products.
        let widen = 1.0 + 2.0 * gamma(3);
        let mut frustum = Frustum { origin: [[0.0; 2]; 3], inverse: [[0.0; 2]; 3], far_inverse: [[0.0; 2]; 3] };
        for axis in 0..3 {
            if inverse[axis].abs().lt(infinity).bits() != 0xff {
                return None;
            }
            frustum.origin[axis] = range::<I>(origin[axis]);
            let [low, high] = range::<I>(inverse[axis]);
            frustum.inverse[axis] = [low, high];
            frustum.far_inverse[axis] = [low * widen, high * widen];
        }
        Some(frustum)
    }

    /// A bit per box (lane) that some ray of the packet may enter for a `t` up to `t_max`,
    /// a superset of the boxes the per-ray test finds entered by any ray whose limit is at
    /// most `t_max`, and per box a distance no farther than any ray's entry (non-negative,
    /// never NaN). `planes` are the boxes' entry and exit planes ([`PacketLanes::entry_exit`]),
    /// and `negative` the packet's direction signs.
    #[inline(always)]
    fn may_enter<I: Isa>(&self, planes: &[[R8<I>; 3]; 2], negative: [bool; 3], t_max: Real) -> (R8<I>, u32) {
        let splat = R8::<I>::splat;
        let mut t_enter = splat(0.0);
        let mut t_exit = splat(t_max);
        for axis in 0..3 {
            let negative = negative[axis] as usize;
            let (near, far) = (planes[0][axis], planes[1][axis]);
            let [origin_low, origin_high] = self.origin[axis];
            // The product of a positive inverse grows with the difference, of a negative one
            // shrinks: the nearest entry takes the smallest difference then, else the largest,
            // and the farthest exit the other; either end of the inverse's range may give it.
            let (near_end, far_end) = if negative == 0 {
                (near - splat(origin_high), far - splat(origin_low))
            } else {
                (near - splat(origin_low), far - splat(origin_high))
            };
            let [inverse_low, inverse_high] = self.inverse[axis];
            let [far_low, far_high] = self.far_inverse[axis];
            let t_near = (near_end * splat(inverse_low)).min(near_end * splat(inverse_high));
            let t_far = (far_end * splat(far_low)).max(far_end * splat(far_high));
            t_enter = t_near.max(t_enter);
            t_exit = t_far.min(t_exit);
        }
        (t_enter, t_enter.le(t_exit).bits())
    }
}

impl<I: Isa> PacketLanes<I> {
    /// A node's planes as the packet's rays meet them: `[0][axis]` the planes every ray enters
    /// its boxes by (the minimum corners' on an axis the rays go up, else the maximum ones'),
    /// `[1][axis]` the planes they leave by. Ordered once per node, the per-ray test indexes
    /// them by slot alone.
    #[inline(always)]
    pub(super) fn entry_exit(&self, node: &BvhNode) -> [[R8<I>; 3]; 2] {
        let [x, y, z] = self.negative.map(usize::from);
        [
            [node.planes::<I>(x, 0), node.planes::<I>(y, 1), node.planes::<I>(z, 2)],
            [node.planes::<I>(1 - x, 0), node.planes::<I>(1 - y, 1), node.planes::<I>(1 - z, 2)],
        ]
    }

    /// The packet's test of eight boxes at once ([`Frustum`]), when it has one: a bit per box
    /// that some ray may enter for a `t` up to `reach` (a superset of those the rays enter each
    /// by its own test) and per box a distance no farther than any ray's entry.
    /// `planes` are the boxes' entry and exit planes ([`PacketLanes::entry_exit`]).
    #[inline(always)]
    pub(super) fn may_enter(&self, planes: &[[R8<I>; 3]; 2], reach: Real) -> Option<(R8<I>, u32)> {
        match &self.frustum {
            Some(frustum) => Some(frustum.may_enter::<I>(planes, self.negative, reach)),
            None => None,
        }
    }

    /// `None` unless there are one to eight rays, all finite, whose direction components share
    /// their signs (as camera rays through a small tile do). Lanes past the last ray repeat it.
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Option<Self> {
        if rays.is_empty() || rays.len() > PACKET {
            return None;
        }
        PacketLanes::from_lanes(&RayLanes::gather(rays))
    }

    /// [`PacketLanes::new`] of rays already side by side: `None` unless every lane is finite
    /// and the lanes' direction components share their signs.
    #[inline(always)]
    pub fn from_lanes(rays: &RayLanes<I>) -> Option<Self> {
        if rays.finite() != 0xff {
            return None;
        }
        // As `SlabLanes::new` computes them for one ray, a lane at a time.
        let one = R8::<I>::splat(1.0);
        let (o, d) = (rays.origin, rays.direction);
        let inverse = [one / d.x, one / d.y, one / d.z];
        let widen = R8::<I>::splat(1.0 + 2.0 * gamma(3));
        let mut negative = [false; 3];
        for (negative, inverse) in negative.iter_mut().zip(&inverse) {
            match inverse.lt(R8::<I>::splat(0.0)).bits() {
                0 => {}
                0xff => *negative = true,
                _ => return None,
            }
        }
        let origin = [o.x, o.y, o.z];
        Some(PacketLanes {
            origin,
            inverse,
            far_inverse: [inverse[0] * widen, inverse[1] * widen, inverse[2] * widen],
            negative,
            frustum: Frustum::new::<I>(&origin, &inverse),
        })
    }
}

/// A child waiting on a packet's stack: a [`Pending`] and the rays (a bit per lane) that entered
/// its box, none of them nearer than `t`.
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
/// own `t_limit`). Children are visited nearest first (by the nearest ray's entry, or the packet's
/// frustum's bound on it). Boxes that no ray of the packet can enter by the frustum's test are
/// not tested ray by ray; each child entered is asked for from memory as soon as it is found
/// entered, the nearest too (it gets a head start of the ordering). `visit(first, count, rays,
/// t_limit)` is called for each leaf with the rays (bits) that reached it and their limits in
/// lanes, starting from `t_max`; it may shrink the rays' limits, which prunes, ray by ray,
/// every box entered beyond.
///
/// A kernel: compile it only inside one (see `crate::simd`).
// The slab test's loop over the axes indexes the node's plane lanes and three of the packet's
// arrays.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub fn traverse_packet<I: Isa>(
    nodes: &[BvhNode],
    lanes: &PacketLanes<I>,
    rays: u32,
    t_max: &[Real; PACKET],
    visitor: &mut impl PacketVisitor<I>,
) {
    if nodes.is_empty() || rays == 0 {
        return;
    }
    let mut space = StackSpace::<PacketPending>::new();
    let mut stack = space.stack(nodes);
    let mut current = PacketPending { t: 0.0, index: 0, count: 0, rays };
    let mut t_limit = R8::<I>::load(&t_max[..]);
    // The farthest any ray may still reach, for the frustum's test; it changes only at leaves.
    let mut reach = (t_limit * R8::<I>::splat(BOX_SLACK)).max_lane();
    // Per slot of a node, the nearest entry and the rays of an entered child; only the slots
    // in `entered_slots` are meaningful, so the arrays are filled once, not for every node.
    let (mut child_entry, mut entered_rays) = ([0.0; WIDTH], [0u32; WIDTH]);
    loop {
        if current.count == 0 {
            let node = &nodes[current.index as usize];
            let limit = t_limit * R8::<I>::splat(BOX_SLACK);
            let mut entered_slots = 0u32;
            // The node's entry and exit planes, as one ray's traversal computes them; each box's
            // are spread across the lanes by one permutation a plane (`vpermps`), not stored
            // and each read back as a broadcast (camera rays through the 1M-triangle mesh 1.1%
            // faster on one thread, 1-2% on two).
            let plane_lanes = lanes.entry_exit(node);
            let mut used = node.used();
            // With a frustum, the boxes are ordered by its entry distances, each no farther
            // than the nearest ray's (the order only decides how soon a box is visited).
            let frustum_entry = match lanes.may_enter(&plane_lanes, reach) {
                Some((t_enter, may_enter)) => {
                    used &= may_enter;
                    let mut entry = [0.0; WIDTH];
                    t_enter.store(&mut entry);
                    Some(entry)
                }
                None => None,
            };
            while used != 0 {
                let slot = used.trailing_zeros() as usize;
                used &= used - 1;
                let mut t_enter = R8::<I>::splat(0.0);
                let mut t_exit = limit;
                for axis in 0..3 {
                    let near = lane_pair::<I>(plane_lanes[0][axis], [slot, slot]);
                    let far = lane_pair::<I>(plane_lanes[1][axis], [slot, slot]);
                    let t_near = (near - lanes.origin[axis]) * lanes.inverse[axis];
                    let t_far = (far - lanes.origin[axis]) * lanes.far_inverse[axis];
                    t_enter = t_near.max(t_enter);
                    t_exit = t_far.min(t_exit);
                }
                let entered_lanes = t_enter.le(t_exit);
                let any_ray = entered_lanes.bits();
                let entered = any_ray & current.rays;
                if entered != 0 {
                    let nearest = if let Some(entry) = &frustum_entry {
                        entry[slot]
                    } else if entered == any_ray {
                        // Usually every ray that enters the box is one of the current rays, and
                        // the nearest entry is one select and the range of the lanes; else lane
                        // by lane.
                        R8::<I>::select(entered_lanes, t_enter, R8::<I>::splat(Real::INFINITY)).min_lane()
                    } else {
                        let mut t = [0.0; PACKET];
                        t_enter.store(&mut t);
                        let mut nearest = Real::INFINITY;
                        let mut remaining = entered;
                        while remaining != 0 {
                            let lane = remaining.trailing_zeros() as usize;
                            remaining &= remaining - 1;
                            nearest = nearest.min(t[lane]);
                        }
                        nearest
                    };
                    child_entry[slot] = nearest;
                    entered_rays[slot] = entered;
                    entered_slots |= 1 << slot;
                    fetch::<I>(nodes, node.child[slot], node.count[slot] as u32, visitor);
                }
            }
            if entered_slots != 0 {
                // Ordered by the keys of one ray's traversal (by entry, then slot), and waiting
                // at the distance the key keeps (rounded down). The same steps as
                // `traverse::nearest_child`, kept apart: a helper shared by both, over either
                // entry type, cost one ray 1-2.5% more instructions (docs/speed.md).
                let key = |slot: usize| sort_key(child_entry[slot], slot);
                let pending = |slot: usize| PacketPending {
                    t: Real::from_bits_key(key(slot)),
                    index: node.child[slot],
                    count: node.count[slot] as u32,
                    rays: entered_rays[slot],
                };
                let first = entered_slots.trailing_zeros() as usize;
                let rest = entered_slots & (entered_slots - 1);
                if rest & rest.wrapping_sub(1) == 0 {
                    // One child or two, the common cases, without a branch on which is nearer
                    // (a coin toss) or on how many: with one, `last` is `first` and nothing
                    // waits.
                    let last = (u32::BITS - 1 - entered_slots.leading_zeros()) as usize;
                    let (near, far) = if key(last) < key(first) { (last, first) } else { (first, last) };
                    stack.push_if(pending(far), rest != 0);
                    current = pending(near);
                } else {
                    let mut keys = [0; WIDTH];
                    let keys = BoxSet::nearest_first(entered_slots, &child_entry, &mut keys);
                    for &ordered in keys[1..].iter().rev() {
                        stack.push(pending(BoxSet::lane(ordered)));
                    }
                    current = pending(BoxSet::lane(keys[0]));
                }
                continue;
            }
        } else {
            visitor.leaf(current.index, current.count, current.rays, &mut t_limit);
            reach = (t_limit * R8::<I>::splat(BOX_SLACK)).max_lane();
        }
        loop {
            let Some(pending) = stack.pop() else { return };
            // Only the rays that have found nothing nearer than where the box is entered go on.
            let limit = t_limit * R8::<I>::splat(BOX_SLACK);
            let rays = R8::<I>::splat(pending.t).le(limit).bits() & pending.rays;
            if rays != 0 {
                current = PacketPending { rays, ..pending };
                break;
            }
        }
    }
}

/// Asks for a child from memory (`count` 0: a node, here; else a leaf's primitives, by the
/// visitor). Called for each child a packet enters, as soon as its box test says so, rather
/// than for those pushed on the stack as they are pushed: the nearest, visited next, waited for
/// its node or leaf otherwise (camera packets 3.8% faster on the 1M-triangle mesh). A branch,
/// not one ray's select between the two addresses (`traverse::fetch`): measured with packets,
/// the select was slower (docs/speed.md).
#[inline(always)]
fn fetch<I: Isa>(nodes: &[BvhNode], index: u32, count: u32, visitor: &impl PacketVisitor<I>) {
    if count == 0 {
        prefetch_node::<I>(nodes, index);
    } else {
        visitor.prefetch(index, count);
    }
}

/// The smallest and largest lane (none being NaN).
#[inline(always)]
fn range<I: Isa>(lanes: R8<I>) -> [Real; 2] {
    [lanes.min_lane(), lanes.max_lane()]
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
