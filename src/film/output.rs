//! Writing a render's files all-or-nothing, so that an interrupted or failed render never leaves a
//! new EXR beside an old PNG, and a golden-suite reader never sees half a file.

use std::fs::{self, File};
use std::io::{self, Cursor, Write};
use std::path::{Path, PathBuf};

use image::{ImageFormat, RgbImage};

use super::exr::encode_exr_named;
use super::png::{color_image, depth_image, normals_image};
use super::{Film, Tonemap};

/// Why an output could not be written or an EXR could not be read. Each message names the file
/// (or "EXR data"/"PNG data" for in-memory bytes) and what went wrong, because these errors end up
/// in test logs and CLI output where there is nothing else to go on.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: io::Error },

    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: io::Error },

    #[error(
        "{failure}; then restoring {} failed too: {source} (the previous outputs are kept in {})",
        path.display(),
        kept.display()
    )]
    Rollback {
        failure: Box<OutputError>,
        path: PathBuf,
        kept: PathBuf,
        source: io::Error,
    },

    #[error("refusing to write {file}: pixel ({x}, {y}) channel {channel} is {value}")]
    NonFinite {
        file: String,
        x: u32,
        y: u32,
        channel: &'static str,
        value: f32,
    },

    #[error(
        "refusing to write {file}: the film is {width}x{height} but holds {colors} colours, \
         {depths} depths and {normals} normals"
    )]
    FilmShape {
        file: String,
        width: u32,
        height: u32,
        colors: usize,
        depths: usize,
        normals: usize,
    },

    #[error("cannot encode {file}: {source}")]
    EncodeExr { file: String, source: ::exr::error::Error },

    #[error("cannot encode {file}: {source}")]
    EncodePng { file: String, source: image::ImageError },

    #[error("{file} is not a readable EXR: {source}")]
    DecodeExr { file: String, source: ::exr::error::Error },

    #[error("{file} cannot be read as a film: {reason}")]
    UnsupportedExr { file: String, reason: String },

    #[error("{file} has no {channel} channel")]
    MissingChannel { file: String, channel: &'static str },

    #[error("output name {name:?} must be a plain file name (no directory, not empty)")]
    InvalidName { name: String },
}

/// Which previews accompany the EXR; the EXR itself is always written because it is what golden
/// comparisons read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputOptions {
    pub tonemap: Tonemap,
    pub depth_range: Option<(f32, f32)>,
    pub normals: bool,
}

/// Writes `NAME.exr`, `NAME.png` and the requested `NAME_depth.png` / `NAME_normals.png` into
/// `dir` (created if missing) and returns their paths in that order.
///
/// Everything is encoded before anything touches the disk, so a film the EXR refuses writes
/// nothing. Files are then staged in a hidden directory inside `dir` and renamed into place one by
/// one; if a rename fails, the ones already made are undone, so existing outputs are either all
/// replaced or all left byte-identical.
pub fn write_outputs(
    dir: &Path,
    name: &str,
    film: &Film,
    options: &OutputOptions,
) -> Result<Vec<PathBuf>, OutputError> {
    if name.is_empty() || Path::new(name).file_name() != Some(name.as_ref()) {
        return Err(OutputError::InvalidName { name: name.to_owned() });
    }
    let path = |suffix: &str| dir.join(format!("{name}{suffix}"));
    let png = |path: PathBuf, image: RgbImage| -> Result<(PathBuf, Vec<u8>), OutputError> {
        let bytes = encode_png_named(&image, &path.display().to_string())?;
        Ok((path, bytes))
    };

    let exr_path = path(".exr");
    let exr = encode_exr_named(film, &exr_path.display().to_string())?;
    let mut files = vec![(exr_path, exr), png(path(".png"), color_image(film, options.tonemap))?];
    if let Some((min, max)) = options.depth_range {
        files.push(png(path("_depth.png"), depth_image(film, min, max, options.tonemap))?);
    }
    if options.normals {
        files.push(png(path("_normals.png"), normals_image(film, options.tonemap))?);
    }

    let pending: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (p.as_path(), &b[..])).collect();
    commit(dir, &pending)?;
    Ok(files.into_iter().map(|(path, _)| path).collect())
}

