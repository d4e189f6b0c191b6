//! Reading a zip in place, without trusting any of it.
//!
//! A learning platform's download is one zip of the whole class, and students put zips of their
//! own inside it. Every entry is checked before a byte of it is written, and one that is refused
//! is refused alone, with the reason, so that a hostile entry costs its author that file and
//! nobody else anything: a name that leaves the folder (`../`, `/etc/…`, `C:\…`), a symbolic
//! link, a name the archive holds twice (which copy would be graded is the archive's choice, not
//! the student's), an encrypted entry, a compression method goldray does not read, and a zip
//! bomb (too many entries, more bytes than [`Limits`] allow in all or in one entry, or
//! compressed more than [`Limits::ratio`] times). Sizes are checked as declared and again while
//! the bytes stream out, since the declared sizes are the archive's word. Names are data: they
//! become paths only through the zip crate's `enclosed_name`, under a folder goldray made.

use std::collections::BTreeMap;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use zip::ZipArchive;
use zip::result::ZipError;

use crate::grade::outcome::Outcome;

/// How much an archive may hold before its entries are refused as a zip bomb.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Entries in one archive (a class of 500 students with 21 pictures each is 10,500).
    pub entries: usize,
    /// Bytes of one entry, uncompressed: the largest file grading reads at all.
    pub entry: u64,
    /// Bytes of all of one archive's entries, uncompressed.
    pub total: u64,
    /// Uncompressed over compressed size, for entries over [`RATIO_FLOOR`]: PNGs are compressed
    /// already, and deflate's best on anything is about 1,000.
    pub ratio: u64,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            entries: 50_000,
            entry: 128 << 20,
            total: 16 << 30,
            ratio: 200,
        }
    }
}

/// Entries smaller than this are not judged by their compression ratio: a small text or a flat
/// picture may well compress a hundred times.
pub const RATIO_FLOOR: u64 = 1 << 20;

/// An entry that may be extracted: a regular file with a safe name.
#[derive(Clone, Debug)]
pub struct Entry {
    pub index: usize,
    /// The name as the archive stores it (lossily decoded), for notes and the report.
    pub name: String,
    /// The same name as a relative path with no `..`: where it goes under a folder.
    pub path: PathBuf,
}

/// An entry that is not extracted, and why (as the verdict an expected file of that name gets).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Refusal {
    pub entry: String,
    #[serde(flatten)]
    pub outcome: Outcome,
}

impl Refusal {
    fn new(entry: &str, outcome: Outcome) -> Refusal {
        Refusal {
            entry: entry.to_owned(),
            outcome,
        }
    }

    /// The note for the report: the entry and why it was not read.
    pub fn note(&self) -> String {
        let reason = match &self.outcome {
            Outcome::TooLarge { reason } | Outcome::Unreadable { reason } | Outcome::Linked { reason } => {
                reason.as_str()
            }
            other => other.word(),
        };
        format!("{}: {reason}", self.entry)
    }
}

/// An archive opened for reading, with the entries that may be extracted and those refused.
pub struct Archive<R> {
    zip: ZipArchive<R>,
    pub entries: Vec<Entry>,
    pub refused: Vec<Refusal>,
    /// The names of the folders the archive lists (`a/b/`), which hold nothing to extract.
    pub folders: Vec<String>,
    limits: Limits,
}

impl Archive<BufReader<File>> {
    /// Opens and checks the archive at `path`; `Err` holds why it cannot be read at all
    /// (truncated, corrupt, not a zip).
    pub fn open(path: &Path, limits: Limits) -> Result<Archive<BufReader<File>>, String> {
        let file = File::open(path).map_err(|e| format!("cannot open the archive: {e}"))?;
        Archive::new(BufReader::new(file), limits)
    }
}

