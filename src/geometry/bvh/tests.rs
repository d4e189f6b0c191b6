use super::*;
use super::super::real::Vec3;
use crate::simd::Lanes;

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
fn node_is_two_cache_lines_with_f32() {
    if size_of::<Real>() == 4 {
        assert_eq!((size_of::<BvhNode>(), align_of::<BvhNode>()), (128, 128));
    }
}

#[test]
fn wide_nodes_have_two_to_eight_children_and_keep_every_leaf() {
    let points: Vec<Vec3> = (0..2000)
        .map(|i| Vec3::new((i * 37 % 101) as Real, (i * 11 % 13) as Real, (i % 7) as Real))
        .collect();
    let boxes = point_boxes(&points);
    let (binary, _) = build::build(boxes.len(), |index| boxes[index], LeafCost::PerPrimitive);
    let bvh = Bvh::build(&boxes);
    let reached = reachable(&binary);
    let binary_leaves = reached.iter().filter(|&&index| binary[index].is_leaf()).count();
    assert_eq!(bvh.leaf_count(), binary_leaves);
    for node in &bvh.nodes {
        let used = node.used().count_ones() as usize;
        assert!((2..=WIDTH).contains(&used), "{used} children");
        assert!(node.count.iter().all(|&count| count <= 4));
    }
    assert!(bvh.node_count() * 2 < reached.len(), "{} wide nodes for {} binary ones", bvh.node_count(), reached.len());
}

#[test]
fn subtrees_laid_out_in_parallel_make_the_same_wide_tree() {
    let points: Vec<Vec3> = (0..20_000)
        .map(|i| Vec3::new((i * 37 % 1009) as Real, (i * 11 % 131) as Real, (i * 5 % 17) as Real))
        .collect();
    let boxes = point_boxes(&points);
    let (binary, _) = build::build(boxes.len(), |index| boxes[index], LeafCost::PerPackOfFour);
    let serial = collapse::collapse_in_parallel_to(&binary, 0);
    assert!(serial.len() > 100, "{} wide nodes", serial.len());
    for depth in 1..=3 {
        assert!(collapse::collapse_in_parallel_to(&binary, depth) == serial, "pieces from depth {depth}");
    }
}

/// The binary nodes reachable from the root, depth first.
fn reachable(binary: &[build::BinaryNode]) -> Vec<usize> {
    let (mut reached, mut stack) = (Vec::new(), vec![0]);
    while let Some(index) = stack.pop() {
        reached.push(index);
        if !binary[index].is_leaf() {
            stack.extend([binary[index].offset as usize, index + 1]);
        }
    }
    reached
}

#[test]
fn slotted_binary_tree_holds_every_primitive_once_and_bounds_its_children() {
    // Large enough that the first levels are split among threads.
    let points: Vec<Vec3> = (0..3 * build::PARALLEL_THRESHOLD)
        .map(|i| Vec3::new((i * 37 % 1009) as Real, (i * 11 % 131) as Real, (i % 7) as Real))
        .collect();
    let boxes = point_boxes(&points);
    let (binary, order) = build::build(boxes.len(), |index| boxes[index], LeafCost::PerPackOfFour);
    assert_eq!(binary.len(), 2 * boxes.len() - 1, "a slot for every node the tree could have");
    let reached = reachable(&binary);
    let mut covered = vec![false; boxes.len()];
    for &index in &reached {
        let node = &binary[index];
        if node.is_leaf() {
            let first = node.offset as usize;
            for slot in &mut covered[first..first + node.prim_count as usize] {
                assert!(!*slot, "two leaves hold primitive {first}");
                *slot = true;
            }
        } else {
            let (first, second) = (&binary[index + 1], &binary[node.offset as usize]);
            assert_eq!(first.bounds.union(second.bounds), node.bounds, "node {index} bounds its children");
        }
    }
    assert!(covered.iter().all(|&c| c), "the leaves hold every primitive");
    let unreached = binary.len() - reached.len();
    assert!(unreached > 0 && reached.len() >= boxes.len() / 2, "{} nodes reached", reached.len());
    let mut sorted = order;
    sorted.sort_unstable();
    assert!(sorted.iter().enumerate().all(|(i, &p)| p == i as u32), "the order is a permutation");
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
        .map(u32::from)
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

/// Records each leaf a traversal reaches with the limit it was reached under, and shrinks the
/// limit as a closest-hit test would (to a distance made from the leaf), so that pruning by
/// the limit takes part; stops at the `stop_at`-th leaf.
#[derive(Clone)]
struct LeafLog {
    calls: Vec<(u32, u32, Real)>,
    stop_at: usize,
}

impl<I: Isa> LeafVisitor<I> for LeafLog {
    fn leaf(&mut self, first: u32, count: u32, t_limit: &mut Real) -> Visit {
        self.calls.push((first, count, *t_limit));
        *t_limit = t_limit.min(100.0 - (first % 17) as Real);
        if self.calls.len() == self.stop_at { Visit::Stop } else { Visit::Continue }
    }
}

/// Runs [`traverse`] for each ray alone and [`traverse_interleaved`] for them together.
struct BothWays<'a> {
    nodes: &'a [BvhNode],
    rays: &'a [Ray],
    t_max: [Real; PACKET],
    stop_at: usize,
}

