//! The variations a platform's download comes in, each graded as the plain download is: Canvas's
//! renamed resubmissions, Moodle's prefixed files instead of folders, Moodle's folder of a participant who handed in nothing, and a
//! zip64 class archive (its duplicate names refused as in any other).

use std::fs;
use std::io::{Cursor, Write};

use goldray::grade::{ClassReport, Layout, Outcome};
use zip::ZipWriter;
use zip::write::SimpleFileOptions;

use crate::lms::{
    Student, canvas_name, canvas_zip, folders, grade, moodle_folder, moodle_zip, rename, scores, setup, zip_of,
};
use crate::parse_csv;

/// The end-of-central-directory record's signature, and the zip64 locator's.
const EOCD: &[u8] = b"PK\x05\x06";
const ZIP64_LOCATOR: &[u8] = b"PK\x06\x07";

/// A zip64 archive of `entries`: the zip crate writes the zip64 end record when told of an
/// extensible data sector (an empty one here), and the classic record is then made to say what a
/// zip64 writer of a large archive says, that its counts and offset are in the zip64 record.
fn zip64_of(entries: &[(String, Vec<u8>)]) -> Vec<u8> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    zip.set_raw_zip64_extensible_data_sector(Box::new([]));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .large_file(true);
    for (name, bytes) in entries {
        zip.start_file(name, options).unwrap();
        zip.write_all(bytes).unwrap();
    }
    let mut bytes = zip.finish().unwrap().into_inner();
    let end = bytes.windows(4).rposition(|w| w == EOCD).unwrap();
    assert!(
        bytes[..end].windows(4).any(|w| w == ZIP64_LOCATOR),
        "no zip64 end record"
    );
    bytes[end + 8..end + 12].copy_from_slice(&[0xff; 4]);
    bytes[end + 16..end + 20].copy_from_slice(&[0xff; 4]);
    bytes
}

#[test]
fn a_zip64_archive_with_a_name_twice_refuses_both_copies_and_grades_the_rest() {
    let (dir, students) = setup("");
    let dir = dir.path();
    let mut entries: Vec<(String, Vec<u8>)> = students[..2]
        .iter()
        .flat_map(|s| s.files.iter().map(move |(f, b)| (canvas_name(s, f), b.clone())))
        .collect();
    // Mallory's colour picture twice under one name (the second written as `colox` and renamed
    // in the bytes: the zip crate's writer refuses a name twice), one copy good, one black.
    let ada = &students[0].files;
    entries.push(("mallorymal_105_9105_color.png".to_owned(), ada[0].1.clone()));
    entries.push((
        "mallorymal_105_9105_colox.png".to_owned(),
        crate::lms::png(&goldray::rgb_image::RgbImage::new(100, 100)),
    ));
    entries.push(("mallorymal_105_9105_normals.png".to_owned(), ada[1].1.clone()));
    let mut bytes = zip64_of(&entries);
    rename(
        &mut bytes,
        b"mallorymal_105_9105_colox.png",
        b"mallorymal_105_9105_color.png",
    );
    fs::write(dir.join("class.zip"), &bytes).unwrap();

    let report = grade(dir, &dir.join("class.zip"), "report");
    assert_eq!(report.layout, Layout::Canvas);
    assert_eq!(report.students.len(), 3);
    let verdicts = |name: &str| {
        let student = report.students.iter().find(|s| s.name == name).unwrap();
        student.images.iter().map(|i| i.outcome.word()).collect::<Vec<_>>()
    };
    assert_eq!(verdicts("lovelaceada"), ["pass", "pass", "pass"]);
    assert_eq!(verdicts("kernighanbrian"), ["fail", "pass", "pass"]);
    let mallory = report.students.iter().find(|s| s.name == "mallorymal").unwrap();
    assert!(
        matches!(&mallory.images[0].outcome, Outcome::Unreadable { reason } if reason.contains("several files of this name")),
        "{:?}",
        mallory.images[0]
    );
    assert_eq!(
        (mallory.images[1].outcome.word(), mallory.images[2].outcome.word()),
        ("pass", "missing")
    );
    let notes: Vec<&String> = mallory
        .refused
        .iter()
        .filter(|n| n.contains("several files of this name"))
        .collect();
    assert_eq!(notes.len(), 1, "one note for the name: {:?}", mallory.refused);
    assert!(
        notes.iter().all(|n| n.starts_with("mallorymal_105_9105_color.png: ")),
        "{notes:?}"
    );
}

