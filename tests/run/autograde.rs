//! `goldray autograde` with a rubric's `[program]`, through the shipped `run_autograder` script on
//! a simulated Gradescope `/autograder` tree: a C++ submission is built, run and graded, and
//! Gradescope's results say what a student needs; a submission that does not compile gets the
//! compiler's messages, not seven bare zeros.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use super::{goldray, project_file, scratch, write_rubric};

/// An `/autograder` tree in `dir`: `source/rubric.toml` with a `[program]`, `submission/` holding
/// the student renderer's sources plus `extra` files.
fn autograder(dir: &Path, extra: &[(&str, &str)]) -> PathBuf {
    let rubric = write_rubric(dir, "wall_time = 30");
    let mut text = fs::read_to_string(&rubric).unwrap();
    text += "\n[program]\nbuild = \"g++ -O1 -o raytracer *.cpp\"\ncommand = \"raytracer\"\n";
    fs::create_dir_all(dir.join("source")).unwrap();
    fs::write(dir.join("source/rubric.toml"), text).unwrap();
    let submission = dir.join("submission");
    fs::create_dir_all(&submission).unwrap();
    fs::copy(
        project_file("tests/data/student_renderer/main.cpp"),
        submission.join("main.cpp"),
    )
    .unwrap();
    for (file, text) in extra {
        fs::write(submission.join(file), text).unwrap();
    }
    dir.to_path_buf()
}

/// Gradescope's run: the shipped `run_autograder` script on the tree at `root`.
fn autograde(root: &Path) -> Value {
    let output = Command::new("bash")
        .arg(project_file("examples/gradescope/run_autograder"))
        .env("AUTOGRADER_ROOT", root)
        .env("GOLDRAY", env!("CARGO_BIN_EXE_goldray"))
        .output()
        .expect("bash runs");
    assert!(
        output.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&fs::read(root.join("results/results.json")).unwrap()).unwrap()
}

#[test]
fn a_cpp_submission_is_built_run_and_graded_for_gradescope() {
    let root = autograder(&scratch("autograde"), &[]);
    let json = autograde(&root);
    let renders = root.join("results/report/renders");
    // The same pictures graded by `goldray grade`, as a class of one.
    let class = root.join("class");
    fs::create_dir_all(class.join("student")).unwrap();
    for file in ["a01.png", "a01n.png", "a01d.png", "a02.png", "a02n.png", "a02d.png"] {
        fs::copy(renders.join(file), class.join("student").join(file)).unwrap();
    }
    let report = root.join("grade-report");
    let graded = goldray(&[
        "grade",
        "--rubric",
        root.join("source/rubric.toml").to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
        "--cache",
        root.join("source/cache").to_str().unwrap(),
        "--quiet",
        class.to_str().unwrap(),
    ]);
    assert!(graded.status.success());
    let grades: Value = serde_json::from_str(&fs::read_to_string(report.join("grades.json")).unwrap()).unwrap();
    let student = &grades["students"][0];
    assert_eq!(json["score"], student["total"]);
    let tests = json["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 6);
    for (test, image) in tests.iter().zip(student["images"].as_array().unwrap()) {
        assert_eq!(test["name"], image["file"]);
        assert_eq!(test["score"], image["points"]);
    }
    // The stand-in renderer draws gradients: every image fails, and each test says by how much.
    assert!(tests.iter().all(|t| t["status"] == "failed"));
    assert!(
        tests[0]["output"].as_str().unwrap().contains("of pixels differ"),
        "{:#}",
        tests[0]
    );
}

#[test]
fn a_submission_that_does_not_compile_gets_the_compilers_messages() {
    let root = autograder(
        &scratch("autograde-broken"),
        &[("broken.cpp", "int broken( { return 0; }\n")],
    );
    let json = autograde(&root);
    assert_eq!(json["score"], 0.0);
    let summary = json["output"].as_str().unwrap();
    assert!(summary.contains("Your program did not build"), "{summary}");
    for test in json["tests"].as_array().unwrap() {
        assert_eq!(test["status"], "failed");
        let said = test["output"].as_str().unwrap();
        assert!(said.starts_with("not run: the build failed"), "{said}");
        assert!(
            said.contains("broken.cpp:1"),
            "the compiler's message reaches the student: {said}"
        );
    }
}