impl Kernel for BothWays<'_> {
    type Output = (Vec<LeafLog>, Vec<LeafLog>);
    fn run<I: Isa>(self) -> Self::Output {
        let fresh = LeafLog { calls: Vec::new(), stop_at: self.stop_at };
        let mut alone = vec![fresh.clone(); self.rays.len()];
        for ((ray, log), &t_max) in self.rays.iter().zip(&mut alone).zip(&self.t_max) {
            traverse::<I>(self.nodes, ray, t_max, log);
        }
        let mut together = vec![fresh; self.rays.len()];
        traverse_interleaved::<I, _>(self.nodes, self.rays, &self.t_max, &mut together);
        (alone, together)
    }
}

/// 3,000 boxes of side 3 spread over a 101×53×29 block, overlapping one another, so that a ray
/// through the block reaches many leaves: the traversal tests' scene, as each box's lowest
/// corner and the tree.
fn overlapping_boxes() -> (Vec<Vec3>, Bvh) {
    let points: Vec<Vec3> = (0..3000)
        .map(|i| Vec3::new((i * 37 % 101) as Real, (i * 11 % 53) as Real, (i * 7 % 29) as Real))
        .collect();
    let boxes: Vec<Aabb> = points.iter().map(|&p| Aabb::new(p, p + Vec3::splat(3.0))).collect();
    let bvh = Bvh::build(&boxes);
    (points, bvh)
}

#[test]
fn interleaved_rays_each_visit_what_they_visit_alone() {
    let (_, bvh) = overlapping_boxes();
    // Rays from all over, in every direction, one starting inside, one along an axis, one
    // not finite (which visits nothing), and one whose limit ends before the boxes start.
    let mut rays: Vec<Ray> = (0..7)
        .map(|k| {
            let k = k as Real;
            let origin = Vec3::new(50.0 + 80.0 * (k * 1.3).sin(), 25.0 + 60.0 * (k * 0.7).cos(), -40.0 + 20.0 * k);
            let target = Vec3::new(10.0 * k, 50.0 - 6.0 * k, 14.0);
            Ray::new(origin, (target - origin).normalize())
        })
        .collect();
    rays[3] = Ray::new(Vec3::new(50.0, 26.0, 14.0), Vec3::new(0.0, 0.0, -1.0));
    rays.push(Ray::new(Vec3::new(Real::NAN, 0.0, 0.0), Vec3::X));
    let mut t_max = [Real::INFINITY; PACKET];
    t_max[5] = 1e-3;
    for path in crate::simd::available() {
        for stop_at in [usize::MAX, 3] {
            for count in [rays.len(), 5, 1] {
                let rays = &rays[..count];
                let (alone, together) =
                    crate::simd::dispatch_on(path, BothWays { nodes: bvh.nodes(), rays, t_max, stop_at }).unwrap();
                if count > 2 {
                    let reached = alone[2].calls.len();
                    assert!(reached == stop_at || (stop_at > 3 && reached > 10), "{path:?}: ray 2 reached {reached} leaves");
                }
                for (k, (alone, together)) in alone.iter().zip(&together).enumerate() {
                    assert_eq!(alone.calls, together.calls, "{path:?}, ray {k} of {count}, stop at {stop_at}");
                }
            }
        }
    }
}

/// The leaves a packet traversal reaches, by ray: `(lane, first, count)`.
struct PacketLog(Vec<(usize, u32, u32)>);

