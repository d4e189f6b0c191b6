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
use goldray::provenance::{Provenance, made_differently};

/// What the comparator made of a snapshot pair.
pub enum Judged {
    /// The comparison, and how the golden and the render were made differently, if they were
    /// ([`made_differently`]: the golden's settings or case may have changed since it was blessed).
    Compared(Box<Comparison>, Option<String>),
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
        let bytes = |contents: &'_ SnapshotContents| match contents {
            SnapshotContents::Binary(Some(bytes)) => Some(bytes.to_vec()),
            _ => None,
        };
        self.judge_bytes(
            bytes(reference.contents()).as_deref(),
            bytes(test.contents()).as_deref(),
        )
    }

    /// Judges the golden EXR's bytes against the render's (`None`: a snapshot without them).
    pub fn judge_bytes(&self, golden: Option<&[u8]>, render: Option<&[u8]>) -> Judged {
        let made =
            |bytes: Option<&[u8]>| bytes.and_then(|bytes| Provenance::from_bytes(bytes, "snapshot").ok().flatten());
        let made_differently = made_differently(
            ("golden", made(golden).as_ref()),
            ("this render", made(render).as_ref()),
        );
        let Some(golden) = golden else {
            return Judged::Unreadable(format!(
                "{} is missing (its .snap is there): restore it from git, or bless the case again",
                self.golden_exr.display()
            ));
        };
        let Some(render) = render else {
            return Judged::Unreadable("the new render has no EXR data".to_owned());
        };
        match (
            Image::from_exr_bytes(golden, &self.golden_exr),
            Image::from_exr_bytes(render, "this render"),
        ) {
            (Ok(golden), Ok(render)) => Judged::Compared(Box::new(self.report(&golden, &render)), made_differently),
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
        let accepted = matches!(&judged, Judged::Compared(c, _) if c.verdict.accepts());
        if let Ok(mut slot) = self.judged.lock() {
            *slot = Some(judged);
        }
        accepted
    }

    fn dyn_clone(&self) -> Box<dyn Comparator> {
        Box::new(self.clone())
    }
}
