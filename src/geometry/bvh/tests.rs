use super::*;
use super::super::real::Vec3;

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
    let binary_leaves = binary.iter().filter(|node| node.is_leaf()).count();
    assert_eq!(bvh.leaf_count(), binary_leaves);
    for node in &bvh.nodes {
        let used = node.used().count_ones() as usize;
        assert!((2..=WIDTH).contains(&used), "{used} children");
        assert!(node.count.iter().all(|&count| count <= 4));
    }
    assert!(bvh.node_count() * 2 < binary.len(), "{} wide nodes for {} binary ones", bvh.node_count(), binary.len());
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