/// A Canvas download's name for `student`'s upload `file` that Canvas gave the id `submission`.
fn canvas_upload(student: &Student, submission: u32, file: &str) -> String {
    let late = if student.late { "LATE_" } else { "" };
    format!("{}_{late}{}_{submission}_{file}", student.canvas, student.id)
}

#[test]
fn canvas_resubmissions_grade_under_the_names_first_uploaded() {
    let (dir, students) = setup("");
    let dir = dir.path();
    let [ada, brian, grace, dennis] = &students[..] else {
        unreachable!()
    };
    let mut entries = Vec::new();
    // Ada uploaded everything again, her depth picture a third time.
    for (file, again, submission) in [
        ("color.png", "color-1.png", 9201),
        ("normals.png", "normals-1.png", 9202),
        ("depth.png", "depth-2.png", 9303),
    ] {
        let bytes = ada.files.iter().find(|(f, _)| f == file).unwrap().1.clone();
        entries.push((canvas_upload(ada, submission, again), bytes));
    }
    // Brian first uploaded a good colour picture, then his broken one, which as the newest is the
    // one graded.
    entries.push((canvas_upload(brian, 9102, "color.png"), ada.files[0].1.clone()));
    entries.push((canvas_upload(brian, 9402, "color-1.png"), brian.files[0].1.clone()));
    for (file, bytes) in &brian.files[1..] {
        entries.push((canvas_name(brian, file), bytes.clone()));
    }
    // Grace's own zip, uploaded again, is read under its name (no rubric file, but no other
    // upload of that name); Dennis handed in once.
    entries.push((canvas_upload(grace, 9503, "renders-1.zip"), grace.files[0].1.clone()));
    for (file, bytes) in &dennis.files {
        entries.push((canvas_name(dennis, file), bytes.clone()));
    }
    let bytes = zip_of(&entries);
    fs::write(dir.join("canvas.zip"), canvas_zip(&students)).unwrap();
    fs::write(dir.join("resubmitted.zip"), &bytes).unwrap();
    let extracted = dir.join("resubmitted");
    zip::ZipArchive::new(Cursor::new(&bytes))
        .unwrap()
        .extract(&extracted)
        .unwrap();

    let expected = scores(&grade(dir, &dir.join("canvas.zip"), "original"), &students);
    assert_eq!(expected[1].1[0], ("fail", 0.0), "Brian's colour picture fails");
    for (submissions, out) in [(dir.join("resubmitted.zip"), "zipped"), (extracted, "unzipped")] {
        let report = grade(dir, &submissions, out);
        assert_eq!(report.layout, Layout::Canvas, "{out}");
        assert_eq!(scores(&report, &students), expected, "{out}");
        let graded = |name: &str| report.students.iter().find(|s| s.name == name).unwrap();
        assert_eq!(
            graded("lovelaceada").images[2].graded_file.as_deref(),
            Some(submissions.join("lovelaceada_101_9303_depth-2.png").as_path()),
            "{out}"
        );
        let notes = &graded("kernighanbrian").refused;
        assert_eq!(notes.len(), 1, "{out}: {notes:?}");
        assert!(
            notes[0].ends_with(
                "kernighanbrian_LATE_102_9102_color.png: an earlier upload of color.png, superseded by \
                 kernighanbrian_LATE_102_9402_color-1.png: not read"
            ),
            "{out}: {notes:?}"
        );
        assert!(graded("lovelaceada").refused.is_empty(), "{out}");
    }
}

/// Moodle's download with "Download submissions in folders" unticked: every file at the top, its
/// name prefixed with what would have been its folder's.
fn moodle_flat_zip(students: &[Student]) -> Vec<u8> {
    let mut entries: Vec<(String, Vec<u8>)> = students
        .iter()
        .flat_map(|s| {
            s.files
                .iter()
                .map(move |(f, b)| (format!("{}{f}", moodle_folder(s)), b.clone()))
        })
        .collect();
    entries.push((
        "Ada Lovelace_101_assignsubmission_onlinetext_onlinetext.html".to_owned(),
        b"<p>see my renders</p>".to_vec(),
    ));
    zip_of(&entries)
}