/// Replaces `path` with `bytes` so that readers see the old content or the new, never a mix,
/// and a crash leaves the old file intact: the bytes go to a synced temporary file beside `path`,
/// which is then renamed over it. Creates the parent directory if missing.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    commit(dir, &[(path, bytes)])
}

/// Lossless 8-bit RGB PNG bytes.
pub fn encode_png(image: &RgbImage) -> Result<Vec<u8>, OutputError> {
    encode_png_named(image, "PNG data")
}

/// [`encode_png`] written with [`write_file_atomic`].
pub fn write_png(path: &Path, image: &RgbImage) -> Result<(), OutputError> {
    let bytes = encode_png_named(image, &path.display().to_string())?;
    write_file_atomic(path, &bytes)
}

fn encode_png_named(image: &RgbImage, file: &str) -> Result<Vec<u8>, OutputError> {
    let mut bytes = Cursor::new(Vec::new());
    image
        .write_to(&mut bytes, ImageFormat::Png)
        .map_err(|source| OutputError::EncodePng {
            file: file.to_owned(),
            source,
        })?;
    Ok(bytes.into_inner())
}

/// A target that has been replaced, and how to undo that.
struct Installed<'a> {
    target: &'a Path,
    /// A hard link to (or copy of) the file it replaced; `None` when there was none.
    previous: Option<PathBuf>,
}

/// Stages every file in a temporary directory inside `dir` (same filesystem, so renames are
/// atomic), then renames them over their targets in order, undoing the earlier renames if a later
/// one fails. The staging directory, with any backups, is removed on the way out.
fn commit(dir: &Path, files: &[(&Path, &[u8])]) -> Result<(), OutputError> {
    let dir_error = |source| OutputError::Write {
        path: dir.to_path_buf(),
        source,
    };
    fs::create_dir_all(dir).map_err(dir_error)?;
    let staging = tempfile::Builder::new()
        .prefix(".goldray-")
        .tempdir_in(dir)
        .map_err(dir_error)?;

    let mut staged = Vec::with_capacity(files.len());
    for (i, &(target, bytes)) in files.iter().enumerate() {
        let temp = staging.path().join(i.to_string());
        write_synced(&temp, bytes).map_err(|source| OutputError::Write {
            path: target.to_path_buf(),
            source,
        })?;
        staged.push(temp);
    }

    let mut installed: Vec<Installed> = Vec::with_capacity(files.len());
    for (i, (&(target, _), temp)) in files.iter().zip(&staged).enumerate() {
        // The last target is never rolled back, so its old content needs no backup.
        let needs_backup = i + 1 < files.len();
        let backup = staging.path().join(format!("{i}.previous"));
        let result =
            preserve(target, &backup, needs_backup).and_then(|previous| fs::rename(temp, target).map(|()| previous));
        match result {
            Ok(previous) => installed.push(Installed { target, previous }),
            Err(source) => {
                let failure = OutputError::Write {
                    path: target.to_path_buf(),
                    source,
                };
                return Err(roll_back(installed, staging, failure));
            }
        }
    }
    Ok(())
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
fn roll_back(installed: Vec<Installed>, staging: tempfile::TempDir, failure: OutputError) -> OutputError {
    for Installed { target, previous } in installed.into_iter().rev() {
        let undone = match &previous {
            Some(backup) => fs::rename(backup, target),
            None => fs::remove_file(target),
        };
        if let Err(source) = undone {
            return OutputError::Rollback {
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
    fn messages_name_the_file_and_the_problem() {
        let error = OutputError::Write {
            path: PathBuf::from("out/a.exr"),
            source: io::Error::from(io::ErrorKind::PermissionDenied),
        };
        assert_eq!(error.to_string(), "cannot write out/a.exr: permission denied");
        let error = OutputError::MissingChannel {
            file: "a.exr".into(),
            channel: "R",
        };
        assert_eq!(error.to_string(), "a.exr has no R channel");
    }

    #[test]
    fn names_with_directories_are_refused() {
        let options = OutputOptions {
            tonemap: Tonemap::Srgb,
            depth_range: None,
            normals: false,
        };
        for name in ["", "..", "a/b", "/abs"] {
            let result = write_outputs(Path::new("unused"), name, &Film::new(1, 1), &options);
            assert!(matches!(result, Err(OutputError::InvalidName { .. })), "{name:?}");
        }
        assert!(!Path::new("unused").exists());
    }
}
