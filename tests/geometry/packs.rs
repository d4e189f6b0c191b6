//! The mesh's packed queries (four triangles per test, eight rays per packet) find exactly what
//! testing every triangle alone with `intersect_triangle` finds, including which triangle wins a
//! tie of `t`: the one with the smaller index.

use goldray::geometry::Ray;
use goldray::geometry::bvh::PACKET;
use goldray::geometry::mesh::{Mesh, MeshHit, VertexNormals};
use goldray::geometry::triangle::{
    RayLanes, TrianglePack, TriangleRay, intersect_pack, intersect_pack_pair, intersect_triangle,
};
use goldray::real::{R8, Real, Vec3};
use goldray::simd::{Isa, Kernel, Lanes};
use proptest::prelude::*;

use super::{Rng, ray_through};

/// The nearest hit over every triangle of the mesh, ties to the smaller index, as `Mesh` numbers
/// its triangles.
pub(super) fn brute_force(mesh: &Mesh, ray: &Ray, t_max: Real) -> Option<MeshHit> {
    let triangle_ray = TriangleRay::new(ray);
    let mut closest: Option<MeshHit> = None;
    for triangle in 0..mesh.triangle_count() as u32 {
        let [p0, p1, p2] = mesh.triangle(triangle);
        if let Some(hit) = intersect_triangle(&triangle_ray, t_max, p0, p1, p2)
            && closest.is_none_or(|best| hit.t < best.t)
        {
            closest = Some(MeshHit {
                t: hit.t,
                triangle,
                barycentrics: [hit.b0, hit.b1, hit.b2],
            });
        }
    }
    closest
}

/// A soup of random triangles, with some duplicated and some sharing a plane, so that ties of
/// `t` happen; and rays aimed at them in fans of eight from one point.
fn check(seed: u64, count: usize) -> usize {
    let mut rng = Rng::new(seed);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..count {
        let centre = rng.in_box(8.0);
        let corners = if i % 7 == 3 {
            // In the plane z = 1, where several overlap.
            [0; 3].map(|_| Vec3::new(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), 1.0))
        } else {
            [0; 3].map(|_| centre + rng.in_box(1.5))
        };
        let first = positions.len() as u32;
        positions.extend(corners);
        triangles.push([first, first + 1, first + 2]);
        if i % 5 == 0 {
            triangles.push([first, first + 1, first + 2]);
        }
    }
    let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).expect("valid");
    let mut hits = 0;
    for fan in 0..60 {
        let origin = rng.in_box(20.0);
        let aim = rng.in_box(6.0);
        let t_max = if fan % 4 == 0 {
            rng.uniform(5.0, 30.0)
        } else {
            Real::INFINITY
        };
        let rays: Vec<Ray> = (0..PACKET)
            .map(|_| {
                if fan % 3 == 0 {
                    ray_through(origin, rng.in_box(8.0))
                } else {
                    ray_through(origin, aim + rng.in_box(0.5))
                }
            })
            .collect();
        let packet = mesh.intersect_packet(&rays, t_max);
        for (ray, from_packet) in rays.iter().zip(packet) {
            let expected = brute_force(&mesh, ray, t_max);
            assert_eq!(mesh.intersect(ray, t_max), expected, "one ray {ray:?}");
            assert_eq!(from_packet, expected, "in a packet {ray:?}");
            assert_eq!(mesh.occluded(ray, t_max), expected.is_some(), "occlusion {ray:?}");
            hits += expected.is_some() as usize;
        }
    }
    hits
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]
    #[test]
    fn packed_queries_agree_with_every_triangle_tested_alone(seed in any::<u64>()) {
        prop_assert!(check(seed, 400) > 40);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    /// Meshes of up to sixteen packs skip their tree (one box test over runs of leaves): the
    /// same hits, ties included.
    #[test]
    fn small_meshes_tested_without_their_tree_agree_too(seed in any::<u64>(), count in 4usize..40) {
        check(seed, count);
    }
}

