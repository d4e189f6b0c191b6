//! goldray's side of `../shared/perfpeers/run.sh`: closest-hit throughput on the peers' data.
//!
//! cargo run --release --example raybench -- DATA_DIR MESH RAYS THREADS
//! (e.g. `target/perfpeers/data knot1m primary 1`)
//!
//! Reads `DATA_DIR/MESH.verts` (f32 xyz), `DATA_DIR/MESH.tris` (u32 index triples) and
//! `DATA_DIR/RAYS.rays` (6 f32 per ray: origin, unit direction), all little-endian; builds
//! goldray's own `Mesh` (its BVH) on THREADS threads, traces every ray for its closest hit with
//! `t` in (0, ∞) on THREADS threads (the rays split into THREADS contiguous runs, as the Embree
//! benchmark does), best of 3 passes, and prints one line in the Embree benchmark's format:
//!
//! `goldray-raybench knot1m primary thr=1 build=…ms X Mrays/s hit=F sum_t=S`
//!
//! `build` is what Embree's figure measures: building what rays are traced through from the
//! vertex and index arrays (the triangles' boxes, the BVH, the triangle packs;
//! `Mesh::bvh_build_time`). `Mesh::new` also checks the data and computes vertex normals for
//! shading, which Embree does not; `RAYBENCH_MESH_TIME=1` reports the whole of `Mesh::new`
//! instead. `hit` is the fraction of rays that hit and `sum_t` the sum of their hit distances,
//! which must agree with Embree's.
//!
//! `RAYBENCH_PASSES=1` traces the rays once instead of three times (for callgrind), and
//! `GOLDRAY_SIMD` chooses the SIMD path (see `goldray::simd`).

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use goldray::geometry::Ray;
use goldray::geometry::bvh::PACKET;
use goldray::geometry::mesh::{Mesh, VertexNormals};
use goldray::real::{Real, Vec3};

/// Rays handed to `Mesh::intersect_packets` at a time: 128 packets a call (24 KB of hits).
const BATCH: usize = 128 * PACKET;