#[test]
fn moodle_prefixed_files_grade_like_its_folders_with_names_and_ids() {
    let (dir, students) = setup("");
    let dir = dir.path();
    folders(&students, &dir.join("folders"));
    let bytes = moodle_flat_zip(&students);
    fs::write(dir.join("flat.zip"), &bytes).unwrap();
    let extracted = dir.join("flat");
    zip::ZipArchive::new(Cursor::new(&bytes))
        .unwrap()
        .extract(&extracted)
        .unwrap();

    let plain = grade(dir, &dir.join("folders"), "plain");
    let expected = scores(&plain, &students);
    for (submissions, out) in [(dir.join("flat.zip"), "zipped"), (extracted.clone(), "unzipped")] {
        let report = grade(dir, &submissions, out);
        assert_eq!(report.layout, Layout::Moodle, "{out}");
        assert_eq!(scores(&report, &students), expected, "{out}");
        assert!(report.ignored.is_empty(), "{out}: {:?}", report.ignored);
        for student in &students {
            let graded = report.students.iter().find(|s| s.name == student.full_name).unwrap();
            let lms = graded.lms.as_ref().unwrap();
            assert_eq!((lms.platform, lms.id.as_str()), (Layout::Moodle, student.id));
        }
        let ada = report.students.iter().find(|s| s.name == "Ada Lovelace").unwrap();
        assert_eq!(ada.folder, submissions.join("Ada Lovelace_101_assignsubmission_*"));
        assert_eq!(
            ada.images[1].graded_file.as_deref(),
            Some(
                submissions
                    .join("Ada Lovelace_101_assignsubmission_file_normals.png")
                    .as_path()
            )
        );
    }
}

/// Moodle's download of the class, with two more participants who handed in no file: one with an
/// empty `_file_` folder, one with only an online text.
fn moodle_with_empty_folders(students: &[Student]) -> Vec<u8> {
    let mut archive = zip::ZipArchive::new(Cursor::new(moodle_zip(students))).unwrap();
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    for index in 0..archive.len() {
        zip.raw_copy_file(archive.by_index(index).unwrap()).unwrap();
    }
    let options = SimpleFileOptions::default();
    zip.add_directory("Edsger Dijkstra_105_assignsubmission_file_/", options)
        .unwrap();
    zip.add_directory("Barbara Liskov_106_assignsubmission_onlinetext_/", options)
        .unwrap();
    zip.start_file(
        "Barbara Liskov_106_assignsubmission_onlinetext_/onlinetext.html",
        options,
    )
    .unwrap();
    zip.write_all(b"<p>I ran out of time</p>").unwrap();
    zip.finish().unwrap().into_inner()
}

#[test]
fn a_moodle_participant_who_handed_in_no_file_is_graded_with_every_file_missing() {
    let (dir, students) = setup("");
    let dir = dir.path();
    let bytes = moodle_with_empty_folders(&students);
    fs::write(dir.join("moodle.zip"), &bytes).unwrap();
    let extracted = dir.join("extracted");
    zip::ZipArchive::new(Cursor::new(&bytes))
        .unwrap()
        .extract(&extracted)
        .unwrap();
    assert!(
        fs::read_dir(extracted.join("Edsger Dijkstra_105_assignsubmission_file_"))
            .unwrap()
            .next()
            .is_none(),
        "the extracted folder is empty"
    );

    for (report, out) in [
        (grade(dir, &dir.join("moodle.zip"), "zipped"), "zipped"),
        (grade(dir, &extracted, "unzipped"), "unzipped"),
    ] {
        assert_eq!(report.layout, Layout::Moodle);
        assert_eq!(report.students.len(), students.len() + 2, "{out}");
        assert!(report.ignored.is_empty(), "{out}: {:?}", report.ignored);
        for (name, id) in [("Edsger Dijkstra", "105"), ("Barbara Liskov", "106")] {
            nobody_handed_in(&report, name, id);
        }
        let csv = parse_csv(&fs::read_to_string(dir.join(out).join("grades-moodle.csv")).unwrap());
        for (name, id) in [("Edsger Dijkstra", "105"), ("Barbara Liskov", "106")] {
            let row = csv.iter().find(|r| r[0] == format!("Participant {id}")).unwrap();
            assert_eq!((row[1].as_str(), row[4].as_str()), (name, "0"), "{out}: {row:?}");
        }
    }
}

/// `name` is a student of `report` with participant id `id`, every file missing and no points.
fn nobody_handed_in(report: &ClassReport, name: &str, id: &str) {
    let student = report
        .students
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("{name} is not graded"));
    let lms = student.lms.as_ref().unwrap();
    assert_eq!((lms.platform, lms.id.as_str()), (Layout::Moodle, id));
    assert!(
        student.images.iter().all(|i| i.outcome == Outcome::Missing),
        "{name}: {:?}",
        student.images
    );
    assert_eq!(student.total, 0.0);
}
