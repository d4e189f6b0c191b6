//! `goldray grade` end to end: a synthetic class made from goldray's own renders (a perfect
//! student, missing shadows, a shifted camera, gamma applied, missing, corrupt, wrong-sized,
//! converted and hostile files) graded against a small rubric; the verdicts and points, the CSV
//! read back, the HTML report opened in headless Chromium, the golden cache, the command line and
//! the shipped course rubric.

// Shared with tests/diagnose.rs and tests/review.rs, whose DevTools driver starts Chromium
// with its flags.
#[allow(dead_code)]
#[path = "grade/chromium.rs"]
mod chromium;
#[path = "grade/class.rs"]
mod class;
#[path = "grade/cli.rs"]
mod cli;
#[path = "grade/integrity.rs"]
mod integrity;
#[path = "grade/lms.rs"]
mod lms;
#[path = "grade/lms_hostile.rs"]
mod lms_hostile;
#[path = "grade/lms_variants.rs"]
mod lms_variants;
#[path = "grade/memory.rs"]
mod memory;
#[path = "grade/platform.rs"]
mod platform;
#[path = "grade/rubrics.rs"]
mod rubrics;
#[path = "grade/scale.rs"]
mod scale;
#[path = "grade/sched.rs"]
mod sched;
mod util;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

use goldray::grade::{ClassReport, GradeOptions, Outcome, StudentResult, grade_class};
use goldray::progress::Silent;

use class::{Class, FILES, HOSTILE, POINTS, make_class_at};

/// The class graded once and shared by the tests that only read the report. It lives in
/// `target/tmp/grade-class/` (replaced by each run), so that the report can be opened after the
/// tests: `target/tmp/grade-class/report/index.html`.
struct Graded {
    class: Class,
    out: PathBuf,
    report: ClassReport,
    seconds: f64,
}

fn graded() -> &'static Graded {
    static GRADED: OnceLock<Graded> = OnceLock::new();
    GRADED.get_or_init(|| {
        let class = make_class_at(&Path::new(env!("CARGO_TARGET_TMPDIR")).join("grade-class"));
        let out = class.dir.join("report");
        let options = GradeOptions {
            out: out.clone(),
            cache: None,
            ..GradeOptions::default()
        };
        let started = Instant::now();
        let report =
            grade_class(&class.rubric, &class.submissions, &options, &Silent).unwrap_or_else(|e| panic!("{e}"));
        let seconds = started.elapsed().as_secs_f64();
        Graded {
            class,
            out,
            report,
            seconds,
        }
    })
}

fn student<'a>(report: &'a ClassReport, name: &str) -> &'a StudentResult {
    report
        .students
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("no student {name}"))
}

/// The verdict words of a student's three images, in rubric order.
fn verdicts(report: &ClassReport, name: &str) -> Vec<&'static str> {
    student(report, name).images.iter().map(|i| i.outcome.word()).collect()
}

#[test]
fn every_student_gets_the_verdicts_and_points_their_files_deserve() {
    let Graded { report, seconds, .. } = graded();
    let expect = [
        ("perfect", ["pass", "pass", "pass"], 4.0),
        ("no_shadows", ["fail", "pass", "pass"], 2.0),
        ("shifted_camera", ["fail", "fail", "fail"], 0.0),
        ("gamma", ["fail", "pass", "pass"], 2.0),
        ("missing_and_corrupt", ["missing", "unreadable", "unreadable"], 0.0),
        ("wrong_sizes", ["wrong size", "wrong size", "wrong size"], 0.0),
        ("formats", ["pass", "pass", "pass"], 4.0),
        ("bad_files", ["wrong format", "too large", "too large"], 0.0),
        ("scribbled", ["partial", "pass", "pass"], 3.0),
        (HOSTILE, ["pass", "pass", "pass"], 4.0),
    ];
    let mut table = String::new();
    for s in &report.students {
        for i in &s.images {
            table += &format!(
                "{:>22} {:>12} {:>8} {:>5} {}\n",
                s.name,
                i.file,
                i.outcome.word(),
                i.points,
                i.explanation
            );
        }
    }
    for (name, words, total) in expect {
        assert_eq!(verdicts(report, name), words, "{name}:\n{table}");
        assert_eq!(student(report, name).total, total, "{name}:\n{table}");
        assert_eq!(student(report, name).max_points, 4.0);
    }
    assert_eq!(
        report.students.len(),
        expect.len(),
        "one result per student folder, hidden folders skipped"
    );
    assert_eq!(report.ignored, ["README.txt"]);
    println!("graded {} students in {seconds:.2} s\n{table}", report.students.len());
}

