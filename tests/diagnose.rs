//! Diagnosis in `goldray grade` (issue 15) on the course rubric's seven commands, at 100×100:
//! a class of imagined students, one per catalogue fault (and family member), whose 21 images
//! goldray renders with that fault, plus students with two faults, correct students and noisy
//! ones. Every image a fault made lose points must be diagnosed as that fault; an image that kept
//! its points gets no diagnosis; nothing is blamed on a mistake that was not made.
//!
//! The same class is graded a second time with every picture perturbed the way an independent
//! program differs from goldray (a camera moved by a fraction of a pixel, ±1-code noise), so
//! that the rule is not tuned to goldray's own renders alone.

// Shared with tests/grade.rs, which uses all of it.
#[allow(dead_code)]
#[path = "grade/chromium.rs"]
mod chromium;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

mod util;

use goldray::case::Case;
use goldray::fault::{Fault, FaultSet};
use goldray::film::{encode_png, picture_with_faults};
use goldray::grade::{ClassReport, GradeOptions, StudentResult, UNEXPLAINED, grade_class, load_rubric};
use goldray::pipeline::{FaultRenderer, fault_applies};
use goldray::progress::Silent;
use goldray::rgb_image::{Rgb, RgbImage, read_png};

const SIZE: u32 = 100;

/// The shipped course rubric at `SIZE`, its paths made absolute, written into `dir`.
fn course_rubric(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = fs::read_to_string(root.join("rubrics/mit6837.toml"))
        .unwrap()
        .replace("size = [800, 800]", &format!("size = [{SIZE}, {SIZE}]"))
        .replace("\"../", &format!("\"{}/", root.display()));
    fs::create_dir_all(dir).unwrap();
    let path = dir.join("mit6837.toml");
    fs::write(&path, text).unwrap();
    path
}

/// How an imagined student's picture differs from goldray's beyond the faults.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Perturbation {
    None,
    /// The camera turned by a twentieth of a pixel, and ±1 code of noise.
    Independent,
}

/// One renderer per render of the rubric, each building its scenes once for every student.
fn renderers_for(rubric: &goldray::grade::Rubric, perturbation: Perturbation) -> Vec<FaultRenderer> {
    rubric
        .renders
        .iter()
        .map(|render| {
            let mut case: Case = render.case.clone();
            if perturbation == Perturbation::Independent {
                jitter_camera(&mut case);
            }
            FaultRenderer::new(&case)
        })
        .collect()
}

/// The 21 pictures of a program with `faults`, as files in `folder`.
fn write_student(
    rubric: &goldray::grade::Rubric,
    renderers: &[FaultRenderer],
    faults: &FaultSet,
    perturbation: Perturbation,
    folder: &Path,
) {
    fs::create_dir_all(folder).unwrap();
    let mut films = BTreeMap::new();
    for spec in &rubric.images {
        let film = films
            .entry(spec.render_index)
            .or_insert_with(|| renderers[spec.render_index].render(&faults.render_part()).unwrap());
        let picture = spec.output.picture();
        let mut image = picture_with_faults(film, picture, goldray::film::Tonemap::Clamp, faults);
        if perturbation == Perturbation::Independent {
            image = noise(&image, 1);
        }
        fs::write(folder.join(&spec.file), encode_png(&image).unwrap()).unwrap();
    }
}

/// Turns the camera sideways by a twentieth of a pixel: every pixel's ray moves by that much,
/// whatever its depth, as sampling or rounding that differs from goldray's might move it.
fn jitter_camera(case: &mut Case) {
    let d = case.camera.direction;
    let up = case.camera.up;
    let side = [
        d[1] * up[2] - d[2] * up[1],
        d[2] * up[0] - d[0] * up[2],
        d[0] * up[1] - d[1] * up[0],
    ];
    let length = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    // A pixel spans 2·tan(fov/2)/(size − 1) of the unit-distance image plane.
    let turn = 2.0 * (case.camera.fov.to_radians() / 2.0).tan() / f64::from(SIZE - 1) / 20.0 * length(d);
    for axis in 0..3 {
        case.camera.direction[axis] += side[axis] / length(side) * turn;
    }
}

