//! Reading what a student handed in, without trusting any of it.
//!
//! Files are opened read-only and never written. Every way a file can be wrong becomes an
//! [`Outcome`] for the report instead of an error: nothing a student submits can stop the batch,
//! exhaust memory (sizes are checked before anything is decoded) or hang it (only regular files
//! are opened, so a FIFO or `/dev/zero` named `a01.png` is refused, not read).
//!
//! PNGs that hold the right picture in another layout are accepted and converted, with a note:
//! grey (copied to R, G and B), grey+alpha and RGBA (alpha ignored), 16-bit (rounded to 8 bits),
//! palette and low bit depths (expanded). Students are graded on their pixels, not on how their
//! PNG library chose to store them.

use std::collections::BTreeMap;
use std::fs::{self, File};
use std::hash::{Hash, Hasher};
use std::io::Read;
use std::path::{Path, PathBuf};

use super::outcome::Outcome;
use crate::rgb_image::{DecodeError, RgbImage, decode_png};

/// The largest file read at all: a 16-bit RGBA PNG of a 4096² image stored uncompressed is
/// 128 MiB, far beyond any honest submission.
const MAX_FILE_BYTES: u64 = 128 << 20;
/// The largest picture decoded, on either side; a decompression bomb declares far more.
const MAX_SIDE: u32 = 16384;
/// The most memory one decoded picture may take (8192² RGBA at 8 bits), checked before decoding
/// because the decoder allocates the whole picture up front.
const MAX_DECODE_BYTES: u64 = 256 << 20;
/// How deep into a student's folder files are looked for (archives often add a level or two).
const MAX_DEPTH: usize = 3;

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";

/// The files of one student's folder, found once and then looked up per expected image.
pub struct Folder {
    root: PathBuf,
    /// Relative paths, shallowest first, then by name, so that lookups are deterministic.
    files: Vec<PathBuf>,
    /// Why the folder itself could not be listed.
    pub error: Option<String>,
    /// Files of the submission that were refused before they reached the folder (entries of a
    /// hostile archive), by the name they would have had, with their verdict.
    pub refused: Vec<(PathBuf, Outcome)>,
}

/// A file to grade, and how it was found when not exactly where expected.
pub struct Located {
    pub path: PathBuf,
    pub note: Option<String>,
}

impl Folder {
    pub fn scan(root: &Path) -> Folder {
        let mut folder = Folder {
            root: root.to_path_buf(),
            files: Vec::new(),
            error: None,
            refused: Vec::new(),
        };
        if let Err(e) = fs::read_dir(root) {
            folder.error = Some(format!("cannot list the folder: {e}"));
            return folder;
        }
        folder.walk(Path::new(""), 0);
        folder.files.sort_by(|a, b| {
            a.components()
                .count()
                .cmp(&b.components().count())
                .then_with(|| a.cmp(b))
        });
        folder
    }

    /// Symbolic links to directories are not followed, so a link loop cannot trap the walk;
    /// hidden entries and macOS archive litter (`__MACOSX`) are skipped.
    fn walk(&mut self, relative: &Path, depth: usize) {
        let Ok(entries) = fs::read_dir(self.root.join(relative)) else {
            return;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            if name.to_string_lossy().starts_with('.') || name == "__MACOSX" {
                continue;
            }
            let path = relative.join(&name);
            match entry.file_type() {
                Ok(kind) if kind.is_dir() => {
                    if depth + 1 < MAX_DEPTH {
                        self.walk(&path, depth + 1);
                    }
                }
                Ok(_) => self.files.push(path),
                Err(_) => {}
            }
        }
    }

    /// `name` at the top of the folder; failing that, the shallowest file of that name in any
    /// case anywhere below, with a note saying where it was found.
    pub fn find(&self, name: &str) -> Option<Located> {
        let exact = Path::new(name);
        if self.files.iter().any(|f| f == exact) {
            return Some(Located {
                path: self.root.join(name),
                note: None,
            });
        }
        let found = self.files.iter().find(|f| {
            f.file_name()
                .is_some_and(|n| n.to_string_lossy().eq_ignore_ascii_case(name))
        })?;
        Some(Located {
            path: self.root.join(found),
            note: Some(format!("expected {name}, graded {} instead", found.display())),
        })
    }
}

impl Folder {
    /// The verdict of a refused file named `name` (ignoring case, shallowest first), when the
    /// folder has no such file: an archive's link named `a01.png` is `linked`, not `missing`.
    pub fn refusal(&self, name: &str) -> Option<&Outcome> {
        let mut named: Vec<&(PathBuf, Outcome)> = self
            .refused
            .iter()
            .filter(|(path, _)| {
                path.file_name()
                    .is_some_and(|n| n.to_string_lossy().eq_ignore_ascii_case(name))
            })
            .collect();
        named.sort_by_key(|(path, _)| path.components().count());
        named.first().map(|(_, outcome)| outcome)
    }

