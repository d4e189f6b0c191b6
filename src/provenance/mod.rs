//! How an output was made, written into the output itself: every EXR goldray writes carries it
//! as header attributes, every PNG as text chunks, under the same `goldray.*` names, so that a
//! file found on its own says which goldray (version, commit), which case (its file name and a
//! hash of it and its assets) and which render settings made it.
//!
//! The record is two groups. The **stable** group is a function of the case and the binary, like
//! the pixels, and is always written: the same case and binary give byte-identical files, so
//! `cmp`, `sha256sum` and content-addressed caches can tell whether anything changed. The **run**
//! group (`goldray.run.*`: render time, thread count, host) differs from one run to the next, so
//! it is written only when asked (`--record-run`); the commands report it through `--stats`
//! either way. [`strip`]`(bytes, Group::Run)` turns a file written with it into the file written
//! without it, byte for byte.
//!
//! Both groups are spliced into already encoded bytes (`exr_header`, `png_text`) rather than
//! handed to the encoders: the exr crate writes custom attributes from a `HashMap`, in an order
//! that changes from one process to the next, which would make the bytes of an EXR random.

mod describe;
mod exr_header;
mod png_text;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

pub use describe::made_differently;

/// The prefix of every provenance name, in EXR headers and PNG text chunks alike.
pub const PREFIX: &str = "goldray.";

/// The prefix of the run group: what changes between two runs of the same render.
pub const RUN_PREFIX: &str = "goldray.run.";

/// The names goldray writes. Each is at most 31 bytes, so that an EXR needs no long-name flag.
pub mod keys {
    pub const VERSION: &str = "goldray.version";
    /// The git commit the binary was built from, with `+modified` when its sources differed;
    /// absent when it was not built from a checkout.
    pub const COMMIT: &str = "goldray.commit";
    /// The case (or course scene) file's name, without its folder.
    pub const CASE: &str = "goldray.case";
    /// BLAKE3 of the case file and the assets it reads ([`super::ContentHash`]).
    pub const CASE_HASH: &str = "goldray.case.blake3";
    /// `WIDTHxHEIGHT`.
    pub const SIZE: &str = "goldray.size";
    pub const SAMPLES: &str = "goldray.samples";
    pub const SEED: &str = "goldray.seed";
    pub const FILTER: &str = "goldray.filter";
    pub const BOUNCES: &str = "goldray.bounces";
    pub const SHADOWS: &str = "goldray.shadows";
    pub const PRECISION: &str = "goldray.precision";
    pub const PROFILE: &str = "goldray.profile";
    pub const TONEMAP: &str = "goldray.tonemap";
    /// Seconds spent rendering (building the scene and writing excluded).
    pub const RUN_SECONDS: &str = "goldray.run.seconds";
    pub const RUN_THREADS: &str = "goldray.run.threads";
    /// The name of the machine that rendered it.
    pub const RUN_HOST: &str = "goldray.run.host";
}

/// One output's provenance: `goldray.*` names and their text values, kept sorted so that a file
/// holds them in one order whatever the order they were set in.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Provenance {
    entries: BTreeMap<String, String>,
}

/// Which part of a file's provenance [`strip`] removes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// `goldray.run.*`: what two runs of the same render may differ in.
    Run,
    /// Every `goldray.*` entry.
    All,
}

impl Group {
    fn contains(self, key: &str) -> bool {
        match self {
            Group::Run => key.starts_with(RUN_PREFIX),
            Group::All => key.starts_with(PREFIX),
        }
    }
}

/// Why provenance could not be read, written or removed.
#[derive(Debug, thiserror::Error)]
pub enum ProvenanceError {
    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: std::io::Error },
    #[error("{file} is not an EXR goldray can stamp: {reason}")]
    Exr { file: String, reason: String },
    #[error("{file} is not a PNG goldray can stamp: {reason}")]
    Png { file: String, reason: String },
    #[error("{file} is neither an EXR nor a PNG")]
    UnknownFormat { file: String },
}

const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
const PNG_MAGIC: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

impl Provenance {
    /// A record holding this build's version and, when known, its commit.
    pub fn this_build() -> Provenance {
        let mut provenance = Provenance::default();
        provenance.set(keys::VERSION, env!("CARGO_PKG_VERSION"));
        if let Some(commit) = build_commit(env!("GOLDRAY_GIT_COMMIT")) {
            provenance.set(keys::COMMIT, commit);
        }
        provenance
    }

    /// Sets `key` (which must start with [`PREFIX`]) to `value`'s text.
    pub fn set(&mut self, key: &str, value: impl fmt::Display) {
        debug_assert!(key.starts_with(PREFIX) && key.len() <= 31, "{key}");
        self.entries.insert(key.to_owned(), value.to_string());
    }

    /// [`Provenance::set`], by value.
    pub fn with(mut self, key: &str, value: impl fmt::Display) -> Provenance {
        self.set(key, value);
        self
    }

    /// The render time, thread count and host of this run (the run group); an unknown host is
    /// left out.
    pub fn with_run(self, render_seconds: f64, threads: usize, host: Option<&str>) -> Provenance {
        let provenance = self
            .with(keys::RUN_SECONDS, format_args!("{render_seconds:.3}"))
            .with(keys::RUN_THREADS, threads);
        match host {
            Some(host) => provenance.with(keys::RUN_HOST, host),
            None => provenance,
        }
    }

    pub fn get(&self, key: &str) -> Option<&str> {
        self.entries.get(key).map(String::as_str)
    }

