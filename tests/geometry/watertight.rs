//! Rays through shared edges and vertices must not slip between triangles.

use goldray::geometry::Ray;
use goldray::geometry::mesh::{Mesh, VertexNormals};
use goldray::geometry::triangle::{TriangleRay, intersect_triangle};
use goldray::real::{Real, Vec3};

use super::{Rng, ray_through};

/// A closed fan around `centre`: triangles `(centre, ring[i], ring[i+1])`, wound consistently.
struct Fan {
    centre: Vec3,
    ring: Vec<Vec3>,
}

impl Fan {
    /// A slightly crumpled fan facing roughly along `axis`, tilted by at most ~35°.
    fn random(rng: &mut Rng, axis: Vec3) -> Fan {
        let normal = (axis + rng.in_box(0.4)).normalize();
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let centre = rng.in_box(5.0);
        // At least 4 spokes, so that with the angular jitter no gap reaches 180° and the fan
        // stays star-shaped around its centre, i.e. has no fold a ray could pass.
        let count = 4 + (rng.next_u64() % 9) as usize;
        let ring = (0..count)
            .map(|i| {
                let angle = (i as Real + rng.uniform(-0.3, 0.3)) * std::f64::consts::TAU as Real / count as Real;
                let radius = rng.uniform(0.7, 1.3);
                centre + (u * angle.cos() + v * angle.sin()) * radius + normal * rng.uniform(-0.02, 0.02)
            })
            .collect();
        Fan { centre, ring }
    }

    fn triangles(&self) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        let n = self.ring.len();
        (0..n).map(move |i| [self.centre, self.ring[i], self.ring[(i + 1) % n]])
    }

    fn hit_count(&self, ray: &Ray) -> usize {
        let triangle_ray = TriangleRay::new(ray);
        self.triangles()
            .filter(|&[p0, p1, p2]| intersect_triangle(&triangle_ray, Real::INFINITY, p0, p1, p2).is_some())
            .count()
    }

    /// Points on the shared edges: the centre and points along each spoke.
    fn shared_points(&self, rng: &mut Rng) -> Vec<Vec3> {
        let mut points = vec![self.centre];
        for &r in &self.ring {
            points.push(self.centre + (r - self.centre) * rng.uniform(0.02, 0.98));
        }
        points
    }
}

const AXES: [Vec3; 6] = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::NEG_X, Vec3::NEG_Y, Vec3::NEG_Z];

#[test]
fn rays_through_shared_edges_and_vertices_of_a_fan_hit_it() {
    let mut rng = Rng::new(1);
    let mut rays = 0;
    for fan_index in 0..600 {
        let axis = AXES[fan_index % 6];
        let fan = Fan::random(&mut rng, axis);
        for target in fan.shared_points(&mut rng) {
            // Axis-aligned: the origin differs from the target only along the axis, so the
            // ray passes exactly through the target point.
            for distance in [3.0, -3.0] {
                let ray = Ray::new(target + axis * distance, -axis * distance.signum());
                assert!(fan.hit_count(&ray) >= 1, "axis ray {ray:?} missed fan {fan_index}");
            }
            for _ in 0..4 {
                let offset = (axis + rng.in_box(0.3)) * rng.uniform(0.5, 20.0);
                let side = if rng.next_u64().is_multiple_of(2) { 1.0 } else { -1.0 };
                let ray = ray_through(target + offset * side, target);
                assert!(fan.hit_count(&ray) >= 1, "ray {ray:?} missed fan {fan_index}");
            }
            rays += 6;
        }
    }
    assert!(rays > 20_000);
}

/// A height field over integer (x, y): every vertex and edge lies exactly on the planes of
/// some triangles' bounding boxes, so axis-aligned rays through them start on slab planes
/// with zero direction components — the case where a naive slab test computes `0·∞ = NaN`
/// and culls the box.
#[test]
fn axis_aligned_rays_through_mesh_vertices_and_edges_hit() {
    let size = 12u32;
    let height = |x: u32, y: u32| ((x * 7 + y * 3) % 5) as Real * 0.25;
    let mut positions = Vec::new();
    for y in 0..=size {
        for x in 0..=size {
            positions.push(Vec3::new(x as Real, y as Real, height(x, y)));
        }
    }
    let vertex = |x: u32, y: u32| y * (size + 1) + x;
    let mut triangles = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let (a, b, c, d) = (vertex(x, y), vertex(x + 1, y), vertex(x + 1, y + 1), vertex(x, y + 1));
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).unwrap();
    let mut checked = 0;
    for y2 in 1..2 * size {
        for x2 in 1..2 * size {
            let (x, y) = (x2 as Real * 0.5, y2 as Real * 0.5);
            for (origin_z, direction) in [(10.0, Vec3::NEG_Z), (-10.0, Vec3::Z)] {
                let ray = Ray::new(Vec3::new(x, y, origin_z), direction);
                assert!(mesh.intersect(&ray, Real::INFINITY).is_some(), "missed at ({x}, {y})");
                assert!(mesh.occluded(&ray, Real::INFINITY), "not occluded at ({x}, {y})");
                checked += 1;
            }
        }
    }
    assert!(checked > 1000);
}
