//! Canvas's resubmissions, undone: a student who uploads `a01.png` again finds `a01-1.png` in the
//! download (then `a01-2.png`), while grading looks for `a01.png`.
//!
//! A name with Canvas's mark (see [`canvas::resubmission`]) gets back the name it was uploaded
//! under when the rubric expects that name, or when the student has no upload of that name: a
//! student's own `frame-1.png` beside their `frame.png`, neither expected, is left as it is, and so
//! is a name the rubric expects as it stands. When two of a student's uploads then share a name
//! (ignoring case, as grading looks files up), the newest is kept, the one with the larger file id
//! (Canvas counts up), then the larger N; each older one is refused with a note naming the upload
//! that superseded it, so that no upload disappears without a word.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::{Item, Refusal, canvas};
use crate::grade::outcome::Outcome;

/// One of a Canvas student's uploads, before their resubmissions are sorted out.
pub(super) struct Upload {
    /// Its name in the student's folder: as the download gives it, until restored.
    pub name: String,
    /// The id Canvas gave the file (the second number of its name).
    pub submission: String,
    pub kind: Kind,
}

pub(super) enum Kind {
    /// A file to stage.
    File(Item),
    /// An entry the class archive refused.
    Refused(Refusal),
}

impl Upload {
    /// Its name in the download, for notes.
    fn download(&self) -> String {
        match &self.kind {
            Kind::File(item) => Path::new(&item.shown)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| item.shown.clone()),
            Kind::Refused(refusal) => refusal.entry.clone(),
        }
    }
}

/// One student's uploads, names restored, the older of any two of one name refused: the files to
/// stage, and the refusals under the names they would have had.
pub(super) fn resolve(uploads: Vec<Upload>, expected: &[&str]) -> (Vec<Item>, Vec<(PathBuf, Refusal)>) {
    let expects = |name: &str| expected.iter().any(|e| e.eq_ignore_ascii_case(name));
    let names: BTreeSet<String> = uploads.iter().map(|u| u.name.to_lowercase()).collect();
    let uploads: Vec<(Upload, u32)> = uploads
        .into_iter()
        .map(|mut upload| match canvas::resubmission(&upload.name) {
            Some((restored, n))
                if !expects(&upload.name) && (expects(&restored) || !names.contains(&restored.to_lowercase())) =>
            {
                upload.name = restored;
                (upload, n)
            }
            _ => (upload, 0),
        })
        .collect();
    // For each name, the newest upload of that name.
    let mut newest: BTreeMap<String, usize> = BTreeMap::new();
    for (i, upload) in uploads.iter().enumerate() {
        let kept = newest.entry(upload.0.name.to_lowercase()).or_insert(i);
        if age(upload) > age(&uploads[*kept]) {
            *kept = i;
        }
    }
    let (mut items, mut refused) = (Vec::new(), Vec::new());
    for (i, (upload, _)) in uploads.iter().enumerate() {
        let kept = newest[&upload.name.to_lowercase()];
        let superseded = (kept != i).then(|| uploads[kept].0.download());
        match (&upload.kind, superseded) {
            (Kind::File(item), None) => items.push(Item {
                path: PathBuf::from(&upload.name),
                ..item.clone()
            }),
            (Kind::Refused(refusal), None) => refused.push((PathBuf::from(&upload.name), refusal.clone())),
            // Refused under its name in the download, which no expected file has: the newest
            // upload decides the verdict of the name, whatever became of the older ones.
            (Kind::File(item), Some(by)) => refused.push((
                PathBuf::from(upload.download()),
                Refusal {
                    entry: item.shown.clone(),
                    outcome: Outcome::Unreadable {
                        reason: format!("an earlier upload of {}, superseded by {by}: not read", upload.name),
                    },
                },
            )),
            (Kind::Refused(refusal), Some(_)) => refused.push((PathBuf::from(upload.download()), refusal.clone())),
        }
    }
    (items, refused)
}

