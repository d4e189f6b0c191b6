//! What provenance costs a render command (`src/provenance`):
//!
//! - `provenance/hash/blob_1m`: `pipeline::provenance` on `cases/bench/blob_1m.toml`, which
//!   hashes the case and its 50 MB OBJ (generated on first use, as `cargo run --release --example
//!   blob -- 8 1 cases/bench/assets/blob_1m.obj` writes it); criterion reports bytes/s. The
//!   commands run this beside the scene build, which reads the same file.
//! - `provenance/stamp/exr_512` and `provenance/strip/exr_512`: splicing a full record into a
//!   512×512 EXR's header and taking the run group out again (one copy of the file each).

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use goldray::case::{LoadOptions, load};
use goldray::film::{Film, encode_exr};
use goldray::geometry::generate::{blob, write_obj};
use goldray::pipeline::provenance;
use goldray::provenance::{Group, strip};

fn provenance_cost(c: &mut Criterion) {
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("cases");
    let obj = cases.join("bench/assets/blob_1m.obj");
    if !obj.exists() {
        let (positions, triangles) = blob(8, 1);
        std::fs::create_dir_all(obj.parent().expect("a directory")).expect("cases/bench/assets is writable");
        write_obj(&obj, &positions, &triangles).expect("the blob OBJ is written");
    }
    let case = load(&cases.join("bench/blob_1m.toml"), &LoadOptions::default()).expect("the bench case loads");
    let bytes = std::fs::metadata(&obj).expect("the OBJ exists").len();

    let mut group = c.benchmark_group("provenance");
    group.sample_size(10);
    group.throughput(Throughput::Bytes(bytes));
    group.bench_function("hash/blob_1m", |b| b.iter(|| provenance(&case).expect("hashes")));

    let exr = encode_exr(&Film::new(512, 512)).expect("encodes");
    let made = provenance(&case).expect("hashes").with_run(1.25, 2, Some("bench"));
    let stamped = made.stamp(&exr, "bench").expect("stamps");
    group.throughput(Throughput::Bytes(exr.len() as u64));
    group.bench_function("stamp/exr_512", |b| {
        b.iter(|| made.stamp(&exr, "bench").expect("stamps"))
    });
    group.bench_function("strip/exr_512", |b| {
        b.iter(|| strip(&stamped, Group::Run).expect("strips"))
    });
    group.finish();
}

criterion_group!(benches, provenance_cost);
criterion_main!(benches);
