//! The leaf tests the mesh's traversals run: packs of four triangles against one ray (nearest
//! hit, or any hit for shadow rays) and one triangle at a time against a packet of rays.

use super::super::bvh::{LeafVisitor, PACKET, PacketVisitor, Visit};
use super::super::real::{R8, Real};
use super::super::triangle::{PackRay, RayLanes, TrianglePack, intersect_pack, intersect_pack_pair, intersect_triangle_rays, lane_hit};
use super::{Mesh, MeshHit};
use crate::simd::{Isa, Lanes};

/// The leaf test of [`Mesh::intersect`]: each pack of the leaf, keeping the nearest hit (the
/// smaller triangle index among hits at the same `t`).
#[derive(Clone, Copy)]
pub(super) struct NearestTriangle<'a, I: Isa> {
    pub(super) mesh: &'a Mesh,
    pub(super) ray: PackRay<I>,
    pub(super) closest: Option<MeshHit>,
}

impl<I: Isa> LeafVisitor<I> for NearestTriangle<'_, I> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit {
        nearest_in_packs(self.mesh, first, count, &self.ray, t_limit, &mut self.closest);
        Visit::Continue
    }

    const LEAF_LINES: usize = PACK_LINES;

    #[inline(always)]
    fn leaf_data(&self, first: u32) -> *const u8 {
        pack_data(self.mesh, first)
    }
}

/// The most cache lines a pack spans from the line it starts in (three with `f32`).
const PACK_LINES: usize = (64 - align_of::<TrianglePack>() + size_of::<TrianglePack>()).div_ceil(64);

/// Where pack `first` lies, for asking for it from memory (computed without indexing: it is
/// never read through).
#[inline(always)]
fn pack_data(mesh: &Mesh, first: u32) -> *const u8 {
    mesh.packs.as_ptr().wrapping_add(first as usize).cast()
}

/// Asks for the cache lines of the packs `first..first + count`. A loop over the leaf's span,
/// not one ray's [`pack_data`] and [`PACK_LINES`]: with packets that form measured slower, for
/// fewer instructions (docs/speed.md).
#[inline(always)]
fn prefetch_packs<I: Isa>(mesh: &Mesh, first: u32, count: u32) {
    let packs = &mesh.packs[first as usize..(first + count) as usize];
    let (start, end) = (packs.as_ptr().cast::<u8>(), packs.as_ptr_range().end.cast::<u8>());
    let mut line = start.wrapping_sub(start as usize % 64);
    while line < end {
        I::prefetch(line);
        line = line.wrapping_add(64);
    }
}

/// Tests the packs `first..first + count` against one ray, keeping in `closest` the nearest
/// hit (the smaller triangle index among hits at the same `t`) and in `t_limit` its `t`.
#[inline(always)]
fn nearest_in_packs<I: Isa>(
    mesh: &Mesh,
    first: u32,
    count: u32,
    ray: &PackRay<I>,
    t_limit: &mut Real,
    closest: &mut Option<MeshHit>,
) {
    for pack in &mesh.packs[first as usize..(first + count) as usize] {
        let found = intersect_pack::<I>(pack, ray, *t_limit);
        let mut lanes = found.lanes;
        if lanes == 0 {
            continue;
        }
        let values = found.values::<4>();
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            if keep_nearer(&values, lane, pack.id(lane), closest) {
                *t_limit = values[0][lane];
            }
        }
    }
}

/// Keeps the hit in `lane` of `values` (on `triangle`) in `closest` when it is nearer than the
/// hit kept (the smaller triangle index among hits at the same `t`), and says whether it did:
/// the ray's limit is then the hit's `t`.
#[inline(always)]
fn keep_nearer<const N: usize>(values: &[[Real; N]; 5], lane: usize, triangle: u32, closest: &mut Option<MeshHit>) -> bool {
    let t = values[0][lane];
    let nearer = match closest {
        Some(best) => t < best.t || (t == best.t && triangle < best.triangle),
        None => true,
    };
    if nearer {
        let hit = lane_hit(values, lane);
        *closest = Some(MeshHit { t, triangle, barycentrics: [hit.b0, hit.b1, hit.b2] });
    }
    nearer
}

/// `limits` with lane `ray` set to `t`, in lanes (see [`PacketVisitor`]).
#[inline(always)]
fn with_limit<I: Isa>(limits: R8<I>, ray: usize, t: Real) -> R8<I> {
    R8::<I>::select(R8::<I>::mask(1 << ray), R8::<I>::splat(t), limits)
}

