//! The golden cache across runs, and `goldray grade` as a TA runs it: its exit codes and messages.

use std::fs;
use std::path::Path;
use std::process::Command;

use goldray::grade::{ClassReport, GradeOptions, grade_class};
use goldray::progress::Silent;

use crate::class::make_class;

#[test]
fn goldens_are_rendered_once_then_read_from_the_cache() {
    let class = make_class();
    let cache = class.dir.join("cache");
    let grade = |out: &str| {
        let options = GradeOptions {
            out: class.dir.join(out),
            cache: Some(cache.clone()),
            ..GradeOptions::default()
        };
        grade_class(&class.rubric, &class.submissions, &options, &Silent).unwrap_or_else(|e| panic!("{e}"))
    };
    let first = grade("first");
    assert_eq!(first.goldens.len(), 1, "three images, one render");
    assert!(!first.goldens[0].cached);
    let second = grade("second");
    assert!(second.goldens[0].cached, "the second run reads the cache");
    let totals = |r: &ClassReport| r.students.iter().map(|s| s.total).collect::<Vec<_>>();
    assert_eq!(totals(&first), totals(&second));

    // A different scene is a different key; a damaged entry is rendered again.
    let entry = cache.join(format!("{}.exr", first.goldens[0].key));
    fs::write(&entry, b"not an EXR").unwrap();
    assert!(!grade("third").goldens[0].cached);
    assert!(
        goldray::film::decode_exr(&fs::read(&entry).unwrap()).is_ok(),
        "the damaged entry was repaired"
    );
}

/// Runs goldray with the user cache folder (where golden renders go by default) at `cache_home`,
/// so that tests never touch the real one.
fn goldray(args: &[&str], cache_home: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(args)
        .env("XDG_CACHE_HOME", cache_home)
        .output()
        .expect("the goldray binary runs")
}

#[test]
fn the_command_exits_0_whatever_the_grades_and_1_when_it_cannot_grade() {
    let class = make_class();
    let out = class.dir.join("cli-report");
    let path = |p: &Path| p.to_str().unwrap().to_owned();
    let run = goldray(
        &[
            "grade",
            "--rubric",
            &path(&class.rubric),
            &path(&class.submissions),
            "--out",
            &path(&out),
            "--jobs",
            "2",
        ],
        &class.dir.join("user-cache"),
    );
    assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("graded 10 students") && stdout.contains("index.html"),
        "{stdout}"
    );
    for file in ["grades.csv", "grades.json", "index.html", "golden/color.png"] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    // The golden cache lives in the user cache folder, not in the report that gets zipped and sent.
    let cache = class.dir.join("user-cache/goldray/goldens");
    assert!(!out.join("cache").exists(), "no cache inside the report");
    assert!(
        fs::read_dir(&cache).is_ok_and(|mut entries| entries.next().is_some()),
        "goldens cached in {}",
        cache.display()
    );
    assert!(
        stdout.contains(&cache.display().to_string()),
        "the summary says where: {stdout}"
    );

    let missing = goldray(
        &[
            "grade",
            "--rubric",
            &path(&class.rubric),
            "/nonexistent/submissions",
            "--out",
            &path(&out),
            "--quiet",
        ],
        &class.dir.join("user-cache"),
    );
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("/nonexistent/submissions"));

    let bad = class.dir.join("bad.toml");
    fs::write(
        &bad,
        fs::read_to_string(&class.rubric)
            .unwrap()
            .replace("points = 2", "pionts = 2"),
    )
    .unwrap();
    let run = goldray(
        &[
            "grade",
            "--rubric",
            &path(&bad),
            &path(&class.submissions),
            "--out",
            &path(&out),
            "--quiet",
        ],
        &class.dir.join("user-cache"),
    );
    assert_eq!(run.status.code(), Some(1));
    let message = String::from_utf8_lossy(&run.stderr);
    assert!(
        message.contains("bad.toml:17:1") && message.contains("did you mean `points`"),
        "{message}"
    );
}