#[test]
fn verdicts_carry_the_evidence_behind_them() {
    let report = &graded().report;
    let by = |name: &str, file: usize| &student(report, name).images[file];

    let no_shadows = by("no_shadows", 0);
    let metrics = no_shadows.metrics.as_ref().expect("a compared image has metrics");
    assert!(metrics.failing_fraction > 0.05, "{metrics:?}");
    assert!(metrics.worst.is_some() && metrics.rmse > 0.0 && metrics.flip > 0.0);
    assert!(
        no_shadows.explanation.contains("over the partial limits"),
        "{}",
        no_shadows.explanation
    );
    assert!(no_shadows.diff_image.is_some() && no_shadows.student_image.is_some());

    let partial = by("scribbled", 0);
    assert_eq!(partial.points, 1.0, "half of 2 points: {}", partial.explanation);
    assert!(
        partial.explanation.contains("50% of the points"),
        "{}",
        partial.explanation
    );
    assert_eq!(
        by("scribbled", 1).outcome,
        Outcome::Pass,
        "a ±3-code wobble is under the 8-code threshold"
    );

    let perfect = by("perfect", 0);
    assert_eq!(
        perfect.student_image.as_deref(),
        Some("golden/color.png"),
        "an identical picture is not copied"
    );
    assert_eq!(perfect.diff_image, None);

    assert_eq!(
        by("wrong_sizes", 0).outcome,
        Outcome::WrongSize {
            expected: [100, 100],
            actual: [120, 90]
        }
    );
    assert!(
        by("wrong_sizes", 0).student_image.is_some(),
        "a wrong-sized picture is still shown"
    );
    let explains = |student: &str, image: usize, needle: &str| {
        let explanation = &by(student, image).explanation;
        assert!(explanation.contains(needle), "{student}, image {image}: {explanation}");
    };
    explains("missing_and_corrupt", 1, "truncated");
    explains("missing_and_corrupt", 2, "corrupt");
    explains("bad_files", 0, "OpenEXR");
    explains("bad_files", 1, "50000×50000");
    explains("bad_files", 2, "MiB decoded");

    let notes = |name: &str, file: usize| by(name, file).notes.join("; ");
    assert!(notes("formats", 0).contains("alpha ignored"), "{}", notes("formats", 0));
    assert!(notes("formats", 1).contains("16-bit"), "{}", notes("formats", 1));
    assert!(notes("formats", 2).contains("grey"), "{}", notes("formats", 2));
    assert!(
        notes(HOSTILE, 0).contains("submission/COLOR.PNG"),
        "{}",
        notes(HOSTILE, 0)
    );
}

#[test]
fn grades_csv_parses_back_to_the_report() {
    let Graded { out, report, .. } = graded();
    let text = fs::read_to_string(out.join("grades.csv")).unwrap();
    let rows = parse_csv(&text);
    let header: Vec<&str> = rows[0].iter().map(String::as_str).collect();
    assert_eq!(
        header,
        [
            "student",
            "color.png",
            "normals.png",
            "depth.png",
            "total",
            "flags",
            "diagnoses"
        ]
    );
    assert_eq!(rows.len(), report.students.len() + 1, "one row per student");
    let by_name: BTreeMap<&str, &Vec<String>> = rows[1..].iter().map(|r| (r[0].as_str(), r)).collect();
    for s in &report.students {
        let row = by_name
            .get(s.name.as_str())
            .unwrap_or_else(|| panic!("{} has no row:\n{text}", s.name));
        let numbers: Vec<f64> = row[1..row.len() - 2].iter().map(|v| v.parse().unwrap()).collect();
        assert_eq!(row[row.len() - 2], goldray::grade::flags(s).join("; "), "{}", s.name);
        assert_eq!(
            row[row.len() - 1],
            goldray::grade::diagnoses_of(s).join("; "),
            "{}",
            s.name
        );
        let points: Vec<f64> = s.images.iter().map(|i| i.points).collect();
        assert_eq!(numbers[..3], points[..], "{}", s.name);
        assert_eq!(numbers[3], s.total);
        assert!(numbers[..3].iter().zip(POINTS).all(|(p, max)| *p <= max));
    }
    let diagnoses = |name: &str| by_name[name].last().unwrap().as_str();
    assert_eq!(diagnoses("no_shadows"), "no-shadows");
    assert_eq!(diagnoses("gamma"), "gamma-applied");
    assert_eq!(diagnoses("perfect"), "");
    let json: serde_json::Value = serde_json::from_str(&fs::read_to_string(out.join("grades.json")).unwrap()).unwrap();
    assert_eq!(json["students"].as_array().unwrap().len(), report.students.len());
    assert_eq!(json["rubric"]["max_points"], 4.0);
}

