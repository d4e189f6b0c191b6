//! Grading a class on many machines with the schedulers courses already have (a Slurm job array,
//! a Kubernetes Indexed Job): `--shard K/N` grades the K-th of N slices of the class, cut from
//! the student folders sorted by name, into its own report folder, and `--merge` combines the
//! shards' folders into the report one run would have written.
//!
//! Each shard writes `shard.json` ([`Manifest`]): which slice it graded of which class, with
//! which rubric and golden renders (the run's fingerprint), and what the merge needs to write the
//! class-wide parts (the rubric, the renders, the loose files). The students' results carry
//! what comparing students with each other needs (each picture's pixel and sample hashes, see
//! `similarity`), so that the merge finds copies across shards as one run finds them.

use std::fmt;
use std::fs;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::diagnosis::DiagnosisRun;
use super::error::GradeError;
use super::golden::GoldenRender;
use super::lms::{Layout, Refusal};
use super::report::RubricSummary;
use super::resume::{StudentRecord, read_record};
use super::timing::RunCost;
use crate::atomic_write::{replace_file, write_file_atomic};
use crate::film::OutputError;

/// The manifest every grading run writes into its report folder.
pub const MANIFEST: &str = "shard.json";

/// The K-th (from 1) of N slices of a class.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole class, in one slice.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// The students (indices into the class sorted by folder name) of this slice: contiguous,
    /// sizes differing by at most one, together every student exactly once.
    pub fn range(&self, students: usize) -> Range<usize> {
        (self.index - 1) * students / self.count..self.index * students / self.count
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Why a `--shard` value is not one.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    #[error("`{0}` is not K/N (e.g. 2/8: the second of eight slices)")]
    Form(String),
    #[error("`{0}`: the slice count N must be at least 1")]
    Count(String),
    #[error("`{given}`: K must be between 1 and {count} (slices are counted from 1)")]
    Index { given: String, count: usize },
}

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(text: &str) -> Result<Shard, ShardError> {
        let form = || ShardError::Form(text.to_owned());
        let (index, count) = text.split_once('/').ok_or_else(form)?;
        let index: usize = index.trim().parse().map_err(|_| form())?;
        let count: usize = count.trim().parse().map_err(|_| form())?;
        if count == 0 {
            return Err(ShardError::Count(text.to_owned()));
        }
        if !(1..=count).contains(&index) {
            return Err(ShardError::Index {
                given: text.to_owned(),
                count,
            });
        }
        Ok(Shard { index, count })
    }
}

/// What a grading run (one shard, or the whole class as shard 1/1) leaves for a merge.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    pub goldray: String,
    /// The run's fingerprint: rubric, golden renders, goldray, diagnosis (see `resume`).
    pub run: String,
    pub shard: Shard,
    /// Every student folder of the class, sorted: shards of one class list the same.
    pub class: Vec<String>,
    /// This shard's students' report names, in class order.
    pub slugs: Vec<String>,
    pub rubric: RubricSummary,
    pub submissions: PathBuf,
    pub layout: Layout,
    pub cache: PathBuf,
    pub goldens: Vec<GoldenRender>,
    pub ignored: Vec<String>,
    pub refused: Vec<Refusal>,
    /// `None` when the run did not diagnose.
    pub diagnosis: Option<DiagnosisRun>,
    pub cost: RunCost,
}

pub fn write_manifest(manifest: &Manifest, out: &Path) -> Result<(), OutputError> {
    let json = serde_json::to_string_pretty(manifest).unwrap_or_default();
    write_file_atomic(&out.join(MANIFEST), (json + "\n").as_bytes())?;
    Ok(())
}

/// A shard's folder, checked: its manifest and every one of its students' results.
pub struct ShardOutput {
    pub dir: PathBuf,
    pub manifest: Manifest,
    pub records: Vec<StudentRecord>,
}

