//! A well-behaved submission: built from C++ sources with `--build`, run through the rubric.

use std::fs;
use std::path::Path;

use super::{files_in, goldray, outcome, project_file, run_ok, scratch, write_rubric};

#[test]
fn a_cpp_submission_is_built_and_run_and_only_the_rubrics_files_come_out() {
    let dir = scratch("student");
    let rubric = write_rubric(&dir, "wall_time = 60");
    let out = dir.join("out");
    // A file from an earlier run that this run must not leave in place.
    fs::create_dir_all(&out).unwrap();
    fs::write(out.join("stray.txt"), "kept: not the rubric's").unwrap();
    let submission = project_file("tests/data/student_renderer");
    let before = files_in(&submission);
    let (record, summary) = run_ok(
        &[
            "run",
            "--rubric",
            rubric.to_str().unwrap(),
            "--submission",
            submission.to_str().unwrap(),
            "--build",
            "g++ -O1 -o raytracer main.cpp",
            "--program",
            "raytracer",
            "--out",
            out.to_str().unwrap(),
        ],
        &out,
    );
    // The build ran in a copy: the committed sources are untouched.
    assert_eq!(files_in(&submission), before);
    let build = record.build.as_ref().expect("the build is recorded");
    let built = build.outcome.as_ref().expect("the build ran");
    assert!(built.succeeded(), "build: {built:#?}");
    assert!(
        fs::read_to_string(out.join("build.log"))
            .unwrap()
            .contains("g++ -O1 -o raytracer main.cpp")
    );

    let mut expected: Vec<String> = ["a01.png", "a01n.png", "a01d.png", "a02.png", "a02n.png", "a02d.png"]
        .map(str::to_owned)
        .to_vec();
    expected.extend(["build.log", "run.json", "stray.txt"].map(str::to_owned));
    expected.sort();
    assert_eq!(files_in(&out), expected);
    for (name, size) in [("scene01", (16, 16)), ("scene02", (16, 12))] {
        let ran = outcome(&record, name);
        assert!(ran.succeeded(), "{name}: {ran:#?}");
        assert!(ran.stdout_tail.contains("rendered data/scene0"), "{}", ran.stdout_tail);
        for file in &super::command(&record, name).outputs {
            assert!(file.delivered, "{file:?}");
            let dims = goldray::rgb_image::read_png(&out.join(&file.file))
                .expect("a PNG")
                .dimensions();
            assert_eq!(dims, size, "{}", file.file);
        }
    }
    // The course's command line, exactly: the scene under data/, the flags, the rubric's names.
    let argv = &super::command(&record, "scene02").argv;
    assert_eq!(
        argv[1..],
        [
            "-input",
            "data/scene02_cube.txt",
            "-size",
            "16",
            "12",
            "-bounces",
            "2",
            "-shadows",
            "-output",
            "a02.png",
            "-normals",
            "a02n.png",
            "-depth",
            "8",
            "18",
            "a02d.png"
        ]
    );
    assert!(
        summary.contains("ran 2 of 2 commands: 2 succeeded, 0 failed"),
        "{summary}"
    );
    assert!(summary.contains("sandbox: "), "{summary}");
}

#[test]
fn a_failed_build_runs_nothing_and_says_so() {
    let dir = scratch("failed-build");
    let rubric = write_rubric(&dir, "wall_time = 30");
    let out = dir.join("out");
    let submission = project_file("tests/data/student_renderer");
    let (record, summary) = run_ok(
        &[
            "run",
            "--rubric",
            rubric.to_str().unwrap(),
            "--submission",
            submission.to_str().unwrap(),
            "--build",
            "echo 'main.cpp:1: error: no' >&2; exit 1",
            "--program",
            "raytracer",
            "--out",
            out.to_str().unwrap(),
        ],
        &out,
    );
    let build = record
        .build
        .as_ref()
        .and_then(|b| b.outcome.as_ref())
        .expect("build ran");
    assert_eq!(build.exit, goldray::sandbox::Exit::Code(1));
    assert!(build.stderr_tail.contains("main.cpp:1: error"));
    for command in &record.commands {
        assert!(command.outcome.is_none() && command.not_run.as_deref().is_some_and(|w| w.contains("build failed")));
        assert!(command.outputs.iter().all(|o| !o.delivered));
    }
    assert!(summary.contains("build: FAILED"), "{summary}");
    assert_eq!(files_in(&out), ["build.log", "run.json"]);
}

/// `goldray run` of `/bin/true` through `rubric` into `out`: its exit code and stderr.
fn run_true(rubric: &Path, out: &Path) -> (Option<i32>, String) {
    let result = goldray(&[
        "run",
        "--rubric",
        rubric.to_str().unwrap(),
        "--program",
        "/bin/true",
        "--out",
        out.to_str().unwrap(),
    ]);
    (
        result.status.code(),
        String::from_utf8_lossy(&result.stderr).into_owned(),
    )
}

#[test]
fn toml_case_renders_are_skipped_and_bad_limits_are_located_errors() {
    let dir = scratch("rubric-errors");
    let case = project_file("cases/spheres_shadows.toml");
    let only_case = dir.join("cases.toml");
    fs::write(
        &only_case,
        format!(
            "[render.s]\ncase = \"{}\"\n[image.\"s.png\"]\nrender = \"s\"\n",
            case.display()
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let (code, stderr) = run_true(&only_case, &out);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("nothing to run") && stderr.contains("TOML case"),
        "{stderr}"
    );

    let (code, stderr) = run_true(&write_rubric(&dir, "wall_tme = 3"), &out);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("rubric.toml:") && stderr.contains("wall_time"),
        "{stderr}"
    );
    let (_, stderr) = run_true(&write_rubric(&dir, "memory = \"4 parsecs\""), &out);
    assert!(stderr.contains("unknown unit `parsecs`"), "{stderr}");
}