/// ±`amplitude` codes of deterministic noise per channel.
fn noise(picture: &RgbImage, amplitude: i16) -> RgbImage {
    RgbImage::from_fn(picture.width(), picture.height(), |x, y| {
        let mut p = picture.get_pixel(x, y).0;
        for (c, v) in p.iter_mut().enumerate() {
            let hash = (u64::from(x) << 40 | u64::from(y) << 20 | c as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let offset = ((hash >> 33) % (2 * amplitude as u64 + 1)) as i16 - amplitude;
            *v = (i16::from(*v) + offset).clamp(0, 255) as u8;
        }
        Rgb(p)
    })
}

/// Every fault once, families with one member each (the usual one, and a second where the
/// family's members differ in kind).
fn catalogue() -> Vec<FaultSet> {
    let mut sets: Vec<FaultSet> = Fault::ALL.iter().map(|f| FaultSet::single(*f)).collect();
    for extra in [
        "gamma-applied=2.2",
        "gamma-applied=1.8",
        "specular-unnormalized-reflection=t",
        "pixel-mapping=upside-down",
        "pixel-mapping=mirrored",
        "wrong-bounces=3",
        "cubemap-face-flipped=horizontal",
    ] {
        sets.push(extra.parse().unwrap());
    }
    sets.retain(|s| s.to_string() != "wrong-bounces=0");
    sets.push("wrong-bounces=5".parse().unwrap());
    sets
}

/// Two faults at once.
const PAIRS: [&str; 5] = [
    "no-shadows+gamma-applied=srgb",
    "no-specular+no-ambient",
    "no-reflections+pixel-mapping=upside-down",
    "falloff-linear+depth-inverted",
    "blinn-phong+normals-not-remapped",
];

/// The course's starter code as shipped: flat colours, and no plane, triangle or transform
/// intersection, no point light, no background (the point light cannot show under flat colours).
/// Its render loop writes a miss's depth from `t = FLT_MAX`, whose conversion to a code overflows:
/// x86 writes that as 0, black as the course's, and so does this starter.
const STARTER: &str = "nothing-shaded+plane-missing+triangle-missing+transform-missing+background-missing";
/// The same starter built on ARM, whose conversion saturates: its depth misses are white. Some of
/// its parts show only together (scene 7's depth image is all white: no floor, no arch, white
/// misses), which only the search down from every part not written finds.
const STARTER_ARM: &str =
    "nothing-shaded+plane-missing+triangle-missing+transform-missing+depth-miss-white+background-missing";

struct Graded {
    dir: PathBuf,
    report: ClassReport,
    /// Each student's fault set (`none` for the correct ones).
    made: BTreeMap<String, FaultSet>,
    seconds: f64,
}

fn grade(name: &str, perturbation: Perturbation) -> Graded {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    if dir.exists() {
        fs::remove_dir_all(&dir).unwrap();
    }
    let rubric_path = course_rubric(&dir);
    let rubric = load_rubric(&rubric_path).unwrap();
    let submissions = dir.join("submissions");
    let renderers = renderers_for(&rubric, perturbation);
    let mut made = BTreeMap::new();
    let mut students: Vec<(String, FaultSet)> = catalogue().into_iter().map(|s| (s.to_string(), s)).collect();
    students.extend(PAIRS.iter().map(|p| (p.replace('+', " + "), p.parse().unwrap())));
    students.push(("correct".to_owned(), FaultSet::NONE));
    students.push(("starter".to_owned(), STARTER.parse().unwrap()));
    students.push(("starter-arm".to_owned(), STARTER_ARM.parse().unwrap()));
    for (name, faults) in &students {
        write_student(&rubric, &renderers, faults, perturbation, &submissions.join(name));
        made.insert(name.clone(), *faults);
    }
    if perturbation == Perturbation::None {
        // ±3 codes of noise on the golden pictures: nothing to blame on a mistake.
        let folder = submissions.join("noisy");
        write_student(&rubric, &renderers, &FaultSet::NONE, Perturbation::None, &folder);
        for spec in &rubric.images {
            let picture = read_png(&folder.join(&spec.file)).unwrap();
            fs::write(folder.join(&spec.file), encode_png(&noise(&picture, 3)).unwrap()).unwrap();
        }
        made.insert("noisy".to_owned(), FaultSet::NONE);
        // The golden pictures rendered again on one thread, and re-encoded by another encoder.
        let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let single = renderers_for(&rubric, Perturbation::None);
        one_thread.install(|| {
            write_student(
                &rubric,
                &single,
                &FaultSet::NONE,
                Perturbation::None,
                &submissions.join("one-thread"),
            )
        });
        made.insert("one-thread".to_owned(), FaultSet::NONE);
        let reencoded = submissions.join("re-encoded");
        fs::create_dir_all(&reencoded).unwrap();
        for spec in &rubric.images {
            let picture = read_png(&submissions.join("correct").join(&spec.file)).unwrap();
            let rgba = util::png_in_layout(&picture, png::ColorType::Rgba, png::BitDepth::Eight);
            fs::write(reencoded.join(&spec.file), rgba).unwrap();
        }
        made.insert("re-encoded".to_owned(), FaultSet::NONE);
    }
    // One cache for both classes: the mistakes' pictures are rendered once.
    let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-cache");
    let options = GradeOptions {
        out: dir.join("report"),
        cache: Some(cache),
        ..GradeOptions::default()
    };
    let started = Instant::now();
    let report = grade_class(&rubric_path, &submissions, &options, &Silent).unwrap_or_else(|e| panic!("{e}"));
    Graded {
        dir,
        report,
        made,
        seconds: started.elapsed().as_secs_f64(),
    }
}

fn exact() -> &'static Graded {
    static GRADED: OnceLock<Graded> = OnceLock::new();
    GRADED.get_or_init(|| grade("diagnose-exact", Perturbation::None))
}

