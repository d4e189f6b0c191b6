//! Grading only what students made: links out of a folder are not read, copies of the published
//! reference are flagged, students who handed in the same pictures are paired, and names chosen
//! by students stay data.

use std::fs;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};

use goldray::grade::{ClassReport, GradeOptions, Outcome, PUBLISHED_COPY, SimilarPair, grade_class};
use goldray::progress::Silent;
use goldray::rgb_image::{Rgb, RgbImage};

use crate::chromium;
use crate::class::{FILES, case, pictures, render, rubric_text, scene_path};

/// A class folder with a rubric (plus `extra` rubric text), the golden pictures, and a
/// "published" folder whose pictures differ from the golden ones on a few pixels, as the
/// course's own binary differs from goldray's.
struct Fixture {
    dir: tempfile::TempDir,
    golden: [RgbImage; 3],
    published: [RgbImage; 3],
}

impl Fixture {
    fn new(extra: &str) -> Fixture {
        let dir = tempfile::tempdir().unwrap();
        let rubric = rubric_text(&scene_path()) + extra;
        fs::write(dir.path().join("rubric.toml"), rubric).unwrap();
        let golden = pictures(&render(&case()));
        let published = golden.clone().map(|mut picture| {
            for x in 0..5 {
                let p = picture.get_pixel_mut(x, 0);
                p.0[0] = p.0[0].wrapping_add(1);
            }
            picture
        });
        fs::create_dir_all(dir.path().join("published")).unwrap();
        for (file, picture) in FILES.iter().zip(&published) {
            goldray::film::write_png(&dir.path().join("published").join(file), picture).unwrap();
        }
        fs::create_dir_all(dir.path().join("submissions")).unwrap();
        Fixture { dir, golden, published }
    }

    fn student(&self, name: &str) -> PathBuf {
        let folder = self.dir.path().join("submissions").join(name);
        fs::create_dir_all(&folder).unwrap();
        folder
    }

    fn hand_in(&self, name: &str, pictures: &[RgbImage; 3]) {
        let folder = self.student(name);
        for (file, picture) in FILES.iter().zip(pictures) {
            goldray::film::write_png(&folder.join(file), picture).unwrap();
        }
    }

    fn grade(&self) -> (ClassReport, PathBuf) {
        let out = self.dir.path().join("report");
        let options = GradeOptions {
            out: out.clone(),
            cache: Some(self.dir.path().join("cache")),
            ..GradeOptions::default()
        };
        let report = grade_class(
            &self.dir.path().join("rubric.toml"),
            &self.dir.path().join("submissions"),
            &options,
            &Silent,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        (report, out)
    }
}

const PUBLISHED: &str = "\n[integrity]\npublished = \"published\"\n";

fn student<'a>(report: &'a ClassReport, name: &str) -> &'a goldray::grade::StudentResult {
    report.students.iter().find(|s| s.name == name).unwrap()
}

/// A wrong picture: the golden one with a band painted over, failing the rubric.
fn broken(picture: &RgbImage, shade: u8) -> RgbImage {
    let mut picture = picture.clone();
    for y in 20..60 {
        for x in 0..picture.width() {
            picture.put_pixel(x, y, Rgb([shade, 0, 255 - shade]));
        }
    }
    picture
}