    /// Feeds `hasher` everything grading `names` reads from this folder: the listing (which
    /// decides where each file is found) and the refused files, and for each expected file its
    /// path in the folder, where a link points and its bytes. Files that cannot be read are
    /// hashed as such. Paths are hashed relative to the folder, so that a download staged in
    /// another temporary folder each run hashes the same.
    pub fn hash_inputs<'a>(&self, names: impl Iterator<Item = &'a str>, hasher: &mut impl Hasher) {
        self.error.hash(hasher);
        self.files.hash(hasher);
        serde_json::to_string(&self.refused).unwrap_or_default().hash(hasher);
        let root = fs::canonicalize(&self.root).ok();
        for name in names {
            let Some(located) = self.find(name) else {
                continue;
            };
            located
                .path
                .strip_prefix(&self.root)
                .unwrap_or(&located.path)
                .hash(hasher);
            fs::read_link(&located.path).ok().hash(hasher);
            fs::canonicalize(&located.path)
                .ok()
                .map(|target| match &root {
                    Some(root) => target.strip_prefix(root).map(Path::to_path_buf).unwrap_or(target),
                    None => target,
                })
                .hash(hasher);
            let bytes = fs::metadata(&located.path)
                .ok()
                .filter(|m| m.is_file() && m.len() <= MAX_FILE_BYTES)
                .and_then(|_| fs::read(&located.path).ok());
            // The file's BLAKE3 digest stands for its bytes: several times faster to compute
            // than feeding megabytes to `hasher`.
            bytes.map(|b| *blake3::hash(&b).as_bytes()).hash(hasher);
        }
    }
}

/// Student folders of a class folder by name, and the names of the other entries. Hidden
/// entries and `__MACOSX` are skipped silently, and so are the folders of `own` (a report or a
/// cache) when they sit inside `submissions`, so that grading twice does not grade the first
/// report.
pub fn student_folders(
    submissions: &Path,
    own: &[&PathBuf],
) -> std::io::Result<(BTreeMap<String, PathBuf>, Vec<String>)> {
    let own: Vec<PathBuf> = own.iter().filter_map(|p| p.canonicalize().ok()).collect();
    let mut folders = BTreeMap::new();
    let mut ignored = Vec::new();
    for entry in fs::read_dir(submissions)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        if name.starts_with('.') || name == "__MACOSX" || path.canonicalize().is_ok_and(|p| own.contains(&p)) {
            continue;
        }
        if path.is_dir() {
            folders.insert(name, path);
        } else {
            ignored.push(name);
        }
    }
    ignored.sort();
    Ok((folders, ignored))
}

/// A decoded submission: 8-bit RGB plus what was done to get there.
pub struct Submitted {
    pub picture: RgbImage,
    pub notes: Vec<String>,
}

/// Reads and decodes `path` as a PNG, whatever its size (the caller judges the size, and still
/// wants a wrong-sized picture for the report).
pub fn read_png(path: &Path) -> Result<Submitted, Outcome> {
    let unreadable = |reason: String| Outcome::Unreadable { reason };
    let meta = fs::metadata(path).map_err(|e| unreadable(format!("cannot read the file: {e}")))?;
    if !meta.is_file() {
        return Err(unreadable("not a regular file".to_owned()));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(Outcome::TooLarge {
            reason: format!(
                "the file is {} MiB; files over {} MiB are not read",
                meta.len() >> 20,
                MAX_FILE_BYTES >> 20
            ),
        });
    }
    let mut bytes = Vec::new();
    File::open(path)
        .and_then(|file| file.take(MAX_FILE_BYTES).read_to_end(&mut bytes))
        .map_err(|e| unreadable(format!("cannot read the file: {e}")))?;
    if bytes.is_empty() {
        return Err(unreadable("the file is empty".to_owned()));
    }
    if !bytes.starts_with(PNG_MAGIC) {
        return Err(Outcome::WrongFormat {
            found: sniff(&bytes).to_owned(),
        });
    }
    if let Some((width, height)) = declared_size(&bytes)
        && (width > MAX_SIDE || height > MAX_SIDE)
    {
        return Err(Outcome::TooLarge {
            reason: format!(
                "the PNG declares {width}×{height} pixels (a decompression bomb?); nothing over \
                 {MAX_SIDE} on a side is decoded"
            ),
        });
    }
    let (picture, notes) = decode(&bytes)?;
    Ok(Submitted { picture, notes })
}

fn decode(bytes: &[u8]) -> Result<(RgbImage, Vec<String>), Outcome> {
    let decoded = decode_png(bytes, MAX_DECODE_BYTES).map_err(decode_failure)?;
    let layout = decoded.layout;
    let mut notes = Vec::new();
    if layout.is_grey() && !layout.has_alpha() {
        notes.push("grey PNG: compared as RGB with equal channels".to_owned());
    }
    if layout.has_alpha() {
        notes.push(match decoded.translucent {
            0 => "PNG with alpha: alpha ignored (every pixel is opaque)".to_owned(),
            n => {
                format!("PNG with alpha: alpha ignored ({n} pixels are not opaque; their colour is compared as stored)")
            }
        });
    }
    if layout.bits == 16 {
        notes.push("16-bit PNG: rounded to 8 bits per channel".to_owned());
    }
    Ok((decoded.image, notes))
}