fn independent() -> &'static Graded {
    static GRADED: OnceLock<Graded> = OnceLock::new();
    GRADED.get_or_init(|| grade("diagnose-independent", Perturbation::Independent))
}

/// How each image of each student was diagnosed, against what the student did.
#[derive(Default, Debug)]
struct Tally {
    /// Images that lost points, and those whose diagnosis names a fault the student made.
    lost: usize,
    named: usize,
    unexplained: Vec<String>,
    /// A mistake the student did not make: the one thing a diagnosis must never do.
    wrong: Vec<String>,
    /// An image with full points and a diagnosis anyway.
    spurious: Vec<String>,
}

/// `visible`: whether the student's mistakes cost this image points by themselves (in the class
/// without perturbations); images that lost points only to the perturbation are not counted.
fn tally(graded: &Graded, students: impl Fn(&str) -> bool, visible: impl Fn(&str, &str) -> bool) -> Tally {
    let mut tally = Tally::default();
    for student in graded.report.students.iter().filter(|s| students(&s.name)) {
        let made = graded.made[&student.name];
        for image in &student.images {
            let what = format!("{} {}", student.name, image.file);
            let Some(diagnosis) = &image.diagnosis else {
                continue;
            };
            if !goldray::grade::loses_points(image) {
                tally.spurious.push(what);
                continue;
            }
            let ids: Vec<&str> = made.faults().map(|f| f.name()).collect();
            let named_or_tied = diagnosis
                .id
                .split('+')
                .chain(diagnosis.alternatives.iter().flat_map(|a| a.split('+')));
            if !visible(&student.name, &image.file) {
                if diagnosis.id != UNEXPLAINED && !named_or_tied.clone().any(|id| ids.contains(&id)) {
                    tally.wrong.push(format!(
                        "{what}: {} (lost points only to the perturbation)",
                        diagnosis.id
                    ));
                }
                continue;
            }
            tally.lost += 1;
            if diagnosis.id == UNEXPLAINED {
                tally.unexplained.push(format!(
                    "{what} (closest {:?})",
                    diagnosis.closest.as_ref().map(|c| &c.faults)
                ));
                continue;
            }
            let named: Vec<&str> = diagnosis.id.split('+').collect();
            let alternatives: Vec<&str> = diagnosis.alternatives.iter().flat_map(|a| a.split('+')).collect();
            if named.iter().all(|id| ids.contains(id)) {
                tally.named += 1;
            } else if named.len() == 1 && alternatives.iter().any(|a| ids.contains(a)) {
                // Two mistakes that draw this image alike: either is right.
                tally.named += 1;
            } else {
                tally.wrong.push(format!(
                    "{what}: {} ({:?})",
                    diagnosis.faults.as_deref().unwrap_or("?"),
                    diagnosis.alternatives
                ));
            }
        }
    }
    tally
}

fn student<'a>(graded: &'a Graded, name: &str) -> &'a StudentResult {
    graded.report.students.iter().find(|s| s.name == name).unwrap()
}

#[test]
fn every_catalogue_fault_is_named_on_every_image_it_costs_points() {
    let graded = exact();
    let tally = tally(
        graded,
        |name| !name.contains(" + ") && !["correct", "noisy", "starter", "starter-arm"].contains(&name),
        |_, _| true,
    );
    println!(
        "graded in {:.1} s; diagnosis {:?}",
        graded.seconds,
        graded.report.diagnosis.as_ref().map(|d| d.seconds)
    );
    println!("{tally:#?}");
    assert!(
        tally.spurious.is_empty(),
        "diagnosed images that kept their points: {:?}",
        tally.spurious
    );
    assert!(
        tally.wrong.is_empty(),
        "blamed on mistakes not made: {:#?}",
        tally.wrong
    );
    assert!(tally.unexplained.is_empty(), "not diagnosed: {:#?}", tally.unexplained);
    assert!(tally.lost > 200, "only {} images lost points", tally.lost);
    // Every fault the course's scenes can show costs points somewhere.
    for fault in Fault::ALL {
        let shown = graded
            .report
            .students
            .iter()
            .any(|s| s.name.starts_with(fault.name()) && s.images.iter().any(goldray::grade::loses_points));
        let applies = load_rubric(&course_rubric(
            &Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-rubric"),
        ))
        .unwrap()
        .renders
        .iter()
        .any(|r| fault_applies(&r.case, fault));
        if !shown {
            println!("{fault}: changes no course image enough to cost points (applies: {applies})");
        }
    }
}