impl<I: Isa> PacketVisitor<I> for PacketLog {
    fn leaf(&mut self, first: u32, count: u32, rays: u32, _t_limit: &mut R8<I>) {
        for lane in 0..PACKET {
            if rays >> lane & 1 != 0 {
                self.0.push((lane, first, count));
            }
        }
    }
}

/// Runs [`traverse`] for each ray alone and [`traverse_packet`] for them together.
struct AloneAndPacket<'a> {
    nodes: &'a [BvhNode],
    rays: &'a [Ray],
    t_max: [Real; PACKET],
}

impl Kernel for AloneAndPacket<'_> {
    /// Each ray's leaves alone, `(first, count)`, and the packet's.
    type Output = (Vec<Vec<(u32, u32)>>, PacketLog);
    fn run<I: Isa>(self) -> Self::Output {
        let mut alone = vec![Vec::new(); self.rays.len()];
        for ((ray, leaves), &t_max) in self.rays.iter().zip(&mut alone).zip(&self.t_max) {
            let mut limit_kept = VisitFn(|first, count, _: &mut Real| {
                leaves.push((first, count));
                Visit::Continue
            });
            traverse::<I>(self.nodes, ray, t_max, &mut limit_kept);
        }
        let lanes = PacketLanes::<I>::new(self.rays).expect("rays that make a packet");
        let mut packet = PacketLog(Vec::new());
        traverse_packet::<I>(self.nodes, &lanes, (1 << self.rays.len()) - 1, &self.t_max, &mut packet);
        (alone, packet)
    }
}

/// A packet of rays through a tile of 4×2 points around `aim`, `step` apart, from `origin`
/// moved by `spread` times each point's offset (0: camera rays from one point).
fn tile(origin: Vec3, spread: Real, aim: Vec3, step: Real) -> Vec<Ray> {
    (0..PACKET)
        .map(|k| {
            let offset = Vec3::new((k % 4) as Real, (k / 4) as Real, 0.0) * step;
            Ray::new(origin + offset * spread, (aim + offset - origin).normalize())
        })
        .collect()
}

#[test]
fn a_packet_reaches_every_leaf_its_rays_reach_alone() {
    let (points, bvh) = overlapping_boxes();
    // Tiles of camera rays from one point, among them one from exactly a box's corner and one
    // whose rays start inside the boxes; then rays from eight points and a tile with a direction
    // component of zero.
    let mut packets = vec![
        tile(Vec3::new(50.0, 26.0, -60.0), 0.0, Vec3::new(40.0, 20.0, 10.0), 0.7),
        tile(Vec3::new(-30.0, -20.0, 80.0), 0.0, Vec3::new(60.0, 30.0, 10.0), 2.5),
        tile(points[17], 0.0, Vec3::new(0.0, 0.0, 0.0), 1.0),
        tile(Vec3::new(50.0, 26.0, 14.0), 0.0, Vec3::new(90.0, 40.0, 20.0), 0.2),
    ];
    let scattered: Vec<Ray> = (0..PACKET)
        .map(|k| Ray::new(Vec3::new(k as Real, -10.0, -10.0), Vec3::new(1.0, 0.6, 0.3).normalize()))
        .collect();
    packets.push(scattered);
    packets.push(tile(Vec3::new(20.0, 20.0, -50.0), 0.0, Vec3::new(20.0, 20.0, 10.0), 0.0));
    let mut t_max = [Real::INFINITY; PACKET];
    t_max[3] = 40.0;
    for path in crate::simd::available() {
        for rays in &packets {
            let (alone, packet) =
                crate::simd::dispatch_on(path, AloneAndPacket { nodes: bvh.nodes(), rays, t_max }).unwrap();
            let reached: usize = alone.iter().map(Vec::len).sum();
            assert!(reached > 2 * PACKET, "{path:?}: the rays reach {reached} leaves alone");
            for (lane, alone) in alone.iter().enumerate() {
                for &(first, count) in alone {
                    assert!(
                        packet.0.contains(&(lane, first, count)),
                        "{path:?}: ray {lane} reaches leaf {first} alone, not in its packet"
                    );
                }
            }
        }
    }
}

/// Every primitive's leaf `(first, count)` as each traversal reaches them: one ray alone, the
/// rays interleaved, and the rays as a packet.
struct EveryTraversal<'a> {
    nodes: &'a [BvhNode],
    rays: &'a [Ray],
}