#[test]
fn links_out_of_the_folder_score_nothing_and_say_where_they_point() {
    let fixture = Fixture::new(PUBLISHED);
    let folder = fixture.student("linker");
    for file in FILES {
        symlink(fixture.dir.path().join("published").join(file), folder.join(file)).unwrap();
    }
    let (report, out) = fixture.grade();
    let linker = student(&report, "linker");
    assert_eq!(linker.total, 0.0);
    for image in &linker.images {
        let Outcome::Linked { reason } = &image.outcome else {
            panic!("{}: {:?}", image.file, image.outcome)
        };
        assert!(reason.contains("published") && reason.contains(&image.file), "{reason}");
        assert!(
            image.student_image.is_none(),
            "nothing outside the submissions is copied"
        );
    }
    let json = fs::read_to_string(out.join("grades.json")).unwrap();
    assert!(json.contains("\"verdict\": \"linked\""), "{json}");
    let kept: Vec<_> = fs::read_dir(out.join("students/linker"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(kept, ["result.json"], "no picture of a linked file in the report");
}

#[test]
fn links_inside_the_folder_are_read_by_default_and_refused_when_the_rubric_says_none() {
    for (extra, expect_linked) in [("", false), ("\n[integrity]\nlinks = \"none\"\n", true)] {
        let fixture = Fixture::new(extra);
        let folder = fixture.student("archiver");
        fs::create_dir_all(folder.join("renders")).unwrap();
        for (file, picture) in FILES.iter().zip(&fixture.golden) {
            goldray::film::write_png(&folder.join("renders").join(file), picture).unwrap();
            symlink(Path::new("renders").join(file), folder.join(file)).unwrap();
        }
        let (report, _) = fixture.grade();
        let outcomes: Vec<&Outcome> = student(&report, "archiver").images.iter().map(|i| &i.outcome).collect();
        for outcome in outcomes {
            assert_eq!(
                matches!(outcome, Outcome::Linked { .. }),
                expect_linked,
                "{extra:?}: {outcome:?}"
            );
            if !expect_linked {
                assert_eq!(*outcome, Outcome::Pass);
            }
        }
    }
}

#[test]
fn copies_of_the_published_reference_are_flagged_and_copies_between_students_are_paired() {
    let fixture = Fixture::new(PUBLISHED);
    // Two students hand in the published pictures: flagged, not paired with each other.
    fixture.hand_in("pub1", &fixture.published);
    fixture.hand_in("pub2", &fixture.published);
    // Two students hand in the same three failing pictures: paired.
    let failing = fixture.golden.clone().map(|p| broken(&p, 10));
    fixture.hand_in("copy1", &failing);
    fixture.hand_in("copy2", &failing);
    // An honest failing student and a correct one: neither flagged nor paired.
    fixture.hand_in("honest", &fixture.golden.clone().map(|p| broken(&p, 200)));
    fixture.hand_in("correct", &fixture.golden);
    let (report, out) = fixture.grade();

    for name in ["pub1", "pub2"] {
        let s = student(&report, name);
        assert!(
            s.images.iter().all(|i| i.flags == [PUBLISHED_COPY]),
            "{name}: {:?}",
            s.images
        );
        assert!(s.total > 0.0, "a flag is a note: the score stands by default");
    }
    for name in ["copy1", "honest", "correct"] {
        assert!(
            student(&report, name).images.iter().all(|i| i.flags.is_empty()),
            "{name}"
        );
    }
    assert_eq!(
        report.similar,
        [SimilarPair {
            students: ["copy1".into(), "copy2".into()],
            files: FILES.iter().map(|f| f.to_string()).collect(),
        }]
    );
    let json: serde_json::Value = serde_json::from_str(&fs::read_to_string(out.join("grades.json")).unwrap()).unwrap();
    assert_eq!(json["similar"][0]["students"], serde_json::json!(["copy1", "copy2"]));
    assert_eq!(json["similar"][0]["files"].as_array().unwrap().len(), 3);
    let csv = fs::read_to_string(out.join("grades.csv")).unwrap();
    assert!(csv.contains("color.png: identical to the published reference"), "{csv}");
    let page = fs::read_to_string(out.join(&student(&report, "pub1").page)).unwrap();
    assert!(page.contains(PUBLISHED_COPY));
    let dom = chromium::dump_dom(&out.join("index.html"));
    assert!(
        dom.contains("Similar submissions") && dom.contains("copy1</a> and <a"),
        "{dom}"
    );
}

#[test]
fn a_rubric_can_make_copying_the_published_reference_cost_points() {
    let fixture = Fixture::new("\n[integrity]\npublished = \"published\"\npublished_copy_credit = 0.25\n");
    fixture.hand_in("pub1", &fixture.published);
    fixture.hand_in("correct", &fixture.golden);
    let (report, _) = fixture.grade();
    let copied = student(&report, "pub1");
    let correct = student(&report, "correct");
    assert!(
        (copied.total - correct.total * 0.25).abs() < 1e-9,
        "{} vs {}",
        copied.total,
        correct.total
    );
    assert!(
        copied.images[0].explanation.contains("keeps 25%"),
        "{}",
        copied.images[0].explanation
    );
}

#[test]
fn hostile_folder_names_stay_data_and_nothing_is_written_outside_the_report() {
    let fixture = Fixture::new("");
    let names = [
        "<script>alert(1)<\\script>",
        "=HYPERLINK(\"evil.example\",\"x\")",
        "new\nline",
        "a..b",
        "-rf",
    ];
    for name in names {
        fixture.hand_in(name, &fixture.golden);
    }
    let before = tree(fixture.dir.path());
    let (report, out) = fixture.grade();
    let after: Vec<PathBuf> = tree(fixture.dir.path())
        .into_iter()
        .filter(|p| !p.starts_with(&out) && !p.starts_with(fixture.dir.path().join("cache")))
        .collect();
    assert_eq!(before, after, "grading wrote outside the report and the cache");
    assert_eq!(report.students.len(), names.len());
    for s in &report.students {
        assert!(
            out.join(&s.page).starts_with(&out) && !s.page.contains(".."),
            "{}",
            s.page
        );
        assert!(out.join(&s.page).is_file(), "{}", s.page);
    }
    let index = fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!index.contains("<script>alert(1)"), "escaped in HTML");
    assert!(index.contains("&lt;script&gt;alert(1)&lt;\\script&gt;"), "{index}");
    let csv = fs::read_to_string(out.join("grades.csv")).unwrap();
    assert!(
        csv.contains("\"'=HYPERLINK(\"\"evil.example\"\",\"\"x\"\")\""),
        "formula-safe: {csv}"
    );
    assert!(csv.contains("\"new\nline\""), "quoted newline: {csv}");
}

/// Every file and folder below `dir`, sorted.
fn tree(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(next) = stack.pop() {
        for entry in fs::read_dir(&next).unwrap().flatten() {
            let path = entry.path();
            if entry.file_type().unwrap().is_dir() {
                stack.push(path.clone());
            }
            found.push(path);
        }
    }
    found.sort();
    found
}