#[test]
fn two_faults_at_once_name_at_least_one_and_nothing_else() {
    let graded = exact();
    let tally = tally(graded, |name| name.contains(" + "), |_, _| true);
    println!("{tally:#?}");
    assert!(tally.wrong.is_empty(), "{:#?}", tally.wrong);
    assert!(tally.spurious.is_empty(), "{:?}", tally.spurious);
    for pair in PAIRS {
        let name = pair.replace('+', " + ");
        let diagnosed: Vec<&str> = student(graded, &name)
            .images
            .iter()
            .filter_map(|i| i.diagnosis.as_ref())
            .filter(|d| d.id != UNEXPLAINED)
            .map(|d| d.id.as_str())
            .collect();
        assert!(!diagnosed.is_empty(), "{pair}: nothing named");
    }
    let both = student(graded, "no-shadows + gamma-applied=srgb");
    assert_eq!(
        both.images[18].diagnosis.as_ref().map(|d| d.id.as_str()),
        Some("no-shadows+gamma-applied"),
        "a07.png carries both mistakes"
    );
}

#[test]
fn correct_and_noisy_submissions_get_no_mistake() {
    let graded = exact();
    for name in ["correct", "noisy", "one-thread", "re-encoded"] {
        for image in &student(graded, name).images {
            let diagnosis = image.diagnosis.as_ref().map(|d| d.id.as_str());
            assert!(
                diagnosis.is_none() || diagnosis == Some(UNEXPLAINED),
                "{name} {}: {diagnosis:?}",
                image.file
            );
        }
    }
    for name in ["correct", "one-thread", "re-encoded"] {
        let images = &student(graded, name).images;
        assert!(
            images.iter().all(|i| i.diagnosis.is_none() && i.points == i.max_points),
            "{name}"
        );
    }
}

/// The starter code's output: every colour image its flat material colours.
#[test]
fn the_starter_codes_flat_colours_are_nothing_shaded() {
    let graded = exact();
    let colour: Vec<_> = student(graded, "nothing-shaded")
        .images
        .iter()
        .filter(|i| !i.file.ends_with("n.png") && !i.file.ends_with("d.png"))
        .collect();
    assert_eq!(colour.len(), 7);
    for image in colour {
        assert_eq!(
            image.diagnosis.as_ref().map(|d| d.id.as_str()),
            Some("nothing-shaded"),
            "{}",
            image.file
        );
    }
}

#[test]
fn an_independent_programs_mistakes_are_diagnosed_too() {
    let lost_exactly: std::collections::HashSet<(String, String)> = exact()
        .report
        .students
        .iter()
        .flat_map(|s| {
            s.images
                .iter()
                .filter(|i| goldray::grade::loses_points(i))
                .map(move |i| (s.name.clone(), i.file.clone()))
        })
        .collect();
    let graded = independent();
    // Where the independent program without mistakes keeps its points, its mistakes must show.
    let correct = student(graded, "correct");
    let correct_passes = |file: &str| {
        correct
            .images
            .iter()
            .any(|i| i.file == file && !goldray::grade::loses_points(i))
    };
    for image in &correct.images {
        println!(
            "correct {}: {} ({})",
            image.file,
            image.outcome.word(),
            image.explanation
        );
    }
    let tally = tally(
        graded,
        |name| name != "correct",
        |name, file| lost_exactly.contains(&(name.to_owned(), file.to_owned())) && correct_passes(file),
    );
    println!("graded in {:.1} s", graded.seconds);
    println!("{tally:#?}");
    let accuracy = tally.named as f64 / tally.lost.max(1) as f64;
    let accused = accusations(graded);
    println!(
        "false accusations: {} of {} images that lost points and were named ({:.2}%)",
        tally.wrong.len(),
        accused,
        100.0 * tally.wrong.len() as f64 / accused.max(1) as f64
    );
    // Acne drawn elsewhere (the camera moved) is still acne, by its signature.
    let acne = student(graded, "shadow-acne")
        .images
        .iter()
        .find(|i| i.file == "a07.png")
        .unwrap();
    assert_eq!(
        acne.diagnosis.as_ref().map(|d| d.id.as_str()),
        Some("shadow-acne"),
        "{}",
        acne.explanation
    );
    for (name, summary) in [
        (
            "starter",
            "unfinished: shading, planes, triangles, transforms and the background are not implemented",
        ),
        (
            "starter-arm",
            "unfinished: shading, planes, triangles, transforms, misses in the depth image and the background are \
             not implemented",
        ),
    ] {
        let starter = student(graded, name);
        assert_eq!(
            starter.unfinished.as_ref().map(|u| u.summary.as_str()),
            Some(summary),
            "{:#?}",
            starter
                .images
                .iter()
                .map(|i| (&i.file, i.diagnosis.as_ref().map(|d| &d.id)))
                .collect::<Vec<_>>()
        );
    }
    println!(
        "named {} of {} images that lost points ({:.1}%)",
        tally.named,
        tally.lost,
        100.0 * accuracy
    );
    assert!(
        tally.wrong.is_empty(),
        "blamed on mistakes not made: {:#?}",
        tally.wrong
    );
    assert!(accuracy >= 0.9, "{accuracy}");
}

