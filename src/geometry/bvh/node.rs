//! The 8-wide tree's node: its children's boxes quantised to a byte per plane, rounded outward.
//!
//! Each axis of a node has an origin and a scale, a power of two, and each child's plane is
//! `origin + q·scale` for a byte `q`, computed as the traversal computes it (an `as` conversion, a
//! multiplication and an addition, each rounded once and identically on every SIMD path). The
//! build chooses every `q` by computing that very expression and checking it against the exact
//! bound, so each stored box contains its child's exact box: a ray that enters the exact box
//! enters the stored one, no sooner. Traversal then tests the stored boxes with the unchanged
//! conservative slab test, so it visits every box the exact tree would (and a few more): the
//! closest hit, ties broken by the fixed rule of the leaf tests, is the same. This halves the node
//! (128 bytes with `f32` instead of 256) and the memory a ray waits for, as Embree's and CWBVH's
//! compressed nodes do.
//!
//! An axis whose boxes cannot be quantised (an infinite or non-finite bound, or an extent that
//! overflows) gets a NaN origin: every plane is NaN and the slab test's `max`/`min`, which keep
//! their second operand for a NaN, let that axis constrain nothing, still conservatively.

use super::super::aabb::Aabb;
use super::super::real::{R8, Real};
use super::WIDTH;
use crate::simd::{Isa, Lanes};

/// Largest plane code: planes are bytes.
const TOP: Real = u8::MAX as Real;

/// One node of the 8-wide tree: the quantised boxes of its (up to eight) children side by side,
/// one lane per child, so that one slab test covers all eight. 128 bytes with `f32`, two cache
/// lines on one 128-byte boundary (which the processor's adjacent-line prefetcher fetches
/// together).
///
/// A child is either another node or a leaf, a run of primitives stored in the node itself.
/// Unused slots are not in `used`, and no ray enters them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(128))]
pub struct BvhNode {
    /// `planes[0]` holds the codes of the children's minimum corners, `planes[1]` their maximum
    /// ones, by axis and then lane.
    planes: [[[u8; WIDTH]; 3]; 2],
    /// Per axis: the plane of code 0 (NaN for an axis that is not quantised).
    origin: [Real; 3],
    /// Per axis: the distance between consecutive codes, a power of two or zero.
    scale: [Real; 3],
    /// Interior child: its node's index. Leaf: the index of its first entry in the primitive order.
    pub(super) child: [u32; WIDTH],
    /// Leaf: its number of entries (at least one). Zero for an interior child or unused slot.
    pub(super) count: [u8; WIDTH],
    /// A bit per slot that holds a child whose box is not empty.
    used: u8,
}

/// A child as the collapse hands it to [`BvhNode::new`]: its exact box, its node or first
/// entry, and its entry count (zero for a node).
#[derive(Clone, Copy, Debug)]
pub(super) struct Child {
    pub bounds: Aabb,
    pub index: u32,
    pub count: u32,
}

impl BvhNode {
    /// Quantises the children's boxes outward (see the module's doc).
    ///
    /// # Panics
    /// With more than [`WIDTH`] children, or a leaf of more than 255 entries (leaves hold at
    /// most four primitives).
    pub(super) fn new(children: &[Child]) -> BvhNode {
        assert!(children.len() <= WIDTH, "a node has at most {WIDTH} children");
        let mut node = BvhNode {
            planes: [[[u8::MAX; WIDTH]; 3], [[0; WIDTH]; 3]],
            origin: [0.0; 3],
            scale: [0.0; 3],
            child: [0; WIDTH],
            count: [0; WIDTH],
            used: 0,
        };
        for (lane, child) in children.iter().enumerate() {
            node.child[lane] = child.index;
            node.count[lane] = u8::try_from(child.count).expect("a leaf holds at most 255 entries");
            if !child.bounds.is_empty() {
                node.used |= 1 << lane;
            }
        }
        for axis in 0..3 {
            let mut bounds = [(0.0, 0.0); WIDTH];
            let mut len = 0;
            for (lane, child) in children.iter().enumerate() {
                if node.used >> lane & 1 != 0 {
                    bounds[len] = (child.bounds.min[axis], child.bounds.max[axis]);
                    len += 1;
                }
            }
            match quantise_axis(&bounds[..len]) {
                Some((origin, scale, codes)) => {
                    node.origin[axis] = origin;
                    node.scale[axis] = scale;
                    let mut code = codes.iter();
                    for lane in 0..children.len() {
                        if node.used >> lane & 1 != 0 {
                            let &(lower, upper) = code.next().expect("a code per used lane");
                            node.planes[0][axis][lane] = lower;
                            node.planes[1][axis][lane] = upper;
                        }
                    }
                }
                None => node.origin[axis] = Real::NAN,
            }
        }
        node
    }