/// RFC 4180: quoted fields may hold commas, doubled quotes and line breaks.
fn parse_csv(text: &str) -> Vec<Vec<String>> {
    let (mut rows, mut row, mut field) = (Vec::new(), Vec::new(), String::new());
    let mut chars = text.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') => quoted = true,
            (false, ',') => row.push(std::mem::take(&mut field)),
            (false, '\r') => {}
            (false, '\n') => {
                row.push(std::mem::take(&mut field));
                rows.push(std::mem::take(&mut row));
            }
            (false, c) => field.push(c),
        }
    }
    rows
}

#[test]
fn student_files_are_never_modified() {
    let Graded { class, .. } = graded();
    for (path, bytes) in &class.files {
        assert_eq!(&fs::read(path).unwrap(), bytes, "{} changed", path.display());
    }
    let mut count = 0;
    let mut stack = vec![class.submissions.clone()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(dir).unwrap().flatten() {
            if entry.file_type().unwrap().is_dir() {
                stack.push(entry.path());
            } else {
                count += 1;
            }
        }
    }
    assert_eq!(count, class.files.len(), "grading added no file to the submissions");
}

#[test]
fn html_escapes_every_student_controlled_string() {
    let Graded { out, report, .. } = graded();
    let index = fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        !index.contains("<img src=x"),
        "the folder name reached the HTML unescaped"
    );
    assert!(index.contains("&lt;img src=x onerror=alert(1)&gt; &amp; &quot;Mallory&quot;"));
    let page = fs::read_to_string(out.join(&student(report, HOSTILE).page)).unwrap();
    assert!(!page.contains("<img src=x") && page.contains("&lt;img src=x"));
    let csv = fs::read_to_string(out.join("grades.csv")).unwrap();
    assert!(
        csv.contains("\"<img src=x onerror=alert(1)> & \"\"Mallory\"\"\""),
        "{csv}"
    );
}

#[test]
fn the_report_opens_in_headless_chromium_with_its_table_and_pictures() {
    let Graded { out, report, .. } = graded();
    let dom = chromium::dump_dom(&out.join("index.html"));
    let rows = dom.matches("<tr><td class=\"name\">").count();
    assert_eq!(rows, report.students.len(), "one table row per student:\n{dom}");
    assert!(
        dom.contains(&format!("data-images-loaded=\"{}\"", FILES.len())),
        "{dom}"
    );
    chromium::assert_pictures_loaded(&dom, "the class page");

    for name in ["no_shadows", "missing_and_corrupt", HOSTILE] {
        let page = out.join(&student(report, name).page);
        let dom = chromium::dump_dom(&page);
        chromium::assert_pictures_loaded(&dom, name);
        let loaded = dom
            .split("data-images-loaded=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap_or("0");
        assert!(
            loaded.parse::<usize>().unwrap() >= FILES.len(),
            "{name}: {loaded} pictures loaded"
        );
    }

    let shot = chromium::screenshot(
        &out.join(&student(report, "no_shadows").page),
        1000,
        800,
        &out.join("shot.png"),
    );
    let colours: std::collections::HashSet<[u8; 3]> = shot.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 500,
        "the screenshot looks blank: {} colours",
        colours.len()
    );
}

