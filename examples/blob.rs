//! Writes the procedural blob mesh as an OBJ file: the 20,480-triangle asset of
//! `cases/blob_mesh.toml` and the ≥1M-triangle meshes used for throughput measurements.
//!
//! cargo run --release --example blob -- SUBDIVISIONS SEED OUT.obj
//! (20·4^SUBDIVISIONS triangles: 5 → 20,480; 8 → 1,310,720)

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::geometry::generate::{blob, write_obj};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parsed = match args.as_slice() {
        [subdivisions, seed, out] => subdivisions
            .parse::<u32>()
            .ok()
            .zip(seed.parse::<u64>().ok())
            .map(|(s, seed)| (s, seed, PathBuf::from(out))),
        _ => None,
    };
    let Some((subdivisions, seed, out)) = parsed.filter(|(s, _, _)| *s <= 10) else {
        eprintln!("usage: blob SUBDIVISIONS(0..=10) SEED OUT.obj");
        return ExitCode::from(2);
    };
    let (positions, triangles) = blob(subdivisions, seed);
    // The benchmark mesh goes to cases/bench/assets/, which git ignores and a fresh clone lacks.
    let parent = out.parent().filter(|p| !p.as_os_str().is_empty());
    let written = parent
        .map_or(Ok(()), std::fs::create_dir_all)
        .and_then(|()| write_obj(&out, &positions, &triangles));
    if let Err(error) = written {
        eprintln!("error: cannot write {}: {error}", out.display());
        return ExitCode::FAILURE;
    }
    eprintln!("wrote {} ({} triangles)", out.display(), triangles.len());
    ExitCode::SUCCESS
}