fn read_le<T>(path: &Path, convert: impl Fn([u8; 4]) -> T) -> Result<Vec<T>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() % 4 != 0 {
        return Err(format!("{}: not a whole number of 4-byte values", path.display()));
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|c| convert([c[0], c[1], c[2], c[3]]))
        .collect())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir, mesh_name, rays_name, threads] = args.as_slice() else {
        eprintln!("usage: raybench DATA_DIR MESH RAYS THREADS");
        return ExitCode::from(2);
    };
    let Some(threads) = threads.parse::<usize>().ok().filter(|&t| t > 0) else {
        eprintln!("raybench: THREADS must be a positive integer");
        return ExitCode::from(2);
    };
    match run(Path::new(dir), mesh_name, rays_name, threads) {
        Ok(line) => {
            println!("{line}");
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("raybench: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(dir: &Path, mesh_name: &str, rays_name: &str, threads: usize) -> Result<String, String> {
    let verts = read_le(&dir.join(format!("{mesh_name}.verts")), f32::from_le_bytes)?;
    let tris = read_le(&dir.join(format!("{mesh_name}.tris")), u32::from_le_bytes)?;
    let ray_data = read_le(&dir.join(format!("{rays_name}.rays")), f32::from_le_bytes)?;
    let positions: Vec<Vec3> = verts
        .chunks_exact(3)
        .map(|v| Vec3::new(v[0] as Real, v[1] as Real, v[2] as Real))
        .collect();
    let triangles: Vec<[u32; 3]> = tris.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let rays: Vec<Ray> = ray_data
        .chunks_exact(6)
        .map(|r| {
            let v = |i: usize| Vec3::new(r[i] as Real, r[i + 1] as Real, r[i + 2] as Real);
            Ray::new(v(0), v(3))
        })
        .collect();

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let build_start = Instant::now();
    let mesh = pool
        .install(|| Mesh::new(&positions, &triangles, VertexNormals::Averaged))
        .map_err(|e| format!("{mesh_name}: {e}"))?;
    let build = if std::env::var_os("RAYBENCH_MESH_TIME").is_some() {
        build_start.elapsed()
    } else {
        mesh.bvh_build_time()
    }
    .as_secs_f64();

    // Rays go eight at a time through `Mesh::intersect_packets`, `BATCH` of them a call, as the
    // renderer's eight-lane integrator traces a band of an image in one call into the kernel
    // (the Embree benchmark makes a call a packet): rays from one point (a pinhole camera's) in
    // tiles of 4×2 pixels when they make a square image (as the Embree benchmark's packets),
    // traced as packets; other rays each on its own way, the eight traversals interleaved.
    // `RAYBENCH_PACKETS=0` traces them one by one through `Mesh::intersect`.
    let from_one_point = rays.iter().all(|ray| ray.origin == rays[0].origin);
    let packets = std::env::var("RAYBENCH_PACKETS").map_or(true, |v| v != "0");
    let rays = if packets && from_one_point { tiles(rays) } else { rays };
    let mut t_out = vec![-1.0f32; rays.len()];
    let per_thread = rays.len().div_ceil(threads).next_multiple_of(8).max(8);
    let mut best = f64::INFINITY;
    let passes = std::env::var("RAYBENCH_PASSES")
        .ok()
        .and_then(|p| p.parse().ok())
        .unwrap_or(3);
    for _ in 0..passes {
        let start = Instant::now();
        std::thread::scope(|scope| {
            for (rays, t_out) in rays.chunks(per_thread).zip(t_out.chunks_mut(per_thread)) {
                let mesh = &mesh;
                scope.spawn(move || {
                    if packets {
                        let mut hits = vec![None; BATCH];
                        for (rays, t_out) in rays.chunks(BATCH).zip(t_out.chunks_mut(BATCH)) {
                            mesh.intersect_packets(rays, Real::INFINITY, &mut hits);
                            for (t, hit) in t_out.iter_mut().zip(&hits) {
                                *t = hit.map_or(-1.0, |hit| hit.t);
                            }
                        }
                    } else {
                        for (ray, t) in rays.iter().zip(t_out) {
                            *t = mesh.intersect(ray, Real::INFINITY).map_or(-1.0, |hit| hit.t);
                        }
                    }
                });
            }
        });
        best = best.min(start.elapsed().as_secs_f64());
    }
    let hits = t_out.iter().filter(|&&t| t >= 0.0).count();
    let sum_t: f64 = t_out.iter().filter(|&&t| t >= 0.0).map(|&t| t as f64).sum();
    Ok(format!(
        "goldray-raybench {mesh_name:<9} {rays_name:<8} thr={threads} build={:7.1}ms {:7.2} Mrays/s hit={:.4} sum_t={sum_t:.3}",
        build * 1e3,
        rays.len() as f64 / best / 1e6,
        hits as f64 / rays.len() as f64,
    ))
}

/// Camera rays of a square image (row by row, as `gen.py` writes them) reordered into tiles of
/// 4×2 pixels, eight consecutive rays a tile, as the Embree benchmark's packets take them: a
/// tile's rays are closer together than a row's eight, so they part ways later in the tree.
/// Rays of any other count stay as they are.
fn tiles(rays: Vec<Ray>) -> Vec<Ray> {
    let side = (rays.len() as f64).sqrt() as usize;
    if side * side != rays.len() || !side.is_multiple_of(4) {
        return rays;
    }
    let mut tiled = Vec::with_capacity(rays.len());
    for tile_y in (0..side).step_by(2) {
        for tile_x in (0..side).step_by(4) {
            for y in tile_y..tile_y + 2 {
                tiled.extend_from_slice(&rays[y * side + tile_x..y * side + tile_x + 4]);
            }
        }
    }
    tiled
}