impl Kernel for EveryTraversal<'_> {
    type Output = [Vec<(u32, u32)>; 3];
    fn run<I: Isa>(self) -> Self::Output {
        let mut alone = Vec::new();
        let mut visit = VisitFn(|first, count, _: &mut Real| {
            alone.push((first, count));
            Visit::Continue
        });
        traverse::<I>(self.nodes, &self.rays[0], Real::INFINITY, &mut visit);
        let mut logs = vec![Vec::new(); self.rays.len()];
        let mut visitors: Vec<_> = logs
            .iter_mut()
            .map(|log| {
                VisitFn(move |first, count, _: &mut Real| {
                    log.push((first, count));
                    Visit::Continue
                })
            })
            .collect();
        traverse_interleaved::<I, _>(self.nodes, self.rays, &[Real::INFINITY; PACKET], &mut visitors);
        drop(visitors);
        let interleaved = logs.pop().expect("rays");
        let lanes = PacketLanes::<I>::new(self.rays).expect("rays that make a packet");
        let mut packet = PacketLog(Vec::new());
        traverse_packet::<I>(self.nodes, &lanes, (1 << self.rays.len()) - 1, &[Real::INFINITY; PACKET], &mut packet);
        let packet = packet.0.iter().filter(|&&(lane, ..)| lane == 0).map(|&(_, first, count)| (first, count)).collect();
        [alone, interleaved, packet]
    }
}

/// Appends, depth first, a binary tree of `levels` levels down a spine: each interior node's
/// first child holds two leaves in the far half of the unit cube, its second continues the
/// spine, which ends in a leaf filling the cube. A ray from below the cube's near corner enters
/// the spine's boxes first, so the traversal goes down the spine with the leaves waiting.
fn spine(nodes: &mut Vec<build::BinaryNode>, levels: usize, leaves: &mut Vec<(u32, u32)>) {
    let (cube, far_half) = (Aabb::new(Vec3::ZERO, Vec3::ONE), Aabb::new(Vec3::splat(0.5), Vec3::ONE));
    let mut leaf = |nodes: &mut Vec<build::BinaryNode>, bounds: Aabb| {
        let first = leaves.len() as u32;
        leaves.push((first, 1));
        nodes.push(build::BinaryNode { bounds, area: bounds.surface_area(), offset: first, prim_count: 1 });
    };
    if levels == 0 {
        return leaf(nodes, cube);
    }
    let interior = |bounds: Aabb| build::BinaryNode { bounds, area: bounds.surface_area(), offset: 0, prim_count: 0 };
    let at = nodes.len();
    nodes.extend([interior(cube), interior(far_half)]);
    leaf(nodes, far_half);
    nodes[at + 1].offset = nodes.len() as u32;
    leaf(nodes, far_half);
    nodes[at].offset = nodes.len() as u32;
    spine(nodes, levels - 1, leaves);
}

#[test]
fn trees_too_tall_for_a_stack_in_the_frame_are_traversed_whole() {
    // The collapse expands the spine, the larger box, first: each wide node takes seven of
    // its levels and pushes seven pairs of leaves on the stack on the way down.
    let (mut binary, mut leaves) = (Vec::new(), Vec::new());
    spine(&mut binary, 200, &mut leaves);
    let nodes = collapse::collapse_in_parallel_to(&binary, 0);
    let height = nodes[0].height as usize;
    assert!(height > 2 * traverse::LOCAL_HEIGHT, "a tree of {height} levels");
    let rays = [Ray::new(Vec3::splat(-1.0), Vec3::new(1.0, 0.9, 0.8).normalize()); 2];
    for path in crate::simd::available() {
        for mut reached in crate::simd::dispatch_on(path, EveryTraversal { nodes: &nodes, rays: &rays }).unwrap() {
            reached.sort_unstable();
            assert_eq!(reached, leaves, "{path:?}");
        }
    }
}

/// For each node of a tree, the boxes the packet's frustum may enter, and those each ray
/// enters by its own slab test with its entry distances.
struct FrustumAndRays<'a> {
    nodes: &'a [BvhNode],
    rays: &'a [Ray],
    t_max: Real,
}

/// Per node: the frustum's bits and entry bounds, and each ray's bits and entries.
type NodeTests = (u32, [Real; WIDTH], Vec<(u32, [Real; WIDTH])>);

