//! Whether a student made the files they are graded on: links out of their folder are not read,
//! and copies of the published reference images are flagged.
//!
//! Archives carry symbolic links, the course's sample images are public, and students share
//! files. Grading reads only files that are the student's own; what it cannot prove (a copy of
//! the published reference, a copy of a classmate's image) it reports as evidence for the TA and
//! leaves the score alone unless the rubric says otherwise.

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

use crate::rgb_image::RgbImage;

use super::error::RubricError;
use super::submission::read_png;
use crate::located_toml::{Field, Table};
use crate::named_enum::named_enum;

named_enum! {
    /// Which symbolic links inside a student's folder are followed.
    #[derive(Default)]
    pub enum LinkPolicy: "link policy" {
        /// A link that resolves inside the student's own folder is read: its content is the
        /// student's own file either way (archives made on Linux and macOS keep such links).
        #[default]
        Inside = "inside",
        /// No link is read, wherever it points.
        None = "none",
    }
}

/// The rubric's `[integrity]` table.
#[derive(Clone, Debug)]
pub struct Integrity {
    pub links: LinkPolicy,
    /// The folder of the published reference images (the course's `sample_out/`), if any.
    pub published: Option<PathBuf>,
    /// The share of its points an image keeps when it is pixel-identical to the published
    /// reference: 1 (the default) makes it a note only, since a correct render can match exactly.
    pub published_copy_credit: f64,
}

impl Default for Integrity {
    fn default() -> Integrity {
        Integrity {
            links: LinkPolicy::Inside,
            published: None,
            published_copy_credit: 1.0,
        }
    }
}

pub(super) const INTEGRITY_KEYS: &[&str] = &["links", "published", "published_copy_credit"];

/// Reads `[integrity]`; `published` is relative to the rubric and must be a folder.
pub(super) fn integrity(table: &Table) -> Result<Integrity, RubricError> {
    table.check_keys(INTEGRITY_KEYS)?;
    let dir = table.doc.dir;
    Ok(Integrity {
        links: table.read("links", LinkPolicy::Inside, Field::variant)?,
        published: table.read("published", None, |f| {
            let path = dir.join(f.string()?);
            if path.is_dir() {
                Ok(Some(path))
            } else {
                Err(f.invalid(format!("{} is not a folder", path.display())))
            }
        })?,
        published_copy_credit: table.read("published_copy_credit", 1.0, |f| match f.number()? {
            v if (0.0..=1.0).contains(&v) => Ok(v),
            _ => Err(f.invalid("must be between 0 and 1")),
        })?,
    })
}

/// Why a submitted file is not read: it is a link, or it resolves outside the student's folder.
/// The text says where it points.
pub fn refuse_link(file: &Path, student_folder: &Path, policy: LinkPolicy) -> Option<String> {
    let own = own_location(student_folder);
    let target = match fs::canonicalize(file) {
        Ok(target) => target,
        Err(_) => return None,
    };
    let is_link = fs::symlink_metadata(file).is_ok_and(|m| m.file_type().is_symlink());
    let pointed = || {
        fs::read_link(file)
            .map(|link| link.display().to_string())
            .unwrap_or_else(|_| target.display().to_string())
    };
    match own {
        Some(own) if !target.starts_with(&own) => Some(format!(
            "{} resolves to {}, outside the student's folder: not read",
            if is_link { "a symbolic link that" } else { "a file that" },
            if is_link {
                pointed()
            } else {
                target.display().to_string()
            }
        )),
        _ if is_link && policy == LinkPolicy::None => Some(format!(
            "a symbolic link to {}: not read (the rubric reads no links)",
            pointed()
        )),
        _ => None,
    }
}

/// Where the student's folder is, as listed in the submissions folder: its parent resolved, but
/// not the folder itself, so that a student folder that is a link to another folder does not
/// make that folder the student's own.
fn own_location(folder: &Path) -> Option<PathBuf> {
    let parent = folder
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    Some(fs::canonicalize(parent).ok()?.join(folder.file_name()?))
}

/// A hash of an image's size and pixels: equal for the same picture however it was encoded.
pub fn pixel_hash(picture: &RgbImage) -> u64 {
    // BLAKE3 rather than the standard hasher: a class's pictures are hundreds of megabytes, and
    // it reads them several times faster.
    let mut hasher = blake3::Hasher::new();
    hasher.update(&picture.width().to_le_bytes());
    hasher.update(&picture.height().to_le_bytes());
    hasher.update(picture.as_raw());
    let digest = hasher.finalize();
    u64::from_le_bytes(digest.as_bytes()[..8].try_into().expect("a BLAKE3 digest has 32 bytes"))
}

/// The published reference images of the rubric's `files`, by file name, as pixel hashes. A
/// file the folder does not have, or cannot decode, is simply not compared.
pub fn published_hashes<'a>(integrity: &Integrity, files: impl Iterator<Item = &'a str>) -> HashMap<String, u64> {
    let Some(dir) = &integrity.published else {
        return HashMap::new();
    };
    files
        .filter_map(|file| {
            let submitted = read_png(&dir.join(file)).ok()?;
            Some((file.to_owned(), pixel_hash(&submitted.picture)))
        })
        .collect()
}

/// The flag put on an image identical to the published reference.
pub const PUBLISHED_COPY: &str = "identical to the published reference";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_out_of_the_folder_are_refused_and_links_inside_follow_the_policy() {
        let dir = tempfile::tempdir().unwrap();
        let alice = dir.path().join("alice");
        let bob = dir.path().join("bob");
        fs::create_dir_all(&alice).unwrap();
        fs::create_dir_all(&bob).unwrap();
        fs::write(alice.join("a.png"), b"x").unwrap();
        fs::write(dir.path().join("reference.png"), b"x").unwrap();
        std::os::unix::fs::symlink(dir.path().join("reference.png"), alice.join("out.png")).unwrap();
        std::os::unix::fs::symlink("a.png", alice.join("inside.png")).unwrap();
        std::os::unix::fs::symlink(&alice, dir.path().join("carol")).unwrap();

        assert_eq!(refuse_link(&alice.join("a.png"), &alice, LinkPolicy::None), None);
        let out = refuse_link(&alice.join("out.png"), &alice, LinkPolicy::Inside).unwrap();
        assert!(out.contains("reference.png") && out.contains("outside"), "{out}");
        assert_eq!(refuse_link(&alice.join("inside.png"), &alice, LinkPolicy::Inside), None);
        let none = refuse_link(&alice.join("inside.png"), &alice, LinkPolicy::None).unwrap();
        assert!(none.contains("a.png"), "{none}");
        // A student folder that is a link to a classmate's: nothing in it is the student's own.
        let carol = dir.path().join("carol");
        assert!(refuse_link(&carol.join("a.png"), &carol, LinkPolicy::Inside).is_some());
        assert!(refuse_link(&bob.join("missing.png"), &bob, LinkPolicy::Inside).is_none());
    }
}