/// How many images a class's diagnoses name a mistake on (what a false accusation is counted
/// against).
fn accusations(graded: &Graded) -> usize {
    graded
        .report
        .students
        .iter()
        .flat_map(|s| &s.images)
        .filter(|i| i.diagnosis.as_ref().is_some_and(|d| d.id != UNEXPLAINED))
        .count()
}

/// The starter code as shipped is one "unfinished" finding with its parts, whatever its images
/// draw alike (a missing transform and a reversed one; a narrow view and missing planes).
#[test]
fn the_starter_code_is_unfinished_with_its_parts() {
    let graded = exact();
    for (name, parts_made) in [("starter", STARTER), ("starter-arm", STARTER_ARM)] {
        let starter = student(graded, name);
        let unfinished = starter.unfinished.as_ref().expect("an unfinished finding");
        let parts: Vec<&str> = unfinished.parts.iter().map(|p| p.id.as_str()).collect();
        assert_eq!(
            parts,
            parts_made.split('+').collect::<Vec<_>>(),
            "{}",
            unfinished.summary
        );
        let made: FaultSet = parts_made.parse().unwrap();
        for image in starter.images.iter().filter(|i| goldray::grade::loses_points(i)) {
            let diagnosis = image.diagnosis.as_ref().unwrap();
            assert_ne!(diagnosis.id, UNEXPLAINED, "{name} {}", image.file);
            let named: FaultSet = diagnosis.id.parse().unwrap();
            assert!(
                named.faults().all(|f| made.contains(f)),
                "{name} {}: {}",
                image.file,
                diagnosis.id
            );
        }
    }
}

#[test]
fn grades_json_has_a_diagnosis_exactly_where_points_were_lost() {
    let graded = exact();
    let json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(graded.dir.join("report/grades.json")).unwrap()).unwrap();
    let mut diagnosed = 0;
    for student in json["students"].as_array().unwrap() {
        for image in student["images"].as_array().unwrap() {
            let lost = matches!(image["verdict"].as_str(), Some("partial" | "fail"));
            let diagnosis = &image["diagnosis"];
            assert_eq!(!diagnosis.is_null(), lost, "{} {}", student["name"], image["file"]);
            if lost {
                diagnosed += 1;
                for key in ["id", "explanation", "confidence", "golden", "explained"] {
                    assert!(!diagnosis[key].is_null(), "{key} in {diagnosis}");
                }
                if diagnosis["id"] != UNEXPLAINED {
                    assert!(diagnosis["residual"]["failing_fraction"].is_number(), "{diagnosis}");
                    assert!(diagnosis["residual_metrics"]["flip"].is_number(), "{diagnosis}");
                    assert!(diagnosis["mistake_image"].is_string(), "{diagnosis}");
                }
            }
        }
    }
    assert!(diagnosed > 250);
    assert!(
        json.get("diagnosis").is_none(),
        "what diagnosis cost is in run.json, not in the grades"
    );
    let run: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(graded.dir.join("report/run.json")).unwrap()).unwrap();
    assert!(run["diagnosis"]["renders"].as_array().unwrap().len() == 7, "{run}");
    let csv = fs::read_to_string(graded.dir.join("report/grades.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",flags,diagnoses"), "{csv}");
    assert!(
        csv.lines()
            .any(|l| l.starts_with("no-shadows,") && l.ends_with(",no-shadows")),
        "{csv}"
    );
}

#[test]
fn the_report_shows_the_mistakes_in_headless_chromium() {
    let graded = exact();
    let out = graded.dir.join("report");
    let dom = chromium::dump_dom(&out.join("index.html"));
    assert!(dom.contains("data-images-broken=\"0\""), "a picture did not load");
    assert!(dom.contains("<h2>Mistakes in the class</h2>"));
    for id in ["no-shadows", "gamma-applied", "nothing-shaded", "pixel-mapping"] {
        assert!(
            dom.contains(&format!("data-mistake=\"{id}\"")),
            "{id} is not in the histogram"
        );
    }
    let page = out.join(&student(graded, "no-shadows + gamma-applied=srgb").page);
    let dom = chromium::dump_dom(&page);
    assert!(
        dom.contains("data-images-broken=\"0\""),
        "a picture did not load:\n{dom}"
    );
    let leads = dom
        .find("<h2>What went wrong</h2>")
        .expect("the page leads with the mistakes");
    let first_image = dom.find("<section class=\"image").unwrap();
    assert!(leads < first_image, "the mistakes come before the images");
    for needle in [
        "data-mistake=\"no-shadows\"",
        "data-mistake=\"gamma-applied\"",
        "Explains <a href=\"#a07.png\">a07.png</a>.",
        "the mistake's render",
        "together with <code class=\"id\">gamma-applied</code>",
    ] {
        assert!(dom.contains(needle), "{needle}");
    }
    let shot = chromium::screenshot(&page, 1200, 1000, &out.join("mistakes.png"));
    let colours: std::collections::HashSet<[u8; 3]> = shot.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 500,
        "the screenshot looks blank: {} colours",
        colours.len()
    );
    chromium::screenshot(&out.join("index.html"), 1200, 1400, &out.join("index.png"));
}