    /// The lanes' planes on `axis`: the minimum corners' when `side` is 0, the maximum ones' when 1.
    #[inline(always)]
    pub(super) fn planes<I: Isa>(&self, side: usize, axis: usize) -> R8<I> {
        // Widened lane by lane into an array the compiler turns into one zero-extension and one
        // conversion; then the same two roundings as `plane`.
        let bytes = &self.planes[side][axis];
        let mut codes = [0.0; WIDTH];
        for lane in 0..WIDTH {
            codes[lane] = bytes[lane] as Real;
        }
        R8::<I>::load(&codes) * R8::<I>::splat(self.scale[axis]) + R8::<I>::splat(self.origin[axis])
    }

    /// A bit per slot holding a child whose box is not empty.
    #[inline(always)]
    pub(super) fn used(&self) -> u32 {
        self.used as u32
    }

    /// The box the traversal tests for the child in `lane` (contains the child's exact box).
    pub fn child_bounds(&self, lane: usize) -> Aabb {
        let mut bounds = Aabb::EMPTY;
        if self.used >> lane & 1 != 0 {
            for axis in 0..3 {
                bounds.min[axis] = plane(self.origin[axis], self.scale[axis], self.planes[0][axis][lane]);
                bounds.max[axis] = plane(self.origin[axis], self.scale[axis], self.planes[1][axis][lane]);
            }
        }
        bounds
    }

    /// Number of leaves among the children.
    pub(super) fn leaf_count(&self) -> usize {
        self.count.iter().filter(|&&count| count > 0).count()
    }
}

/// The plane of `code`, rounded exactly as [`BvhNode::planes`] rounds it.
#[inline]
fn plane(origin: Real, scale: Real, code: u8) -> Real {
    code as Real * scale + origin
}

/// The origin, the scale and each child's `(lower, upper)` codes on one axis, given the
/// children's `(min, max)` on it, with every lower plane at or below its bound and every upper
/// plane at or above; `None` when the axis cannot be quantised (see the module's doc).
fn quantise_axis(bounds: &[(Real, Real)]) -> Option<(Real, Real, [(u8, u8); WIDTH])> {
    let low = bounds.iter().map(|b| b.0).fold(Real::INFINITY, Real::min);
    let high = bounds.iter().map(|b| b.1).fold(Real::NEG_INFINITY, Real::max);
    let extent = high - low;
    if !(low.is_finite() && high.is_finite() && extent.is_finite()) {
        return None;
    }
    // The smallest power of two with 255 steps covering the extent; twice that when the
    // rounding of the planes leaves an upper bound uncovered.
    let mut scale = if extent > 0.0 { smallest_power_of_two_at_least(extent / TOP) } else { 0.0 };
    'scales: loop {
        let mut codes = [(0, 0); WIDTH];
        for (code, &(min, max)) in codes.iter_mut().zip(bounds) {
            let Some(upper) = upper_code(low, scale, max) else {
                if !(scale * 2.0).is_finite() {
                    return None;
                }
                scale *= 2.0;
                continue 'scales;
            };
            *code = (lower_code(low, scale, min), upper);
        }
        return Some((low, scale, codes));
    }
}

/// The largest code whose plane is at or below `bound` (code 0's plane is the origin, at or
/// below every bound).
fn lower_code(origin: Real, scale: Real, bound: Real) -> u8 {
    let mut code = if scale > 0.0 { ((bound - origin) / scale).floor().clamp(0.0, TOP) as u8 } else { 0 };
    while code > 0 && plane(origin, scale, code) > bound {
        code -= 1;
    }
    while code < u8::MAX && plane(origin, scale, code + 1) <= bound {
        code += 1;
    }
    code
}

