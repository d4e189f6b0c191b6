//! Triangle meshes with their own BVH, built once and shared (behind an `Arc`) by every
//! instance that places the mesh in a scene.

mod flat;
mod leaf_tests;
mod placed;

use std::time::{Duration, Instant};

use super::aabb::Aabb;
use super::huge_page_vec;
use super::bvh::{Bvh, LeafCost, MAX_PRIMITIVES, PACKET, PacketLanes, traverse, traverse_interleaved, traverse_packet};
use super::triangle::{
    PackRay, RayLanes, TriangleHit, TrianglePack, face_normal, normalize,
    triangle_surface,
};
use super::{Ray, SurfaceHit, lanes};
use super::real::{Real, Vec3};
pub use crate::build_error::MeshError;
use flat::FlatLeaves;
use leaf_tests::{AnyTriangle, NearestTriangle, NearestTriangles};
use crate::simd::{Isa, Kernel, dispatch};
use rayon::prelude::*;

/// The vertex normals a mesh is built with.
#[derive(Clone, Debug)]
pub enum VertexNormals {
    /// The assignment's rule: a vertex normal is the normalised, unweighted sum of the unit
    /// normals of the triangles using that vertex (by position index). Zero-area triangles
    /// have no normal and contribute nothing.
    Averaged,
    /// Normals with their own index triples, one per triangle, as OBJ `vn` data comes.
    Indexed {
        normals: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
    },
}

/// Which vertex normals [`Mesh::load_obj`] uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalSource {
    /// The file's `vn` normals when every face corner references one, otherwise averaged.
    FromFileOrAveraged,
    /// Always [`VertexNormals::Averaged`], ignoring any `vn` (the assignment's behaviour).
    Averaged,
}

/// The closest hit found by [`Mesh::intersect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshHit {
    pub t: Real,
    /// Index in the mesh's own (BVH) order, as used by [`Mesh::triangle`].
    pub triangle: u32,
    pub barycentrics: [Real; 3],
}

/// A triangle mesh ready for ray queries.
///
/// Triangles are numbered in BVH leaf order. Each leaf's triangles are packed four to a
/// [`TrianglePack`] (corner positions inline, one SIMD lane per triangle), so a leaf is tested
/// with one packed test and no index indirection; the leaves point at their packs. The corners
/// are also kept per triangle for shading. Normals that are zero or not finite (from the file,
/// or averaged over degenerate or cancelling faces) are stored as zero; a triangle with any such
/// corner is shaded with its geometric normal.
#[derive(Clone, Debug)]
pub struct Mesh {
    corners: Vec<[Vec3; 3]>,
    normal_indices: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    packs: Vec<TrianglePack>,
    /// Its leaves are runs of `packs`.
    bvh: Bvh,
    /// For a small mesh, its leaves behind one box test, which rays take instead of the tree.
    flat: Option<FlatLeaves>,
    /// Kept for render statistics, which report BVH builds apart from OBJ parsing.
    bvh_build_time: Duration,
}

impl Mesh {
    /// Validates the data (finite positions, indices in range, at least one triangle) and
    /// builds the BVH.
    pub fn new(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        vertex_normals: VertexNormals,
    ) -> Result<Mesh, MeshError> {
        validate(positions, triangles)?;
        let (normals, normal_indices) = match vertex_normals {
            VertexNormals::Averaged => (averaged_normals(positions, triangles), triangles.to_vec()),
            VertexNormals::Indexed {
                normals,
                triangles: normal_triangles,
            } => {
                validate_normal_indices(&normals, &normal_triangles, triangles.len())?;
                let unit = normals
                    .iter()
                    .map(|&n| normalize(n).unwrap_or(Vec3::ZERO))
                    .collect();
                (unit, normal_triangles)
            }
        };
        let corners_of = |[a, b, c]: [u32; 3]| [positions[a as usize], positions[b as usize], positions[c as usize]];
        let build_start = Instant::now();
        let bounds_of = |index: usize| Aabb::from_points(corners_of(triangles[index]));
        let (mut bvh, order) = Bvh::build_from(triangles.len(), bounds_of, LeafCost::PerPackOfFour).into_leaf_order();
        let mut corners: Vec<[Vec3; 3]> = huge_page_vec(order.len());
        corners.par_extend(order.par_iter().map(|&i| corners_of(triangles[i as usize])));
        let leaves = bvh.leaves();
        let flat = FlatLeaves::new(&leaves, &corners);
        let packs = pack_leaves(&mut bvh, &leaves, &corners);
        let bvh_build_time = build_start.elapsed();
        Ok(Mesh {
            corners,
            normal_indices: order.par_iter().map(|&i| normal_indices[i as usize]).collect(),
            normals,
            packs,
            bvh,
            flat,
            bvh_build_time,
        })
    }