/// The mistakes' pictures are stored once per distinct picture (most mistakes leave a render's
/// normals and depth as the golden draws them), every set's file a link to it, and a grading
/// that reads them back names the same mistakes.
#[cfg(unix)]
#[test]
fn the_mistake_cache_stores_each_picture_once() {
    use std::os::unix::fs::MetadataExt;
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-content-cache");
    if dir.exists() {
        fs::remove_dir_all(&dir).unwrap();
    }
    let rubric_path = course_rubric(&dir);
    let rubric = load_rubric(&rubric_path).unwrap();
    let renderers = renderers_for(&rubric, Perturbation::None);
    let submissions = dir.join("submissions");
    let made: FaultSet = "no-shadows".parse().unwrap();
    write_student(&rubric, &renderers, &made, Perturbation::None, &submissions.join("s"));
    let grade = |out: &str| {
        let options = GradeOptions {
            out: dir.join(out),
            cache: Some(dir.join("cache")),
            ..GradeOptions::default()
        };
        grade_class(&rubric_path, &submissions, &options, &Silent).unwrap()
    };
    let first = grade("first");
    let faults = dir.join("cache/faults");
    let (mut files, mut inodes, mut contents) = (0, std::collections::HashSet::new(), 0);
    for render in fs::read_dir(&faults).unwrap() {
        for set in fs::read_dir(render.unwrap().path()).unwrap() {
            let set = set.unwrap().path();
            for file in fs::read_dir(&set).unwrap() {
                let meta = file.unwrap().metadata().unwrap();
                if set.ends_with("by-content") {
                    contents += 1;
                } else {
                    files += 1;
                    inodes.insert((meta.dev(), meta.ino()));
                }
            }
        }
    }
    assert!(files > 0, "nothing cached in {}", faults.display());
    assert_eq!(
        inodes.len(),
        contents,
        "every set's file is a link to one stored picture"
    );
    assert!(contents * 2 < files, "{contents} pictures stored for {files} files");

    let second = grade("second");
    let read: usize = second
        .diagnosis
        .as_ref()
        .unwrap()
        .renders
        .iter()
        .map(|r| r.cached)
        .sum();
    let rendered: usize = second
        .diagnosis
        .as_ref()
        .unwrap()
        .renders
        .iter()
        .map(|r| r.rendered)
        .sum();
    assert!(read > 0 && rendered == 0, "read {read}, rendered {rendered}");
    let ids = |report: &ClassReport| -> Vec<Option<String>> {
        report.students[0]
            .images
            .iter()
            .map(|i| i.diagnosis.as_ref().map(|d| d.id.clone()))
            .collect()
    };
    assert_eq!(ids(&first), ids(&second));
    assert!(ids(&second).contains(&Some("no-shadows".to_owned())));
}

