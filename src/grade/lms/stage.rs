//! Staging: one student's files put in a folder of their own, under the names they are graded by,
//! so that grading reads a download's student as it reads a folder.
//!
//! Files come out of the class archive (through its checks) or are copied from an extracted
//! download (regular files only: a link is refused, never followed). A zip among them is the
//! student's own archive: its entries are extracted beside the student's other files, with the
//! same checks, and the zip itself is not kept. Nothing is written outside `root`, which the
//! caller makes inside a temporary directory.

use std::collections::BTreeMap;
use std::fs::{self, File};
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

use super::archive::{Archive, Limits, Refusal};
use super::{Item, Origin};
use crate::grade::outcome::Outcome;

/// What staging made of a student's files.
#[derive(Clone, Debug, Default)]
pub struct Staged {
    /// For each staged file (relative to the student's folder), where it came from.
    pub shown: BTreeMap<PathBuf, String>,
    /// Files that were refused, under the name they would have had, and why.
    pub refused: Vec<(PathBuf, Refusal)>,
}

/// Stages `items` under `root` (created if needed); `class` is the class archive the items'
/// entries are in, if any. Failures are refusals of the files concerned, never errors: only
/// what a student handed in can fail here, and that must not stop the class.
pub fn stage(items: &[Item], class: Option<&Path>, root: &Path, limits: Limits) -> Staged {
    let mut staged = Staged::default();
    // Made even when every file is refused: an empty folder grades as files missing, each with
    // its refusal, not as a folder that cannot be listed.
    let _ = fs::create_dir_all(root);
    let mut archive = None;
    let refuse = |staged: &mut Staged, path: &Path, entry: &str, outcome: Outcome| {
        staged.refused.push((
            path.to_path_buf(),
            Refusal {
                entry: entry.to_owned(),
                outcome,
            },
        ));
    };
    for item in items {
        // A name from a download is data: `..` or `.` (Canvas's `smithjohn_1_2_..`, or one
        // restored from `.-1.`) would be the folder above or the folder itself, never a file.
        let plain = |c: Component| matches!(c, Component::Normal(_));
        if item.path.as_os_str().is_empty() || !item.path.components().all(plain) {
            let outcome = unreadable("its name is not a file's name (empty, . or ..): not read");
            refuse(&mut staged, &item.path, &item.shown, outcome);
            continue;
        }
        let target = root.join(&item.path);
        let copied = match &item.origin {
            Origin::Entry(index) => {
                if archive.is_none()
                    && let Some(path) = class
                {
                    archive = Some(Archive::open(path, limits));
                }
                match &mut archive {
                    Some(Ok(archive)) => match archive.entries.iter().find(|e| e.index == *index).cloned() {
                        Some(entry) => archive.extract(&entry, &target),
                        None => Err(unreadable("not among the archive's readable entries")),
                    },
                    Some(Err(reason)) => Err(unreadable(reason)),
                    None => Err(unreadable("no archive to read it from")),
                }
            }
            Origin::File(path) => copy_file(path, &target, limits),
        };
        match copied {
            Ok(()) if is_zip(&item.path) => expand(&target, item, root, limits, &mut staged),
            Ok(()) => {
                staged.shown.insert(item.path.clone(), item.shown.clone());
            }
            Err(outcome) => refuse(&mut staged, &item.path, &item.shown, outcome),
        }
    }
    staged
}

fn is_zip(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("zip"))
}

/// A student's own zip, staged at `zip`: its entries extracted under `root` beside the student's
/// other files, then the zip removed.
fn expand(zip: &Path, item: &Item, root: &Path, limits: Limits, staged: &mut Staged) {
    let inner = |name: &str| format!("{}/{name}", item.shown);
    match Archive::open(zip, limits) {
        Ok(mut archive) => {
            for refusal in std::mem::take(&mut archive.refused) {
                let path = PathBuf::from(&refusal.entry);
                staged.refused.push((
                    path,
                    Refusal {
                        entry: inner(&refusal.entry),
                        outcome: refusal.outcome,
                    },
                ));
            }
            for entry in archive.entries.clone() {
                if entry
                    .path
                    .components()
                    .next()
                    .is_some_and(|c| c.as_os_str() == "__MACOSX")
                {
                    continue;
                }
                match archive.extract(&entry, &root.join(&entry.path)) {
                    Ok(()) => {
                        staged.shown.insert(entry.path.clone(), inner(&entry.name));
                    }
                    Err(outcome) => staged.refused.push((
                        entry.path.clone(),
                        Refusal {
                            entry: inner(&entry.name),
                            outcome,
                        },
                    )),
                }
            }
        }
        Err(reason) => staged.refused.push((
            item.path.clone(),
            Refusal {
                entry: item.shown.clone(),
                outcome: unreadable(&reason),
            },
        )),
    }
    let _ = fs::remove_file(zip);
}

/// Copies one file of an extracted download, refusing anything but a regular file within the
/// size limit.
fn copy_file(from: &Path, to: &Path, limits: Limits) -> Result<(), Outcome> {
    let meta = fs::symlink_metadata(from).map_err(|e| unreadable(&format!("cannot be read: {e}")))?;
    if meta.file_type().is_symlink() {
        let target = fs::read_link(from).map(|t| t.display().to_string()).unwrap_or_default();
        return Err(Outcome::Linked {
            reason: format!("a symbolic link to {target} in a download: not read"),
        });
    }
    if !meta.is_file() {
        return Err(unreadable("not a regular file: not read"));
    }
    if meta.len() > limits.entry {
        return Err(Outcome::TooLarge {
            reason: format!("{} bytes, over the limit of {}: not read", meta.len(), limits.entry),
        });
    }
    if let Some(parent) = to.parent() {
        fs::create_dir_all(parent).map_err(|e| unreadable(&format!("cannot be staged: {e}")))?;
    }
    let mut source = File::open(from).map_err(|e| unreadable(&format!("cannot be read: {e}")))?;
    let mut out = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(to)
        .map_err(|e| match e.kind() {
            io::ErrorKind::AlreadyExists => unreadable("a second file of this name: not read"),
            _ => unreadable(&format!("cannot be staged: {e}")),
        })?;
    io::copy(&mut (&mut source).take(limits.entry), &mut out)
        .map(|_| ())
        .map_err(|e| unreadable(&format!("cannot be read: {e}")))
}

fn unreadable(reason: &str) -> Outcome {
    Outcome::Unreadable {
        reason: reason.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_that_is_not_a_file_name_is_refused_and_nothing_is_written_outside() {
        let dir = tempfile::tempdir().unwrap();
        let source = dir.path().join("source.png");
        fs::write(&source, b"png").unwrap();
        let item = |path: &str| Item {
            path: PathBuf::from(path),
            origin: Origin::File(source.clone()),
            shown: format!("download/smithjohn_1_2_{path}"),
        };
        let root = dir.path().join("staging/smithjohn");
        let staged = stage(
            &[item(".."), item("."), item(""), item("a/../../b.png"), item("a01.png")],
            None,
            &root,
            Limits::default(),
        );
        assert_eq!(staged.refused.len(), 4, "{:?}", staged.refused);
        assert!(
            staged
                .refused
                .iter()
                .all(|(_, r)| r.note().contains("not a file's name"))
        );
        assert_eq!(staged.shown.keys().collect::<Vec<_>>(), [Path::new("a01.png")]);
        let mut written: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        written.sort();
        assert_eq!(written, ["source.png", "staging"]);
        assert_eq!(fs::read_dir(dir.path().join("staging")).unwrap().count(), 1);
    }
}