#[test]
fn of_coinciding_triangles_the_smaller_index_wins() {
    let positions = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    // Twenty copies of one triangle: every ray that hits one hits all at the same t.
    let mesh = Mesh::new(&positions, &[[0, 1, 2]; 20], VertexNormals::Averaged).expect("valid");
    let rays: Vec<Ray> = (0..PACKET)
        .map(|k| Ray::new(Vec3::new(k as Real * 0.05 - 0.2, 0.0, 3.0), Vec3::new(0.0, 0.1, -1.0)))
        .collect();
    let packet = mesh.intersect_packet(&rays, Real::INFINITY);
    for (ray, from_packet) in rays.iter().zip(packet) {
        let hit = mesh.intersect(ray, Real::INFINITY).expect("hit");
        assert_eq!(hit.triangle, 0);
        assert_eq!(from_packet, Some(hit));
    }
}

/// Per pack and pair of rays: the lanes each ray hits alone and in the pair, and the bits of
/// the hit lanes' values (`t`, edges, inverse determinant) alone and in the pair.
type PairRecord = ((u32, u32), (u32, u32), Vec<u64>, Vec<u64>);

struct PairsAndSingles<'a> {
    packs: &'a [TrianglePack],
    rays: &'a [Ray],
    t_max: &'a [Real; PACKET],
}

impl Kernel for PairsAndSingles<'_> {
    type Output = Vec<PairRecord>;
    fn run<I: Isa>(self) -> Vec<PairRecord> {
        let lanes = RayLanes::<I>::new(self.rays).expect("rays that share a permutation");
        let mut records = Vec::new();
        for pack in self.packs {
            for a in 0..PACKET {
                for b in a + 1..PACKET {
                    let pair = intersect_pack_pair::<I>(pack, &lanes, [a, b], R8::<I>::load(&self.t_max[..]));
                    let (alone_a, alone_b) = (
                        intersect_pack::<I>(pack, &lanes.pack_ray(a), self.t_max[a]),
                        intersect_pack::<I>(pack, &lanes.pack_ray(b), self.t_max[b]),
                    );
                    let (pair_values, values_a, values_b) =
                        (pair.values::<8>(), alone_a.values::<4>(), alone_b.values::<4>());
                    let (mut in_pair, mut alone) = (Vec::new(), Vec::new());
                    for lane in (0..8).filter(|lane| pair.lanes >> lane & 1 != 0) {
                        let single = if lane < 4 { &values_a } else { &values_b };
                        for value in 0..5 {
                            in_pair.push((pair_values[value][lane] as f64).to_bits());
                            alone.push((single[value][lane % 4] as f64).to_bits());
                        }
                    }
                    records.push((
                        (pair.lanes & 0xf, pair.lanes >> 4),
                        (alone_a.lanes, alone_b.lanes),
                        in_pair,
                        alone,
                    ));
                }
            }
        }
        records
    }
}

/// The few rays that reach a leaf are tested two at a time, a pack's four triangles against
/// each ray in one half of eight lanes: every pair finds, lane for lane and bit for bit, what
/// each of its rays finds alone, on every SIMD path, limits included.
#[test]
fn a_pair_of_rays_finds_in_a_pack_what_each_finds_alone() {
    let mut rng = Rng::new(17);
    let packs: Vec<TrianglePack> = (0..40)
        .map(|k| {
            let triangles: Vec<[Vec3; 3]> = (0..1 + k % 4)
                .map(|_| {
                    let centre = Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-3.0, 3.0));
                    [0; 3].map(|_| centre + rng.in_box(1.2))
                })
                .collect();
            TrianglePack::new(k * 4, &triangles)
        })
        .collect();
    let origin = Vec3::new(0.0, 0.0, 8.0);
    let rays: Vec<Ray> = (0..PACKET)
        .map(|_| {
            Ray::new(
                origin,
                Vec3::new(rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15), -1.0),
            )
        })
        .collect();
    let mut t_max = [Real::INFINITY; PACKET];
    (t_max[2], t_max[5]) = (8.5, 9.5);
    let mut hits = 0;
    for path in goldray::simd::available() {
        let records = goldray::simd::dispatch_on(
            path,
            PairsAndSingles {
                packs: &packs,
                rays: &rays,
                t_max: &t_max,
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        for (in_pair, alone, pair_values, values) in records {
            assert_eq!(in_pair, alone, "{path:?}: the lanes hit");
            assert_eq!(pair_values, values, "{path:?}: the hits' values");
            hits += (alone.0 | alone.1).count_ones();
        }
    }
    assert!(hits > 100, "the rays hit too few triangles ({hits}) to test much");
}