impl Kernel for FrustumAndRays<'_> {
    type Output = Option<Vec<NodeTests>>;
    fn run<I: Isa>(self) -> Self::Output {
        let lanes = PacketLanes::<I>::new(self.rays).expect("rays that make a packet");
        let mut tests = Vec::new();
        for node in self.nodes {
            let (bound, may_enter) = lanes.may_enter(&lanes.entry_exit(node), self.t_max * BOX_SLACK)?;
            let mut bounds = [0.0; WIDTH];
            bound.store(&mut bounds);
            let mut rays = Vec::new();
            for ray in self.rays {
                let (t_enter, hits) = traverse::node_hits::<I>(node, &traverse::SlabLanes::new(ray), self.t_max);
                let mut entries = [0.0; WIDTH];
                t_enter.store(&mut entries);
                rays.push((hits, entries));
            }
            tests.push((may_enter & node.used(), bounds, rays));
        }
        Some(tests)
    }
}

#[test]
fn a_packets_frustum_keeps_every_box_a_ray_enters_and_culls_others() {
    let (_, bvh) = overlapping_boxes();
    let packets = [
        tile(Vec3::new(50.0, 26.0, -60.0), 0.1, Vec3::new(40.0, 20.0, 10.0), 0.7),
        tile(Vec3::new(-30.0, -20.0, 80.0), 0.1, Vec3::new(60.0, 30.0, 10.0), 2.5),
        tile(Vec3::new(50.0, 26.0, 14.0), 0.1, Vec3::new(90.0, 40.0, 20.0), 0.2),
    ];
    for path in crate::simd::available() {
        for rays in &packets {
            for t_max in [Real::INFINITY, 30.0] {
                let tests = crate::simd::dispatch_on(path, FrustumAndRays { nodes: bvh.nodes(), rays, t_max })
                    .unwrap()
                    .expect("finite inverses make a frustum");
                let (mut kept, mut entered) = (0, 0);
                for (may_enter, bounds, rays) in &tests {
                    let mut any_ray = 0;
                    for (hits, entries) in rays {
                        assert_eq!(hits & !may_enter, 0, "{path:?}: a ray enters a box the frustum culls");
                        for slot in (0..WIDTH).filter(|&slot| hits >> slot & 1 != 0) {
                            assert!(bounds[slot] <= entries[slot], "{path:?}: the frustum's entry is farther");
                        }
                        any_ray |= hits;
                    }
                    (kept, entered) = (kept + may_enter.count_ones(), entered + any_ray.count_ones());
                }
                let used: u32 = bvh.nodes().iter().map(|node| node.used().count_ones()).sum();
                assert!(kept < used / 4, "{path:?}: kept {kept} of {used} boxes, {entered} entered");
                assert!(entered > 0 || t_max < Real::INFINITY, "{path:?}: the rays enter no box");
            }
        }
    }
}

/// `a/b ≤ c/d` for positive denominators.
fn ratio_le((a, b): (i64, i64), (c, d): (i64, i64)) -> bool {
    a * d <= c * b
}

/// Whether the ray meets the box for some `t` in `[0, t_limit]`, in exact rational arithmetic
/// (every coordinate an integer, so every distance a ratio of integers).
fn enters_exactly(origin: [i64; 3], direction: [i64; 3], min: [i64; 3], max: [i64; 3], t_limit: Option<i64>) -> bool {
    let (mut enter, mut exit) = ((0, 1), t_limit.map(|t| (t, 1)));
    for axis in 0..3 {
        let (o, d) = (origin[axis], direction[axis]);
        if d == 0 {
            if o < min[axis] || o > max[axis] {
                return false;
            }
            continue;
        }
        let (near, far) = if d > 0 { (min[axis], max[axis]) } else { (max[axis], min[axis]) };
        let (near, far) = ((d.signum() * (near - o), d.abs()), (d.signum() * (far - o), d.abs()));
        if ratio_le(enter, near) {
            enter = near;
        }
        if exit.is_none_or(|exit| ratio_le(far, exit)) {
            exit = Some(far);
        }
    }
    exit.is_none_or(|exit| ratio_le(enter, exit))
}

struct SlabTest<'a> {
    boxes: &'a BoxSet,
    ray: Ray,
    t_limit: Real,
}

