//! BVH traversal must find exactly what testing every primitive finds.

use goldray::geometry::Ray;
use goldray::geometry::aabb::Aabb;
use goldray::geometry::bvh::Bvh;
use goldray::geometry::triangle::{TriangleRay, intersect_triangle};
use goldray::real::{Real, Vec3};
use proptest::prelude::*;

use super::{Rng, ray_through};

type Triangle = [Vec3; 3];

fn random_triangles(rng: &mut Rng, count: usize, spread: Real) -> Vec<Triangle> {
    (0..count)
        .map(|_| {
            let centre = rng.in_box(spread);
            let size = rng.uniform(0.05, 2.0);
            [0; 3].map(|_| centre + rng.in_box(size))
        })
        .collect()
}

fn bounds_of(triangles: &[Triangle]) -> Vec<Aabb> {
    triangles.iter().map(|t| Aabb::from_points(*t)).collect()
}

fn hit_t(triangle_ray: &TriangleRay, t_max: Real, triangle: &Triangle) -> Option<Real> {
    intersect_triangle(triangle_ray, t_max, triangle[0], triangle[1], triangle[2]).map(|h| h.t)
}

fn brute_force_closest(triangles: &[Triangle], ray: &Ray, t_max: Real) -> Option<Real> {
    let triangle_ray = TriangleRay::new(ray);
    triangles
        .iter()
        .filter_map(|t| hit_t(&triangle_ray, t_max, t))
        .reduce(Real::min)
}

fn bvh_closest(bvh: &Bvh, triangles: &[Triangle], ray: &Ray, t_max: Real) -> Option<Real> {
    let triangle_ray = TriangleRay::new(ray);
    bvh.closest(ray, t_max, |prim, limit| {
        hit_t(&triangle_ray, limit, &triangles[prim as usize])
    })
}

fn bvh_any(bvh: &Bvh, triangles: &[Triangle], ray: &Ray, t_max: Real) -> bool {
    let triangle_ray = TriangleRay::new(ray);
    bvh.any(ray, t_max, |prim, limit| {
        hit_t(&triangle_ray, limit, &triangles[prim as usize]).is_some()
    })
}

/// Rays aimed at random triangles (so most hit), some axis-aligned, some with a finite reach.
fn check_against_brute_force(triangles: &[Triangle], rng: &mut Rng, ray_count: usize) -> usize {
    let bvh = Bvh::build(&bounds_of(triangles));
    let mut hits = 0;
    for i in 0..ray_count {
        let target = triangles[(rng.next_u64() % triangles.len() as u64) as usize];
        let aim = (target[0] + target[1] + target[2]) / 3.0 + rng.in_box(0.2);
        let ray = match i % 4 {
            0 => {
                let axis = [Vec3::X, Vec3::NEG_Y, Vec3::Z][i % 3];
                Ray::new(aim - axis * 30.0, axis)
            }
            _ => ray_through(rng.in_box(30.0), aim),
        };
        let t_max = if i % 3 == 0 {
            rng.uniform(0.2, 1.0)
        } else {
            Real::INFINITY
        };
        let expected = brute_force_closest(triangles, &ray, t_max);
        assert_eq!(
            bvh_closest(&bvh, triangles, &ray, t_max),
            expected,
            "closest, ray {ray:?}"
        );
        assert_eq!(
            bvh_any(&bvh, triangles, &ray, t_max),
            expected.is_some(),
            "any, ray {ray:?}"
        );
        hits += expected.is_some() as usize;
    }
    hits
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]
    #[test]
    fn traversal_agrees_with_brute_force(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let triangles = random_triangles(&mut rng, 3000, 10.0);
        let hits = check_against_brute_force(&triangles, &mut rng, 600);
        prop_assert!(hits > 200, "too few rays hit anything ({hits})");
    }
}

#[test]
fn identical_triangles() {
    let mut rng = Rng::new(2);
    let triangle = random_triangles(&mut rng, 1, 1.0)[0];
    let triangles = vec![triangle; 2000];
    assert!(check_against_brute_force(&triangles, &mut rng, 300) > 100);
}

/// Triangles `(v, −v, w)` with `|w| ≤ |v|` all have boxes centred exactly on the origin.
#[test]
fn coinciding_centroids() {
    let mut rng = Rng::new(3);
    let triangles: Vec<Triangle> = (0..1500)
        .map(|_| {
            let v = rng.in_box(3.0).abs() + Vec3::splat(0.01);
            let w = v * rng.in_box(1.0);
            [v, -v, w]
        })
        .collect();
    assert!(bounds_of(&triangles).iter().all(|b| b.centroid() == Vec3::ZERO));
    let bvh = Bvh::build(&bounds_of(&triangles));
    assert!(bvh.leaf_count() >= 1500 / 4);
    assert!(check_against_brute_force(&triangles, &mut rng, 300) > 100);
}

#[test]
fn single_triangle() {
    let mut rng = Rng::new(4);
    let triangles = random_triangles(&mut rng, 1, 1.0);
    let bvh = Bvh::build(&bounds_of(&triangles));
    assert_eq!((bvh.node_count(), bvh.leaf_count()), (1, 1));
    assert!(check_against_brute_force(&triangles, &mut rng, 100) > 10);
}

#[test]
fn no_primitives() {
    let bvh = Bvh::build(&[]);
    let ray = Ray::new(Vec3::ZERO, Vec3::ONE);
    assert_eq!(
        bvh.closest(&ray, Real::INFINITY, |_, _| panic!("no primitive to test")),
        None
    );
    assert!(!bvh.any(&ray, Real::INFINITY, |_, _| panic!("no primitive to test")));
    assert_eq!((bvh.node_count(), bvh.leaf_count()), (0, 0));
}

#[test]
fn tree_shape_is_sane() {
    let mut rng = Rng::new(5);
    let triangles = random_triangles(&mut rng, 20_000, 50.0);
    let bvh = Bvh::build(&bounds_of(&triangles));
    let (nodes, leaves) = (bvh.node_count(), bvh.leaf_count());
    assert!(
        nodes < leaves && 7 * nodes >= leaves - 1,
        "a tree of two to eight children per node: {nodes} nodes, {leaves} leaves"
    );
    assert!(bvh.leaf_count() >= 20_000 / 4, "leaves hold at most 4 primitives");
    let mut order = bvh.prim_indices().to_vec();
    order.sort_unstable();
    assert!(order.iter().enumerate().all(|(i, &p)| p == i as u32), "a permutation");
    let union = bounds_of(&triangles).into_iter().fold(Aabb::EMPTY, Aabb::union);
    assert_eq!(bvh.bounds(), union);
}

#[test]
fn build_is_identical_for_any_thread_count() {
    let mut rng = Rng::new(6);
    let bounds = bounds_of(&random_triangles(&mut rng, 60_000, 100.0));
    let build_with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| Bvh::build(&bounds))
    };
    let single = build_with(1);
    assert!(single == build_with(2), "1 and 2 threads built different trees");
    assert!(single == build_with(3), "1 and 3 threads built different trees");
}
