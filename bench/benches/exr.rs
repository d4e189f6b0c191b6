//! What writing and reading a render's linear EXR costs (`film::encode_exr`, `film::decode_exr`):
//! each render writes one, and a grading or `goldray diff` reads goldens back.
//!
//! - `exr/encode_800`, `exr/decode_800`: an 800×800 film with depth, normals and variance (the
//!   ten channels of a sampled render), its colour smooth with a little per-pixel noise as a
//!   sampled render's is; on rayon's pool of one thread and of two (the blocks are compressed and
//!   decompressed side by side).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use goldray::film::{Film, decode_exr, encode_exr};

const SIDE: u32 = 800;

/// A stateless hash of a pixel and a channel to `[0, 1)`: the film's noise.
fn noise(k: usize, salt: u32) -> f32 {
    let mut h = (k as u32).wrapping_mul(0x9e37_79b9) ^ salt.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    (h >> 8) as f32 / (1 << 24) as f32
}

/// A render-like film: a lit disc over gradients, a floor plane's depth, two normals.
fn film() -> Film {
    let mut film = Film::new(SIDE, SIDE);
    for k in 0..film.color.len() {
        let (x, y) = (
            (k as u32 % SIDE) as f32 / SIDE as f32,
            (k as u32 / SIDE) as f32 / SIDE as f32,
        );
        let disc = (x - 0.5).powi(2) + (y - 0.4).powi(2) < 0.06;
        let jitter = 0.02 * noise(k, 1);
        film.color[k] = if disc {
            [0.9 + jitter, 0.5 * x, 0.3 * y]
        } else {
            [0.8 * y, 0.7 * x + jitter, 0.9]
        };
        film.depth[k] = if y > 0.7 { 2.0 / (y - 0.69) } else { f32::INFINITY };
        film.normal[k] = if disc { [x - 0.5, y - 0.4, 0.8] } else { [0.0, 1.0, 0.0] };
    }
    film.variance = Some(
        (0..film.color.len())
            .map(|k| [0.01 * noise(k, 2), 0.01 * noise(k, 3), 0.01 * noise(k, 4)])
            .collect(),
    );
    film
}

fn exr_cost(c: &mut Criterion) {
    let film = film();
    let bytes = encode_exr(&film).expect("encodes");
    let mut group = c.benchmark_group("exr");
    group.sample_size(20);
    group.throughput(Throughput::Bytes(bytes.len() as u64));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        group.bench_function(format!("encode_800/{threads}_threads"), |b| {
            b.iter(|| pool.install(|| encode_exr(&film).expect("encodes")))
        });
        group.bench_function(format!("decode_800/{threads}_threads"), |b| {
            b.iter(|| pool.install(|| decode_exr(&bytes).expect("decodes")))
        });
    }
    group.finish();
}

criterion_group!(benches, exr_cost);
criterion_main!(benches);
