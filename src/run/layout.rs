//! A command's working folder: the scene and its assets laid out as the course's `data/` folder
//! before it runs, and the files it was to write taken out of it afterwards.

use std::fs::{self, File, OpenOptions};
use std::io::Read;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

use super::command::{CourseCommand, DATA};
use super::error::RunError;
use crate::atomic_write::write_file_atomic;
use crate::sandbox::{OutputRecord, show_bytes};

/// Fills the empty folder `work` with copies of the scene and its assets (copies: the program may
/// write over them, and must not change the originals).
pub fn lay_out(work: &Path, command: &CourseCommand) -> Result<(), RunError> {
    let data = work.join(DATA);
    fs::create_dir_all(&data).map_err(RunError::io("create", &data))?;
    let scene_name = command.scene.file_name().unwrap_or_default();
    let copy = |from: &Path, to: &Path| -> Result<(), RunError> {
        if let Some(parent) = to.parent() {
            fs::create_dir_all(parent).map_err(RunError::io("create", parent))?;
        }
        fs::copy(from, to).map(|_| ()).map_err(RunError::io("copy", from))
    };
    copy(&command.scene, &data.join(scene_name))?;
    for (asset, relative) in &command.assets {
        copy(asset, &data.join(relative))?;
    }
    Ok(())
}

/// Moves the program's `file` from `work` into `out` under the same name, if it is a regular file
/// of at most `max_bytes` (never following a link the program made, never blocking on a pipe it
/// made). The copy in `out` is replaced whole. When there is nothing to deliver, an older file of
/// that name in `out` is removed, so that it is not graded as this run's.
pub fn deliver(work: &Path, file: &str, out: &Path, max_bytes: u64) -> OutputRecord {
    let target = out.join(file);
    let problem = match read_regular(&work.join(file), max_bytes) {
        Ok(bytes) => match write_file_atomic(&target, &bytes) {
            Ok(()) => None,
            Err(e) => Some(e.to_string()),
        },
        Err(problem) => Some(problem),
    };
    if problem.is_some() {
        let _ = fs::remove_file(&target);
    }
    OutputRecord {
        file: file.to_owned(),
        delivered: problem.is_none(),
        problem,
    }
}

fn read_regular(path: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    let opened = OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path);
    let file: File = match opened {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err("not written".to_owned()),
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
            return Err("a symbolic link, not a file: not followed".to_owned());
        }
        Err(e) => return Err(format!("cannot open it: {e}")),
    };
    let meta = file.metadata().map_err(|e| format!("cannot read it: {e}"))?;
    if !meta.is_file() {
        return Err("not a regular file".to_owned());
    }
    if meta.len() > max_bytes {
        return Err(format!("larger than the file size limit ({})", show_bytes(max_bytes)));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read it: {e}"))?;
    Ok(bytes)
}
