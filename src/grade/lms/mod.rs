//! Submissions as learning platforms hand them over: a folder of student folders, or a Canvas or
//! Moodle download, zipped or extracted.
//!
//! [`read_class`] finds the students and their files without extracting anything: a plain
//! folder's students are its folders, as ever; a download's students are found by the names the
//! platform gives (see `canvas` and `moodle`), each with their name and id on the platform, and
//! the names Canvas changes when a file is uploaded again given back (see `resubmission`). A
//! student whose files are not a folder of their own is [`stage`]d just before grading: their
//! files copied (out of the archive, with its checks) into a folder of a temporary directory,
//! their own zips expanded beside them, and the report told where each file came from.

mod archive;
pub mod canvas;
mod found;
pub mod moodle;
mod resubmission;
mod stage;

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use archive::{Limits, Refusal};
pub use stage::{Staged, stage};

use found::{Found, placement};

/// How the submissions were laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Layout {
    /// One folder per student, named as the student appears.
    Folders,
    /// Canvas's "Download Submissions": flat files `name_[LATE_]userid_submissionid_original`.
    Canvas,
    /// Moodle's "Download all submissions": a folder per student, `Full Name_ID_assignsubmission_file_`.
    Moodle,
}

impl Layout {
    pub fn describe(self) -> &'static str {
        match self {
            Layout::Folders => "one folder per student",
            Layout::Canvas => "a Canvas download",
            Layout::Moodle => "a Moodle download",
        }
    }
}

/// Who a student is on the learning platform.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LmsId {
    pub platform: Layout,
    /// Canvas's user id, or Moodle's participant id.
    pub id: String,
    /// Canvas marked the submission late.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub late: bool,
}

/// Where a student's files come from.
#[derive(Clone, Debug)]
pub enum Source {
    /// A folder of their own, read where it is (today's layout).
    Folder(PathBuf),
    /// Files to be staged, each under the name it is graded by.
    Files(Vec<Item>),
}

/// One file of a student to be staged.
#[derive(Clone, Debug)]
pub struct Item {
    /// Where it goes in the student's staged folder: the original name restored.
    pub path: PathBuf,
    pub origin: Origin,
    /// Where it was found, for the report (`class.zip/alice_12_34_a01.png`).
    pub shown: String,
}

#[derive(Clone, Debug)]
pub enum Origin {
    /// The entry of that index of the class archive.
    Entry(usize),
    /// A file of an extracted download.
    File(PathBuf),
}

/// One student as the platform names them.
#[derive(Clone, Debug)]
pub struct Student {
    /// As the report names them: the folder's name, Canvas's `smithjohn`, Moodle's full name;
    /// with the id added when two students share a name.
    pub name: String,
    pub lms: Option<LmsId>,
    pub source: Source,
    /// Where the student's files are, for the report.
    pub shown: PathBuf,
    /// Their archive entries that were refused, under the names they would have had, and their
    /// Canvas uploads that a newer one of the same name superseded, under their download names.
    pub refused: Vec<(PathBuf, Refusal)>,
}

/// A class as read from its submissions.
pub struct Class {
    pub layout: Layout,
    /// The class archive, when the submissions are a zip.
    pub archive: Option<PathBuf>,
    /// Sorted by name: shards cut this list.
    pub students: Vec<Student>,
    /// Entries that are not students' (loose files), by name.
    pub ignored: Vec<String>,
    /// Entries of the class archive that were refused and belong to no student.
    pub refused: Vec<Refusal>,
}

/// Whether `path` is read as an archive rather than a folder.
pub fn is_archive(path: &Path) -> bool {
    path.is_file() && path.extension().is_some_and(|e| e.eq_ignore_ascii_case("zip"))
}

