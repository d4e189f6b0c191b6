//! Replacing files so that readers see the old content or the new, never a mix, and a set of files
//! all-or-nothing, so that a failed or interrupted run never leaves a new EXR beside an old PNG.
//!
//! A leaf module: renders, statistics, reports and exported cases all write through it.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Why a file could not be replaced. Messages name the file the caller asked for, never the
/// temporary file beside it.
#[derive(Debug, thiserror::Error)]
pub enum AtomicWriteError {
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: io::Error },

    #[error(
        "{failure}; then restoring {} failed too: {source} (the previous outputs are kept in {})",
        path.display(),
        kept.display()
    )]
    Rollback {
        failure: Box<AtomicWriteError>,
        path: PathBuf,
        kept: PathBuf,
        source: io::Error,
    },
}

/// Replaces `path` with `bytes` so that readers see the old content or the new, never a mix,
/// and a crash leaves the old file intact: the bytes go to a synced temporary file beside `path`,
/// which is then renamed over it. Creates the parent directory if missing.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    write_files_atomic(parent_folder(path), &[(path, bytes)])
}

/// [`write_file_atomic`] without syncing: readers still see the old file or the whole new one
/// (the bytes go to a temporary file beside `path`, renamed over it), but a power failure soon
/// after may lose the new content. For outputs written by the hundred that are cheap to make
/// again, and checked when read back (a report's per-student pictures, pages and results), where
/// a sync per file would cost more than making the file.
pub fn replace_file(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    let error = |source| AtomicWriteError::Write {
        path: path.to_path_buf(),
        source,
    };
    let dir = parent_folder(path);
    fs::create_dir_all(dir).map_err(error)?;
    // Created like any output (the umask decides who may read it).
    let temp = temporary_beside(dir, "tmp");
    let written = File::create_new(&temp)
        .and_then(|mut file| file.write_all(bytes))
        .and_then(|()| fs::rename(&temp, path));
    if written.is_err() {
        let _ = fs::remove_file(&temp);
    }
    written.map_err(error)
}

