//! A platform's download with hostile entries (names that climb out or are absolute, a link, a
//! zip bomb, a broken nested zip, an encrypted entry, names twice): each refused on its own with
//! a reason, nothing written outside the report, the rest of the class graded.

use std::fs;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};

use goldray::grade::Outcome;
use zip::ZipWriter;
use zip::write::SimpleFileOptions;

use crate::lms::{canvas_name, grade, rename, setup, zip_of};

/// Sets the encryption flag of the entry named `name`, in its local and central headers.
fn encrypt_flag(bytes: &mut [u8], name: &[u8]) {
    let mut at = 0;
    while let Some(i) = bytes[at..].windows(name.len()).position(|w| w == name) {
        let start = at + i;
        if bytes[start - 46..start - 42] == [0x50, 0x4b, 0x01, 0x02] {
            bytes[start - 46 + 8] |= 1;
        } else if bytes[start - 30..start - 26] == [0x50, 0x4b, 0x03, 0x04] {
            bytes[start - 30 + 6] |= 1;
        }
        at = start + name.len();
    }
}

#[test]
fn hostile_entries_are_refused_one_by_one_and_the_others_graded() {
    let (dir, students) = setup("");
    let dir = dir.path();
    let honest = &students[..2];
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let deflated = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for student in honest {
        for (file, bytes) in &student.files {
            zip.start_file(canvas_name(student, file), deflated).unwrap();
            zip.write_all(bytes).unwrap();
        }
    }
    let outside = dir.join("outside");
    fs::create_dir_all(&outside).unwrap();
    let absolute = outside.join("absolute.png");
    zip.start_file("../../x.png", deflated).unwrap();
    zip.write_all(b"escape").unwrap();
    zip.start_file(absolute.display().to_string(), deflated).unwrap();
    zip.write_all(b"escape").unwrap();
    zip.start_file("mallorymal_105_9105_../../y.png", deflated).unwrap();
    zip.write_all(b"escape").unwrap();
    zip.add_symlink("mallorymal_105_9105_color.png", "/etc/passwd", deflated)
        .unwrap();
    // A gigabyte of zeros: about a megabyte deflated.
    zip.start_file("mallorymal_105_9105_depth.png", deflated).unwrap();
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..1024 {
        zip.write_all(&zeros).unwrap();
    }
    let truncated = zip_of(&[("normals.png".to_owned(), students[0].files[1].1.clone())]);
    zip.start_file("mallorymal_105_9105_renders.zip", deflated).unwrap();
    zip.write_all(&truncated[..truncated.len() / 2]).unwrap();
    for name in ["aaaa.png", "bbbb.png", "secret.png"] {
        zip.start_file(format!("mallorymal_105_9105_{name}"), deflated).unwrap();
        zip.write_all(name.as_bytes()).unwrap();
    }
    let mut bytes = zip.finish().unwrap().into_inner();
    assert!(bytes.len() < 4 << 20, "the bomb is small: {} bytes", bytes.len());
    rename(&mut bytes, b"bbbb.png", b"aaaa.png");
    encrypt_flag(&mut bytes, b"mallorymal_105_9105_secret.png");
    fs::write(dir.join("class.zip"), &bytes).unwrap();
    let before = listing(dir);

    let report = grade(dir, &dir.join("class.zip"), "report");
    assert_eq!(report.students.len(), 3);
    let expected = [("pass", 2.0), ("pass", 1.0), ("pass", 1.0)];
    let ada = &report.students.iter().find(|s| s.name == "lovelaceada").unwrap();
    assert_eq!(
        ada.images
            .iter()
            .map(|i| (i.outcome.word(), i.points))
            .collect::<Vec<_>>(),
        expected
    );
    let mallory = report.students.iter().find(|s| s.name == "mallorymal").unwrap();
    assert!(
        matches!(mallory.images[0].outcome, Outcome::Linked { .. }),
        "{:?}",
        mallory.images[0]
    );
    assert!(
        matches!(mallory.images[2].outcome, Outcome::TooLarge { .. }),
        "{:?}",
        mallory.images[2]
    );
    assert_eq!(mallory.images[1].outcome, Outcome::Missing);
    let notes = mallory.refused.join("\n");
    for expected in [
        "color.png: a symbolic link",
        "depth.png: 1073741824 bytes uncompressed, over the limit",
        "renders.zip: not a readable zip archive",
        "aaaa.png: the archive holds several files of this name",
        "secret.png: encrypted",
    ] {
        assert!(notes.contains(expected), "no `{expected}` in:\n{notes}");
    }
    let loose: Vec<String> = report.refused.iter().map(|r| r.note()).collect();
    assert_eq!(loose.len(), 3, "the entries that name no student: {loose:?}");
    assert!(
        loose.iter().all(|n| n.contains("leaves the archive's folder")),
        "{loose:?}"
    );

    // Nothing was written but the report (and the golden cache it was told to use).
    assert_eq!(listing(dir), before);
    assert!(!absolute.exists() && !dir.join("x.png").exists() && !dir.parent().unwrap().join("x.png").exists());
    let html = fs::read_to_string(dir.join("report").join(&mallory.page)).unwrap();
    assert!(
        html.contains("a symbolic link in the archive"),
        "the student's page names the refusals"
    );
}

/// Every path under `dir` outside the report and the cache.
fn listing(dir: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, into: &mut Vec<PathBuf>) {
        for entry in fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            if path.ends_with("report") || path.ends_with("cache") {
                continue;
            }
            if path.is_dir() {
                walk(&path, into);
            }
            into.push(path);
        }
    }
    let mut paths = Vec::new();
    walk(dir, &mut paths);
    paths.sort();
    paths
}
