//! The 8-wide tree's node: its children's boxes quantised to a byte per plane, rounded outward.
//!
//! Each axis of a node has an origin and a scale, a power of two, and each child's plane is
//! `origin + q·scale` for a byte `q`, computed as the traversal computes it: `q·scale` is exact
//! (a power of two times a byte, never overflowing: see `quantise_axis`), so the addition is the
//! only rounding, whether a path fuses the two (x86's multiply-add) or not, and every SIMD path
//! gets the same plane. The
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
    /// Levels of nodes in the subtree this node heads, itself included (1 when every child is
    /// a leaf): the root's sizes a traversal's stack (see `traverse::StackSpace`).
    pub(super) height: u8,
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
            height: 1,
        };
        for (lane, child) in children.iter().enumerate() {
            node.child[lane] = child.index;
            node.count[lane] = u8::try_from(child.count).expect("a leaf holds at most 255 entries");
            if !child.bounds.is_empty() {
                node.used |= 1 << lane;
            }
        }
        if node.used == 0 {
            return node;
        }
        // By axis and lane; unused lanes copy a used one's bounds: their codes are never read.
        let first_used = &children[node.used.trailing_zeros() as usize];
        let (mut min, mut max) = ([[0.0; WIDTH]; 3], [[0.0; WIDTH]; 3]);
        for lane in 0..WIDTH {
            let source = if node.used >> lane & 1 != 0 { &children[lane] } else { first_used };
            let (low, high) = (source.bounds.min.to_array(), source.bounds.max.to_array());
            for axis in 0..3 {
                (min[axis][lane], max[axis][lane]) = (low[axis], high[axis]);
            }
        }
        for (axis, (min, max)) in min.iter().zip(&max).enumerate() {
            match quantise_axis(min, max) {
                Some((origin, scale, lower, upper)) => {
                    node.origin[axis] = origin;
                    node.scale[axis] = scale;
                    (node.planes[0][axis], node.planes[1][axis]) = (lower, upper);
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
        // conversion; then `plane`'s one rounding (its product is exact).
        let bytes = &self.planes[side][axis];
        let mut codes = [0.0; WIDTH];
        for lane in 0..WIDTH {
            codes[lane] = bytes[lane] as Real;
        }
        R8::<I>::load(&codes).mul_add_exact(R8::<I>::splat(self.scale[axis]), R8::<I>::splat(self.origin[axis]))
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

/// The plane of `code`, rounded exactly as [`BvhNode::planes`] rounds it: once, in the addition,
/// since `quantise_axis` only chooses scales whose products with a byte are exact.
#[inline]
fn plane(origin: Real, scale: Real, code: u8) -> Real {
    code as Real * scale + origin
}

/// The origin, the scale and each lane's lower and upper codes on one axis, given the lanes'
/// `min` and `max` on it, with every lower plane at or below its bound and every upper plane at
/// or above; `None` when the axis cannot be quantised (see the module's doc). Lane by lane
/// without branches, so that it runs on all lanes at once: the build quantises every node.
#[allow(clippy::type_complexity)]
fn quantise_axis(min: &[Real; WIDTH], max: &[Real; WIDTH]) -> Option<(Real, Real, [u8; WIDTH], [u8; WIDTH])> {
    let low = min.iter().copied().fold(Real::INFINITY, Real::min);
    let high = max.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    let extent = high - low;
    if !(low.is_finite() && high.is_finite() && extent.is_finite()) {
        return None;
    }
    // The smallest power of two with 255 steps covering the extent (at least the smallest
    // subnormal, a power of two, when the division underflows); twice that when the rounding of
    // the planes leaves an upper bound uncovered, and none when 255 steps would overflow. A
    // power of two at or above the smallest subnormal times a byte is then exact, so a plane
    // rounds once however a path computes it (see `plane`).
    let mut scale = if extent > 0.0 { smallest_power_of_two_at_least(extent / TOP).max(Real::from_bits(1)) } else { 0.0 };
    while (scale * TOP).is_finite() {
        let (mut lower, mut upper) = ([0; WIDTH], [0; WIDTH]);
        for lane in 0..WIDTH {
            // The truncated quotient, one lower if the plane's rounding put it above; code 0
            // (the origin's plane, at or below every bound) if even that is above.
            let code = estimate(low, scale, min[lane]);
            let code = code - (plane(low, scale, code) > min[lane]) as u8;
            lower[lane] = if plane(low, scale, code) > min[lane] { 0 } else { code };
            // The truncated quotient, one higher if its plane is below.
            let code = estimate(low, scale, max[lane]);
            upper[lane] = code.saturating_add((plane(low, scale, code) < max[lane]) as u8);
        }
        if (0..WIDTH).all(|lane| plane(low, scale, upper[lane]) >= max[lane]) {
            return Some((low, scale, lower, upper));
        }
        scale *= 2.0;
    }
    None
}

/// About `(bound − origin) / scale`, truncated and clamped to a code (an `as` conversion, not
/// `floor`, which baseline x86-64 calls a library function for).
#[inline]
fn estimate(origin: Real, scale: Real, bound: Real) -> u8 {
    // Never negative (the origin is the lowest bound); `as` saturates at 255 and takes NaN to 0.
    if scale > 0.0 { ((bound - origin) / scale) as u8 } else { 0 }
}

/// The smallest power of two at or above a positive finite `x`, by its bits: a mantissa that is
/// not zero is rounded up into the exponent (a subnormal `x` gives the smallest normal power,
/// still at or above it; an `x` beyond the largest power gives infinity).
fn smallest_power_of_two_at_least(x: Real) -> Real {
    let mantissa = (1 << (Real::MANTISSA_DIGITS - 1)) - 1;
    Real::from_bits((x.to_bits() + mantissa) & !mantissa)
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
            -1e-37 as Real..1e-37 as Real,
            (1e6 as Real..1e7 as Real),
            // Extents whose 255 steps would overflow a power of two's scale.
            (1e36 as Real..1e38 as Real),
            (-1e38 as Real..-1e36 as Real),
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

    /// A node's planes as the traversal decodes them on `I`'s path, by side, axis and lane.
    struct DecodedPlanes<'a>(&'a BvhNode);

    impl crate::simd::Kernel for DecodedPlanes<'_> {
        type Output = [[[Real; WIDTH]; 3]; 2];
        fn run<I: Isa>(self) -> Self::Output {
            let mut planes = [[[0.0; WIDTH]; 3]; 2];
            for (side, planes) in planes.iter_mut().enumerate() {
                for (axis, planes) in planes.iter_mut().enumerate() {
                    self.0.planes::<I>(side, axis).store(planes);
                }
            }
            planes
        }
    }

    proptest! {
        /// The traversal's planes are the ones the build checked against the exact bounds
        /// (`plane`, through `child_bounds`), bit for bit on every SIMD path, whether the path
        /// fuses the multiplication and the addition or not.
        #[test]
        fn decoded_planes_are_the_checked_ones_on_every_path(boxes in prop::collection::vec(aabb(), 1..=WIDTH)) {
            let children: Vec<Child> = boxes.iter().map(|&bounds| Child { bounds, index: 0, count: 1 }).collect();
            let node = BvhNode::new(&children);
            let checked: Vec<Aabb> = (0..boxes.len()).map(|lane| node.child_bounds(lane)).collect();
            for path in crate::simd::available() {
                let decoded = crate::simd::dispatch_on(path, DecodedPlanes(&node)).unwrap();
                for (side, planes) in decoded.iter().enumerate() {
                    for (axis, lanes) in planes.iter().enumerate() {
                        for (lane, (plane, bounds)) in lanes.iter().zip(&checked).enumerate() {
                            let expected = if side == 0 { bounds.min[axis] } else { bounds.max[axis] };
                            prop_assert_eq!(plane.to_bits(), expected.to_bits(), "{:?} side {} axis {} lane {}", path, side, axis, lane);
                        }
                    }
                }
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