/// Writes `path` with `bytes` only if no file is there yet, so that concurrent writers of the
/// same content-addressed file leave one file, whoever came first: the bytes go to a synced
/// temporary file beside `path`, which is then linked to `path` (a link never replaces).
pub fn publish_file(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    let temp = temporary_beside(parent_folder(path), "new");
    write_file_atomic(&temp, bytes)?;
    let published = match fs::hard_link(&temp, path) {
        Err(e) if e.kind() != io::ErrorKind::AlreadyExists => Err(AtomicWriteError::Write {
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    };
    let _ = fs::remove_file(&temp);
    published
}

/// Makes `link` a hard link to the file `original` (same filesystem), replacing whatever `link`
/// was atomically: readers see the old file or the new link, never neither. For content-addressed
/// caches, where many names stand for one file.
pub fn link_file(original: &Path, link: &Path) -> Result<(), AtomicWriteError> {
    let error = |source| AtomicWriteError::Write {
        path: link.to_path_buf(),
        source,
    };
    let dir = parent_folder(link);
    fs::create_dir_all(dir).map_err(error)?;
    let temp = temporary_beside(dir, "link");
    let linked = fs::hard_link(original, &temp).and_then(|()| fs::rename(&temp, link));
    if linked.is_err() {
        let _ = fs::remove_file(&temp);
    }
    linked.map_err(error)
}

/// A name in `dir` that no other writer in this or another process uses, for a file that is
/// renamed or linked into place.
fn temporary_beside(dir: &Path, extension: &str) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    dir.join(format!(
        ".goldray-{}-{}.{extension}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Checks, before any work is spent on it, that `path` could be written: it is not a folder, and
/// its folder (or, when that is missing, the nearest existing folder above it, since writing
/// creates missing folders) accepts a new file. The error names `path`, never a temporary file.
pub fn check_writable(path: &Path) -> Result<(), AtomicWriteError> {
    if path.is_dir() {
        return Err(AtomicWriteError::Write {
            path: path.to_path_buf(),
            source: io::ErrorKind::IsADirectory.into(),
        });
    }
    check_folder_writable(parent_folder(path)).map_err(|source| AtomicWriteError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// [`check_writable`] for a folder that files will be written into (created if missing).
pub fn check_writable_folder(folder: &Path) -> Result<(), AtomicWriteError> {
    check_folder_writable(folder).map_err(|source| AtomicWriteError::Write {
        path: folder.to_path_buf(),
        source,
    })
}

fn check_folder_writable(folder: &Path) -> io::Result<()> {
    let mut existing = folder;
    while fs::symlink_metadata(existing).is_err() {
        match existing.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => existing = parent,
            _ => {
                existing = Path::new(".");
                break;
            }
        }
    }
    if !existing.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::NotADirectory,
            format!("{} is not a folder", existing.display()),
        ));
    }
    tempfile::Builder::new()
        .prefix(".goldray-check-")
        .tempfile_in(existing)
        .map(drop)
}

/// The folder `path` is written in: its parent, or `.` for a bare file name.
pub fn parent_folder(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// A target that has been replaced, and how to undo that.
struct Installed<'a> {
    target: &'a Path,
    /// A hard link to (or copy of) the file it replaced; `None` when there was none.
    previous: Option<PathBuf>,
}

/// Replaces every `(target, bytes)` pair, all or nothing: stages every file in a temporary directory inside `dir` (same filesystem, so renames are
/// atomic), then renames them over their targets in order, undoing the earlier renames if a later
/// one fails. The staging directory, with any backups, is removed on the way out.
pub fn write_files_atomic(dir: &Path, files: &[(&Path, &[u8])]) -> Result<(), AtomicWriteError> {
    let dir_error = |source| AtomicWriteError::Write {
        path: dir.to_path_buf(),
        source,
    };
    fs::create_dir_all(dir).map_err(dir_error)?;
    let staging = tempfile::Builder::new()
        .prefix(".goldray-")
        .tempdir_in(dir)
        .map_err(dir_error)?;

    let staged: Vec<PathBuf> = (0..files.len()).map(|i| staging.path().join(i.to_string())).collect();
    // Each file is synced before anything is renamed, so a crash leaves every target old or
    // whole and new. The syncs wait on the disk, not the processor, and are issued side by side
    // (a thread each) so that the file system commits them together: one after another, each
    // waits for its own journal commit, a few milliseconds apiece on a busy disk.
    let jobs: Vec<(&[u8], &PathBuf)> = files.iter().map(|&(_, bytes)| bytes).zip(&staged).collect();
    let results = side_by_side(&jobs, |&(bytes, temp)| write_synced(temp, bytes));
    for (&(target, _), result) in files.iter().zip(results) {
        result.map_err(|source| AtomicWriteError::Write {
            path: target.to_path_buf(),
            source,
        })?;
    }

    let mut installed: Vec<Installed> = Vec::with_capacity(files.len());
    // Every target of a set keeps its old content until all are installed, the last one too
    // (which is never rolled back), so that the old contents are freed side by side below rather
    // than one by one inside the renames.
    let needs_backup = files.len() > 1;
    for (i, (&(target, _), temp)) in files.iter().zip(&staged).enumerate() {
        let backup = staging.path().join(format!("{i}.previous"));
        let result =
            preserve(target, &backup, needs_backup).and_then(|previous| fs::rename(temp, target).map(|()| previous));
        match result {
            Ok(previous) => installed.push(Installed { target, previous }),
            Err(source) => {
                let failure = AtomicWriteError::Write {
                    path: target.to_path_buf(),
                    source,
                };
                return Err(roll_back(installed, staging, failure));
            }
        }
    }
    // Freeing a replaced file can wait on the journal: about 4 ms each on ext4 mounted with
    // `discard` (strace -T), most of a small render's writing. Unlinked side by side, a set of
    // old contents costs about one such wait; the staging folder, then empty, goes on drop (which
    // also removes whatever a failed unlink left).
    let backups: Vec<PathBuf> = installed
        .into_iter()
        .filter_map(|installed| installed.previous)
        .collect();
    side_by_side(&backups, |backup| fs::remove_file(backup));
    Ok(())
}

/// `job` of every item, in order, each on a thread of its own so that jobs waiting on the disk
/// wait together: inline for a single item, and for any item the system refuses a thread for.
fn side_by_side<T: Sync, R: Send>(items: &[T], job: impl Fn(&T) -> R + Sync) -> Vec<R> {
    if items.len() < 2 {
        return items.iter().map(job).collect();
    }
    std::thread::scope(|scope| {
        let job = &job;
        let running: Vec<_> = items
            .iter()
            .map(|item| {
                std::thread::Builder::new()
                    .spawn_scoped(scope, move || job(item))
                    .map_err(|_| item)
            })
            .collect();
        running
            .into_iter()
            .map(|thread| match thread {
                Ok(thread) => thread.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
                Err(item) => job(item),
            })
            .collect()
    })
}

/// Keeps the current content of `target` at `backup` (when asked to and there is any), refusing a
/// directory in the way with a clearer message than the rename's.
fn preserve(target: &Path, backup: &Path, needs_backup: bool) -> io::Result<Option<PathBuf>> {
    match fs::symlink_metadata(target) {
        Err(error) if error.kind() == io::ErrorKind::NotFound => Ok(None),
        Err(error) => Err(error),
        Ok(meta) if meta.is_dir() => Err(io::ErrorKind::IsADirectory.into()),
        Ok(_) if !needs_backup => Ok(None),
        Ok(_) => {
            // A hard link costs nothing; filesystems without them get a copy.
            if fs::hard_link(target, backup).is_err() {
                fs::copy(target, backup)?;
            }
            Ok(Some(backup.to_path_buf()))
        }
    }
}

/// Undoes `installed` newest first. Should that fail too, the staging directory is kept so that
/// the previous content is not lost, and the error says where it is.
fn roll_back(installed: Vec<Installed>, staging: tempfile::TempDir, failure: AtomicWriteError) -> AtomicWriteError {
    for Installed { target, previous } in installed.into_iter().rev() {
        let undone = match &previous {
            Some(backup) => fs::rename(backup, target),
            None => fs::remove_file(target),
        };
        if let Err(source) = undone {
            return AtomicWriteError::Rollback {
                failure: Box::new(failure),
                path: target.to_path_buf(),
                kept: staging.keep(),
                source,
            };
        }
    }
    failure
}

fn write_synced(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = File::create(path)?;
    file.write_all(bytes)?;
    file.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replace_file_replaces_whole_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("sub/page.html");
        replace_file(&path, b"first").expect("write");
        replace_file(&path, b"second").expect("replace");
        assert_eq!(fs::read(&path).expect("read"), b"second");
        let left: Vec<_> = fs::read_dir(dir.path().join("sub")).expect("list").collect();
        assert_eq!(left.len(), 1, "only the page: {left:?}");
        fs::create_dir_all(dir.path().join("folder")).expect("folder");
        let error = replace_file(&dir.path().join("folder"), b"x").unwrap_err().to_string();
        assert!(
            error.starts_with(&format!("cannot write {}", dir.path().join("folder").display())),
            "{error}"
        );
        assert_eq!(
            fs::read_dir(dir.path()).expect("list").count(),
            2,
            "the temporary file is removed"
        );
    }

    #[test]
    fn a_published_file_keeps_the_first_content_and_links_share_it() {
        #[cfg(unix)]
        use std::os::unix::fs::MetadataExt;
        let dir = tempfile::tempdir().expect("temp dir");
        let content = dir.path().join("by-content/abc.png");
        fs::create_dir_all(content.parent().unwrap()).expect("folder");
        publish_file(&content, b"first").expect("publish");
        publish_file(&content, b"second").expect("a second publisher is not an error");
        assert_eq!(fs::read(&content).expect("read"), b"first");
        let link = dir.path().join("set/color.png");
        replace_file(&link, b"an older copy").expect("write");
        link_file(&content, &link).expect("link");
        assert_eq!(fs::read(&link).expect("read"), b"first");
        #[cfg(unix)]
        assert_eq!(
            fs::metadata(&link).unwrap().ino(),
            fs::metadata(&content).unwrap().ino()
        );
        let left = |folder: &str| fs::read_dir(dir.path().join(folder)).expect("list").count();
        assert_eq!((left("by-content"), left("set")), (1, 1), "no temporary file is left");
    }

    #[test]
    fn writability_is_checked_at_the_nearest_existing_folder_and_names_the_path_given() {
        let dir = tempfile::tempdir().expect("tempdir");
        assert!(check_writable(&dir.path().join("a.png")).is_ok());
        assert!(check_writable(&dir.path().join("new/deeper/a.png")).is_ok());
        assert!(check_writable_folder(&dir.path().join("new")).is_ok());
        let error = check_writable(dir.path()).unwrap_err().to_string();
        assert!(
            error.starts_with(&format!("cannot write {}", dir.path().display())),
            "{error}"
        );
        fs::write(dir.path().join("file"), b"x").expect("write");
        let error = check_writable(&dir.path().join("file/a.png")).unwrap_err().to_string();
        assert!(
            error.contains("file/a.png") && error.contains("is not a folder"),
            "{error}"
        );
        assert_eq!(
            fs::read_dir(dir.path()).expect("list").count(),
            1,
            "a check leaves nothing behind"
        );
    }

    #[test]
    fn jobs_side_by_side_return_their_results_in_order() {
        let items: Vec<u32> = (0..5).collect();
        assert_eq!(side_by_side(&items, |&i| i * 10), [0, 10, 20, 30, 40]);
        assert_eq!(side_by_side(&items[..1], |&i| i + 1), [1]);
        assert!(side_by_side(&items[..0], |&i| i).is_empty());
    }

    #[test]
    fn a_set_of_files_replaces_old_contents_and_leaves_no_staging_behind() {
        let dir = tempfile::tempdir().expect("temp dir");
        let (a, b, c) = (
            dir.path().join("a.png"),
            dir.path().join("b.png"),
            dir.path().join("c.png"),
        );
        write_files_atomic(dir.path(), &[(&a, b"old a"), (&b, b"old b")]).expect("first set");
        write_files_atomic(dir.path(), &[(&a, b"new a"), (&b, b"new b"), (&c, b"new c")]).expect("second set");
        for (path, content) in [(&a, "new a"), (&b, "new b"), (&c, "new c")] {
            assert_eq!(fs::read_to_string(path).expect("read"), content);
        }
        assert_eq!(
            fs::read_dir(dir.path()).expect("list").count(),
            3,
            "no staging folder or backup is left"
        );
    }

    #[test]
    fn messages_name_the_file_and_the_problem() {
        let error = AtomicWriteError::Write {
            path: PathBuf::from("out/a.exr"),
            source: io::Error::from(io::ErrorKind::PermissionDenied),
        };
        assert_eq!(error.to_string(), "cannot write out/a.exr: permission denied");
    }
}