/// The decoder's errors, sorted into what a TA needs to know.
fn decode_failure(error: DecodeError) -> Outcome {
    match error {
        DecodeError::TooLarge {
            width,
            height,
            layout,
            bytes,
            limit,
        } => Outcome::TooLarge {
            reason: format!(
                "the PNG declares {width}×{height} pixels of {layout}, {} MiB decoded (a decompression bomb?); \
                 nothing over {} MiB is decoded",
                bytes >> 20,
                limit >> 20
            ),
        },
        DecodeError::OverMemoryLimit => Outcome::TooLarge {
            reason: "decoding would exceed the memory limit".to_owned(),
        },
        DecodeError::Truncated => Outcome::Unreadable {
            reason: "truncated PNG: the file ends before the image data does".to_owned(),
        },
        DecodeError::Read { source, .. } => Outcome::Unreadable {
            reason: format!("cannot read the file: {source}"),
        },
        DecodeError::Corrupt(e) => Outcome::Unreadable {
            reason: format!("corrupt PNG: {e}"),
        },
    }
}

/// Width and height from the IHDR chunk, which a valid PNG has right after its signature.
fn declared_size(bytes: &[u8]) -> Option<(u32, u32)> {
    let header = bytes.get(8..24)?;
    if &header[4..8] != b"IHDR" {
        return None;
    }
    let word = |at: usize| u32::from_be_bytes([header[at], header[at + 1], header[at + 2], header[at + 3]]);
    Some((word(8), word(12)))
}

/// What a file that is not a PNG is, by its first bytes, so the verdict can say "a JPEG" rather
/// than "unreadable".
fn sniff(bytes: &[u8]) -> &'static str {
    const SIGNATURES: &[(&[u8], &str)] = &[
        (b"\x76\x2f\x31\x01", "an OpenEXR image"),
        (b"\xff\xd8\xff", "a JPEG image"),
        (b"GIF8", "a GIF image"),
        (b"BM", "a BMP image"),
        (b"P3", "a PPM image"),
        (b"P6", "a PPM image"),
        (b"II*\0", "a TIFF image"),
        (b"MM\0*", "a TIFF image"),
        (b"RIFF", "a RIFF file (WebP?)"),
        (b"%PDF", "a PDF document"),
        (b"PK\x03\x04", "a ZIP archive"),
        (b"\x1f\x8b", "a gzip archive"),
    ];
    SIGNATURES
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
        .map_or("not an image (its first bytes match no known format)", |(_, what)| what)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reason(outcome: Outcome) -> String {
        match outcome {
            Outcome::Unreadable { reason } | Outcome::TooLarge { reason } => reason,
            Outcome::WrongFormat { found } => found,
            other => panic!("unexpected {other:?}"),
        }
    }

    #[test]
    fn files_that_are_not_pngs_are_named_by_their_signature() {
        assert_eq!(sniff(b"\x76\x2f\x31\x01rest"), "an OpenEXR image");
        assert_eq!(sniff(b"\xff\xd8\xff\xe0"), "a JPEG image");
        assert_eq!(sniff(b"P6\n100 100\n255\n"), "a PPM image");
        assert!(sniff(b"hello").starts_with("not an image"));
    }

    #[test]
    fn the_declared_size_comes_from_the_header_alone() {
        let mut bytes = PNG_MAGIC.to_vec();
        bytes.extend([0, 0, 0, 13]);
        bytes.extend(b"IHDR");
        bytes.extend(800u32.to_be_bytes());
        bytes.extend(600u32.to_be_bytes());
        assert_eq!(declared_size(&bytes), Some((800, 600)));
        assert_eq!(declared_size(&bytes[..20]), None);
    }

    #[test]
    fn directories_empty_and_absent_files_are_verdicts() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty.png");
        fs::write(&empty, b"").unwrap();
        assert!(reason(read_png(dir.path()).err().unwrap()).contains("not a regular file"));
        assert!(reason(read_png(&empty).err().unwrap()).contains("empty"));
        assert!(reason(read_png(&dir.path().join("absent.png")).err().unwrap()).contains("cannot read"));
    }

    #[test]
    fn a_file_is_found_nested_and_in_another_case_with_a_note() {
        let dir = tempfile::tempdir().unwrap();
        fs::create_dir_all(dir.path().join("hw4/out")).unwrap();
        fs::write(dir.path().join("hw4/out/A01.PNG"), b"x").unwrap();
        fs::write(dir.path().join("a02.png"), b"x").unwrap();
        let folder = Folder::scan(dir.path());
        assert!(folder.find("a02.png").is_some_and(|found| found.note.is_none()));
        let nested = folder.find("a01.png").unwrap();
        assert_eq!(nested.path, dir.path().join("hw4/out/A01.PNG"));
        assert!(nested.note.unwrap().contains("hw4/out/A01.PNG"));
        assert!(folder.find("a03.png").is_none());
    }
}
