//! The student's side of a run: which program runs, from which folder, and the fresh copy of the
//! submission that a build works in.

use std::fs;
use std::path::{Path, PathBuf};

use super::error::RunError;

/// At most this many files and folders are copied from a submission: a folder that holds more
/// is not a ray tracer's sources.
const MAX_ENTRIES: usize = 100_000;

/// The program to run: an absolute path, and the folder of the submission it belongs to (which
/// every command may read).
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    pub path: PathBuf,
    pub args: Vec<String>,
    pub folder: Option<PathBuf>,
}

/// The submission's folder: `--submission DIR`, else the folder of `--program` when it is a path.
pub fn submission_folder(program: &str, submission: Option<&Path>) -> Option<PathBuf> {
    match submission {
        Some(dir) => Some(dir.to_path_buf()),
        None if program.contains('/') => {
            let path = std::path::absolute(program).ok()?;
            path.parent().map(Path::to_path_buf)
        }
        None => None,
    }
}

/// Finds `argv[0]`. After a build (`built` is the copy, `original` the submission it was copied
/// from), a relative path, or an absolute one inside the submission, names the file in the copy,
/// and a bare name is first looked for there; otherwise a path is taken from the current folder
/// and a bare name is looked up in `PATH`.
pub fn resolve(argv: &[String], original: Option<&Path>, built: Option<&Path>) -> Result<Program, RunError> {
    let (first, args) = argv.split_first().ok_or(RunError::NoProgram)?;
    let path = match built {
        Some(copy) => {
            let given = Path::new(first);
            let inside = match (given.is_absolute(), original) {
                (true, Some(original)) => std::path::absolute(original)
                    .ok()
                    .and_then(|o| given.strip_prefix(o).ok().map(Path::to_path_buf)),
                (true, None) => None,
                (false, _) => Some(given.to_path_buf()),
            };
            // A bare name is the build's output unless the copy lacks it and PATH has it (a
            // failed build leaves it missing: that is reported per command, not here).
            match (inside, on_path(first)) {
                (Some(relative), _) if first.contains('/') || copy.join(&relative).exists() => copy.join(relative),
                (_, _) if first.contains('/') => given.to_path_buf(),
                (_, Some(found)) => found,
                (_, None) => copy.join(first),
            }
        }
        None if first.contains('/') => std::path::absolute(first).map_err(RunError::io("find", first))?,
        None => on_path(first).ok_or_else(|| RunError::ProgramNotFound(first.clone()))?,
    };
    if built.is_none() && !path.is_file() {
        return Err(RunError::ProgramNotFound(first.clone()));
    }
    Ok(Program {
        path,
        args: args.to_vec(),
        folder: built.map(Path::to_path_buf).or_else(|| original.map(Path::to_path_buf)),
    })
}

fn on_path(name: &str) -> Option<PathBuf> {
    let paths = std::env::var_os("PATH")?;
    std::env::split_paths(&paths)
        .map(|dir| dir.join(name))
        .find(|candidate| candidate.is_file())
        .and_then(|found| std::path::absolute(found).ok())
}

/// Copies the submission folder `from` into the new folder `to`: folders, regular files (with
/// their permissions, so a shipped script stays executable) and symbolic links as links (never
/// followed: a link out of the submission stays a link, which the sandbox does not let the build
/// read).
pub fn copy_submission(from: &Path, to: &Path) -> Result<(), RunError> {
    if !from.is_dir() {
        return Err(RunError::Io {
            what: "copy the submission",
            path: from.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotADirectory, "not a folder"),
        });
    }
    let mut count = 0;
    copy_tree(from, to, &mut count)
}

/// Feeds `hasher` every entry of the submission folder `folder`: relative paths in name order,
/// each file's bytes (through its own BLAKE3 digest), each link's target (never followed).
pub fn hash_submission(folder: &Path, hasher: &mut blake3::Hasher) -> Result<(), RunError> {
    let mut count = 0;
    hash_tree(folder, Path::new(""), hasher, &mut count)
}

fn hash_tree(root: &Path, relative: &Path, hasher: &mut blake3::Hasher, count: &mut usize) -> Result<(), RunError> {
    let dir = root.join(relative);
    let mut entries = fs::read_dir(&dir)
        .map_err(RunError::io("list", &dir))?
        .collect::<Result<Vec<_>, _>>()
        .map_err(RunError::io("list", &dir))?;
    entries.sort_by_key(|entry| entry.file_name());
    for entry in entries {
        *count += 1;
        if *count > MAX_ENTRIES {
            return Err(too_many(root));
        }
        let path = relative.join(entry.file_name());
        let source = entry.path();
        let kind = entry.file_type().map_err(RunError::io("read", &source))?;
        hasher.update(path.as_os_str().as_encoded_bytes());
        if kind.is_dir() {
            hasher.update(b"/");
            hash_tree(root, &path, hasher, count)?;
        } else if kind.is_file() {
            let file = fs::File::open(&source).map_err(RunError::io("read", &source))?;
            let mut digest = blake3::Hasher::new();
            digest.update_reader(file).map_err(RunError::io("read", &source))?;
            hasher.update(b"=").update(digest.finalize().as_bytes());
        } else if kind.is_symlink() {
            let link = fs::read_link(&source).map_err(RunError::io("read", &source))?;
            hasher.update(b"->").update(link.as_os_str().as_encoded_bytes());
        }
    }
    Ok(())
}

fn too_many(folder: &Path) -> RunError {
    RunError::Io {
        what: "take the submission",
        path: folder.to_path_buf(),
        source: std::io::Error::other(format!("more than {MAX_ENTRIES} files")),
    }
}

fn copy_tree(from: &Path, to: &Path, count: &mut usize) -> Result<(), RunError> {
    fs::create_dir_all(to).map_err(RunError::io("create", to))?;
    for entry in fs::read_dir(from).map_err(RunError::io("list", from))? {
        let entry = entry.map_err(RunError::io("list", from))?;
        *count += 1;
        if *count > MAX_ENTRIES {
            return Err(too_many(from));
        }
        let (source, target) = (entry.path(), to.join(entry.file_name()));
        let kind = entry.file_type().map_err(RunError::io("read", &source))?;
        if kind.is_dir() {
            copy_tree(&source, &target, count)?;
        } else if kind.is_file() {
            fs::copy(&source, &target).map_err(RunError::io("copy", &source))?;
        } else if kind.is_symlink() {
            let link = fs::read_link(&source).map_err(RunError::io("read", &source))?;
            std::os::unix::fs::symlink(link, &target).map_err(RunError::io("copy", &source))?;
        }
    }
    Ok(())
}