/// How late an upload is: its file id as a number of any length, then its mark's N.
fn age((upload, n): &(Upload, u32)) -> (usize, &str, u32) {
    let id = upload.submission.trim_start_matches('0');
    (id.len(), id, *n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grade::lms::Origin;

    fn file(original: &str, submission: &str) -> Upload {
        Upload {
            name: original.to_owned(),
            submission: submission.to_owned(),
            kind: Kind::File(Item {
                path: PathBuf::from(original),
                origin: Origin::File(PathBuf::new()),
                shown: format!("class.zip/smith_1_{submission}_{original}"),
            }),
        }
    }

    /// The staged files as (name, the download's file id), and the refusals' paths.
    fn resolved(uploads: Vec<Upload>, expected: &[&str]) -> (Vec<(String, String)>, Vec<String>) {
        let (items, refused) = resolve(uploads, expected);
        let items = items
            .iter()
            .map(|i| {
                let id = i.shown.split('_').nth(2).unwrap().to_owned();
                (i.path.display().to_string(), id)
            })
            .collect();
        (items, refused.iter().map(|(p, _)| p.display().to_string()).collect())
    }

    fn named(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
        pairs.iter().map(|(a, b)| ((*a).to_owned(), (*b).to_owned())).collect()
    }

    #[test]
    fn a_resubmitted_name_is_restored_when_expected_or_free() {
        let uploads = vec![file("a01-1.png", "5"), file("notes-2.txt", "6"), file("a02-0.png", "7")];
        let (items, refused) = resolved(uploads, &["a01.png"]);
        assert_eq!(
            items,
            named(&[("a01.png", "5"), ("notes.txt", "6"), ("a02-0.png", "7")])
        );
        assert!(refused.is_empty());
    }

    #[test]
    fn an_unexpected_name_beside_its_original_is_left_alone() {
        let uploads = vec![file("frame.png", "5"), file("frame-1.png", "6")];
        let (items, refused) = resolved(uploads, &["a01.png"]);
        assert_eq!(items, named(&[("frame.png", "5"), ("frame-1.png", "6")]));
        assert!(refused.is_empty());
        // A name the rubric expects as it stands is never changed.
        let (items, _) = resolved(vec![file("scene-1.png", "5")], &["scene-1.png"]);
        assert_eq!(items, named(&[("scene-1.png", "5")]));
    }

    #[test]
    fn the_newest_of_one_name_is_kept_and_the_others_refused_with_a_note() {
        let uploads = vec![file("a01-2.png", "30"), file("a01.png", "10"), file("A01-1.png", "20")];
        let (items, refused) = resolve(uploads, &["a01.png"]);
        assert_eq!(items.len(), 1);
        assert_eq!(
            (items[0].path.to_str(), items[0].shown.as_str()),
            (Some("a01.png"), "class.zip/smith_1_30_a01-2.png")
        );
        let notes: Vec<String> = refused.iter().map(|(_, r)| r.note()).collect();
        assert_eq!(
            notes,
            [
                "class.zip/smith_1_10_a01.png: an earlier upload of a01.png, superseded by smith_1_30_a01-2.png: not read",
                "class.zip/smith_1_20_A01-1.png: an earlier upload of A01.png, superseded by smith_1_30_a01-2.png: not read",
            ]
        );
        // Under their names in the download, so that they give no expected file a verdict.
        assert_eq!(refused[0].0, PathBuf::from("smith_1_10_a01.png"));
    }

    #[test]
    fn a_longer_file_id_is_newer_and_n_breaks_a_tie() {
        let (items, _) = resolved(vec![file("a01-1.png", "999"), file("a01.png", "1000")], &["a01.png"]);
        assert_eq!(items, named(&[("a01.png", "1000")]));
        let (items, _) = resolved(vec![file("a01-2.png", "7"), file("a01-1.png", "7")], &["a01.png"]);
        assert_eq!(items, named(&[("a01.png", "7")]));
        let (items, refused) = resolve(vec![file("a01-2.png", "7"), file("a01-1.png", "7")], &["a01.png"]);
        assert!(items[0].shown.ends_with("a01-2.png") && refused.len() == 1);
    }

    #[test]
    fn a_refused_newest_upload_keeps_the_verdict_of_its_name() {
        let mut newest = file("a01-1.png", "9");
        newest.kind = Kind::Refused(Refusal {
            entry: "smith_1_9_a01-1.png".to_owned(),
            outcome: Outcome::Linked {
                reason: "a symbolic link in the archive: not read".to_owned(),
            },
        });
        let (items, refused) = resolve(vec![file("a01.png", "3"), newest], &["a01.png"]);
        assert!(items.is_empty());
        let paths: Vec<&Path> = refused.iter().map(|(p, _)| p.as_path()).collect();
        assert_eq!(paths, [Path::new("smith_1_3_a01.png"), Path::new("a01.png")]);
        assert!(matches!(refused[1].1.outcome, Outcome::Linked { .. }));
    }
}