/// The smallest code whose plane is at or above `bound`; `None` if even 255's is below.
fn upper_code(origin: Real, scale: Real, bound: Real) -> Option<u8> {
    let mut code = if scale > 0.0 { ((bound - origin) / scale).ceil().clamp(0.0, TOP) as u8 } else { 0 };
    while code < u8::MAX && plane(origin, scale, code) < bound {
        code += 1;
    }
    while code > 0 && plane(origin, scale, code - 1) >= bound {
        code -= 1;
    }
    (plane(origin, scale, code) >= bound).then_some(code)
}

/// The smallest power of two at or above a positive finite `x` (the largest finite power of
/// two if none is finite).
fn smallest_power_of_two_at_least(x: Real) -> Real {
    let mut power = x.log2().ceil().exp2();
    if !power.is_finite() || power == 0.0 {
        power = if x > 1.0 { Real::MAX.log2().floor().exp2() } else { Real::MIN_POSITIVE };
    }
    while power < x && (power * 2.0).is_finite() {
        power *= 2.0;
    }
    while power / 2.0 >= x {
        power /= 2.0;
    }
    power
}

#[cfg(test)]
mod tests {
    use super::super::super::real::Vec3;
    use super::*;
    use proptest::prelude::*;

    fn coordinate() -> impl Strategy<Value = Real> {
        prop_oneof![
            -1e3 as Real..1e3 as Real,
            -1e-3 as Real..1e-3 as Real,
            (1e6 as Real..1e7 as Real),
            Just(0.0 as Real),
        ]
    }

    fn aabb() -> impl Strategy<Value = Aabb> {
        prop::array::uniform6(coordinate()).prop_map(|c| {
            let (a, b) = (Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5]));
            Aabb::new(a.min(b), a.max(b))
        })
    }

    fn contains(outer: &Aabb, inner: &Aabb) -> bool {
        outer.min.cmple(inner.min).all() && inner.max.cmple(outer.max).all()
    }

    proptest! {
        /// The property the traversal's exactness rests on: each stored box holds its child's
        /// exact box, whatever their sizes and distances (tiny boxes beside huge ones, offsets
        /// far from the origin, flat boxes).
        #[test]
        fn quantised_boxes_contain_the_exact_ones(boxes in prop::collection::vec(aabb(), 1..=WIDTH)) {
            let children: Vec<Child> = boxes.iter().map(|&bounds| Child { bounds, index: 0, count: 1 }).collect();
            let node = BvhNode::new(&children);
            for (lane, exact) in boxes.iter().enumerate() {
                let stored = node.child_bounds(lane);
                prop_assert!(contains(&stored, exact), "lane {lane}: {stored:?} does not contain {exact:?}");
            }
        }
    }

    #[test]
    fn quantised_boxes_are_tight() {
        // A byte per plane: each stored plane within two steps (of 1/255 of the node's extent,
        // rounded up to a power of two) of the exact one.
        let boxes = [
            Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 3.0)),
            Aabb::new(Vec3::new(0.3, 0.7, 1.1), Vec3::new(0.4, 0.9, 1.3)),
        ];
        let children: Vec<Child> = boxes.iter().map(|&bounds| Child { bounds, index: 0, count: 1 }).collect();
        let node = BvhNode::new(&children);
        let step = Vec3::new(1.0, 2.0, 3.0) / 255.0 * 4.0;
        let stored = node.child_bounds(1);
        assert!((stored.min - boxes[1].min).cmple(step).all() && (boxes[1].max - stored.max).cmpge(-step).all());
        assert!((stored.max - boxes[1].max).cmple(step).all(), "{stored:?}");
    }

    #[test]
    fn empty_and_unbounded_children() {
        let finite = Aabb::new(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0));
        let unbounded = Aabb::new(Vec3::new(Real::NEG_INFINITY, 0.0, 0.0), Vec3::new(0.0, 1.0, 1.0));
        let children = [finite, Aabb::EMPTY, unbounded].map(|bounds| Child { bounds, index: 0, count: 1 });
        let node = BvhNode::new(&children);
        assert_eq!(node.used(), 0b101, "the empty box is never entered");
        // x cannot be quantised: NaN planes, which the slab test reads as unbounded.
        assert!(node.child_bounds(0).min.x.is_nan() && node.child_bounds(2).max.x.is_nan());
        let stored = node.child_bounds(0);
        assert_eq!((stored.min.y, stored.max.y, stored.min.z, stored.max.z), (-1.0, 1.0, -1.0, 1.0));
    }
}