    /// The closest hit in `(0, t_max]`. Of hits at the same `t`, the triangle with the smaller
    /// index wins, so the hit does not depend on the order the BVH is traversed in.
    pub fn intersect(&self, ray: &Ray, t_max: Real) -> Option<MeshHit> {
        struct Closest<'a>(&'a Mesh, &'a Ray, Real);
        impl Kernel for Closest<'_> {
            type Output = Option<MeshHit>;
            #[inline(always)]
            fn run<I: Isa>(self) -> Option<MeshHit> {
                self.0.closest_lanes::<I>(self.1, self.2)
            }
        }
        dispatch(Closest(self, ray, t_max))
    }

    /// [`Mesh::intersect`] inside a caller's kernel (see `crate::simd`), which saves a second
    /// dispatch when a scene's query reaches the mesh.
    #[inline(always)]
    pub fn closest_lanes<I: Isa>(&self, ray: &Ray, t_max: Real) -> Option<MeshHit> {
        let Some(flat) = &self.flat else {
            let mut nearest = NearestTriangle { mesh: self, ray: PackRay::<I>::new(ray), closest: None };
            traverse::<I>(self.bvh.nodes(), ray, t_max, &mut nearest);
            return nearest.closest;
        };
        let (hits, t) = flat.entered::<I>(ray, t_max);
        if hits == 0 {
            return None;
        }
        let mut nearest = NearestTriangle { mesh: self, ray: PackRay::<I>::new(ray), closest: None };
        flat.visit::<I>(hits, &t, t_max, &mut nearest);
        nearest.closest
    }

    /// [`Mesh::intersect`] of up to [`PACKET`] rays at once, each result exactly what
    /// [`Mesh::intersect`] returns for that ray. Rays that share the signs of their direction
    /// components and their dominant axis (camera rays through a small tile, say) are traced as
    /// a packet: each node and each triangle is tested against all of them at once. Others are
    /// traced each on its own way, their traversals interleaved so that their nodes are fetched
    /// from memory together.
    ///
    /// # Panics
    /// If there are more than [`PACKET`] rays.
    pub fn intersect_packet(&self, rays: &[Ray], t_max: Real) -> [Option<MeshHit>; PACKET] {
        assert!(rays.len() <= PACKET, "a packet holds at most {PACKET} rays");
        let mut hits = [None; PACKET];
        self.intersect_packets(rays, t_max, &mut hits);
        hits
    }

    /// [`Mesh::intersect_packet`] of every run of [`PACKET`] rays of `rays` in turn (the last
    /// may be shorter), in one call: `hits[k]` is ray `k`'s hit, exactly what
    /// [`Mesh::intersect`] returns for it. For a caller with many packets (a whole image's
    /// camera rays): each call into the instruction set's kernel saves registers, makes its
    /// constants again and copies its result out, which one call for all saves (camera rays
    /// through the 1M-triangle mesh 1.7% faster than a call a packet).
    ///
    /// # Panics
    /// If `hits` is shorter than `rays`.
    pub fn intersect_packets(&self, rays: &[Ray], t_max: Real, hits: &mut [Option<MeshHit>]) {
        struct Closest<'a>(&'a Mesh, &'a [Ray], Real, &'a mut [Option<MeshHit>]);
        impl Kernel for Closest<'_> {
            type Output = ();
            #[inline(always)]
            fn run<I: Isa>(self) {
                let Closest(mesh, rays, t_max, hits) = self;
                let hits = &mut hits[..rays.len()];
                for (rays, hits) in rays.chunks(PACKET).zip(hits.chunks_mut(PACKET)) {
                    let found = mesh.closest_packet::<I>(rays, &[t_max; PACKET]);
                    hits.copy_from_slice(&found[..rays.len()]);
                }
            }
        }
        assert!(hits.len() >= rays.len(), "a hit for every ray");
        dispatch(Closest(self, rays, t_max, hits))
    }

    /// [`Mesh::intersect_packet`] inside a caller's kernel (see `crate::simd`), ray `k` with its
    /// own `t_max[k]`: each result exactly what [`Mesh::closest_lanes`] returns for that ray.
    ///
    /// # Panics
    /// If there are more than [`PACKET`] rays.
    #[inline(always)]
    pub fn closest_packet<I: Isa>(&self, rays: &[Ray], t_max: &[Real; PACKET]) -> [Option<MeshHit>; PACKET] {
        assert!(rays.len() <= PACKET, "a packet holds at most {PACKET} rays");
        if rays.is_empty() {
            return [None; PACKET];
        }
        // Gathered once for both set-ups, and the triangles' set-up made only for rays that
        // make a packet: random rays fail the first and go their own ways. One call of the
        // interleaved traversal, which is inlined: two would compile it twice.
        let gathered = lanes::RayLanes::<I>::gather(rays);
        let slab = PacketLanes::<I>::from_lanes(&gathered);
        let triangle_rays = if slab.is_some() { RayLanes::<I>::from_lanes(&gathered) } else { None };
        let (Some(slab), Some(triangle_rays)) = (slab, triangle_rays) else {
            return self.closest_interleaved::<I>(rays, t_max);
        };
        let mut nearest = NearestTriangles { mesh: self, rays: triangle_rays, closest: [None; PACKET] };
        traverse_packet::<I>(self.bvh.nodes(), &slab, (1u32 << rays.len()) - 1, t_max, &mut nearest);
        nearest.closest
    }

    /// [`Mesh::closest_packet`] of rays that do not make a packet: each ray's own traversal,
    /// interleaved with the others' so that their nodes are fetched from memory together.
    #[inline(always)]
    fn closest_interleaved<I: Isa>(&self, rays: &[Ray], t_max: &[Real; PACKET]) -> [Option<MeshHit>; PACKET] {
        let mut closest = [None; PACKET];
        if rays.is_empty() {
            return closest;
        }
        if self.flat.is_some() {
            for ((hit, ray), &t_max) in closest.iter_mut().zip(rays).zip(t_max) {
                *hit = self.closest_lanes::<I>(ray, t_max);
            }
            return closest;
        }
        // A loop rather than `array::from_fn`: a closure may be compiled outside the kernel.
        let mut nearest = [NearestTriangle { mesh: self, ray: PackRay::<I>::new(&rays[0]), closest: None }; PACKET];
        for (nearest, ray) in nearest[1..].iter_mut().zip(&rays[1..]) {
            nearest.ray = PackRay::<I>::new(ray);
        }
        traverse_interleaved::<I, _>(self.bvh.nodes(), rays, t_max, &mut nearest);
        for (hit, nearest) in closest.iter_mut().zip(&nearest) {
            *hit = nearest.closest;
        }
        closest
    }

    /// Whether anything is hit in `(0, t_max]`; cheaper than [`Mesh::intersect`] because it
    /// stops at the first hit.
    pub fn occluded(&self, ray: &Ray, t_max: Real) -> bool {
        struct Any<'a>(&'a Mesh, &'a Ray, Real);
        impl Kernel for Any<'_> {
            type Output = bool;
            #[inline(always)]
            fn run<I: Isa>(self) -> bool {
                self.0.any_lanes::<I>(self.1, self.2)
            }
        }
        dispatch(Any(self, ray, t_max))
    }

    /// [`Mesh::occluded`] inside a caller's kernel (see `crate::simd`).
    #[inline(always)]
    pub fn any_lanes<I: Isa>(&self, ray: &Ray, t_max: Real) -> bool {
        let Some(flat) = &self.flat else {
            let mut blocker = AnyTriangle { mesh: self, ray: PackRay::<I>::new(ray), found: false };
            traverse::<I>(self.bvh.nodes(), ray, t_max, &mut blocker);
            return blocker.found;
        };
        let (hits, t) = flat.entered::<I>(ray, t_max);
        if hits == 0 {
            return false;
        }
        let mut blocker = AnyTriangle { mesh: self, ray: PackRay::<I>::new(ray), found: false };
        flat.visit::<I>(hits, &t, t_max, &mut blocker);
        blocker.found
    }

    /// Point, error bound and normals of a hit returned by [`Mesh::intersect`].
    pub fn surface(&self, hit: &MeshHit) -> SurfaceHit {
        let [p0, p1, p2] = self.corners[hit.triangle as usize];
        let [b0, b1, b2] = hit.barycentrics;
        let triangle_hit = TriangleHit {
            t: hit.t,
            b0,
            b1,
            b2,
        };
        triangle_surface(p0, p1, p2, self.vertex_normals(hit.triangle), &triangle_hit)
    }

    /// Corner positions of a triangle (in the mesh's order).
    pub fn triangle(&self, index: u32) -> [Vec3; 3] {
        self.corners[index as usize]
    }

    /// Unit corner normals of a triangle, or `None` when it is shaded with its geometric normal.
    pub fn vertex_normals(&self, index: u32) -> Option<[Vec3; 3]> {
        let normals = self.normal_indices[index as usize].map(|n| self.normals[n as usize]);
        normals.iter().all(|&n| n != Vec3::ZERO).then_some(normals)
    }

    pub fn triangle_count(&self) -> usize {
        self.corners.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// The acceleration structure, for statistics (node and leaf counts).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// How long [`Mesh::new`] took to build what rays are traced through: the triangles' boxes,
    /// the BVH and the triangle packs (the rest of a load is reading the file, checking it and
    /// the vertex normals).
    pub fn bvh_build_time(&self) -> Duration {
        self.bvh_build_time
    }
}

