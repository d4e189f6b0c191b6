//! Grading at course scale, through the command line: a class graded in N shards and merged gives
//! the report of one run (N = 1, 2, 3, 7), shards only read a prepared cache, bad shard arguments
//! and shard sets are refused with clear messages, and a rerun resumes.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use super::class::{Class, make_class};

/// Runs goldray on `args` with progress lines (standard error is not a terminal).
fn goldray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(args)
        .output()
        .expect("the goldray binary runs")
}

fn succeeded(output: &Output) -> (String, String) {
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    );
    assert!(output.status.success(), "{stdout}\n{stderr}");
    (stdout, stderr)
}

fn text(path: &Path) -> String {
    path.to_str().unwrap().to_owned()
}

/// `goldray grade` of slice `index` of `count` into `out`, which must succeed.
fn grade_shard(
    rubric: &str,
    submissions: &str,
    (index, count): (usize, usize),
    out: &Path,
    cache: &str,
    extra: &[&str],
) {
    let (slice, out) = (format!("{index}/{count}"), text(out));
    let mut args = vec![
        "grade",
        "--rubric",
        rubric,
        submissions,
        "--shard",
        &slice,
        "--out",
        &out,
        "--cache",
        cache,
    ];
    args.extend(extra);
    succeeded(&goldray(&args));
}

/// Every file under `dir` with its bytes, by relative path, except what says how one run went
/// (`run.json`, and each student's `result.json`, which keeps the student's timings) or which
/// slice it was (`shard.json`).
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, found: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, found);
            } else if !["run.json", "shard.json", "result.json"]
                .iter()
                .any(|f| path.ends_with(f))
            {
                found.insert(path.strip_prefix(root).unwrap().to_owned(), fs::read(&path).unwrap());
            }
        }
    }
    let mut found = BTreeMap::new();
    walk(dir, dir, &mut found);
    found
}

/// Every file of the cache with its modification time: what a run that must not write the cache
/// may not change.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, std::time::SystemTime> {
    fn walk(dir: &Path, found: &mut BTreeMap<PathBuf, std::time::SystemTime>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, found);
            }
            found.insert(path.clone(), fs::metadata(&path).unwrap().modified().unwrap());
        }
    }
    let mut found = BTreeMap::new();
    walk(dir, &mut found);
    found
}

/// Makes every folder of `dir` read-only (or writable again), so that a process that is not root
/// cannot add to it.
fn set_read_only(dir: &Path, read_only: bool) {
    use std::os::unix::fs::PermissionsExt;
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            set_read_only(&path, read_only);
        }
    }
    let mode = if read_only { 0o555 } else { 0o755 };
    fs::set_permissions(dir, fs::Permissions::from_mode(mode)).unwrap();
}

/// The class of `tests/grade/class.rs`, plus a student who copied `no_shadows`'s pictures and sorts
/// last, so that the copy and its source land in different shards.
fn class_with_a_copy() -> Class {
    let class = make_class();
    let source = class.submissions.join("no_shadows");
    let copy = class.submissions.join("zz_copier");
    fs::create_dir_all(&copy).unwrap();
    for entry in fs::read_dir(&source).unwrap() {
        let path = entry.unwrap().path();
        fs::copy(&path, copy.join(path.file_name().unwrap())).unwrap();
    }
    class
}

#[test]
fn shards_merged_give_the_report_of_one_run_and_only_read_the_prepared_cache() {
    let class = class_with_a_copy();
    let (rubric, submissions) = (text(&class.rubric), text(&class.submissions));
    let cache = class.dir.join("cache");
    let (prepared, _) = succeeded(&goldray(&[
        "grade",
        "--prepare",
        "--rubric",
        &rubric,
        "--cache",
        &text(&cache),
    ]));
    assert!(prepared.contains("1 rendered"), "{prepared}");
    let single = class.dir.join("single");
    succeeded(&goldray(&[
        "grade",
        "--rubric",
        &rubric,
        &submissions,
        "--out",
        &text(&single),
        "--cache",
        &text(&cache),
    ]));
    let expected = files(&single);
    let grades: serde_json::Value = serde_json::from_slice(&expected[Path::new("grades.json")]).unwrap();
    assert!(
        grades["similar"]
            .as_array()
            .unwrap()
            .iter()
            .any(|pair| pair["students"] == serde_json::json!(["no_shadows", "zz_copier"])),
        "the copy is found: {}",
        grades["similar"]
    );

    let before = snapshot(&cache);
    set_read_only(&cache, true);
    for count in [1, 2, 3, 7] {
        let dirs: Vec<String> = (1..=count)
            .map(|index| {
                let dir = class.dir.join(format!("shards-{count}/{index}"));
                grade_shard(&rubric, &submissions, (index, count), &dir, &text(&cache), &[]);
                assert_eq!(
                    dir.join("grades.csv").exists(),
                    count == 1,
                    "a slice of the class leaves the class-wide files to the merge"
                );
                text(&dir)
            })
            .rev()
            .collect();
        let merged = class.dir.join(format!("merged-{count}"));
        let mut args = vec!["grade", "--merge", merged.to_str().unwrap()];
        args.extend(dirs.iter().map(String::as_str));
        let (summary, _) = succeeded(&goldray(&args));
        assert!(summary.contains("graded 11 students"), "{summary}");
        let found = files(&merged);
        assert_eq!(
            found.keys().collect::<Vec<_>>(),
            expected.keys().collect::<Vec<_>>(),
            "{count} shards"
        );
        for (path, bytes) in &expected {
            assert!(found[path] == *bytes, "{} differs with {count} shards", path.display());
        }
    }
    set_read_only(&cache, false);
    assert_eq!(snapshot(&cache), before, "shards do not write the cache");
}

