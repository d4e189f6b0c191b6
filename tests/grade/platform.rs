//! Grading one submission where a course lives: `goldray check` (a student's self-check) and
//! `goldray autograde` (Gradescope's autograder) on students of the synthetic class, against the
//! class graded by `goldray grade`.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

use super::{graded, student};

fn goldray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(args)
        .output()
        .expect("the goldray binary runs")
}

fn copy_folder(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
}

#[test]
fn check_names_the_mistake_and_where_to_look_and_exits_by_the_points() {
    let class = &graded().class;
    let rubric = class.rubric.to_str().unwrap();
    let folder = class.submissions.join("no_shadows");
    let output = goldray(&["check", "--rubric", rubric, folder.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.starts_with("2 / 4 points\ncolor.png: fail, 0 / 2\n"), "{text}");
    assert!(text.contains("mistake: no-shadows: "), "{text}");
    assert!(text.contains("where to look: "), "{text}");
    assert!(text.contains("normals.png: pass, 1 / 1"), "{text}");

    let perfect = class.submissions.join("perfect");
    let output = goldray(&["check", "--rubric", rubric, perfect.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(text.starts_with("4 / 4 points\n"), "{text}");
    assert!(!text.contains("mistake"), "{text}");
}

#[test]
fn autograde_writes_gradescopes_results_with_the_grade_of_goldray_grade() {
    let graded = graded();
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("autograder");
    let _ = fs::remove_dir_all(&root);
    copy_folder(&graded.class.submissions.join("no_shadows"), &root.join("submission"));
    let mut rubric = fs::read_to_string(&graded.class.rubric).unwrap();
    rubric += "\n[gradescope]\nvisibility = \"after_due_date\"\nimages = { \"depth.png\" = \"hidden\" }\n";
    fs::create_dir_all(root.join("source")).unwrap();
    fs::write(root.join("source/rubric.toml"), rubric).unwrap();
    let results = root.join("results/results.json");
    let paths = [
        root.join("source/rubric.toml"),
        root.join("submission"),
        results.clone(),
    ];
    let [rubric, submission, results_path] = paths.each_ref().map(|p| p.to_str().unwrap());
    let args = [
        "autograde",
        "--rubric",
        rubric,
        "--submission",
        submission,
        "--results",
        results_path,
    ];
    let output = goldray(&args);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let bytes = fs::read(&results).unwrap();
    let json: Value = serde_json::from_slice(&bytes).unwrap();

    let expected = student(&graded.report, "no_shadows");
    assert_eq!(json["score"].as_f64(), Some(expected.total));
    assert_eq!(json["output_format"], "text");
    assert_eq!(json["visibility"], "after_due_date");
    let summary = json["output"].as_str().unwrap();
    assert!(
        summary.contains("2 of 4 points") && summary.contains("Mistake no-shadows (color.png)"),
        "{summary}"
    );
    let tests = json["tests"].as_array().unwrap();
    assert_eq!(tests.len(), expected.images.len());
    for (test, image) in tests.iter().zip(&expected.images) {
        let mut keys: Vec<&str> = test.as_object().unwrap().keys().map(String::as_str).collect();
        keys.sort_unstable();
        assert_eq!(keys, ["max_score", "name", "output", "score", "status", "visibility"]);
        assert_eq!(test["name"], image.file.as_str());
        assert_eq!(test["score"].as_f64(), Some(image.points));
        assert_eq!(test["max_score"].as_f64(), Some(image.max_points));
        let passed = image.points == image.max_points;
        assert_eq!(test["status"], if passed { "passed" } else { "failed" });
        assert!(!test["output"].as_str().unwrap().is_empty());
    }
    let color = &tests[0];
    let said = color["output"].as_str().unwrap();
    assert!(
        said.contains("mistake: no-shadows") && said.contains("where to look"),
        "{said}"
    );
    assert_eq!(color["visibility"], "after_due_date");
    assert_eq!(tests[2]["visibility"], "hidden");
    // The report a TA can open sits beside the results; grading again writes the same bytes.
    assert!(root.join("results/report/index.html").is_file());
    let again = goldray(&args);
    assert!(again.status.success());
    assert_eq!(fs::read(&results).unwrap(), bytes);
}