/// Packs each leaf's triangles (`corners` is in leaf order) four at a time, in leaf order, and
/// points the leaf at its packs.
fn pack_leaves(bvh: &mut Bvh, leaves: &[(u32, u32)], corners: &[[Vec3; 3]]) -> Vec<TrianglePack> {
    // Each pack's run of triangles, and where each leaf's packs start (by its first triangle).
    let mut runs = Vec::with_capacity(corners.len().div_ceil(4) + leaves.len());
    let mut first_pack = vec![0u32; corners.len()];
    for &(first, count) in leaves {
        first_pack[first as usize] = runs.len() as u32;
        runs.extend((first..first + count).step_by(4).map(|start| (start, (start + 4).min(first + count))));
    }
    // An indexed parallel iterator writes each pack in its place, where `flat_map` would
    // gather them in pieces and copy them again.
    let mut packs = huge_page_vec(runs.len());
    packs.par_extend(runs.par_iter().map(|&(start, end)| TrianglePack::new(start, &corners[start as usize..end as usize])));
    bvh.remap_leaves(|first, count| (first_pack[first as usize], count.div_ceil(4)));
    packs
}

fn validate(positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), MeshError> {
    if triangles.is_empty() {
        return Err(MeshError::NoTriangles);
    }
    for (count, limit) in [(positions.len(), u32::MAX as usize), (triangles.len(), MAX_PRIMITIVES)] {
        if count > limit {
            return Err(MeshError::TooLarge { count, limit });
        }
    }
    if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::NonFinitePosition {
            vertex,
            position: positions[vertex].to_array().map(f64::from),
        });
    }
    for (triangle, corners) in triangles.iter().enumerate() {
        if let Some(&index) = corners.iter().find(|&&i| i as usize >= positions.len()) {
            let vertex_count = positions.len();
            return Err(MeshError::VertexIndexOutOfRange {
                triangle,
                index,
                vertex_count,
            });
        }
    }
    Ok(())
}