/// The class in `submissions` (a folder or a `.zip`), skipping hidden entries, `__MACOSX` and
/// the folders of `own` (the report, the cache). `expected` are the file names the rubric
/// expects, which decide whether Canvas's `a01-1.png` is given back its name `a01.png`.
pub fn read_class(submissions: &Path, own: &[&PathBuf], expected: &[&str], limits: Limits) -> io::Result<Class> {
    if is_archive(submissions) {
        return read_archive(submissions, expected, limits);
    }
    let own: Vec<PathBuf> = own.iter().filter_map(|p| p.canonicalize().ok()).collect();
    let mut entries: Vec<(String, PathBuf, bool)> = Vec::new();
    for entry in fs::read_dir(submissions)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        if skipped(&name) || path.canonicalize().is_ok_and(|p| own.contains(&p)) {
            continue;
        }
        let is_dir = path.is_dir();
        entries.push((name, path, is_dir));
    }
    entries.sort();
    let names: Vec<(String, bool)> = entries.iter().map(|(n, _, d)| (n.clone(), *d)).collect();
    let layout = detect(&names);
    let mut found = Found::default();
    for (name, path, is_dir) in entries {
        if layout == Layout::Folders && is_dir {
            found.folder(&name, &path);
            continue;
        }
        let mut placed = false;
        if is_dir && let Some(place) = placement(layout, &format!("{name}/"), submissions) {
            found.enrol(&place);
            placed = true;
        }
        // Each file as the download names it (`folder/file` or `file`), and where it is. A top
        // file is `path` itself: `path.join("")` would be `path/`, which no file can be opened as.
        let files: Vec<(PathBuf, PathBuf)> = if is_dir {
            let mut relative = Vec::new();
            walk(&path, Path::new(""), 0, &mut relative);
            relative
                .iter()
                .map(|r| (Path::new(&name).join(r), path.join(r)))
                .collect()
        } else {
            vec![(PathBuf::from(&name), path.clone())]
        };
        for (within, file) in files {
            if let Some(place) = placement(layout, &within.to_string_lossy(), submissions) {
                let item = Item {
                    path: PathBuf::from(place.relative),
                    shown: file.display().to_string(),
                    origin: Origin::File(file),
                };
                found.add(&place, item);
                placed = true;
            }
        }
        if !placed {
            found.ignored.push(name);
        }
    }
    Ok(found.class(layout, None, Vec::new(), expected))
}

/// Hidden entries and macOS archive litter.
fn skipped(name: &str) -> bool {
    name.starts_with('.') || name == "__MACOSX"
}

/// Which layout names the most of the top-level entries (name, is a folder): Moodle's folders
/// or prefixed files, Canvas's files, or else plain folders.
fn detect(top: &[(String, bool)]) -> Layout {
    let moodle = top.iter().filter(|(n, _)| moodle::parse(n).is_some()).count();
    let canvas = top.iter().filter(|(n, d)| !d && canvas::parse(n).is_some()).count();
    match (moodle, canvas) {
        (0, 0) => Layout::Folders,
        (m, c) if m >= c => Layout::Moodle,
        _ => Layout::Canvas,
    }
}

/// The files under `dir`, relative to it, at most three levels down, links included as files
/// (staging refuses them).
fn walk(root: &Path, relative: &Path, depth: usize, files: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(root.join(relative)) else {
        return;
    };
    let mut entries: Vec<_> = entries.flatten().collect();
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let name = entry.file_name();
        if skipped(&name.to_string_lossy()) {
            continue;
        }
        let path = relative.join(&name);
        match entry.file_type() {
            Ok(kind) if kind.is_dir() => {
                if depth + 1 < 3 {
                    walk(root, &path, depth + 1, files);
                }
            }
            Ok(_) => files.push(path),
            Err(_) => {}
        }
    }
}

/// A class archive: its entries sorted into students by the layout their names follow.
fn read_archive(path: &Path, expected: &[&str], limits: Limits) -> io::Result<Class> {
    let archive = archive::Archive::open(path, limits)
        .map_err(|reason| io::Error::new(io::ErrorKind::InvalidData, format!("{}: {reason}", path.display())))?;
    let shown = |name: &str| format!("{}/{name}", path.display());
    let mut top: Vec<(String, bool)> = archive
        .entries
        .iter()
        .map(|e| &e.name)
        .chain(&archive.folders)
        .map(|name| {
            let mut parts = name.splitn(2, '/');
            let first = parts.next().unwrap_or_default().to_owned();
            (first, parts.next().is_some())
        })
        .filter(|(first, _)| !skipped(first))
        .collect();
    top.sort();
    top.dedup();
    let layout = detect(&top);
    let mut found = Found::default();
    for entry in &archive.entries {
        match placement(layout, &entry.name, path) {
            Some(place) => {
                let item = Item {
                    path: PathBuf::from(place.relative),
                    origin: Origin::Entry(entry.index),
                    shown: shown(&entry.name),
                };
                found.add(&place, item);
            }
            None if !skipped(entry.name.split('/').next().unwrap_or_default()) => {
                found.ignored.push(entry.name.clone())
            }
            None => {}
        }
    }
    for folder in &archive.folders {
        let name = format!("{}/", folder.split('/').next().unwrap_or_default());
        if let Some(place) = placement(layout, &name, path) {
            found.enrol(&place);
        }
    }
    let mut refused = Vec::new();
    for refusal in &archive.refused {
        match placement(layout, &refusal.entry, path) {
            Some(place) => found.refuse(&place, refusal.clone()),
            None => refused.push(refusal.clone()),
        }
    }
    Ok(found.class(layout, Some(path.to_path_buf()), refused, expected))
}