#[test]
fn a_rubric_can_grant_credit_per_mistake() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-credit");
    if dir.exists() {
        fs::remove_dir_all(&dir).unwrap();
    }
    let plain = course_rubric(&dir);
    let rubric = load_rubric(&plain).unwrap();
    let renderers = renderers_for(&rubric, Perturbation::None);
    let submissions = dir.join("submissions");
    write_student(
        &rubric,
        &renderers,
        &"no-shadows".parse().unwrap(),
        Perturbation::None,
        &submissions.join("s"),
    );
    let credited = dir.join("credited.toml");
    let text = fs::read_to_string(&plain).unwrap();
    fs::write(&credited, format!("{text}\n[mistake.\"no-shadows\"]\ncredit = 0.75\n")).unwrap();
    let cache = Some(Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-cache"));
    let grade = |rubric: &Path, out: &str| {
        let options = GradeOptions {
            out: dir.join(out),
            cache: cache.clone(),
            ..GradeOptions::default()
        };
        grade_class(rubric, &submissions, &options, &Silent).unwrap()
    };
    let without = grade(&plain, "plain");
    let with = grade(&credited, "credited");
    let a07 = |r: &ClassReport| r.students[0].images[18].clone();
    assert_eq!(a07(&without).points, 0.0, "{}", a07(&without).explanation);
    assert_eq!(a07(&with).points, 1.5, "{}", a07(&with).explanation);
    assert_eq!(a07(&with).diagnosis.unwrap().credit, Some(0.75));
    assert!(
        a07(&with)
            .explanation
            .contains("75% of the points for the diagnosed mistake no-shadows")
    );
    assert_eq!(with.students[0].total, without.students[0].total + 1.5);
    // The other images are as they were.
    for (a, b) in with.students[0]
        .images
        .iter()
        .zip(&without.students[0].images)
        .filter(|(a, _)| a.file != "a07.png")
    {
        assert_eq!(a.points, b.points, "{}", a.file);
    }

    fs::write(&credited, format!("{text}\n[mistake.\"no-shadow\"]\ncredit = 0.75\n")).unwrap();
    let error = load_rubric(&credited).unwrap_err().to_string();
    assert!(
        error.contains("not a mistake of the catalogue") && error.contains("did you mean `no-shadows`"),
        "{error}"
    );
    fs::write(&credited, format!("{text}\n[mistake.\"no-shadows\"]\ncredit = 2\n")).unwrap();
    let error = load_rubric(&credited).unwrap_err().to_string();
    assert!(error.contains("between 0 and 1"), "{error}");
}

/// The course's own binary rendered the course's scenes edited the way one mistake changes them
/// (`tests/data/mit6837/faulty/make.sh`): an independent program's sampling, rounding and
/// quantisation, with a mistake goldray did not draw. Every image that loses points is diagnosed
/// as the mistake it was made with.
#[test]
fn the_course_binarys_mistakes_are_diagnosed() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-course-binary");
    if dir.exists() {
        fs::remove_dir_all(&dir).unwrap();
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rubric = dir.join("rubric.toml");
    fs::create_dir_all(&dir).unwrap();
    let text = fs::read_to_string(course_rubric(&dir))
        .unwrap()
        .replace(&format!("size = [{SIZE}, {SIZE}]"), "size = [200, 200]");
    fs::write(&rubric, text).unwrap();
    let faulty = root.join("tests/data/mit6837/faulty");
    let submissions = dir.join("submissions");
    let mut handed_in = 0;
    for entry in fs::read_dir(&faulty).unwrap().flatten().filter(|e| e.path().is_dir()) {
        let folder = submissions.join(entry.file_name());
        fs::create_dir_all(&folder).unwrap();
        for file in fs::read_dir(entry.path()).unwrap().flatten() {
            fs::copy(file.path(), folder.join(file.file_name())).unwrap();
            handed_in += 1;
        }
    }
    let options = GradeOptions {
        out: dir.join("report"),
        cache: Some(dir.join("cache")),
        ..GradeOptions::default()
    };
    let report = grade_class(&rubric, &submissions, &options, &Silent).unwrap();
    let (mut lost, mut named, mut wrong) = (0, 0, Vec::new());
    for student in &report.students {
        for image in student.images.iter().filter(|i| goldray::grade::loses_points(i)) {
            lost += 1;
            let diagnosis = image.diagnosis.as_ref().unwrap();
            let ids: Vec<&str> = std::iter::once(diagnosis.id.as_str())
                .chain(diagnosis.alternatives.iter().map(String::as_str))
                .collect();
            println!(
                "{} {}: {} ({:?}) {}",
                student.name,
                image.file,
                diagnosis.faults.as_deref().unwrap_or("unexplained"),
                diagnosis.alternatives,
                image.explanation
            );
            if ids.contains(&student.name.as_str()) {
                named += 1;
            } else if diagnosis.id != UNEXPLAINED {
                wrong.push(format!("{} {}: {}", student.name, image.file, diagnosis.id));
            }
        }
    }
    println!("{named} of {lost} images that lost points named ({handed_in} handed in)");
    assert!(wrong.is_empty(), "{wrong:?}");
    assert!(lost >= 14, "only {lost} of {handed_in} images lost points");
    assert_eq!(named, lost, "every image that lost points is named");
}

