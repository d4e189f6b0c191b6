//! The pending goldens of a project: insta's `golden/NAME.snap.new` files, each with the case it
//! belongs to and the golden it would replace.
//!
//! A name only ever comes from this list. A name from a command line or a request is looked up
//! in it ([`Project::find`]) and refused when absent, so no path is built from what a user or a
//! page sent.

use std::fs;
use std::path::{Path, PathBuf};

use super::error::ReviewError;
use super::snapshot::{SnapshotHeader, binary_path};

/// A project laid out as goldray's own: cases in `cases/`, goldens in `golden/`.
#[derive(Clone, Debug)]
pub struct Project {
    pub root: PathBuf,
}

/// One pending golden and the files around it. Paths are the project's (`root/golden/…`).
#[derive(Clone, Debug)]
pub struct Pending {
    /// The case name: letters, digits, `_` and `-`, as the golden suite allows.
    pub name: String,
    /// `golden/NAME.snap.new`.
    pub snap_new: PathBuf,
    pub header: SnapshotHeader,
    /// `golden/NAME.snap`, which may not exist yet (a new case).
    pub snap: PathBuf,
    /// `cases/NAME.toml`, which gives the tolerance the suite judged with.
    pub case_file: PathBuf,
}

/// What [`Project::pending`] found.
#[derive(Clone, Debug, Default)]
pub struct PendingList {
    pub pending: Vec<Pending>,
    /// `.snap.new` files that cannot be reviewed here, each with the reason.
    pub skipped: Vec<(PathBuf, String)>,
}

/// The golden suite's rule for a case name (it names the snapshot file).
pub fn is_case_name(name: &str) -> bool {
    !name.is_empty() && name.len() <= 200 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

impl Project {
    pub fn new(root: impl Into<PathBuf>) -> Project {
        Project { root: root.into() }
    }

    pub fn golden_dir(&self) -> PathBuf {
        self.root.join("golden")
    }

    /// Every `golden/*.snap.new`, sorted by name. A project without a `golden/` folder has none.
    pub fn pending(&self) -> Result<PendingList, ReviewError> {
        let dir = self.golden_dir();
        let entries = match fs::read_dir(&dir) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(PendingList::default()),
            Err(source) => return Err(ReviewError::List { path: dir, source }),
        };
        let mut list = PendingList::default();
        for entry in entries {
            let entry = entry.map_err(|source| ReviewError::List {
                path: dir.clone(),
                source,
            })?;
            let file_name = entry.file_name();
            let Some(name) = file_name.to_str().and_then(|n| n.strip_suffix(".snap.new")) else {
                continue;
            };
            let path = entry.path();
            if !is_case_name(name) {
                list.skipped
                    .push((path, "not a case name (letters, digits, `_` and `-`)".to_owned()));
                continue;
            }
            match SnapshotHeader::read(&path) {
                Ok(header) => list.pending.push(Pending {
                    name: name.to_owned(),
                    snap: dir.join(format!("{name}.snap")),
                    case_file: self.root.join("cases").join(format!("{name}.toml")),
                    snap_new: path,
                    header,
                }),
                Err(error) => list.skipped.push((path, error.to_string())),
            }
        }
        list.pending.sort_by(|a, b| a.name.cmp(&b.name));
        list.skipped.sort();
        Ok(list)
    }

    /// The pending golden called `name`, looked up in the list (never joined to a path).
    pub fn find(&self, name: &str) -> Result<Pending, ReviewError> {
        let list = self.pending()?;
        let names = list.pending.iter().map(|p| p.name.clone()).collect();
        list.pending
            .into_iter()
            .find(|p| p.name == name)
            .ok_or_else(|| ReviewError::NotPending {
                name: name.to_owned(),
                pending: names,
            })
    }
}

impl Pending {
    /// `golden/NAME.snap.new.exr`: the new render.
    pub fn new_data(&self) -> PathBuf {
        binary_path(&self.snap_new, &self.header.extension)
    }

    /// `golden/NAME.snap.exr`: where the new render goes when accepted.
    pub fn data(&self) -> PathBuf {
        binary_path(&self.snap, &self.header.extension)
    }

    /// The golden's bytes as it stands, from its own header's extension; `None` for a new case.
    pub fn old_data(&self) -> Result<Option<PathBuf>, ReviewError> {
        if !self.snap.exists() {
            return Ok(None);
        }
        let header = SnapshotHeader::read(&self.snap)?;
        Ok(Some(binary_path(&self.snap, &header.extension)))
    }
}

/// `path` relative to `root` when it is inside it: pages and messages do not show where the
/// project lives on this machine.
pub fn relative(root: &Path, path: &Path) -> String {
    path.strip_prefix(root).unwrap_or(path).display().to_string()
}
