//! Diagnosis on a program goldray did not write (issue 33): `tests/data/independent_renderer/`
//! holds a small ray tracer in C++ with its own single-precision arithmetic, scene parser and PNG
//! writer, built here with `c++ -O2`, and three scenes in the course's format. A class of students
//! is that program with mistakes planted (`PLANT=…`): the starter code's unwritten parts one at a
//! time and all at once, a few parts of a finished program left unwritten, and shadow acne from
//! shadow rays started on the surface. Every planted mistake must be named, the starter as one
//! "unfinished" finding with exactly its parts, and nothing it did not do.

#[allow(dead_code)]
#[path = "grade/chromium.rs"]
mod chromium;

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use goldray::fault::FaultSet;
use goldray::grade::{ClassReport, GradeOptions, StudentResult, UNEXPLAINED, grade_class, loses_points};
use goldray::progress::Silent;

/// The course's command for each render of `rubric.toml`, as a student's program is run.
const COMMANDS: [&[&str]; 3] = [
    &[
        "-input",
        "shadows.txt",
        "-size",
        "120",
        "120",
        "-shadows",
        "-output",
        "b01.png",
        "-normals",
        "b01n.png",
        "-depth",
        "5",
        "15",
        "b01d.png",
    ],
    &[
        "-input",
        "shapes.txt",
        "-size",
        "120",
        "120",
        "-output",
        "b02.png",
        "-normals",
        "b02n.png",
        "-depth",
        "5",
        "15",
        "b02d.png",
    ],
    &[
        "-input",
        "mirror.txt",
        "-size",
        "120",
        "120",
        "-bounces",
        "2",
        "-output",
        "b03.png",
        "-normals",
        "b03n.png",
        "-depth",
        "4",
        "14",
        "b03d.png",
    ],
];

/// Each student: the mistakes planted (`PLANT`), and the catalogue ids they must be named as.
const STUDENTS: [(&str, &[&str]); 16] = [
    ("", &[]),
    ("plane", &["plane-missing"]),
    ("triangle", &["triangle-missing"]),
    ("transform", &["transform-missing"]),
    ("point-light", &["point-light-missing"]),
    ("background", &["background-missing"]),
    ("shading", &["nothing-shaded"]),
    ("specular", &["no-specular"]),
    ("shadows", &["no-shadows"]),
    ("reflections", &["no-reflections"]),
    ("acne", &["shadow-acne"]),
    ("depth-miss", &["depth-miss-white"]),
    (
        "starter",
        &[
            "nothing-shaded",
            "plane-missing",
            "triangle-missing",
            "transform-missing",
            "background-missing",
        ],
    ),
    // The starter as it runs on ARM: its depth misses white.
    (
        "starter,depth-miss",
        &[
            "nothing-shaded",
            "plane-missing",
            "triangle-missing",
            "transform-missing",
            "depth-miss-white",
            "background-missing",
        ],
    ),
    (
        "plane,transform,background",
        &["plane-missing", "transform-missing", "background-missing"],
    ),
    (
        "triangle,point-light,shadows",
        &["triangle-missing", "point-light-missing", "no-shadows"],
    ),
];

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/independent_renderer")
}

fn folder_name(plant: &str) -> String {
    if plant.is_empty() {
        "correct".to_owned()
    } else {
        plant.replace(',', "+")
    }
}

/// The renderer built, and the class it drew graded.
struct Graded {
    dir: PathBuf,
    report: ClassReport,
}

fn graded() -> &'static Graded {
    static GRADED: OnceLock<Graded> = OnceLock::new();
    GRADED.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-independent-renderer");
        if dir.exists() {
            fs::remove_dir_all(&dir).unwrap();
        }
        fs::create_dir_all(&dir).unwrap();
        let program = dir.join("raytracer");
        let built = Command::new("c++")
            .args(["-O2", "-o"])
            .arg(&program)
            .arg(data().join("raytracer.cpp"))
            .output()
            .expect("a C++ compiler (c++) builds the independent renderer");
        assert!(built.status.success(), "{}", String::from_utf8_lossy(&built.stderr));
        let submissions = dir.join("submissions");
        for (plant, _) in STUDENTS {
            let folder = submissions.join(folder_name(plant));
            fs::create_dir_all(&folder).unwrap();
            for command in COMMANDS {
                let ran = Command::new(&program)
                    .args(command.iter().map(|a| resolve(a, &folder)))
                    .env("PLANT", plant)
                    .output()
                    .unwrap();
                assert!(
                    ran.status.success(),
                    "{plant}: {}",
                    String::from_utf8_lossy(&ran.stderr)
                );
            }
        }
        let options = GradeOptions {
            out: dir.join("report"),
            cache: Some(dir.join("cache")),
            ..GradeOptions::default()
        };
        let report =
            grade_class(&data().join("rubric.toml"), &submissions, &options, &Silent).unwrap_or_else(|e| panic!("{e}"));
        Graded { dir, report }
    })
}

/// A scene is read from the data folder; a picture is written into the student's folder.
fn resolve(argument: &str, folder: &Path) -> String {
    if argument.ends_with(".txt") {
        data().join(argument).display().to_string()
    } else if argument.ends_with(".png") {
        folder.join(argument).display().to_string()
    } else {
        argument.to_owned()
    }
}