/// The course's reference images (800×800, made by the course's binary) as a correct submission
/// get no diagnosis; with a mistake of the PNG writing applied to their 8-bit codes (all a program
/// that quantised first and then made the mistake could have written) each is diagnosed as it.
#[test]
fn the_course_references_with_output_mistakes_are_diagnosed() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-references");
    if dir.exists() {
        fs::remove_dir_all(&dir).unwrap();
    }
    fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut rubric = "[defaults]\nthreshold = 8\npass_fraction = 0.01\npartial_fraction = 0.05\npass_flip = 0.1\npartial_flip = 0.2\n".to_owned();
    for (n, scene, range) in [
        ("01", "scene01_plane", "8, 18"),
        ("02", "scene02_cube", "8, 18"),
        ("05", "scene05_bunny_200", "0.8, 1.0"),
    ] {
        let scene = root.join(format!("cases/mit6837/{scene}.txt"));
        rubric += &format!(
            "[render.s{n}]\nscene = {scene:?}\nsize = [800, 800]\n[image.\"a{n}.png\"]\nrender = \"s{n}\"\n\
             [image.\"a{n}n.png\"]\nrender = \"s{n}\"\noutput = \"normals\"\n\
             [image.\"a{n}d.png\"]\nrender = \"s{n}\"\noutput = \"depth\"\ndepth = [{range}]\n"
        );
    }
    let rubric_path = dir.join("rubric.toml");
    fs::write(&rubric_path, rubric).unwrap();
    let reference = |file: &str| read_png(&root.join("tests/data/mit6837").join(file)).unwrap();
    let submissions = dir.join("submissions");
    let correct = submissions.join("reference");
    fs::create_dir_all(&correct).unwrap();
    for n in ["01", "02", "05"] {
        for suffix in ["", "n", "d"] {
            let file = format!("a{n}{suffix}.png");
            fs::copy(root.join("tests/data/mit6837").join(&file), correct.join(&file)).unwrap();
        }
    }
    // A linear value within its 8-bit code, for curves applied after quantising.
    let value = |code: u8| {
        if code == 0 {
            0.0
        } else {
            (f64::from(code) + 0.5) / 255.0
        }
    };
    let curve = |picture: &RgbImage, f: &dyn Fn(f64) -> f64| {
        let mut out = picture.clone();
        out.pixels_mut()
            .for_each(|p| p.0 = p.0.map(|c| (f(value(c)).clamp(0.0, 1.0) * 255.0) as u8));
        out
    };
    let srgb = |c: f64| {
        if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let miss = |normals: &RgbImage, x: u32, y: u32| normals.get_pixel(x, y).0 == [127; 3];
    let mistakes: Vec<(&str, &str, RgbImage)> = vec![
        (
            "a01.png",
            "gamma-applied",
            curve(&reference("a01.png"), &|c| c.powf(1.0 / 2.2)),
        ),
        (
            "a02.png",
            "gamma-applied",
            curve(&reference("a02.png"), &|c| c.powf(1.0 / 1.8)),
        ),
        ("a05.png", "gamma-applied", curve(&reference("a05.png"), &srgb)),
        (
            "a01n.png",
            "normals-not-remapped",
            curve(&reference("a01n.png"), &|c| 2.0 * c - 1.0),
        ),
        ("a02n.png", "pixel-mapping", reference("a02n.png").flipped_vertically()),
        (
            "a05n.png",
            "pixel-mapping",
            reference("a05n.png").flipped_horizontally(),
        ),
        ("a02d.png", "depth-inverted", {
            let (depth, normals) = (reference("a02d.png"), reference("a02n.png"));
            RgbImage::from_fn(800, 800, |x, y| {
                if miss(&normals, x, y) {
                    Rgb([0; 3])
                } else {
                    Rgb(depth.get_pixel(x, y).0.map(|c| 254 - c.min(254)))
                }
            })
        }),
        ("a01d.png", "depth-miss-white", {
            let (depth, normals) = (reference("a01d.png"), reference("a01n.png"));
            RgbImage::from_fn(800, 800, |x, y| {
                if miss(&normals, x, y) {
                    Rgb([255; 3])
                } else {
                    *depth.get_pixel(x, y)
                }
            })
        }),
        ("a05d.png", "pixel-mapping", reference("a05d.png").flipped_vertically()),
    ];
    let faulty = submissions.join("outputs");
    fs::create_dir_all(&faulty).unwrap();
    for (file, _, picture) in &mistakes {
        fs::write(faulty.join(file), encode_png(picture).unwrap()).unwrap();
    }
    let options = GradeOptions {
        out: dir.join("report"),
        cache: Some(dir.join("cache")),
        ..GradeOptions::default()
    };
    let report = grade_class(&rubric_path, &submissions, &options, &Silent).unwrap();
    let by_name = |name: &str| report.students.iter().find(|s| s.name == name).unwrap();
    for image in &by_name("reference").images {
        assert!(
            image.diagnosis.is_none() && image.points == image.max_points,
            "{}: {}",
            image.file,
            image.explanation
        );
    }
    for (file, id, _) in &mistakes {
        let image = by_name("outputs").images.iter().find(|i| i.file == *file).unwrap();
        let diagnosis = image
            .diagnosis
            .as_ref()
            .unwrap_or_else(|| panic!("{file}: {}", image.explanation));
        println!(
            "{file}: {} ({:?})",
            diagnosis.faults.as_deref().unwrap_or("unexplained"),
            diagnosis.alternatives
        );
        assert_eq!(diagnosis.id, *id, "{file}: {}", image.explanation);
    }
}
