//! Procedural meshes for tests, cases and benchmarks, so that large inputs need not be stored.

use std::collections::HashMap;
use std::io::{BufWriter, Write};
use std::path::Path;

use glam::DVec3;

use super::real::{Real, Vec3};

/// Smooth bumps that make the blob irregular; more would only cost time.
const BUMP_COUNT: u64 = 16;
/// Keeps the surface well away from its centre, so every point closer than this to the origin
/// is inside (used by tests that shoot rays from inside).
pub const BLOB_MIN_RADIUS: Real = 0.35;

/// A closed, lumpy, sphere-like mesh: an icosahedron subdivided `subdivisions` times
/// (20·4^s triangles) with each vertex moved radially by a smooth noise derived from `seed`.
///
/// Deterministic for a given platform: built in f64 from a stateless hash of the seed. The
/// surface is a radial graph over the unit sphere with a positive radius, so it never folds
/// and every triangle stays wound counter-clockwise seen from outside.
pub fn blob(subdivisions: u32, seed: u64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut directions, mut triangles) = icosahedron();
    for _ in 0..subdivisions {
        triangles = subdivide(&mut directions, &triangles);
    }
    let bumps: Vec<Bump> = (0..BUMP_COUNT).map(|i| Bump::new(seed, i)).collect();
    let positions = directions
        .iter()
        .map(|&u| {
            let radius = 1.0 + bumps.iter().map(|bump| bump.height(u)).sum::<f64>();
            let p = u * radius.max(BLOB_MIN_RADIUS as f64);
            Vec3::new(p.x as Real, p.y as Real, p.z as Real)
        })
        .collect();
    (positions, triangles)
}

/// Writes a plain OBJ (`v` and `f` lines only, 1-based indices). Coordinates are printed in
/// their shortest exact form, so loading the file gives back the same positions.
pub fn write_obj(path: &Path, positions: &[Vec3], triangles: &[[u32; 3]]) -> std::io::Result<()> {
    let mut out = BufWriter::new(std::fs::File::create(path)?);
    for p in positions {
        writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for [a, b, c] in triangles {
        writeln!(out, "f {} {} {}", a + 1, b + 1, c + 1)?;
    }
    out.flush()
}

/// A Gaussian-like bump `height · exp(sharpness · (cos θ − 1))` around a random direction.
struct Bump {
    centre: DVec3,
    height: f64,
    sharpness: f64,
}

impl Bump {
    fn new(seed: u64, index: u64) -> Bump {
        let uniform = |k: u64| unit_interval(hash(seed, index * 4 + k));
        let z = 2.0 * uniform(0) - 1.0;
        let phi = std::f64::consts::TAU * uniform(1);
        let ring = (1.0 - z * z).max(0.0).sqrt();
        Bump {
            centre: DVec3::new(ring * phi.cos(), ring * phi.sin(), z),
            height: 0.5 * uniform(2) - 0.25,
            sharpness: 2.0 + 10.0 * uniform(3),
        }
    }

    fn height(&self, direction: DVec3) -> f64 {
        self.height * (self.sharpness * (direction.dot(self.centre) - 1.0)).exp()
    }
}

/// SplitMix64 of the seed and a stream index: stateless, so any value can be computed alone.
fn hash(seed: u64, index: u64) -> u64 {
    let mut z = seed ^ index.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn unit_interval(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64
}

/// The 12 unit vertices and 20 faces, counter-clockwise seen from outside.
fn icosahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let vertices = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .map(|(x, y, z)| DVec3::new(x, y, z).normalize());
    let faces = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    (vertices.to_vec(), faces)
}

/// Splits every triangle into four through its edge midpoints (pushed out to the unit
/// sphere), keeping the winding. Midpoints are shared through a map keyed by the edge, and
/// numbered in the order triangles are visited, so the result is deterministic.
fn subdivide(directions: &mut Vec<DVec3>, triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3 / 2);
    let mut midpoint = |a: u32, b: u32| {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            directions.push((directions[a as usize] + directions[b as usize]).normalize());
            (directions.len() - 1) as u32
        })
    };
    let mut finer = Vec::with_capacity(triangles.len() * 4);
    for &[a, b, c] in triangles {
        let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
        finer.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    finer
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosahedron_faces_point_outwards() {
        let (vertices, faces) = icosahedron();
        for [a, b, c] in faces {
            let [a, b, c] = [a, b, c].map(|i| vertices[i as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
    }

    #[test]
    fn blob_is_deterministic_and_seed_dependent() {
        assert_eq!(blob(2, 7), blob(2, 7));
        assert_ne!(blob(2, 7).0, blob(2, 8).0);
    }

    #[test]
    fn blob_is_lumpy_but_keeps_its_minimum_radius() {
        let (positions, _) = blob(3, 1);
        let radii: Vec<Real> = positions.iter().map(|p| p.length()).collect();
        let (low, high) = radii
            .iter()
            .fold((Real::MAX, 0.0 as Real), |(l, h), &r| (l.min(r), h.max(r)));
        assert!(low >= BLOB_MIN_RADIUS * 0.999, "{low}");
        assert!(high - low > 0.1, "not irregular: radii in [{low}, {high}]");
    }
}