fn student<'a>(graded: &'a Graded, plant: &str) -> &'a StudentResult {
    let name = folder_name(plant);
    graded.report.students.iter().find(|s| s.name == name).unwrap()
}

/// The catalogue ids a student's diagnoses name.
fn named(student: &StudentResult) -> BTreeSet<String> {
    student
        .images
        .iter()
        .filter_map(|i| i.diagnosis.as_ref())
        .filter(|d| d.id != UNEXPLAINED)
        .flat_map(|d| {
            d.id.parse::<FaultSet>()
                .unwrap()
                .faults()
                .map(|f| f.name().to_owned())
                .collect::<Vec<_>>()
        })
        .collect()
}

fn describe(student: &StudentResult) -> String {
    let mut text = String::new();
    for image in &student.images {
        let diagnosis = image.diagnosis.as_ref().map_or("-".to_owned(), |d| {
            let closest = d
                .closest
                .as_ref()
                .map_or(String::new(), |c| format!(" (closest {})", c.faults));
            format!("{}{closest} {:?}", d.faults.as_deref().unwrap_or(&d.id), d.alternatives)
        });
        text += &format!("  {} {}: {diagnosis}\n", image.file, image.outcome.word());
    }
    text
}

#[test]
fn every_planted_mistake_is_named_and_nothing_else() {
    let graded = graded();
    let mut failures = Vec::new();
    for (plant, expected) in STUDENTS {
        let student = student(graded, plant);
        println!("{}:\n{}", folder_name(plant), describe(student));
        let named = named(student);
        let expected: BTreeSet<String> = expected.iter().map(|id| (*id).to_owned()).collect();
        if named != expected {
            failures.push(format!("{}: named {named:?}, planted {expected:?}", folder_name(plant)));
        }
        // An image that lost points for a single planted mistake is explained by it.
        if expected.len() == 1 {
            for image in student.images.iter().filter(|i| loses_points(i)) {
                let diagnosis = image.diagnosis.as_ref().unwrap();
                if diagnosis.id == UNEXPLAINED {
                    failures.push(format!("{} {}: unexplained", folder_name(plant), image.file));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(
        student(graded, "").images.iter().all(|i| !loses_points(i)),
        "the independent renderer without mistakes keeps every point:\n{}",
        describe(student(graded, ""))
    );
}

#[test]
fn unfinished_work_is_one_finding_with_exactly_its_parts() {
    let graded = graded();
    for (plant, parts) in [
        (
            "starter",
            vec!["shading", "planes", "triangles", "transforms", "the background"],
        ),
        (
            "starter,depth-miss",
            vec![
                "shading",
                "planes",
                "triangles",
                "transforms",
                "misses in the depth image",
                "the background",
            ],
        ),
        (
            "plane,transform,background",
            vec!["planes", "transforms", "the background"],
        ),
        (
            "triangle,point-light,shadows",
            vec!["point lights", "shadows", "triangles"],
        ),
    ] {
        let student = student(graded, plant);
        let unfinished = student
            .unfinished
            .as_ref()
            .unwrap_or_else(|| panic!("{plant}: no unfinished finding\n{}", describe(student)));
        let found: BTreeSet<&str> = unfinished.parts.iter().map(|p| p.part.as_str()).collect();
        assert_eq!(
            found,
            parts.iter().copied().collect(),
            "{plant}: {}",
            unfinished.summary
        );
        assert!(unfinished.summary.starts_with("unfinished: "), "{}", unfinished.summary);
        for part in &unfinished.parts {
            assert!(!part.images.is_empty(), "{plant}: {} explains no image", part.id);
        }
    }
    let starter = &student(graded, "starter").unfinished.as_ref().unwrap().summary;
    assert_eq!(
        starter,
        "unfinished: shading, planes, triangles, transforms and the background are not implemented"
    );
    // One mistake is not "unfinished".
    assert!(student(graded, "plane").unfinished.is_none());
    let json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(graded.dir.join("report/grades.json")).unwrap()).unwrap();
    let starter_json = json["students"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == "starter")
        .unwrap();
    assert_eq!(starter_json["unfinished"]["summary"], starter.as_str());
    assert_eq!(starter_json["unfinished"]["parts"].as_array().unwrap().len(), 5);
}

/// The starter's page leads with one "unfinished" finding, not a section per part and image:
/// looked at in headless Chromium (the screenshot is kept beside the report).
#[test]
fn the_starters_page_shows_one_unfinished_finding() {
    let graded = graded();
    let page = graded.dir.join("report").join(&student(graded, "starter").page);
    let dom = chromium::dump_dom(&page);
    chromium::assert_pictures_loaded(&dom, "the starter's page");
    let findings = dom.matches("<section class=\"mistake").count();
    assert_eq!(findings, 1, "one finding on the page:\n{dom}");
    assert!(dom.contains("data-mistake=\"unfinished\""));
    assert!(dom.contains("Unfinished: shading, planes, triangles, transforms and the background are not implemented."));
    for id in [
        "nothing-shaded",
        "plane-missing",
        "triangle-missing",
        "transform-missing",
        "background-missing",
    ] {
        assert!(dom.contains(&format!("data-part=\"{id}\"")), "{id}");
    }
    let shot = chromium::screenshot(&page, 1200, 900, &graded.dir.join("starter-page.png"));
    let colours: BTreeSet<[u8; 3]> = shot.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 200,
        "the screenshot looks blank: {} colours",
        colours.len()
    );
}
