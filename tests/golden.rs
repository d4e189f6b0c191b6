//! The golden suite: every `cases/*.toml` is rendered and compared with its snapshot in `golden/`
//! within the case's `[tolerance]`, so that a change that breaks a picture fails loudly and one
//! that moves a value by an ulp does not.
//!
//! Snapshots are insta binary snapshots (`golden/NAME.snap` + `golden/NAME.snap.exr`) judged by
//! [`comparator::ToleranceComparator`] instead of byte equality. insta decides what is written:
//! nothing under `CI=true`, `golden/NAME.snap.new*` for `cargo insta review` locally, the golden
//! itself with `INSTA_UPDATE=always`. A snapshot within tolerance is never rewritten, so goldens
//! do not churn with platform noise.

#[path = "golden/comparator.rs"]
mod comparator;

use std::fs;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use goldray::case::{Case, LoadOptions, load};
use goldray::film::{Film, Tonemap, color_image, encode_exr, write_png};
use goldray::pipeline::{provenance, render_case};
use goldray::provenance::{Group, strip};

use comparator::{Judged, ToleranceComparator};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn cases_dir() -> PathBuf {
    Path::new(ROOT).join("cases")
}

fn golden_dir() -> PathBuf {
    Path::new(ROOT).join("golden")
}

/// Heatmaps and previews of failing cases go beside the build, never into the source tree, so a
/// CI run writes nothing a commit could pick up.
fn diffs_dir() -> PathBuf {
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    tmp.parent().unwrap_or(tmp).join("golden-diffs")
}

/// A path relative to the project root when it is inside it, so messages stay short.
pub fn shown(path: &Path) -> String {
    path.strip_prefix(ROOT).unwrap_or(path).display().to_string()
}

/// Sorted, so that failures are reported in the same order on every run.
fn case_files() -> Vec<PathBuf> {
    let entries = fs::read_dir(cases_dir()).unwrap_or_else(|e| panic!("cannot list {}: {e}", shown(&cases_dir())));
    let mut files: Vec<PathBuf> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "toml"))
        .collect();
    files.sort();
    files
}

struct Rendered {
    case: Case,
    film: Film,
    exr: Vec<u8>,
}

/// Loads, renders and encodes one case; an error is the message to fail with.
fn render(path: &Path) -> Result<Rendered, String> {
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(format!(
            "{}: a case name may only hold letters, digits, `_` and `-` (it names the snapshot file); rename the file",
            shown(path)
        ));
    }
    let case = load(path, &LoadOptions::default()).map_err(|e| e.to_string())?;
    let film = render_case(&case).map_err(|e| e.to_string())?;
    // The stable provenance only: a snapshot is compared by content, so the run's time and
    // thread count would make every re-blessed golden differ from the last.
    let made = provenance(&case).map_err(|e| e.to_string())?;
    let exr = encode_exr(&film)
        .map_err(|e| e.to_string())
        .and_then(|bytes| made.stamp(&bytes, "the render").map_err(|e| e.to_string()))
        .map_err(|e| format!("{}: {e}", shown(path)))?;
    Ok(Rendered { case, film, exr })
}

#[test]
fn every_case_matches_its_golden_image() {
    let files = case_files();
    assert!(!files.is_empty(), "no cases found in {}", shown(&cases_dir()));
    // Rendering is the slow part and needs no insta state, so it runs on every core; the
    // assertions then run one by one on this thread, where insta's settings are bound.
    let rendered: Vec<Result<Rendered, String>> = files.par_iter().map(|path| render(path)).collect();
    let mut failures: Vec<String> = rendered
        .into_iter()
        .filter_map(|result| result.and_then(|r| check(&r)).err())
        .collect();
    failures.extend(orphan_goldens(&files));

    assert!(
        failures.is_empty(),
        "{} of {} golden cases failed:\n\n{}",
        failures.len(),
        files.len(),
        failures.join("\n\n")
    );
}

/// Runs the insta assertion for one case under the tolerance comparator and turns its outcome
/// into a message a person can act on.
fn check(rendered: &Rendered) -> Result<(), String> {
    let case = &rendered.case;
    let name = &case.name;
    let golden = golden_dir().join(format!("{name}.snap"));
    let golden_exr = PathBuf::from(shown(&golden.with_extension("snap.exr")));
    let comparator = ToleranceComparator::new(name, &case.tolerance, &golden_exr, &diffs_dir());
    let judged = comparator.judged();

    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path(golden_dir());
    settings.set_prepend_module_to_snapshot(false);
    settings.set_omit_expression(true);
    settings.set_description(case.description.clone().unwrap_or_else(|| name.clone()));
    settings.set_comparator(Box::new(comparator));
    let snapshot = format!("{name}.exr");
    let asserted = panic::catch_unwind(AssertUnwindSafe(|| {
        settings.bind(|| insta::assert_binary_snapshot!(snapshot.as_str(), rendered.exr.clone()));
    }));

    let judged = judged.lock().map(|mut slot| slot.take()).unwrap_or(None);
    match (asserted, judged) {
        (Ok(()), Some(Judged::Compared(comparison, _))) if !comparison.verdict.accepts() => {
            eprintln!("rewrote the golden of case {name} (INSTA_UPDATE); it differed by:\n{comparison}");
            Ok(())
        }
        (Ok(()), Some(Judged::Compared(comparison, _)))
            if comparison.metrics.as_ref().is_some_and(|m| m.failing_pixels > 0) =>
        {
            eprintln!("warning: case {name} is within tolerance but some pixels moved:\n{comparison}");
            Ok(())
        }
        (Ok(()), _) => Ok(()),
        (Err(_), judged) => {
            if judged.is_none() {
                let preview = diffs_dir().join(format!("{name}.actual.png"));
                let _ = write_png(&preview, &color_image(&rendered.film, Tonemap::Srgb));
            }
            Err(failure_message(case, &golden, judged))
        }
    }
}

