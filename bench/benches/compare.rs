//! What comparing an 800×800 picture with a golden one costs (`src/compare`), as grading a class
//! compares each student's picture; most of it is FLIP:
//!
//! - `compare/identical`: a picture equal to the golden one (a byte comparison, no FLIP).
//! - `compare/first_difference`: the first differing picture against a golden, which makes the
//!   golden's FLIP reference (its filtered maps and per-pixel halves of the error); a class pays
//!   this once per golden image.
//! - `compare/scattered_200`: 200 scattered pixels differ (FLIP by spreading each difference).
//! - `compare/band_120_rows`: a band of 120 rows differs by a few codes (FLIP by filtering those
//!   rows of the picture).

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use goldray::compare::{Image, Tolerance, compare};
use goldray::rgb_image::{Rgb, RgbImage};

const SIDE: u32 = 800;

/// A render-like picture: a lit disc, gradients, a dark floor.
fn golden() -> RgbImage {
    RgbImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (x as f32 / SIDE as f32, y as f32 / SIDE as f32);
        if (u - 0.5).powi(2) + (v - 0.4).powi(2) < 0.06 {
            Rgb([230, (120.0 + 100.0 * u) as u8, (40.0 + 60.0 * v) as u8])
        } else if v > 0.7 {
            Rgb([30, 30, (60.0 * v) as u8])
        } else {
            Rgb([(200.0 * v) as u8, (180.0 * u) as u8, 220])
        }
    })
}

fn compare_cost(c: &mut Criterion) {
    let golden = golden();
    let mut scattered = golden.clone();
    for i in 0..200u32 {
        let pixel = scattered.get_pixel_mut((i * 97) % SIDE, (i * 389) % SIDE);
        pixel.0 = pixel.0.map(|c| c ^ 0x20);
    }
    let mut band = golden.clone();
    for y in 300..420 {
        for x in 0..SIDE {
            let pixel = band.get_pixel_mut(x, y);
            pixel.0 = pixel.0.map(|c| c.saturating_sub(5));
        }
    }
    let tolerance = Tolerance::DEFAULT;
    let expected = Image::from_rgb8(golden.clone(), "golden.png");
    let [same, scattered, band] = [golden.clone(), scattered, band].map(|p| Image::from_rgb8(p, "student.png"));
    // The golden's FLIP reference, made once as grading makes it.
    compare(&expected, &scattered, &tolerance);

    let mut group = c.benchmark_group("compare");
    group.sample_size(20);
    group.bench_function("identical", |b| b.iter(|| compare(&expected, &same, &tolerance)));
    group.bench_function("first_difference", |b| {
        b.iter_batched(
            || Image::from_rgb8(golden.clone(), "golden.png"),
            |fresh| compare(&fresh, &scattered, &tolerance),
            BatchSize::LargeInput,
        )
    });
    group.bench_function("scattered_200", |b| {
        b.iter(|| compare(&expected, &scattered, &tolerance))
    });
    group.bench_function("band_120_rows", |b| b.iter(|| compare(&expected, &band, &tolerance)));
    group.finish();
}

criterion_group!(benches, compare_cost);
criterion_main!(benches);
