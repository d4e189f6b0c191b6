//! Calibrates the statistical verdict (docs/statistical-verdict.md): renders every sampled case of
//! `cases/` with other seeds and judges each render against its golden image, as the golden
//! suite does, to measure the false-alarm rate; then renders each planted bug (tests/noise/
//! planted.rs) with other seeds to measure the detection rate, and prints the power the verdict
//! states. For grading's `statistical = true`, it also counts the pixels of each re-seeded
//! picture (8-bit, the case's tone map) that differ from the golden picture by more than one code
//! plus the allowance the golden's variance gives.
//!
//! ```sh
//! cargo run --release --example calibrate_noise               # 50 seeds per case, 10 per bug
//! cargo run --release --example calibrate_noise -- 200 20     # more
//! ```

// Shared with tests/noise.rs, which uses all of it.
#[allow(dead_code)]
#[path = "../tests/noise/planted.rs"]
mod planted;

use std::path::Path;

use rayon::prelude::*;

use goldray::case::{LoadOptions, load};
use goldray::compare::noise::png_allowance;
use goldray::compare::{Image, PNG_DEFAULTS, Tolerance, compare_widened};
use goldray::film::{color_image, read_exr};
use goldray::options::Seeding;

use planted::{Bug, judge, render, reseeded};

/// Seeds far from any case's own.
const FIRST_SEED: u64 = 1000;

fn main() {
    let mut args = std::env::args()
        .skip(1)
        .map(|a| a.parse::<u64>().expect("a whole number of seeds"));
    let seeds = args.next().unwrap_or(50);
    let bug_seeds = args.next().unwrap_or(10);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<_> = std::fs::read_dir(root.join("cases"))
        .expect("cases/ is readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut total_alarms = 0;
    let mut total_runs = 0;
    for file in files {
        let case = load(&file, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        if case.render.trace.samples <= 1 {
            continue;
        }
        let golden_path = root.join("golden").join(format!("{}.snap.exr", case.name));
        let golden = Image::read(&golden_path).unwrap_or_else(|e| panic!("{e}"));
        let seed_list: Vec<u64> = (FIRST_SEED..)
            .filter(|&s| s != case.render.trace.seed)
            .take(seeds as usize)
            .collect();
        let golden_film = read_exr(&golden_path).unwrap_or_else(|e| panic!("{e}"));
        let tonemap = case.render.tonemap;
        let golden_picture = Image::from_rgb8(color_image(&golden_film, tonemap), "golden picture");
        let allowance = png_allowance(&golden_film, tonemap).expect("a sampled golden carries variance");
        let png_rule = Tolerance {
            pixel: 1.0,
            ..PNG_DEFAULTS
        };
        let judged: Vec<(bool, f64, usize)> = seed_list
            .par_iter()
            .map(|&seed| {
                let film = render(&reseeded(&case, seed), Seeding::Seeded);
                let comparison = judge(&case, &golden, &film, "reseeded");
                let z = comparison
                    .noise
                    .as_ref()
                    .and_then(|n| n.strongest)
                    .map_or(0.0, |s| s.z.abs());
                let picture = Image::from_rgb8(color_image(&film, tonemap), "picture");
                let graded = compare_widened(&golden_picture, &picture, &png_rule, &allowance);
                let png_failing = graded.metrics.map_or(usize::MAX, |m| m.failing_pixels);
                (!comparison.verdict.accepts(), z, png_failing)
            })
            .collect();
        let alarms = judged.iter().filter(|(failed, ..)| *failed).count();
        let largest = judged.iter().map(|&(_, z, _)| z).fold(0.0, f64::max);
        let png_worst = judged.iter().map(|&(.., failing)| failing).max().unwrap_or(0);
        let png_total: usize = judged.iter().map(|&(.., failing)| failing).sum();
        total_alarms += alarms;
        total_runs += judged.len();
        let golden_self = judge(&case, &golden, &render(&case, Seeding::Seeded), "golden seed");
        let noise = golden_self.noise.expect("a sampled golden carries variance");
        println!(
            "{}: {} of {} re-seeded renders fail ({:.1}%; nominal {}%); largest |z| {:.2} against the threshold {:.2}",
            case.name,
            alarms,
            judged.len(),
            100.0 * alarms as f64 / judged.len() as f64,
            100.0 * noise.alpha,
            largest,
            noise.z_critical
        );
        println!(
            "  graded as 8-bit pictures (statistical = true, threshold 1 code): {png_total} pixels beyond \
             threshold + allowance in {} pictures of {} pixels, at most {png_worst} in one",
            judged.len(),
            golden.pixels()
        );
        let p = &noise.power;
        let shift = |s: Option<f64>| s.map_or_else(|| "none".to_owned(), |s| format!("{s:.2e}"));
        println!(
            "  power (80%): uniform {}, {}×{} area median {} / least sensitive {}",
            shift(p.uniform_shift),
            p.window,
            p.window,
            shift(p.local_shift_median),
            shift(p.local_shift_worst)
        );
        for bug in Bug::all(&case) {
            let (buggy, seeding) = bug.apply(&case).expect("listed bugs apply");
            let detected = (FIRST_SEED + 500..FIRST_SEED + 500 + bug_seeds)
                .into_par_iter()
                .filter(|&seed| {
                    let film = render(&reseeded(&buggy, seed), seeding);
                    !judge(&case, &golden, &film, "buggy").verdict.accepts()
                })
                .count();
            println!("  {}: detected in {detected} of {bug_seeds}", bug.name(&case));
        }
    }
    println!(
        "all sampled cases: {total_alarms} false alarms in {total_runs} renders ({:.2}%)",
        100.0 * total_alarms as f64 / total_runs.max(1) as f64
    );
}