impl<R: Read + Seek> Archive<R> {
    pub fn new(reader: R, limits: Limits) -> Result<Archive<R>, String> {
        let mut zip = ZipArchive::new(reader).map_err(|e| unreadable_archive(&e))?;
        let mut duplicates = BTreeMap::new();
        if zip.has_duplicate_names() {
            // The zip crate found the central directory (zip64 or not) and says a name repeats,
            // but keeps one entry per name: which names repeat is read from the directory again.
            let start = zip.central_directory_start();
            let mut reader = zip.into_inner();
            duplicates =
                central_names(&mut reader, start, limits.entries).map_err(|e| unreadable_archive(&ZipError::Io(e)))?;
            zip = ZipArchive::new(reader).map_err(|e| unreadable_archive(&e))?;
        }
        let count = zip.len().max(duplicates.values().sum());
        let (mut entries, mut refused, mut folders) = (Vec::new(), Vec::new(), Vec::new());
        if count > limits.entries {
            return Err(format!(
                "the archive holds {} entries, over the limit of {} (a zip bomb?): not read",
                count, limits.entries
            ));
        }
        let mut total: u64 = 0;
        for index in 0..zip.len() {
            let Ok(file) = zip.by_index_raw(index) else {
                refused.push(Refusal::new(
                    &format!("entry {index}"),
                    unreadable("its header cannot be read"),
                ));
                continue;
            };
            let name = String::from_utf8_lossy(file.name_raw()).into_owned();
            let mode = file.unix_mode().unwrap_or(0) & 0o170_000;
            let refusal = if duplicates.get(file.name_raw()).is_some_and(|n| *n > 1) {
                Some(unreadable("the archive holds several files of this name: none is read"))
            } else if file.is_symlink() {
                Some(Outcome::Linked {
                    reason: "a symbolic link in the archive: not read".to_owned(),
                })
            } else if file.is_dir() {
                // Nothing is written for a folder, but it may be a student who handed in nothing
                // (Moodle's folder of a participant without files).
                if !leaves_folder(&name) {
                    folders.push(name);
                }
                continue;
            } else if leaves_folder(&name) || file.enclosed_name().is_none() {
                Some(unreadable(
                    "its name leaves the archive's folder (../ or absolute): not read",
                ))
            } else if ![0, 0o100_000].contains(&mode) {
                Some(unreadable(
                    "not a regular file (a device, a pipe or a socket): not read",
                ))
            } else if file.encrypted() {
                Some(unreadable("encrypted: goldray has no password, not read"))
            } else if !matches!(
                file.compression(),
                zip::CompressionMethod::Stored | zip::CompressionMethod::Deflated
            ) {
                Some(unreadable(&format!(
                    "compressed with {:?}, which goldray does not read (only stored and deflated)",
                    file.compression()
                )))
            } else if file.size() > limits.entry {
                Some(too_large(&format!(
                    "{} bytes uncompressed, over the limit of {} (a zip bomb?): not read",
                    file.size(),
                    limits.entry
                )))
            } else if file.size() > RATIO_FLOOR && file.size() / file.compressed_size().max(1) > limits.ratio {
                Some(too_large(&format!(
                    "compressed {} times, over the limit of {} (a zip bomb?): not read",
                    file.size() / file.compressed_size().max(1),
                    limits.ratio
                )))
            } else if total.saturating_add(file.size()) > limits.total {
                Some(too_large(&format!(
                    "the archive's files add up to more than {} bytes (a zip bomb?): not read",
                    limits.total
                )))
            } else {
                None
            };
            match refusal {
                Some(outcome) => refused.push(Refusal::new(&name, outcome)),
                None => {
                    total += file.size();
                    let path = file.enclosed_name().unwrap_or_default();
                    entries.push(Entry { index, name, path });
                }
            }
        }
        Ok(Archive {
            zip,
            entries,
            refused,
            folders,
            limits,
        })
    }

