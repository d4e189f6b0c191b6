//! Every SIMD path computes the same pictures, bit for bit (docs/ARCHITECTURE.md, "Determinism"):
//! golden files travel between machines whose processors run different paths. Each path this
//! processor can run is forced in turn (`goldray::simd::set_path`), every shipped case is
//! rendered (and a few in double precision too), and each EXR's bytes are compared with the
//! portable path's; so are the hits of the mesh queries (one ray, packets, occlusion) on a
//! generated mesh.
//!
//! The path is process-wide, so this file holds a single test.

use std::fs;
use std::path::{Path, PathBuf};

use goldray::case::{Case, LoadOptions, load};
use goldray::film::encode_exr;
use goldray::geometry::Ray;
use goldray::geometry::bvh::PACKET;
use goldray::geometry::generate::blob;
use goldray::geometry::mesh::{Mesh, MeshHit, VertexNormals};
use goldray::options::Precision;
use goldray::pipeline::render_case;
use goldray::real::{Real, Vec3};
use goldray::simd::{SimdPath, available, set_path};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn cases() -> Vec<Case> {
    let mut files: Vec<PathBuf> = fs::read_dir(Path::new(ROOT).join("cases"))
        .expect("cases/ is readable")
        .map(|entry| entry.expect("entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "toml"))
        .collect();
    files.sort();
    let mut cases: Vec<Case> = files
        .iter()
        .map(|path| load(path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    // Double precision has lanes of its own: a few cases with every kind of shape.
    let doubled: Vec<Case> = cases
        .iter()
        .filter(|case| {
            ["spheres_shadows", "blob_mesh", "transforms", "course_scene07_arch"].contains(&case.name.as_str())
        })
        .map(|case| {
            let mut case = case.clone();
            case.render.precision = Precision::F64;
            case.name.push_str(" (f64)");
            case
        })
        .collect();
    cases.extend(doubled);
    cases
}

/// For a fan of rays: each ray's hit alone, the packet's hits, and whether each ray is blocked.
type FanResults = (Vec<Option<MeshHit>>, Vec<Option<MeshHit>>, Vec<bool>);

/// Rays at a generated blob from all around (coherent fans of eight from one point, and
/// scattered ones), in packets of eight.
fn mesh_queries() -> Vec<FanResults> {
    let (positions, triangles) = blob(5, 3);
    let mesh = Mesh::new(&positions, &triangles, VertexNormals::Averaged).expect("a valid mesh");
    let mut state = 7u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 40) as Real / (1u64 << 24) as Real * 2.0 - 1.0
    };
    let mut results = Vec::new();
    for fan in 0..200 {
        let origin = Vec3::new(uniform(), uniform(), uniform()) * if fan % 2 == 0 { 3.0 } else { 0.3 };
        let aim = Vec3::new(uniform(), uniform(), uniform()) * 0.5 - origin;
        let rays: Vec<Ray> = (0..PACKET)
            .map(|k| {
                let spread = if fan % 3 == 0 { 1.0 } else { 0.02 };
                Ray::new(origin, aim + Vec3::new(uniform(), uniform(), k as Real * 0.01) * spread)
            })
            .collect();
        let one_by_one = rays.iter().map(|ray| mesh.intersect(ray, Real::INFINITY)).collect();
        let packet = mesh.intersect_packet(&rays, Real::INFINITY).to_vec();
        let blocked = rays.iter().map(|ray| mesh.occluded(ray, 2.0)).collect();
        results.push((one_by_one, packet, blocked));
    }
    results
}

#[test]
fn every_simd_path_renders_the_same_exr_bytes() {
    let cases = cases();
    let run = |path: SimdPath| {
        set_path(path).unwrap_or_else(|e| panic!("{e}"));
        let exrs: Vec<Vec<u8>> = cases
            .iter()
            .map(|case| {
                encode_exr(&render_case(case).unwrap_or_else(|e| panic!("{}: {e}", case.name))).expect("encodes")
            })
            .collect();
        (exrs, mesh_queries())
    };
    let (reference, reference_queries) = run(SimdPath::Portable);
    for (one_by_one, packet, _) in &reference_queries {
        assert_eq!(
            &one_by_one[..],
            &packet[..one_by_one.len()],
            "a packet finds what its rays find one by one"
        );
    }
    assert!(
        reference_queries
            .iter()
            .flat_map(|(hits, _, _)| hits)
            .filter(|hit| hit.is_some())
            .count()
            > 500
    );
    let paths = available();
    eprintln!("SIMD paths compared with the portable one: {paths:?}");
    for path in paths.into_iter().filter(|&path| path != SimdPath::Portable) {
        let (exrs, queries) = run(path);
        for (case, (expected, actual)) in cases.iter().zip(reference.iter().zip(&exrs)) {
            assert!(
                expected == actual,
                "{}: the {} path wrote different EXR bytes",
                case.name,
                path.name()
            );
        }
        assert!(
            queries == reference_queries,
            "the {} path found different mesh hits",
            path.name()
        );
    }
    set_path(SimdPath::Portable).expect("always available");
}
