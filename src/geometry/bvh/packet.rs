//! Packets of up to eight coherent rays traversing the tree together.

use super::super::Ray;
use super::super::real::{R8, Real};
use crate::simd::{Isa, Lanes, MaskOps};
use super::*;
use super::traverse::{StackSpace, sort_key};

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
// The slab test's loop over the axes indexes the planes and four of the packet's arrays.
#[allow(clippy::needless_range_loop)]
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
    let mut space = StackSpace::<PacketPending>::new();
    let mut stack = space.stack(nodes);
    let mut current = PacketPending { t: 0.0, index: 0, count: 0, rays };
    loop {
        if current.count == 0 {
            let node = &nodes[current.index as usize];
            let limit = R8::<I>::load(&t_limit[..]) * R8::<I>::splat(BOX_SLACK);
            let mut children = [(0u64, 0u32); WIDTH];
            let mut hit = 0;
            // The node's planes, as one ray's traversal computes them, then lane by lane.
            let mut planes = [[[0.0; WIDTH]; 3]; 2];
            for (side, planes) in planes.iter_mut().enumerate() {
                for (axis, planes) in planes.iter_mut().enumerate() {
                    node.planes::<I>(side, axis).store(planes);
                }
            }
            let mut used = node.used();
            while used != 0 {
                let slot = used.trailing_zeros() as usize;
                used &= used - 1;
                let mut t_enter = R8::<I>::splat(0.0);
                let mut t_exit = limit;
                for axis in 0..3 {
                    let negative = lanes.negative[axis] as usize;
                    let near = R8::<I>::splat(planes[negative][axis][slot]);
                    let far = R8::<I>::splat(planes[1 - negative][axis][slot]);
                    let t_near = (near - lanes.origin[axis]) * lanes.inverse[axis];
                    let t_far = (far - lanes.origin[axis]) * lanes.far_inverse[axis];
                    t_enter = t_near.max(t_enter);
                    t_exit = t_far.min(t_exit);
                }
                let entered_lanes = t_enter.le(t_exit);
                let any_ray = entered_lanes.bits();
                let entered = any_ray & current.rays;
                if entered != 0 {
                    // Usually every ray that enters the box is one of the current rays, and the
                    // nearest entry is one select and a tree of minimums; else lane by lane.
                    let nearest = if entered == any_ray {
                        min_lane::<I>(R8::<I>::select(entered_lanes, t_enter, R8::<I>::splat(Real::INFINITY)))
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
                    PacketPending { t, index: node.child[slot], count: node.count[slot] as u32, rays }
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
            let limit = R8::<I>::load(&t_limit[..]) * R8::<I>::splat(BOX_SLACK);
            let rays = R8::<I>::splat(pending.t).le(limit).bits() & pending.rays;
            if rays != 0 {
                current = PacketPending { rays, ..pending };
                break;
            }
        }
    }
}

/// The smallest lane (none being NaN), by a tree of minimums over the stored lanes.
#[inline(always)]
fn min_lane<I: Isa>(lanes: R8<I>) -> Real {
    let mut t = [0.0; PACKET];
    lanes.store(&mut t);
    let pairs = [t[0].min(t[4]), t[1].min(t[5]), t[2].min(t[6]), t[3].min(t[7])];
    pairs[0].min(pairs[2]).min(pairs[1].min(pairs[3]))
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
