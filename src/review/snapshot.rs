//! insta's binary snapshot files, as far as accepting one needs them.
//!
//! A binary snapshot is two files: `NAME.snap`, a YAML header between two `---` lines (`source`,
//! `description`, `extension: exr`, `snapshot_kind: binary`, …), and `NAME.snap.exr`, the bytes.
//! A pending one is `NAME.snap.new` and `NAME.snap.new.exr`, whose header also holds
//! `assertion_line`.
//!
//! `cargo insta accept` reads the pending header and writes it back with insta's YAML writer,
//! less `assertion_line` (insta's `MetaData::trim_for_persistence`), followed by `---`; the
//! bytes are written beside it under the extension the header names. A pending file is insta's
//! own writer's output, so writing it back gives the same lines it holds: the accepted header
//! here is the pending header with the `assertion_line` line taken out. That holds only for the
//! keys insta 1.x writes and for a header in its writer's form, so anything else (a key this
//! version of insta does not know, which it would drop; a text snapshot; a legacy header) is
//! refused rather than guessed at. `tests/review.rs` checks the result byte for byte against
//! insta's own code.

use std::path::{Path, PathBuf};

use super::error::ReviewError;

/// The header keys insta 1.x writes (`MetaData::as_content`), in its order.
const KNOWN_KEYS: [&str; 8] = [
    "source",
    "assertion_line",
    "description",
    "expression",
    "info",
    "input_file",
    "extension",
    "snapshot_kind",
];

/// A binary snapshot's header, read from a `.snap` or `.snap.new` file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SnapshotHeader {
    /// The header's lines, from the opening `---` to the closing one, each ending in `\n`.
    lines: Vec<String>,
    /// The binary file's extension (`exr`): letters and digits only, so that it never makes a
    /// path leave the folder.
    pub extension: String,
}

impl SnapshotHeader {
    pub fn read(path: &Path) -> Result<SnapshotHeader, ReviewError> {
        let bytes = std::fs::read(path).map_err(|source| ReviewError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        SnapshotHeader::parse(&bytes).map_err(|message| ReviewError::Snapshot {
            path: path.to_path_buf(),
            message,
        })
    }

    /// Reads a header written by insta; the message says what is not.
    pub fn parse(bytes: &[u8]) -> Result<SnapshotHeader, String> {
        let text = std::str::from_utf8(bytes).map_err(|_| "the header is not UTF-8 text".to_owned())?;
        let mut lines = text.split_inclusive('\n');
        if lines.next() != Some("---\n") {
            return Err("no `---` header (a legacy insta format)".to_owned());
        }
        let mut header = vec!["---\n".to_owned()];
        let mut closed = false;
        for line in lines {
            header.push(line.to_owned());
            if line.trim_end() == "---" {
                closed = true;
                break;
            }
        }
        if !closed || !header.last().is_some_and(|l| l.ends_with('\n')) {
            return Err("the header has no closing `---` line".to_owned());
        }
        let mut kind = None;
        let mut extension = None;
        for line in &header[1..header.len() - 1] {
            // Continuation lines (a nested `info` map, a long string) are indented.
            if line.starts_with([' ', '\t']) {
                continue;
            }
            let Some((key, value)) = line.split_once(':') else {
                return Err(format!("unexpected header line `{}`", line.trim_end()));
            };
            if !KNOWN_KEYS.contains(&key) {
                return Err(format!(
                    "unknown header key `{key}` (written by another insta version?)"
                ));
            }
            match key {
                "snapshot_kind" => kind = Some(value.trim().to_owned()),
                "extension" => extension = Some(value.trim().to_owned()),
                _ => {}
            }
        }
        if kind.as_deref() != Some("binary") {
            return Err("not a binary snapshot (goldens are EXR files)".to_owned());
        }
        let extension = extension.ok_or("a binary snapshot without `extension`")?;
        if extension.is_empty() || !extension.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(format!("extension `{extension}` is not letters and digits"));
        }
        Ok(SnapshotHeader {
            lines: header,
            extension,
        })
    }

    /// The `.snap` file `cargo insta accept` writes from this pending header: the same lines
    /// without `assertion_line`.
    pub fn accepted(&self) -> String {
        self.lines
            .iter()
            .filter(|line| !line.starts_with("assertion_line:"))
            .map(String::as_str)
            .collect()
    }

    /// The header's `description`, for the page, when it is a plain one-line value.
    pub fn description(&self) -> Option<String> {
        let line = self
            .lines
            .iter()
            .find_map(|l| l.strip_prefix("description: "))?
            .trim_end();
        let unquoted = match line.strip_prefix('"').and_then(|l| l.strip_suffix('"')) {
            Some(inner) => inner.replace("\\\"", "\"").replace("\\\\", "\\"),
            None => line.to_owned(),
        };
        Some(unquoted)
    }
}

/// The binary file of snapshot `snap` with this extension: insta's `build_binary_path`, the
/// extension appended to the file's own (`NAME.snap` → `NAME.snap.exr`, `NAME.snap.new` →
/// `NAME.snap.new.exr`).
pub fn binary_path(snap: &Path, extension: &str) -> PathBuf {
    let mut name = snap.as_os_str().to_owned();
    name.push(".");
    name.push(extension);
    PathBuf::from(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    const PENDING: &str = "---\nsource: tests/golden.rs\nassertion_line: 125\ndescription: \"Five \\\"spheres\\\"\"\n\
                           extension: exr\nsnapshot_kind: binary\n---\n";

    #[test]
    fn accepting_drops_only_the_assertion_line() {
        let header = SnapshotHeader::parse(PENDING.as_bytes()).expect("parses");
        assert_eq!(header.extension, "exr");
        assert_eq!(
            header.accepted(),
            "---\nsource: tests/golden.rs\ndescription: \"Five \\\"spheres\\\"\"\nextension: exr\nsnapshot_kind: binary\n---\n"
        );
        assert_eq!(header.description().as_deref(), Some("Five \"spheres\""));
    }

    #[test]
    fn what_insta_would_not_write_back_unchanged_is_refused() {
        let refused = |text: &str| SnapshotHeader::parse(text.as_bytes()).expect_err(text);
        assert!(refused("source: x\n").contains("legacy"));
        assert!(refused("---\nsource: x\n").contains("closing"));
        assert!(refused("---\nsource: x\nsnapshot_kind: binary\nextension: exr\nfuture: 1\n---\n").contains("future"));
        assert!(refused("---\nsource: x\n---\nbody\n").contains("not a binary"));
        assert!(refused("---\nextension: ../x\nsnapshot_kind: binary\n---\n").contains("letters"));
    }

    #[test]
    fn binary_files_sit_beside_their_snapshot() {
        assert_eq!(
            binary_path(Path::new("golden/a.snap.new"), "exr"),
            Path::new("golden/a.snap.new.exr")
        );
    }
}