fn failure_message(case: &Case, golden: &Path, judged: Option<Judged>) -> String {
    let name = &case.name;
    let actual_png = diffs_dir().join(format!("{name}.actual.png"));
    let case_file = shown(&case.path);
    let preview = shown(&actual_png);
    let pending = if is_ci() {
        "CI=true, so nothing was written: run the suite locally to get a pending snapshot".to_owned()
    } else {
        format!("pending as {}.new", shown(golden))
    };
    let accept = format!(
        "accept it with `cargo insta review` ({pending}) or `INSTA_UPDATE=always cargo test --release --test golden`"
    );
    match judged {
        None => format!(
            "case {name} ({case_file}) has no golden image {}.\n  look at {preview}; if it is right, {accept}, \
             then commit golden/{name}.snap and golden/{name}.snap.exr",
            shown(golden)
        ),
        Some(Judged::Unreadable(message)) => {
            format!("case {name} ({case_file}): {message}\n  if the new render ({preview}) is right, {accept}")
        }
        Some(Judged::Compared(comparison, made_differently)) => {
            let made_differently = made_differently.map(|line| format!("made differently: {line}\n  "));
            format!(
                "case {name} ({case_file}): {}{comparison}  if the change is intended, compare {preview} with its \
                 .expected.png, then {accept}",
                made_differently.unwrap_or_default()
            )
        }
    }
}

/// A golden without a case would never be checked again; say so rather than keep dead files.
fn orphan_goldens(case_files: &[PathBuf]) -> Vec<String> {
    let Ok(entries) = fs::read_dir(golden_dir()) else {
        return Vec::new();
    };
    let mut orphans: Vec<String> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "snap"))
        .filter_map(|path| {
            let stem = path.file_stem()?.to_string_lossy().into_owned();
            let has_case = case_files
                .iter()
                .any(|case| case.file_stem().is_some_and(|s| s.to_string_lossy() == stem));
            (!has_case).then(|| {
                format!(
                    "{} has no case cases/{stem}.toml: delete it and {}.exr, or restore the case",
                    shown(&path),
                    shown(&path)
                )
            })
        })
        .collect();
    orphans.sort();
    orphans
}

/// insta's own reading of `CI`, so the message matches what insta did.
fn is_ci() -> bool {
    !matches!(std::env::var("CI").as_deref(), Err(_) | Ok("" | "0" | "false"))
}

/// A failure says how the golden and the render were made differently, before the verdict: here
/// a golden of `jitter` with seed 7 and 16 samples against a render with seed 8 and one sample
/// (the case file unchanged). Another seed alone passes: sampled renders are judged by their noise.
#[test]
fn a_failure_names_how_the_golden_and_the_render_were_made_differently() {
    let mut case = load(&cases_dir().join("jitter.toml"), &LoadOptions::default()).expect("loads");
    let stamped = |case: &Case| {
        let film = render_case(case).expect("renders");
        provenance(case)
            .expect("provenance")
            .stamp(&encode_exr(&film).expect("encodes"), "jitter")
            .expect("stamps")
    };
    let golden = stamped(&case);
    case.render.trace.seed = 8;
    case.render.trace.samples = 1;
    let render = stamped(&case);
    // Its pictures go to a folder of its own, not beside the suite's.
    let pictures = tempfile::tempdir().expect("tempdir");
    let comparator = ToleranceComparator::new(
        &case.name,
        &case.tolerance,
        Path::new("jitter.snap.exr"),
        pictures.path(),
    );
    let judged = comparator.judge_bytes(Some(&golden), Some(&render));
    assert!(
        matches!(&judged, Judged::Compared(c, _) if !c.verdict.accepts()),
        "one sample fails a 16-sample golden"
    );
    let message = failure_message(&case, Path::new("golden/jitter.snap"), Some(judged));
    assert!(
        message.contains("made differently: golden: seed 7, 16 spp; this render: seed 8, 1 spp\n  FAIL"),
        "{message}"
    );

    // A golden blessed before provenance: the render's side is summarised.
    let unstamped = strip(&golden, Group::All).expect("strips");
    let judged = comparator.judge_bytes(Some(&unstamped), Some(&render));
    let message = failure_message(&case, Path::new("golden/jitter.snap"), Some(judged));
    assert!(
        message.contains("made differently: golden: no provenance; this render: jitter.toml, 128x128, seed 8, 1 spp"),
        "{message}"
    );
}
