//! A handful of boxes tested at once without a tree.

use super::super::Ray;
use super::super::aabb::Aabb;
use super::super::real::{Real, Vec3};
use crate::simd::{Isa, Lanes};
use super::*;
use super::super::real::R8;
use super::traverse::{LaneBoxes, SlabLanes, node_hits, sort_key};

/// Up to eight boxes side by side, tested at once with the traversal's slab test: a handful of
/// objects that need no tree.
#[derive(Clone, Debug)]
pub struct BoxSet {
    /// `bounds[0]` holds the boxes' minimum corners, `bounds[1]` their maximum ones, by axis and
    /// then lane; unused lanes hold the empty box, which no ray enters.
    bounds: [[[Real; WIDTH]; 3]; 2],
    len: usize,
}

impl LaneBoxes for BoxSet {
    #[inline(always)]
    fn planes<I: Isa>(&self, side: usize, axis: usize) -> R8<I> {
        R8::<I>::load(&self.bounds[side][axis])
    }

    #[inline(always)]
    fn used(&self) -> u32 {
        u32::MAX
    }
}

impl BoxSet {
    /// # Panics
    /// With more than [`WIDTH`] boxes.
    pub fn new(bounds: &[Aabb]) -> BoxSet {
        assert!(bounds.len() <= WIDTH, "a box set holds at most {WIDTH} boxes");
        let mut set = BoxSet {
            bounds: [[[Real::INFINITY; WIDTH]; 3], [[Real::NEG_INFINITY; WIDTH]; 3]],
            len: bounds.len(),
        };
        for (lane, bounds) in bounds.iter().enumerate() {
            for axis in 0..3 {
                set.bounds[0][axis][lane] = bounds.min[axis];
                set.bounds[1][axis][lane] = bounds.max[axis];
            }
        }
        set
    }

    /// The boxes, in the order they were given.
    pub fn boxes(&self) -> impl Iterator<Item = Aabb> + '_ {
        (0..self.len).map(|lane| {
            let corner = |side: usize| Vec3::new(self.bounds[side][0][lane], self.bounds[side][1][lane], self.bounds[side][2][lane]);
            Aabb { min: corner(0), max: corner(1) }
        })
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
        let (t_enter, hits) = node_hits::<I>(self, &SlabLanes::<I>::new(ray), t_limit);
        t_enter.store(&mut t);
        (hits, t)
    }

    /// The boxes of `hits` (from [`BoxSet::entered`]) nearest first, in the low bits of keys
    /// that sort by entry distance: the first of `keys`, one a box. Sorted in the caller's
    /// array and read there: an array returned is copied, eight lanes at a time, from keys just
    /// written one by one, which waits for those writes to reach the cache.
    #[inline(always)]
    pub fn nearest_first<'k>(hits: u32, t: &[Real; WIDTH], keys: &'k mut [u64; WIDTH]) -> &'k [u64] {
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
        &keys[..count]
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

