//! The insta comparator that judges a golden EXR by the case's tolerance instead of its bytes.
//!
//! insta only asks "do these match?", so the full comparison is left in a shared slot for the test
//! to report from, and the pictures a reviewer needs (heatmap, expected and actual previews) are
//! written here, where both images are at hand.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use insta::internals::SnapshotContents;
use insta::{Comparator, Snapshot};

use goldray::compare::{Comparison, Image, Tolerance, Verdict, compare, comparison_heatmap};
use goldray::film::write_png;

/// What the comparator made of a snapshot pair.
pub enum Judged {
    Compared(Box<Comparison>),
    /// The golden (or the new render) could not be decoded; the message says which and why.
    Unreadable(String),
}

#[derive(Clone)]
pub struct ToleranceComparator {
    name: String,
    tolerance: Tolerance,
    golden_exr: PathBuf,
    diffs: PathBuf,
    judged: Arc<Mutex<Option<Judged>>>,
}

impl ToleranceComparator {
    pub fn new(name: &str, tolerance: &Tolerance, golden_exr: &Path, diffs: &Path) -> Self {
        ToleranceComparator {
            name: name.to_owned(),
            tolerance: tolerance.clone(),
            golden_exr: golden_exr.to_path_buf(),
            diffs: diffs.to_path_buf(),
            judged: Arc::new(Mutex::new(None)),
        }
    }

    /// The slot the last judgement is left in; clones of the comparator (insta clones its
    /// settings) share it.
    pub fn judged(&self) -> Arc<Mutex<Option<Judged>>> {
        Arc::clone(&self.judged)
    }

    fn judge(&self, reference: &Snapshot, test: &Snapshot) -> Judged {
        let golden = match reference.contents() {
            SnapshotContents::Binary(Some(bytes)) => Image::from_exr_bytes(bytes, &self.golden_exr),
            _ => {
                return Judged::Unreadable(format!(
                    "{} is missing (its .snap is there): restore it from git, or bless the case again",
                    self.golden_exr.display()
                ));
            }
        };
        let render = match test.contents() {
            SnapshotContents::Binary(Some(bytes)) => Image::from_exr_bytes(bytes, "this render"),
            _ => return Judged::Unreadable("the new render has no EXR data".to_owned()),
        };
        match (golden, render) {
            (Ok(golden), Ok(render)) => Judged::Compared(Box::new(self.report(&golden, &render))),
            (Err(e), _) | (_, Err(e)) => Judged::Unreadable(e.to_string()),
        }
    }

    /// Compares and, unless the render passes outright, writes the heatmap (of the evidence, for a
    /// sampled case) and both previews.
    fn report(&self, golden: &Image, render: &Image) -> Comparison {
        let mut comparison = compare(golden, render, &self.tolerance);
        let file = |suffix: &str| self.diffs.join(format!("{}{suffix}.png", self.name));
        if comparison.verdict == Verdict::Pass {
            for suffix in ["", ".expected", ".actual"] {
                let _ = std::fs::remove_file(file(suffix));
            }
            return comparison;
        }
        let _ = write_png(&file(".expected"), &golden.preview);
        let _ = write_png(&file(".actual"), &render.preview);
        if let Some(heatmap) = comparison_heatmap(golden, render, &comparison)
            && write_png(&file(""), &heatmap).is_ok()
        {
            comparison.diff_image = Some(PathBuf::from(super::shown(&file(""))));
        }
        comparison
    }
}

impl Comparator for ToleranceComparator {
    fn matches(&self, reference: &Snapshot, test: &Snapshot) -> bool {
        let judged = self.judge(reference, test);
        let accepted = matches!(&judged, Judged::Compared(c) if c.verdict.accepts());
        if let Ok(mut slot) = self.judged.lock() {
            *slot = Some(judged);
        }
        accepted
    }

    fn dyn_clone(&self) -> Box<dyn Comparator> {
        Box::new(self.clone())
    }
}