#[test]
fn bad_shard_arguments_and_shard_sets_are_refused_with_the_reason() {
    let class = make_class();
    let (rubric, submissions) = (text(&class.rubric), text(&class.submissions));
    let cache = text(&class.dir.join("cache"));
    for (shard, message) in [
        ("0/3", "K must be between 1 and 3"),
        ("4/3", "K must be between 1 and 3"),
        ("1/0", "N must be at least 1"),
        ("half", "is not K/N"),
    ] {
        let output = goldray(&["grade", "--rubric", &rubric, &submissions, "--shard", shard]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{shard}: {stderr}");
        assert!(stderr.contains(message), "{shard}: {stderr}");
    }
    let shard = |rubric: &str, index: usize, count: usize, name: &str| {
        let dir = class.dir.join(name);
        grade_shard(rubric, &submissions, (index, count), &dir, &cache, &["--no-diagnose"]);
        text(&dir)
    };
    let (first, second, third) = (
        shard(&rubric, 1, 3, "a"),
        shard(&rubric, 2, 3, "b"),
        shard(&rubric, 3, 3, "c"),
    );
    let half = shard(&rubric, 1, 2, "half");
    let other_rubric = class.dir.join("other.toml");
    fs::write(
        &other_rubric,
        fs::read_to_string(&class.rubric)
            .unwrap()
            .replace("points = 2", "points = 3"),
    )
    .unwrap();
    let other = shard(&text(&other_rubric), 2, 3, "other");
    let merged = text(&class.dir.join("merged"));
    let merge = |dirs: &[&str]| {
        let mut args = vec!["grade", "--merge", merged.as_str()];
        args.extend(dirs);
        let output = goldray(&args);
        assert_eq!(output.status.code(), Some(1), "{dirs:?}");
        String::from_utf8_lossy(&output.stderr).into_owned()
    };
    assert!(merge(&[&first, &second]).contains("missing slice(s) 3/3"));
    assert!(merge(&[&first, &second, &third, &second]).contains("slice 2/3 is given twice"));
    assert!(merge(&[&first, &other, &third]).contains("different rubrics"));
    assert!(merge(&[&first, &half]).contains("different slice counts (1/3 and 1/2)"));
    assert!(merge(&[&first, &text(&class.submissions)]).contains("is not a graded shard"));
    fs::remove_file(class.dir.join("c/students/perfect/result.json")).unwrap();
    let unfinished = merge(&[&first, &second, &third]);
    assert!(
        unfinished.contains("no complete result for student perfect"),
        "{unfinished}"
    );
    assert!(
        !class.dir.join("merged/grades.csv").exists(),
        "a refused merge writes no grades"
    );
    let usage = goldray(&["grade", "--merge", &merged]);
    assert_eq!(usage.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&usage.stderr).contains("needs the shards' report folders"));
}

#[test]
fn a_rerun_resumes_regrading_only_what_changed_or_was_not_trusted() {
    let class = make_class();
    let (rubric, submissions) = (text(&class.rubric), text(&class.submissions));
    let cache = text(&class.dir.join("cache"));
    let out = class.dir.join("report");
    let grade = |out: &Path, extra: &[&str]| {
        let mut args = vec!["grade", "--rubric", &rubric, &submissions, "--cache", &cache, "--out"];
        let out = text(out);
        args.push(&out);
        args.extend(extra);
        succeeded(&goldray(&args))
    };
    let (first, _) = grade(&out, &[]);
    assert!(first.contains("(10 students graded)"), "{first}");
    for step in ["per graded student", "decode", "compare", "FLIP", "diagnosis", "report"] {
        assert!(first.contains(step), "the summary says where the time went: {first}");
    }
    let run: serde_json::Value = serde_json::from_slice(&fs::read(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["graded"], 10, "{run}");
    assert!(run["timings"]["flip"].as_f64().unwrap() > 0.0, "{run}");

    // One result deleted, one cut short, one student's picture replaced by another's.
    fs::remove_file(out.join("students/perfect/result.json")).unwrap();
    let gamma = out.join("students/gamma/result.json");
    let bytes = fs::read(&gamma).unwrap();
    fs::write(&gamma, &bytes[..bytes.len() / 2]).unwrap();
    fs::copy(
        class.submissions.join("no_shadows/color.png"),
        class.submissions.join("shifted_camera/color.png"),
    )
    .unwrap();
    let (second, progress) = grade(&out, &[]);
    assert!(
        second.contains("(3 students graded, 7 kept from an earlier run)"),
        "{second}"
    );
    let regraded: Vec<&str> = progress
        .lines()
        .filter(|l| l.starts_with("grading ") && !l.contains("kept from an earlier run"))
        .collect();
    assert_eq!(regraded.len(), 3, "{progress}");
    for name in ["perfect", "gamma", "shifted_camera"] {
        assert!(
            regraded.iter().any(|l| l.contains(&format!(": {name} ("))),
            "{name}: {progress}"
        );
    }

    let fresh = class.dir.join("fresh");
    grade(&fresh, &[]);
    for file in [
        "grades.csv",
        "grades.json",
        "index.html",
        "students/shifted_camera.html",
    ] {
        assert!(
            fs::read(out.join(file)).unwrap() == fs::read(fresh.join(file)).unwrap(),
            "{file} differs from a fresh run's"
        );
    }
    let (forced, _) = grade(&out, &["--force"]);
    assert!(forced.contains("(10 students graded)"), "{forced}");
    let (nothing_changed, _) = grade(&out, &[]);
    assert!(
        nothing_changed.contains("(0 students graded, 10 kept from an earlier run)"),
        "{nothing_changed}"
    );
}