fn validate_normal_indices(
    normals: &[Vec3],
    normal_triangles: &[[u32; 3]],
    triangle_count: usize,
) -> Result<(), MeshError> {
    if normal_triangles.len() != triangle_count {
        let found = normal_triangles.len();
        return Err(MeshError::NormalTriangleCount {
            expected: triangle_count,
            found,
        });
    }
    for (triangle, corners) in normal_triangles.iter().enumerate() {
        if let Some(&index) = corners.iter().find(|&&i| i as usize >= normals.len()) {
            let normal_count = normals.len();
            return Err(MeshError::NormalIndexOutOfRange {
                triangle,
                index,
                normal_count,
            });
        }
    }
    Ok(())
}

/// One unit normal per position, following [`VertexNormals::Averaged`]; zero where the sum
/// cannot be normalised (no usable face, or faces cancelling out).
fn averaged_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    // The face normals in parallel; their sums in triangle order, as always.
    let faces: Vec<Option<Vec3>> = triangles
        .par_iter()
        .map(|corners| {
            let [p0, p1, p2] = corners.map(|i| positions[i as usize]);
            face_normal(p0, p1, p2)
        })
        .collect();
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for (corners, face) in triangles.iter().zip(faces) {
        if let Some(normal) = face {
            for &vertex in corners {
                sums[vertex as usize] += normal;
            }
        }
    }
    sums.into_par_iter().map(|sum| normalize(sum).unwrap_or(Vec3::ZERO)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles folded along the shared edge (0, 1).
    fn roof() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(-1.0, 0.0, -1.0),
        ];
        (positions, vec![[0, 2, 1], [0, 1, 3]])
    }

    #[test]
    fn rejects_invalid_data() {
        let (positions, triangles) = roof();
        let averaged = || VertexNormals::Averaged;
        assert!(matches!(
            Mesh::new(&positions, &[], averaged()),
            Err(MeshError::NoTriangles)
        ));
        let out_of_range = Mesh::new(&positions, &[[0, 1, 4]], averaged());
        assert!(matches!(
            out_of_range,
            Err(MeshError::VertexIndexOutOfRange { index: 4, .. })
        ));
        let mut nan = positions.clone();
        nan[2].y = Real::NAN;
        let non_finite = Mesh::new(&nan, &triangles, averaged());
        assert!(matches!(
            non_finite,
            Err(MeshError::NonFinitePosition { vertex: 2, .. })
        ));
        let normals = VertexNormals::Indexed {
            normals: vec![Vec3::Z],
            triangles: vec![[0, 0, 1]],
        };
        let bad_normals = Mesh::new(&positions, &triangles[..1], normals);
        assert!(matches!(
            bad_normals,
            Err(MeshError::NormalIndexOutOfRange { index: 1, .. })
        ));
    }

    #[test]
    fn averaged_normals_are_unweighted_sums_of_face_normals() {
        let (positions, triangles) = roof();
        let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap();
        let face = |[a, b, c]: [u32; 3]| {
            let p = |i: u32| positions[i as usize];
            (p(b) - p(a)).cross(p(c) - p(a)).normalize()
        };
        let shared = (face(triangles[0]) + face(triangles[1])).normalize();
        for index in 0..2 {
            let corners = mesh.triangle(index);
            let normals = mesh.vertex_normals(index).expect("usable normals");
            for (corner, normal) in corners.iter().zip(normals) {
                let expected = if corner.x == 0.0 {
                    shared
                } else {
                    face(triangles[if corner.x > 0.0 { 0 } else { 1 }])
                };
                assert!(
                    (normal - expected).length() < 1e-6,
                    "{corner}: {normal} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn unusable_normals_fall_back_to_the_geometric_normal() {
        let (positions, triangles) = roof();
        let normals = VertexNormals::Indexed {
            normals: vec![Vec3::Y, Vec3::ZERO, Vec3::NAN],
            triangles: vec![[0, 0, 0], [0, 1, 0]],
        };
        let mesh = Mesh::new(&positions, &triangles, normals).unwrap();
        let usable: Vec<bool> = (0..2).map(|i| mesh.vertex_normals(i).is_some()).collect();
        assert_eq!(usable.iter().filter(|&&u| u).count(), 1);
        let ray = Ray::new(Vec3::new(-0.3, 0.2, 5.0), Vec3::NEG_Z);
        let hit = mesh.intersect(&ray, Real::INFINITY).expect("hit");
        let surface = mesh.surface(&hit);
        assert_eq!(mesh.vertex_normals(hit.triangle), None);
        assert_eq!(surface.shading_normal, surface.geometric_normal);
    }

    #[test]
    fn intersect_and_occluded() {
        let (positions, triangles) = roof();
        let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap();
        let ray = Ray::new(Vec3::new(0.3, 0.2, 5.0), Vec3::NEG_Z);
        let hit = mesh.intersect(&ray, Real::INFINITY).expect("hit");
        assert!((hit.t - 5.3).abs() < 1e-5, "{hit:?}");
        assert!(mesh.occluded(&ray, 6.0));
        assert!(!mesh.occluded(&ray, 5.0));
        assert_eq!(mesh.intersect(&ray, 5.0), None);
        assert_eq!(mesh.triangle_count(), 2);
        assert_eq!(
            mesh.bounds(),
            Aabb::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 1.0, 0.0))
        );
    }
}