    /// Every entry, sorted by name.
    pub fn entries(&self) -> impl Iterator<Item = (&str, &str)> {
        self.entries.iter().map(|(k, v)| (k.as_str(), v.as_str()))
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The provenance in an EXR's or a PNG's bytes (told apart by their signature), or `None`
    /// when the file has none: an image from another program, or a goldray file older than
    /// provenance. Names outside `goldray.*` are ignored.
    pub fn from_bytes(bytes: &[u8], file: &str) -> Result<Option<Provenance>, ProvenanceError> {
        let entries = if bytes.starts_with(&EXR_MAGIC) {
            exr_header::read(bytes, file)?
        } else if bytes.starts_with(&PNG_MAGIC) {
            png_text::read(bytes, file)?
        } else {
            return Err(ProvenanceError::UnknownFormat { file: file.to_owned() });
        };
        let entries: BTreeMap<String, String> = entries.into_iter().filter(|(k, _)| k.starts_with(PREFIX)).collect();
        Ok((!entries.is_empty()).then_some(Provenance { entries }))
    }

    /// [`Provenance::from_bytes`] of a file.
    pub fn read(path: &Path) -> Result<Option<Provenance>, ProvenanceError> {
        let bytes = std::fs::read(path).map_err(|source| ProvenanceError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Provenance::from_bytes(&bytes, &path.display().to_string())
    }

    /// `bytes` (an EXR or a PNG that goldray encoded) with this provenance in it, replacing any
    /// `goldray.*` entries already there. `file` names the output in errors.
    pub fn stamp(&self, bytes: &[u8], file: &str) -> Result<Vec<u8>, ProvenanceError> {
        let entries: Vec<(&str, &str)> = self.entries().collect();
        replace(
            bytes,
            file,
            &Edit {
                group: Group::All,
                entries: &entries,
            },
        )
    }
}

/// What [`replace`] does to a file: removes the entries of `group`, then adds `entries`.
#[derive(Clone, Copy)]
struct Edit<'a> {
    group: Group,
    entries: &'a [(&'a str, &'a str)],
}

/// `bytes` edited in whichever format they are (EXR or PNG, by their magic number).
fn replace(bytes: &[u8], file: &str, edit: &Edit) -> Result<Vec<u8>, ProvenanceError> {
    if bytes.starts_with(&EXR_MAGIC) {
        exr_header::replace(bytes, file, edit)
    } else if bytes.starts_with(&PNG_MAGIC) {
        png_text::replace(bytes, file, edit)
    } else {
        Err(ProvenanceError::UnknownFormat { file: file.to_owned() })
    }
}

/// `bytes` without the provenance entries of `group`, every other byte as it was: what the
/// determinism tests compare. An EXR's chunk offsets are shifted by what was removed, so the
/// result is the file the encoder would have written without those entries.
pub fn strip(bytes: &[u8], group: Group) -> Result<Vec<u8>, ProvenanceError> {
    replace(bytes, "image data", &Edit { group, entries: &[] })
}

/// The commit `build.rs` recorded (`GOLDRAY_GIT_COMMIT`): `None` when it recorded none, which is
/// how a build from a source archive, or without git, says it has no commit to name.
pub fn build_commit(recorded: &str) -> Option<&str> {
    let commit = recorded.trim();
    (!commit.is_empty()).then_some(commit)
}

/// An incremental BLAKE3 hash of a case and its assets. Each part is framed by its length, so
/// moving bytes from one file to the next changes the hash. BLAKE3 (the `blake3` crate, the
/// reference implementation) because it hashes a 50 MB mesh in milliseconds with the SIMD the
/// machine has, so stamping costs nothing next to loading that mesh.
#[derive(Default)]
pub struct ContentHash(blake3::Hasher);

impl ContentHash {
    pub fn add(&mut self, part: &[u8]) {
        self.0.update(&(part.len() as u64).to_le_bytes());
        self.0.update(part);
    }

    /// 64 lowercase hex digits.
    pub fn finish(&self) -> String {
        self.0.finalize().to_hex().to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_build_without_a_commit_records_none() {
        assert_eq!(build_commit(""), None);
        assert_eq!(build_commit("  \n"), None);
        assert_eq!(build_commit("0123abc+modified"), Some("0123abc+modified"));
        let bare = Provenance::default().with(keys::VERSION, "0.1.0");
        assert_eq!(bare.get(keys::COMMIT), None);
    }

    #[test]
    fn this_build_names_its_version_and_the_commit_build_rs_found() {
        let provenance = Provenance::this_build();
        assert_eq!(provenance.get(keys::VERSION), Some(env!("CARGO_PKG_VERSION")));
        assert_eq!(provenance.get(keys::COMMIT), build_commit(env!("GOLDRAY_GIT_COMMIT")));
    }

    #[test]
    fn every_name_fits_an_exr_without_long_names() {
        for key in [
            keys::VERSION,
            keys::COMMIT,
            keys::CASE,
            keys::CASE_HASH,
            keys::SIZE,
            keys::SAMPLES,
            keys::SEED,
            keys::FILTER,
            keys::BOUNCES,
            keys::SHADOWS,
            keys::PRECISION,
            keys::PROFILE,
            keys::TONEMAP,
            keys::RUN_SECONDS,
            keys::RUN_THREADS,
            keys::RUN_HOST,
        ] {
            assert!(key.starts_with(PREFIX) && key.len() <= 31, "{key}");
        }
    }

    #[test]
    fn the_hash_frames_each_part() {
        let hash = |parts: &[&[u8]]| {
            let mut hash = ContentHash::default();
            parts.iter().for_each(|part| hash.add(part));
            hash.finish()
        };
        assert_ne!(hash(&[b"ab", b"c"]), hash(&[b"a", b"bc"]));
        assert_eq!(hash(&[b"ab", b"c"]), hash(&[b"ab", b"c"]));
        assert_eq!(hash(&[]).len(), 64);
    }
}
