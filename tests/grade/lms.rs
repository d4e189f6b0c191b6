//! Grading a learning platform's download as it comes: one class zipped as Canvas and as Moodle
//! hand it over (and extracted, and as plain folders) grades alike, with the platform's names and
//! ids; hostile archive entries are refused one by one; the grades go back as each platform's
//! CSV; resuming and shards hold for a zip.

use std::fs;
use std::io::{Cursor, Write};
use std::path::Path;

use goldray::grade::{ClassReport, GradeOptions, Layout, Shard, grade_class, merge_shards};
use goldray::progress::Silent;
use goldray::rgb_image::{Rgb, RgbImage};
use zip::ZipWriter;
use zip::write::SimpleFileOptions;

use crate::class::{case, pictures, render, rubric_text, scene_path};
use crate::{chromium, parse_csv};

/// One student of the class: the name each platform gives them, their ids, and their files.
pub struct Student {
    pub full_name: &'static str,
    pub canvas: &'static str,
    pub id: &'static str,
    pub late: bool,
    pub files: Vec<(String, Vec<u8>)>,
}

pub fn png(picture: &RgbImage) -> Vec<u8> {
    goldray::film::encode_png(picture).unwrap()
}

/// A zip of `entries` (name, bytes), deflated.
pub fn zip_of(entries: &[(String, Vec<u8>)]) -> Vec<u8> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, bytes) in entries {
        zip.start_file(name, options).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// Four students: one perfect, one late with a broken colour picture, one who uploaded a zip of
/// their own (with a colour picture nearly identical to the late one's), one who named a file
/// wrong.
pub fn students() -> Vec<Student> {
    let [color, normals, depth] = pictures(&render(&case()));
    let mut broken = color.clone();
    for y in 0..40 {
        for x in 0..100 {
            broken.put_pixel(x, y, Rgb([0, 0, 0]));
        }
    }
    // At 100×100 one pixel is 0.01% of the picture: only an identical copy is paired.
    let nearly = broken.clone();
    let good = |color: &RgbImage| {
        vec![
            ("color.png".to_owned(), png(color)),
            ("normals.png".to_owned(), png(&normals)),
            ("depth.png".to_owned(), png(&depth)),
        ]
    };
    let own_zip = zip_of(
        &good(&nearly)
            .into_iter()
            .map(|(name, bytes)| (format!("out/{name}"), bytes))
            .collect::<Vec<_>>(),
    );
    let mut wrong_name = good(&color);
    wrong_name[0].0 = "colour.png".to_owned();
    vec![
        Student {
            full_name: "Ada Lovelace",
            canvas: "lovelaceada",
            id: "101",
            late: false,
            files: good(&color),
        },
        Student {
            full_name: "Brian Kernighan",
            canvas: "kernighanbrian",
            id: "102",
            late: true,
            files: good(&broken),
        },
        Student {
            full_name: "Grace Hopper",
            canvas: "hoppergrace",
            id: "103",
            late: false,
            files: vec![("renders.zip".to_owned(), own_zip)],
        },
        Student {
            full_name: "Dennis Ritchie",
            canvas: "ritchiedennis",
            id: "104",
            late: false,
            files: wrong_name,
        },
    ]
}

pub fn canvas_name(student: &Student, file: &str) -> String {
    let late = if student.late { "LATE_" } else { "" };
    format!("{}_{late}{}_9{}_{file}", student.canvas, student.id, student.id)
}

pub fn moodle_folder(student: &Student) -> String {
    format!("{}_{}_assignsubmission_file_", student.full_name, student.id)
}

pub fn canvas_zip(students: &[Student]) -> Vec<u8> {
    zip_of(
        &students
            .iter()
            .flat_map(|s| s.files.iter().map(move |(f, b)| (canvas_name(s, f), b.clone())))
            .collect::<Vec<_>>(),
    )
}

pub fn moodle_zip(students: &[Student]) -> Vec<u8> {
    let mut entries: Vec<(String, Vec<u8>)> = students
        .iter()
        .flat_map(|s| {
            s.files
                .iter()
                .map(move |(f, b)| (format!("{}/{f}", moodle_folder(s)), b.clone()))
        })
        .collect();
    entries.push((
        "Ada Lovelace_101_assignsubmission_onlinetext_/onlinetext.html".to_owned(),
        b"<p>see my renders</p>".to_vec(),
    ));
    zip_of(&entries)
}

/// The class as plain folders, named by full name, each student's own zip extracted.
pub fn folders(students: &[Student], dir: &Path) {
    for student in students {
        let folder = dir.join(student.full_name);
        for (file, bytes) in &student.files {
            if file.ends_with(".zip") {
                let mut archive = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
                archive.extract(&folder).unwrap();
            } else {
                fs::create_dir_all(&folder).unwrap();
                fs::write(folder.join(file), bytes).unwrap();
            }
        }
    }
}

pub fn grade(dir: &Path, submissions: &Path, out: &str) -> ClassReport {
    let options = GradeOptions {
        out: dir.join(out),
        cache: Some(dir.join("cache")),
        ..GradeOptions::default()
    };
    grade_class(&dir.join("rubric.toml"), submissions, &options, &Silent).unwrap_or_else(|e| panic!("{e}"))
}

/// A student's platform id, each image's verdict and points, and the total.
pub type Score = (String, Vec<(&'static str, f64)>, f64);

/// Each student's verdicts and points by platform id (by full name for plain folders).
pub fn scores(report: &ClassReport, students: &[Student]) -> Vec<Score> {
    let mut scores: Vec<_> = report
        .students
        .iter()
        .map(|s| {
            let id = match &s.lms {
                Some(lms) => lms.id.clone(),
                None => students.iter().find(|t| t.full_name == s.name).unwrap().id.to_owned(),
            };
            (
                id,
                s.images.iter().map(|i| (i.outcome.word(), i.points)).collect(),
                s.total,
            )
        })
        .collect();
    scores.sort_by(|a, b| a.0.cmp(&b.0));
    scores
}

pub fn setup(extra: &str) -> (tempfile::TempDir, Vec<Student>) {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("rubric.toml"), rubric_text(&scene_path()) + extra).unwrap();
    (dir, students())
}

#[test]
fn canvas_and_moodle_downloads_grade_like_folders_with_the_platforms_names_and_ids() {
    let (dir, students) = setup("\n[lms]\nassignment = \"Assignment 4 (1234)\"\n");
    let dir = dir.path();
    folders(&students, &dir.join("folders"));
    fs::write(dir.join("canvas.zip"), canvas_zip(&students)).unwrap();
    fs::write(dir.join("moodle.zip"), moodle_zip(&students)).unwrap();
    let extracted = dir.join("moodle-extracted");
    zip::ZipArchive::new(Cursor::new(moodle_zip(&students)))
        .unwrap()
        .extract(&extracted)
        .unwrap();
    let canvas_extracted = dir.join("canvas-extracted");
    zip::ZipArchive::new(Cursor::new(canvas_zip(&students)))
        .unwrap()
        .extract(&canvas_extracted)
        .unwrap();

    let plain = grade(dir, &dir.join("folders"), "plain");
    let canvas = grade(dir, &dir.join("canvas.zip"), "canvas");
    let moodle = grade(dir, &dir.join("moodle.zip"), "moodle");
    let unzipped = grade(dir, &extracted, "unzipped");
    let canvas_unzipped = grade(dir, &canvas_extracted, "canvas-unzipped");
    assert_eq!(plain.layout, Layout::Folders);
    assert_eq!(canvas.layout, Layout::Canvas);
    assert_eq!(moodle.layout, Layout::Moodle);
    assert_eq!(unzipped.layout, Layout::Moodle);
    assert_eq!(canvas_unzipped.layout, Layout::Canvas);
    let expected = scores(&plain, &students);
    assert_eq!(expected.len(), 4);
    // The late student lost points on colour, the wrong name costs colour, the own zip is read.
    assert_eq!(expected[1].1[0], ("fail", 0.0));
    assert_eq!(expected[2].1, [("fail", 0.0), ("pass", 1.0), ("pass", 1.0)]);
    assert_eq!(expected[3].1[0], ("missing", 0.0));
    for report in [&canvas, &moodle, &unzipped, &canvas_unzipped] {
        assert_eq!(scores(report, &students), expected, "{:?}", report.layout);
    }

    for student in &students {
        let graded = canvas.students.iter().find(|s| s.name == student.canvas).unwrap();
        let lms = graded.lms.as_ref().unwrap();
        assert_eq!(
            (lms.platform, lms.id.as_str(), lms.late),
            (Layout::Canvas, student.id, student.late)
        );
        let graded = moodle.students.iter().find(|s| s.name == student.full_name).unwrap();
        assert_eq!(graded.lms.as_ref().unwrap().id, student.id);
    }
    // Where each graded file was, in the download: the same every run, never the staging folder.
    let grace = canvas.students.iter().find(|s| s.name == "hoppergrace").unwrap();
    assert_eq!(
        grace.images[0].graded_file.as_deref(),
        Some(
            dir.join("canvas.zip/hoppergrace_103_9103_renders.zip/out/color.png")
                .as_path()
        )
    );
    let ada = moodle.students.iter().find(|s| s.name == "Ada Lovelace").unwrap();
    assert_eq!(
        ada.images[1].graded_file.as_deref(),
        Some(
            dir.join("moodle.zip/Ada Lovelace_101_assignsubmission_file_/normals.png")
                .as_path()
        )
    );
    // The copy inside Grace's own zip is paired with the late student's picture.
    for report in [&plain, &canvas, &moodle] {
        assert_eq!(report.similar.len(), 1, "{:?}: {:?}", report.layout, report.similar);
        assert_eq!(report.similar[0].files, ["color.png"]);
    }
    let json = fs::read_to_string(dir.join("canvas/grades.json")).unwrap();
    assert!(
        json.contains("\"layout\": \"canvas\"") && json.contains("\"id\": \"102\""),
        "{json}"
    );
    assert!(
        !json.contains("goldray-grade-"),
        "a staging path leaked into grades.json"
    );
    let csv = parse_csv(&fs::read_to_string(dir.join("canvas/grades.csv")).unwrap());
    assert_eq!(csv[1][0], "hoppergrace");
}

#[test]
fn the_platforms_csvs_read_back_with_their_columns_and_values() {
    let (dir, students) = setup("\n[lms]\nassignment = \"Assignment 4 (1234)\"\n");
    let dir = dir.path();
    fs::write(dir.join("canvas.zip"), canvas_zip(&students)).unwrap();
    fs::write(dir.join("moodle.zip"), moodle_zip(&students)).unwrap();
    grade(dir, &dir.join("canvas.zip"), "canvas");
    grade(dir, &dir.join("moodle.zip"), "moodle");

    let canvas = parse_csv(&fs::read_to_string(dir.join("canvas/grades-canvas.csv")).unwrap());
    assert_eq!(
        canvas[0],
        [
            "Student",
            "ID",
            "SIS User ID",
            "SIS Login ID",
            "Section",
            "Assignment 4 (1234)"
        ]
    );
    assert_eq!(canvas[1], ["Points Possible", "", "", "", "", "4"]);
    let row = |id: &str| canvas.iter().find(|r| r[1] == id).unwrap().clone();
    assert_eq!(row("101"), ["lovelaceada", "101", "", "", "", "4"]);
    assert_eq!(row("102")[5], "2");
    assert_eq!(row("104")[5], "2");
    assert_eq!(canvas.len(), 2 + students.len());
    assert!(!dir.join("canvas/grades-moodle.csv").exists());

    let moodle = parse_csv(&fs::read_to_string(dir.join("moodle/grades-moodle.csv")).unwrap());
    assert_eq!(
        moodle[0],
        [
            "Identifier",
            "Full name",
            "Email address",
            "Status",
            "Grade",
            "Maximum Grade",
            "Grade can be changed",
            "Last modified (submission)",
            "Last modified (grade)",
            "Feedback comments"
        ]
    );
    let row = |id: &str| {
        moodle
            .iter()
            .find(|r| r[0] == format!("Participant {id}"))
            .unwrap()
            .clone()
    };
    let brian = row("102");
    assert_eq!(
        (brian[1].as_str(), brian[4].as_str(), brian[5].as_str()),
        ("Brian Kernighan", "2", "4")
    );
    // The self-check's words, lost points first, as Moodle's HTML comment: a line each.
    let feedback = &brian[9];
    let lines: Vec<&str> = feedback.split("<br>\n").collect();
    assert_eq!(lines[0], "2 / 4 points", "{feedback}");
    assert_eq!(lines[1], "color.png: fail, 0 / 2", "{feedback}");
    assert!(lines[2..].contains(&"normals.png: pass, 1 / 1"), "{feedback}");
    // The darkened band's explanation and the mistake the diagnosis names (or says it cannot),
    // indented as in the terminal.
    assert!(
        lines[2].starts_with("&nbsp;&nbsp;") && lines[3].starts_with("&nbsp;&nbsp;"),
        "{feedback}"
    );
    assert!(row("104")[9].contains("color.png: missing, 0 / 2"));
    assert!(!dir.join("moodle/grades-canvas.csv").exists());
}

#[test]
fn a_malformed_lms_table_is_a_located_rubric_error() {
    let (dir, _) = setup("\n[lms]\nassignment = \"\"\n");
    let options = GradeOptions {
        out: dir.path().join("out"),
        cache: Some(dir.path().join("cache")),
        ..GradeOptions::default()
    };
    let error = grade_class(&dir.path().join("rubric.toml"), dir.path(), &options, &Silent)
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("rubric.toml:") && error.contains("empty"), "{error}");
}

#[test]
fn a_zip_resumes_by_student_and_shards_by_student_into_the_same_bytes() {
    let (dir, mut students) = setup("");
    let dir = dir.path();
    let zip = dir.join("canvas.zip");
    fs::write(&zip, canvas_zip(&students)).unwrap();
    let first = grade(dir, &zip, "whole");
    let csv = fs::read(dir.join("whole/grades.csv")).unwrap();
    let json = fs::read(dir.join("whole/grades.json")).unwrap();
    let again = grade(dir, &zip, "whole");
    assert_eq!(again.cost.reused, 4, "an unchanged zip regrades nobody");
    assert_eq!(fs::read(dir.join("whole/grades.json")).unwrap(), json);

    for k in 1..=2 {
        let options = GradeOptions {
            out: dir.join(format!("shard{k}")),
            cache: Some(dir.join("cache")),
            shard: Shard { index: k, count: 2 },
            ..GradeOptions::default()
        };
        let slice = grade_class(&dir.join("rubric.toml"), &zip, &options, &Silent).unwrap();
        assert_eq!(slice.students.len(), 2, "two students a shard");
    }
    merge_shards(&dir.join("merged"), &[dir.join("shard2"), dir.join("shard1")]).unwrap();
    assert_eq!(fs::read(dir.join("merged/grades.csv")).unwrap(), csv);
    assert_eq!(fs::read(dir.join("merged/grades.json")).unwrap(), json);

    // Brian hands in a fixed picture: only he is graded again.
    students[1].files = students[0].files.clone();
    fs::write(&zip, canvas_zip(&students)).unwrap();
    let fixed = grade(dir, &zip, "whole");
    assert_eq!((fixed.cost.reused, fixed.cost.graded), (3, 1));
    assert_eq!(first.students.len(), fixed.students.len());
}

/// Patches every occurrence of `from` in `bytes` (names in local and central headers).
pub fn rename(bytes: &mut [u8], from: &[u8], to: &[u8]) {
    assert_eq!(from.len(), to.len());
    let mut at = 0;
    while let Some(i) = bytes[at..].windows(from.len()).position(|w| w == from) {
        bytes[at + i..at + i + to.len()].copy_from_slice(to);
        at += i + to.len();
    }
}

#[test]
fn a_zip_graded_class_report_opens_in_headless_chromium() {
    let (dir, students) = setup("");
    let dir = dir.path();
    fs::write(dir.join("canvas.zip"), canvas_zip(&students)).unwrap();
    let report = grade(dir, &dir.join("canvas.zip"), "report");
    let index = dir.join("report/index.html");
    let dom = chromium::dump_dom(&index);
    assert_eq!(
        dom.matches("<tr><td class=\"name\">").count(),
        report.students.len(),
        "{dom}"
    );
    assert!(dom.contains("read as a Canvas download"), "{dom}");
    assert!(
        dom.contains("Canvas user 102 <span class=\"late\">late</span>"),
        "{dom}"
    );
    chromium::assert_pictures_loaded(&dom, "the Canvas class page");
    let shot_path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lms-report.png");
    let shot = chromium::screenshot(&index, 1300, 900, &shot_path);
    let colours: std::collections::HashSet<[u8; 3]> = shot.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 200,
        "the screenshot looks blank: {} colours",
        colours.len()
    );
}