    /// Writes `entry` to `target`, which must not exist yet (a second file of one name is
    /// refused, never overwritten). The bytes stream through the size limit; a file that broke it
    /// or failed its checksum is removed again.
    pub fn extract(&mut self, entry: &Entry, target: &Path) -> Result<(), Outcome> {
        let mut file = self
            .zip
            .by_index(entry.index)
            .map_err(|e| unreadable(&format!("cannot be read: {e}")))?;
        let declared = file.size();
        if let Some(parent) = target.parent() {
            fs::create_dir_all(parent).map_err(|e| unreadable(&format!("cannot be extracted: {e}")))?;
        }
        let mut out = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(target)
            .map_err(|e| match e.kind() {
                io::ErrorKind::AlreadyExists => unreadable("a second file of this name: not read"),
                _ => unreadable(&format!("cannot be extracted: {e}")),
            })?;
        let cap = declared.min(self.limits.entry);
        let copied = io::copy(&mut (&mut file).take(cap + 1), &mut out);
        let refusal = match copied {
            Ok(n) if n > cap => Some(too_large("holds more bytes than it declares (a zip bomb?): not read")),
            Ok(_) => None,
            Err(e) => Some(unreadable(&format!("corrupt: {e}"))),
        };
        match refusal {
            Some(outcome) => {
                drop(out);
                let _ = fs::remove_file(target);
                Err(outcome)
            }
            None => Ok(()),
        }
    }
}

/// How many times each name appears in the central directory that starts at `start`, counting at
/// most `limit + 1` entries. The zip crate keeps one entry per name, so a second entry of the same
/// name would otherwise go unseen; it has found where the directory starts (in a zip64 archive
/// too), and a central header is laid out alike in both: only its name and lengths are read here.
fn central_names<R: Read + Seek>(reader: &mut R, start: u64, limit: usize) -> io::Result<BTreeMap<Vec<u8>, usize>> {
    reader.seek(SeekFrom::Start(start))?;
    let mut names = BTreeMap::new();
    let mut header = [0u8; 46];
    for _ in 0..=limit {
        if reader.read_exact(&mut header).is_err() || header[..4] != [0x50, 0x4b, 0x01, 0x02] {
            break;
        }
        let length = |at: usize| u16::from_le_bytes([header[at], header[at + 1]]);
        let mut name = vec![0; usize::from(length(28))];
        reader.read_exact(&mut name)?;
        reader.seek(SeekFrom::Current(i64::from(length(30)) + i64::from(length(32))))?;
        *names.entry(name).or_default() += 1;
    }
    Ok(names)
}

/// Whether a stored name is absolute (`/x`, `\\x`, `C:x`) or climbs out with `..` anywhere: such
/// a name is refused even where the zip crate would make it safe (it resolves `a/../b` and drops
/// a leading `/`), since no honest archive holds one.
fn leaves_folder(name: &str) -> bool {
    let bytes = name.as_bytes();
    name.starts_with(['/', '\\'])
        || (bytes.len() >= 2 && bytes[1] == b':' && bytes[0].is_ascii_alphabetic())
        || name.split(['/', '\\']).any(|part| part == "..")
}

fn unreadable_archive(error: &ZipError) -> String {
    format!("not a readable zip archive (truncated or corrupt?): {error}")
}

fn unreadable(reason: &str) -> Outcome {
    Outcome::Unreadable {
        reason: reason.to_owned(),
    }
}

fn too_large(reason: &str) -> Outcome {
    Outcome::TooLarge {
        reason: reason.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_climb_or_start_at_a_root_leave_the_folder() {
        for name in [
            "../x.png",
            "a/../../x.png",
            "a/..",
            "/etc/x.png",
            "\\x.png",
            "C:x.png",
            "a\\..\\x",
        ] {
            assert!(leaves_folder(name), "{name}");
        }
        for name in ["a.png", "a/b.png", "a..b.png", "..a/x.png"] {
            assert!(!leaves_folder(name), "{name}");
        }
    }
}