/// The leaf test of [`Mesh::occluded`]: stops at the first pack with a hit.
pub(super) struct AnyTriangle<'a, I: Isa> {
    pub(super) mesh: &'a Mesh,
    pub(super) ray: PackRay<I>,
    pub(super) found: bool,
}

impl<I: Isa> LeafVisitor<I> for AnyTriangle<'_, I> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit {
        for pack in &self.mesh.packs[first as usize..(first + count) as usize] {
            if intersect_pack::<I>(pack, &self.ray, *t_limit).lanes != 0 {
                self.found = true;
                return Visit::Stop;
            }
        }
        Visit::Continue
    }

    const LEAF_LINES: usize = PACK_LINES;

    #[inline(always)]
    fn leaf_data(&self, first: u32) -> *const u8 {
        pack_data(self.mesh, first)
    }
}

/// Up to this many rays at a leaf, [`NearestTriangles`] tests them two at a time (each pack
/// against a pair, [`intersect_pack_pair`]): cheaper than a test of all eight lanes per triangle.
const FEW_RAYS: u32 = 6;

/// The leaf test of [`Mesh::intersect_packet`]: each triangle of the leaf against the rays
/// that reached it, keeping each ray's nearest hit as [`NearestTriangle`] does.
pub(super) struct NearestTriangles<'a, I: Isa> {
    pub(super) mesh: &'a Mesh,
    pub(super) rays: RayLanes<I>,
    pub(super) closest: [Option<MeshHit>; PACKET],
}

impl<I: Isa> PacketVisitor<I> for NearestTriangles<'_, I> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, rays: u32, t_limit: &mut R8<I>) {
        // A leaf reached by few rays tests its packs against two of them at a time (four
        // triangles each), and a last one alone, rather than each triangle against all eight
        // lanes. Every test gives each ray the same hits, bit for bit.
        if rays.count_ones() <= FEW_RAYS {
            let mut remaining = rays;
            while remaining != 0 {
                let lane = remaining.trailing_zeros() as usize;
                remaining &= remaining - 1;
                if remaining == 0 {
                    let ray = self.rays.pack_ray(lane);
                    let mut limits = [0.0; PACKET];
                    t_limit.store(&mut limits);
                    let mut limit = limits[lane];
                    nearest_in_packs(self.mesh, first, count, &ray, &mut limit, &mut self.closest[lane]);
                    *t_limit = with_limit::<I>(*t_limit, lane, limit);
                    break;
                }
                let other = remaining.trailing_zeros() as usize;
                remaining &= remaining - 1;
                self.nearest_in_packs_pair(first, count, [lane, other], t_limit);
            }
            return;
        }
        for pack in &self.mesh.packs[first as usize..(first + count) as usize] {
            let mut live = pack.live();
            while live != 0 {
                let triangle = live.trailing_zeros() as usize;
                live &= live - 1;
                let found = intersect_triangle_rays::<I>(pack, triangle, &self.rays, *t_limit);
                let hits = found.lanes & rays;
                if hits == 0 {
                    continue;
                }
                let values = found.values::<8>();
                let id = pack.id(triangle);
                let mut lanes = hits;
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    keep_nearer(&values, lane, id, &mut self.closest[lane]);
                }
                // A lane per ray, each hit no farther than its ray's limit, which is its kept
                // hit's `t`: kept or tied, the ray's limit is now the hit's `t`.
                *t_limit = R8::<I>::select(R8::<I>::mask(hits), found.t(), *t_limit);
            }
        }
    }

    #[inline(always)]
    fn prefetch(&self, first: u32, count: u32) {
        prefetch_packs::<I>(self.mesh, first, count);
    }
}

impl<I: Isa> NearestTriangles<'_, I> {
    /// [`nearest_in_packs`] for the rays in lanes `pair[0]` and `pair[1]` at once, each pack
    /// tested against both ([`intersect_pack_pair`]), their hits kept ray by ray in lane order
    /// as the one-ray loop keeps them.
    #[inline(always)]
    fn nearest_in_packs_pair(&mut self, first: u32, count: u32, pair: [usize; 2], t_limit: &mut R8<I>) {
        for pack in &self.mesh.packs[first as usize..(first + count) as usize] {
            let found = intersect_pack_pair::<I>(pack, &self.rays, pair, *t_limit);
            let mut lanes = found.lanes;
            if lanes == 0 {
                continue;
            }
            let values = found.values::<8>();
            while lanes != 0 {
                let lane = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let ray = pair[lane / 4];
                if keep_nearer(&values, lane, pack.id(lane % 4), &mut self.closest[ray]) {
                    *t_limit = with_limit::<I>(*t_limit, ray, values[0][lane]);
                }
            }
        }
    }
}