/// Reads the shards' folders and checks that they are the N slices of one class, graded alike:
/// the same goldray, rubric, golden renders and class, each slice exactly once, every student's
/// result complete. Returns them in slice order.
pub fn read_shards(dirs: &[PathBuf]) -> Result<Vec<ShardOutput>, GradeError> {
    let fail = |message: String| GradeError::Merge(message);
    if dirs.is_empty() {
        return Err(fail("no shard folders given".to_owned()));
    }
    let mut shards: Vec<(PathBuf, Manifest)> = Vec::new();
    for dir in dirs {
        let path = dir.join(MANIFEST);
        let text = fs::read_to_string(&path).map_err(|e| {
            fail(format!(
                "{} is not a graded shard: cannot read {}: {e}",
                dir.display(),
                path.display()
            ))
        })?;
        let manifest: Manifest =
            serde_json::from_str(&text).map_err(|e| fail(format!("{}: not a shard manifest: {e}", path.display())))?;
        shards.push((dir.clone(), manifest));
    }
    let (first_dir, first) = shards[0].clone();
    for (dir, manifest) in &shards[1..] {
        let differs = |what: &str| {
            fail(format!(
                "{} and {} were graded with {what}",
                first_dir.display(),
                dir.display()
            ))
        };
        if manifest.goldray != first.goldray {
            return Err(differs(&format!(
                "different goldray versions ({} and {})",
                first.goldray, manifest.goldray
            )));
        }
        if manifest.run != first.run {
            return Err(differs(
                "different rubrics, golden renders or goldray builds (or one diagnosed and the other did not)",
            ));
        }
        if manifest.shard.count != first.shard.count {
            return Err(differs(&format!(
                "different slice counts ({} and {})",
                first.shard, manifest.shard
            )));
        }
        if manifest.class != first.class {
            return Err(differs(
                "different class listings (the submissions folder changed between them)",
            ));
        }
    }
    let count = first.shard.count;
    shards.sort_by_key(|(_, m)| m.shard.index);
    for pair in shards.windows(2) {
        if pair[0].1.shard.index == pair[1].1.shard.index {
            return Err(fail(format!(
                "slice {} is given twice: {} and {}",
                pair[0].1.shard,
                pair[0].0.display(),
                pair[1].0.display()
            )));
        }
    }
    let missing: Vec<String> = (1..=count)
        .filter(|k| !shards.iter().any(|(_, m)| m.shard.index == *k))
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(fail(format!("missing slice(s) {} of the class", missing.join(", "))));
    }
    let images = first.rubric.images.len();
    shards
        .into_iter()
        .map(|(dir, manifest)| {
            let range = manifest.shard.range(manifest.class.len());
            if range.len() != manifest.slugs.len() {
                return Err(fail(format!(
                    "{}: slice {} of {} students should have {} students, the manifest lists {}",
                    dir.display(),
                    manifest.shard,
                    manifest.class.len(),
                    range.len(),
                    manifest.slugs.len()
                )));
            }
            let records = manifest
                .slugs
                .iter()
                .zip(&manifest.class[range])
                .map(|(slug, name)| match read_record(&dir, slug, images) {
                    Some(record) if record.run == manifest.run && record.result.name == *name => Ok(record),
                    _ => Err(fail(format!(
                        "{}: no complete result for student {name} (students/{slug}/result.json): grade slice {} again",
                        dir.display(),
                        manifest.shard
                    ))),
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok(ShardOutput { dir, manifest, records })
        })
        .collect()
}

/// Copies a shard's pictures into the merged report: the golden pictures, the mistakes' pictures
/// and each of its students' folder (their pictures, heatmaps and result).
pub fn copy_pictures(shard: &ShardOutput, out: &Path) -> Result<(), OutputError> {
    copy_tree(
        &shard.dir.join(super::golden::GOLDEN_DIR),
        &out.join(super::golden::GOLDEN_DIR),
    )?;
    copy_tree(
        &shard.dir.join(super::diagnose::MISTAKES_DIR),
        &out.join(super::diagnose::MISTAKES_DIR),
    )?;
    copy_tree(
        &shard.dir.join(super::score::THUMBNAILS_DIR),
        &out.join(super::score::THUMBNAILS_DIR),
    )?;
    for slug in &shard.manifest.slugs {
        let student = Path::new("students").join(slug);
        copy_tree(&shard.dir.join(&student), &out.join(&student))?;
    }
    Ok(())
}

/// Every file under `from` (which may not exist: nothing to copy), written atomically under `to`.
fn copy_tree(from: &Path, to: &Path) -> Result<(), OutputError> {
    let Ok(entries) = fs::read_dir(from) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        let (source, target) = (entry.path(), to.join(entry.file_name()));
        match entry.file_type() {
            Ok(kind) if kind.is_dir() => copy_tree(&source, &target)?,
            Ok(kind) if kind.is_file() => {
                let bytes = fs::read(&source).map_err(|e| OutputError::Read {
                    path: source.clone(),
                    source: e,
                })?;
                replace_file(&target, &bytes)?;
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_say_what_is_wrong() {
        assert_eq!("2/7".parse(), Ok(Shard { index: 2, count: 7 }));
        assert_eq!("1/1".parse(), Ok(Shard::WHOLE));
        assert_eq!(
            "0/3".parse::<Shard>().unwrap_err().to_string(),
            "`0/3`: K must be between 1 and 3 (slices are counted from 1)"
        );
        assert!(matches!(
            "4/3".parse::<Shard>(),
            Err(ShardError::Index { count: 3, .. })
        ));
        assert_eq!("1/0".parse::<Shard>(), Err(ShardError::Count("1/0".to_owned())));
        for bad in ["3", "a/b", "1/", "-1/3", "1/2/3"] {
            assert_eq!(bad.parse::<Shard>(), Err(ShardError::Form(bad.to_owned())), "{bad}");
        }
    }

    #[test]
    fn slices_cover_the_class_once_in_order() {
        for students in [0, 1, 5, 20, 101] {
            for count in [1, 2, 3, 7, 30] {
                let ranges: Vec<Range<usize>> = (1..=count)
                    .map(|index| Shard { index, count }.range(students))
                    .collect();
                assert_eq!(ranges[0].start, 0);
                assert_eq!(ranges[count - 1].end, students);
                for pair in ranges.windows(2) {
                    assert_eq!(pair[0].end, pair[1].start);
                }
                let sizes: Vec<usize> = ranges.iter().map(|r| r.len()).collect();
                assert!(
                    sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1,
                    "{sizes:?}"
                );
            }
        }
    }
}
