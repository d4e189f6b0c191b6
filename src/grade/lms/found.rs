//! Students as a download's names place them: which student an entry or file belongs to, under
//! what name, and the class they add up to.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::resubmission::{self, Kind, Upload};
use super::{Class, Item, Layout, LmsId, Refusal, Source, Student, canvas, moodle, skipped};

/// Whose file an archive entry is, under what name.
pub(super) struct Placement<'a> {
    name: &'a str,
    platform: Layout,
    id: &'a str,
    late: bool,
    /// Canvas's id of the file (empty elsewhere): which of two uploads is the newer.
    submission: &'a str,
    /// Where the student's files are, for the report.
    folder: PathBuf,
    /// The file's name in the student's folder.
    pub(super) relative: &'a str,
}

/// The student an entry named `name` of the archive at `archive` belongs to in `layout`. A folder
/// is named with its `/` (`Full Name_ID_assignsubmission_file_/`): its placement is the student
/// with an empty `relative`.
pub(super) fn placement<'a>(layout: Layout, name: &'a str, archive: &Path) -> Option<Placement<'a>> {
    let (first, rest) = match name.split_once('/') {
        Some((first, rest)) => (first, Some(rest)),
        None => (name, None),
    };
    if skipped(first) || first.is_empty() {
        return None;
    }
    match (layout, rest) {
        (Layout::Folders, Some(rest)) => Some(Placement {
            name: first,
            platform: Layout::Folders,
            id: "",
            late: false,
            submission: "",
            folder: archive.join(first),
            relative: rest,
        }),
        (Layout::Moodle, _) => {
            let m = moodle::parse(first)?;
            let relative = rest.unwrap_or(m.rest);
            // Prefixed files ("Download submissions in folders" unticked) have no folder: the
            // report shows the prefix they share.
            let folder = match rest {
                Some(_) => archive.join(first),
                None => archive.join(format!("{}_{}_assignsubmission_*", m.full_name, m.participant)),
            };
            (rest.is_some() || !relative.is_empty()).then_some(Placement {
                name: m.full_name,
                platform: Layout::Moodle,
                id: m.participant,
                late: false,
                submission: "",
                folder,
                relative,
            })
        }
        (Layout::Canvas, None) => {
            let c = canvas::parse(first)?;
            Some(Placement {
                name: c.name,
                platform: Layout::Canvas,
                id: c.user_id,
                late: c.late,
                submission: c.submission_id,
                folder: canvas_folder(archive, &c),
                relative: c.original,
            })
        }
        _ => None,
    }
}

/// Students as they are found, grouped by their id on the platform (a folder's name for plain
/// folders).
#[derive(Default)]
pub(super) struct Found {
    students: BTreeMap<(Layout, String), Student>,
    /// Canvas students' files and refused entries by user id, held back until all are known:
    /// whether `a01-1.png` is a resubmission to restore depends on the student's other uploads.
    uploads: BTreeMap<String, Vec<Upload>>,
    pub(super) ignored: Vec<String>,
}

impl Found {
    pub(super) fn folder(&mut self, name: &str, path: &Path) {
        let student = Student {
            name: name.to_owned(),
            lms: None,
            source: Source::Folder(path.to_path_buf()),
            shown: path.to_path_buf(),
            refused: Vec::new(),
        };
        self.students.insert((Layout::Folders, name.to_owned()), student);
    }

    /// The student `place` names, made on first sight.
    fn student(&mut self, place: &Placement) -> &mut Student {
        let key = match place.platform {
            Layout::Folders => place.name,
            _ => place.id,
        };
        let student = self
            .students
            .entry((place.platform, key.to_owned()))
            .or_insert_with(|| Student {
                name: place.name.to_owned(),
                lms: (place.platform != Layout::Folders).then(|| LmsId {
                    platform: place.platform,
                    id: place.id.to_owned(),
                    late: false,
                }),
                source: Source::Files(Vec::new()),
                shown: place.folder.clone(),
                refused: Vec::new(),
            });
        if let Some(lms) = &mut student.lms {
            lms.late |= place.late;
        }
        student
    }

    /// The student `place` names, with or without files: a Moodle participant's empty folder is
    /// a student who handed in nothing, graded with every file missing, not a folder to ignore.
    pub(super) fn enrol(&mut self, place: &Placement) {
        self.student(place);
    }

    pub(super) fn add(&mut self, place: &Placement, item: Item) {
        if place.platform == Layout::Canvas {
            self.upload(place, Kind::File(item));
        } else if let Source::Files(items) = &mut self.student(place).source {
            items.push(item);
        }
    }

    pub(super) fn refuse(&mut self, place: &Placement, refusal: Refusal) {
        if place.platform == Layout::Canvas {
            self.upload(place, Kind::Refused(refusal));
        } else {
            let relative = PathBuf::from(place.relative);
            self.student(place).refused.push((relative, refusal));
        }
    }

    fn upload(&mut self, place: &Placement, kind: Kind) {
        self.student(place);
        self.uploads.entry(place.id.to_owned()).or_default().push(Upload {
            name: place.relative.to_owned(),
            submission: place.submission.to_owned(),
            kind,
        });
    }

    /// The class, students sorted by name then id, names made distinct by their id; Canvas's
    /// resubmissions resolved against the rubric's `expected` file names.
    pub(super) fn class(
        mut self,
        layout: Layout,
        archive: Option<PathBuf>,
        refused: Vec<Refusal>,
        expected: &[&str],
    ) -> Class {
        for (id, uploads) in std::mem::take(&mut self.uploads) {
            let (items, refusals) = resubmission::resolve(uploads, expected);
            if let Some(student) = self.students.get_mut(&(Layout::Canvas, id)) {
                student.source = Source::Files(items);
                student.refused.extend(refusals);
            }
        }
        let mut students: Vec<Student> = self.students.into_values().collect();
        let id = |s: &Student| s.lms.as_ref().map(|l| l.id.clone()).unwrap_or_default();
        students.sort_by(|a, b| a.name.cmp(&b.name).then_with(|| id(a).cmp(&id(b))));
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        for student in &students {
            *counts.entry(student.name.clone()).or_default() += 1;
        }
        for student in &mut students {
            if counts[&student.name] > 1
                && let Some(lms) = &student.lms
            {
                student.name = format!("{} ({})", student.name, lms.id);
            }
        }
        let mut ignored = self.ignored;
        ignored.sort();
        Class {
            layout,
            archive,
            students,
            ignored,
            refused,
        }
    }
}

/// A Canvas student's files have no folder: the report shows the pattern they share.
fn canvas_folder(root: &Path, file: &canvas::CanvasFile) -> PathBuf {
    let late = if file.late { "LATE_" } else { "" };
    root.join(format!("{}_{late}{}_*", file.name, file.user_id))
}
