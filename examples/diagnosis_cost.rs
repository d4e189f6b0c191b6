//! What diagnosis costs: grades a synthetic class on the shipped course rubric (the seven
//! commands at 800×800, 21 images a student) with and without diagnosis, and prints the times.
//!
//! ```sh
//! cargo run --release --example diagnosis_cost -- [STUDENTS] [DIR]
//! ```
//!
//! The class (default 24 students, in `target/diagnosis-cost/`) is drawn by goldray: a quarter of
//! the students correct, half with one catalogue mistake, a quarter with two, chosen in turn from
//! the catalogue. Grading runs five times on the same class, the golden renders cached
//! beforehand: without diagnosis; with diagnosis and no fault pictures cached (the first grading
//! of a term); with diagnosis twice more (the cache warm); and without diagnosis again. The
//! figures printed are the faster of each pair, so that the machine's load moves them less.

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use goldray::fault::{Fault, FaultSet};
use goldray::film::{Tonemap, encode_png, picture_with_faults};
use goldray::grade::{ClassReport, Diagnose, GradeOptions, grade_class_diagnosing, load_rubric};
use goldray::pipeline::{FaultRenderer, fault_applies};
use goldray::progress::Silent;

fn main() {
    let mut args = std::env::args().skip(1);
    let students: usize = args.next().map_or(24, |n| n.parse().expect("STUDENTS is a number"));
    let dir = PathBuf::from(args.next().unwrap_or_else(|| "target/diagnosis-cost".to_owned()));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rubric_path = root.join("rubrics/mit6837.toml");
    let rubric = load_rubric(&rubric_path).unwrap_or_else(|e| panic!("{e}"));
    if dir.exists() {
        fs::remove_dir_all(&dir).unwrap();
    }
    let submissions = dir.join("submissions");

    // Mistakes that show in at least one course picture, in catalogue order.
    let shown: Vec<FaultSet> = Fault::ALL
        .iter()
        .filter(|f| rubric.renders.iter().any(|r| fault_applies(&r.case, **f)))
        .map(|f| FaultSet::single(*f))
        .collect();
    let started = Instant::now();
    let renderers: Vec<FaultRenderer> = rubric.renders.iter().map(|r| FaultRenderer::new(&r.case)).collect();
    let mut next = 0;
    for student in 0..students {
        let faults = match student % 4 {
            0 => FaultSet::NONE,
            3 => {
                next += 2;
                shown[(next - 2) % shown.len()].union(shown[(next - 1) % shown.len()])
            }
            _ => {
                next += 1;
                shown[(next - 1) % shown.len()]
            }
        };
        let folder = submissions.join(format!("{student:02}-{faults}"));
        fs::create_dir_all(&folder).unwrap();
        let mut films = std::collections::HashMap::new();
        for spec in &rubric.images {
            let film = films
                .entry(spec.render_index)
                .or_insert_with(|| renderers[spec.render_index].render(&faults.render_part()).unwrap());
            let picture = spec.output.picture();
            let image = picture_with_faults(film, picture, Tonemap::Clamp, &faults);
            fs::write(folder.join(&spec.file), encode_png(&image).unwrap()).unwrap();
        }
    }
    println!(
        "class of {students} students drawn in {:.1} s ({} threads)",
        started.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );

    let cache = dir.join("cache");
    let grade = |name: &str, diagnose: Diagnose| -> (f64, ClassReport) {
        let options = GradeOptions {
            out: dir.join(name),
            cache: Some(cache.clone()),
            ..GradeOptions::default()
        };
        let started = Instant::now();
        let report = grade_class_diagnosing(&rubric_path, &submissions, &options, diagnose, &Silent)
            .unwrap_or_else(|e| panic!("{e}"));
        (started.elapsed().as_secs_f64(), report)
    };
    // The goldens rendered once, so that every timed run reads them from the cache. Each warm
    // figure is the faster of two runs, one early and one late, against the load's drift.
    grade("warm-up", Diagnose::No);
    let (without_first, _) = grade("without", Diagnose::No);
    let (cold, report) = grade("cold", Diagnose::Yes);
    let (warm_first, _) = grade("warm", Diagnose::Yes);
    let (warm_second, _) = grade("warm-again", Diagnose::Yes);
    let (without_second, _) = grade("without-again", Diagnose::No);
    let (without, warm) = (without_first.min(without_second), warm_first.min(warm_second));
    let run = report.diagnosis.expect("diagnosed");
    let rendered: usize = run.renders.iter().map(|r| r.rendered).sum();
    let sets: usize = run.renders.iter().map(|r| r.fault_sets).sum();
    println!("images that lost points: {}, explained: {}", run.images, run.explained);
    println!("fault sets compared: {sets}, rendered on the cold run: {rendered}");
    println!("grading without diagnosis:          {without:7.1} s ({without_first:.1} and {without_second:.1})");
    println!(
        "with diagnosis, fault cache cold:   {cold:7.1} s ({:.2}x)",
        cold / without
    );
    println!(
        "with diagnosis, fault cache warm:   {warm:7.1} s ({:.2}x; {warm_first:.1} and {warm_second:.1})",
        warm / without
    );
}