impl crate::simd::Kernel for SlabTest<'_> {
    type Output = u32;
    fn run<I: Isa>(self) -> u32 {
        self.boxes.entered::<I>(&self.ray, self.t_limit).0
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2048))]
    /// The slab test never misses a box the ray meets exactly, on every path: boxes whose
    /// faces, edges and corners the ray grazes (planes through points of the ray at whole `t`),
    /// zero direction components (infinite inverses, origins on a plane), inverses that round
    /// (directions of 3 and 7), origins far from the boxes, where the differences round the
    /// most, and limits that end on a face.
    #[test]
    fn the_slab_test_never_misses_a_box_the_ray_meets_exactly(
        origin in proptest::array::uniform3(-8i64..=8),
        far_origin in proptest::bool::ANY,
        direction in proptest::array::uniform3(proptest::sample::select(vec![-13i64, -7, -3, -1, 0, 0, 1, 3, 5, 6, 9, 11])),
        corners in proptest::collection::vec(
            proptest::array::uniform3((-6i64..=6, proptest::sample::select(vec![-2i64, -1, 0, 0, 0, 1, 2]))),
            16,
        ),
        t_limit in proptest::option::of(0i64..=6),
    ) {
        // Far origins step back along the ray (a million units), keeping the boxes on its path.
        let back = if far_origin { 1 << 20 } else { 0 };
        let origin = [0, 1, 2].map(|axis| origin[axis] - back * direction[axis]);
        let t_limit = t_limit.map(|t| t + back);
        // A corner is a point of the ray at whole `t`, moved by a few units on each axis.
        let point = |[(t, nudge_x), (_, nudge_y), (_, nudge_z)]: [(i64, i64); 3]| {
            let t = t.abs() + back;
            [0, 1, 2].map(|axis| origin[axis] + t * direction[axis] + [nudge_x, nudge_y, nudge_z][axis])
        };
        let boxes: Vec<([i64; 3], [i64; 3])> = corners
            .chunks_exact(2)
            .map(|pair| {
                let (a, b) = (point(pair[0]), point(pair[1]));
                ([0, 1, 2].map(|axis| a[axis].min(b[axis])), [0, 1, 2].map(|axis| a[axis].max(b[axis])))
            })
            .collect();
        let real = |v: [i64; 3]| Vec3::new(v[0] as Real, v[1] as Real, v[2] as Real);
        let set = BoxSet::new(&boxes.iter().map(|&(min, max)| Aabb::new(real(min), real(max))).collect::<Vec<_>>());
        let ray = Ray::new(real(origin), real(direction));
        let limit = t_limit.map_or(Real::INFINITY, |t| t as Real);
        for path in crate::simd::available() {
            let hits = crate::simd::dispatch_on(path, SlabTest { boxes: &set, ray, t_limit: limit }).unwrap();
            for (lane, &(min, max)) in boxes.iter().enumerate() {
                if enters_exactly(origin, direction, min, max, t_limit) {
                    proptest::prop_assert!(hits >> lane & 1 != 0, "{:?}: box {:?}–{:?} missed", path, min, max);
                }
            }
        }
    }
}

#[test]
fn nearest_first_orders_every_set_of_entered_boxes_by_distance_then_lane() {
    // Distances with ties (the lane decides), zero and the largest finite one; every set of
    // entered lanes.
    let distance_sets: [[Real; WIDTH]; 3] = [
        [3.0, 1.0, 2.0, 0.5, 7.0, 0.25, 6.0, 4.0],
        [1.0, 1.0, 0.0, 2.0, 0.0, Real::MAX, 1.0, 2.0],
        [8.0, 7.0, 6.0, 5.0, 4.0, 3.0, 2.0, 1.0],
    ];
    for t in &distance_sets {
        for hits in 0..=u8::MAX as u32 {
            let mut keys = [0; WIDTH];
            let lanes: Vec<usize> = BoxSet::nearest_first(hits, t, &mut keys).iter().map(|&key| BoxSet::lane(key)).collect();
            let mut expected: Vec<usize> = (0..WIDTH).filter(|&lane| hits >> lane & 1 != 0).collect();
            expected.sort_by(|&a, &b| t[a].total_cmp(&t[b]).then(a.cmp(&b)));
            assert_eq!(lanes, expected, "hits {hits:08b}, distances {t:?}");
        }
    }
}