/// A rubric as wide as the course's (21 images): in a 1400-pixel window the per-image cells run
/// off screen, but each student's name and the list of images that lost points stay in view.
#[test]
fn a_wide_class_table_keeps_names_and_lost_points_on_screen() {
    use goldray::film::{Tonemap, color_image, encode_png};

    let dir = tempfile::tempdir().unwrap();
    let scene = class::scene_path();
    let mut rubric = format!(
        "title = \"Wide\"\n\n[defaults]\nthreshold = 8\npass_fraction = 0.01\n\n[render.spheres]\ncase = {scene:?}\nsize = [64, 64]\n"
    );
    let files: Vec<String> = (1..=21).map(|i| format!("c{i:02}.png")).collect();
    for file in &files {
        rubric.push_str(&format!("\n[image.\"{file}\"]\nrender = \"spheres\"\n"));
    }
    let rubric_path = dir.path().join("wide.toml");
    fs::write(&rubric_path, rubric).unwrap();
    let mut case = goldray::case::load(&scene, &goldray::case::LoadOptions::default()).unwrap();
    case.render.trace.width = 64;
    case.render.trace.height = 64;
    let png = encode_png(&color_image(
        &goldray::pipeline::render_case(&case).unwrap(),
        Tonemap::Clamp,
    ))
    .unwrap();
    for student in ["alice", "bob"] {
        let folder = dir.path().join("submissions").join(student);
        fs::create_dir_all(&folder).unwrap();
        for file in &files {
            // Bob's last image is missing: the cell furthest to the right.
            if !(student == "bob" && file == "c21.png") {
                fs::write(folder.join(file), &png).unwrap();
            }
        }
    }
    let out = dir.path().join("report");
    let options = GradeOptions {
        out: out.clone(),
        cache: Some(dir.path().join("cache")),
        ..GradeOptions::default()
    };
    let report = grade_class(&rubric_path, &dir.path().join("submissions"), &options, &Silent).unwrap();
    assert_eq!(student(&report, "bob").images[20].outcome, Outcome::Missing);

    let index = out.join("index.html");
    let html = fs::read_to_string(&index).unwrap();
    assert!(html.contains("<th>Lost points on</th>"), "{html}");
    assert!(
        html.contains(">1: <a class=\"v-missing\""),
        "bob's summary names the missing image"
    );
    let dom = chromium::dump_dom_at(&index, 1400, 900);
    assert!(
        dom.contains("data-table-scrolls=\"true\""),
        "21 columns overflow 1400 px:\n{dom}"
    );
    assert!(
        dom.contains("data-summary-in-view=\"true\""),
        "names and summaries stay on screen:\n{dom}"
    );
}

/// A report stays small when students pass: a passing picture that is not identical to the
/// golden one is kept as a thumbnail with no heatmap, stored once for every student who handed in
/// the same picture; a picture that loses points keeps its full size and its heatmap.
#[test]
fn passing_pictures_are_thumbnails_and_only_lost_points_get_heatmaps() {
    use goldray::film::{Tonemap, color_image};
    use goldray::rgb_image::Rgb;

    let dir = tempfile::tempdir().unwrap();
    let scene = class::scene_path();
    let rubric = format!(
        "[defaults]\nthreshold = 8\npass_fraction = 0.01\n\n[render.spheres]\ncase = {scene:?}\nsize = [400, 400]\n\n[image.\"c.png\"]\nrender = \"spheres\"\n"
    );
    fs::write(dir.path().join("r.toml"), rubric).unwrap();
    let mut case = goldray::case::load(&scene, &goldray::case::LoadOptions::default()).unwrap();
    (case.render.trace.width, case.render.trace.height) = (400, 400);
    let golden = color_image(&goldray::pipeline::render_case(&case).unwrap(), Tonemap::Clamp);
    let mut nearly = golden.clone();
    nearly.put_pixel(10, 10, Rgb([255, 0, 255]));
    let mut broken = golden.clone();
    for y in 0..200 {
        for x in 0..400 {
            broken.put_pixel(x, y, Rgb([0, 0, 0]));
        }
    }
    for (name, picture) in [("nearly", &nearly), ("nearly_too", &nearly), ("broken", &broken)] {
        fs::create_dir_all(dir.path().join("subs").join(name)).unwrap();
        goldray::film::write_png(&dir.path().join("subs").join(name).join("c.png"), picture).unwrap();
    }
    let out = dir.path().join("report");
    let options = GradeOptions {
        out: out.clone(),
        cache: Some(dir.path().join("cache")),
        ..GradeOptions::default()
    };
    let report = grade_class(&dir.path().join("r.toml"), &dir.path().join("subs"), &options, &Silent).unwrap();
    let nearly = &student(&report, "nearly").images[0];
    assert_eq!(nearly.outcome, Outcome::Pass);
    assert!(nearly.diff_image.is_none(), "no heatmap for full points");
    let thumbnail = util::read_png(&out.join(nearly.student_image.as_ref().unwrap()));
    assert_eq!((thumbnail.width(), thumbnail.height()), (300, 300));
    assert_eq!(
        student(&report, "nearly_too").images[0].student_image,
        nearly.student_image,
        "the same passing picture is one file"
    );
    assert_eq!(fs::read_dir(out.join("thumbnails")).unwrap().count(), 1);
    let broken = &student(&report, "broken").images[0];
    assert_eq!(broken.outcome, Outcome::Fail);
    let full = util::read_png(&out.join(broken.student_image.as_ref().unwrap()));
    assert_eq!((full.width(), full.height()), (400, 400));
    assert!(out.join(broken.diff_image.as_ref().unwrap()).is_file());
}
