//! A class at once: `goldray run --programs` builds and runs every student's sources, one
//! student's failure (a compile error, a crash, an endless loop) stops nobody else, `goldray
//! grade` then names each failure on the student's image and page, the grades of the built and
//! run submission equal those of the same program run by hand, and a second run reruns only the
//! student whose sources changed.

use std::fs;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

use super::{files_in, goldray, project_file, scratch, write_rubric};

const BUILD: &str = "g++ -O1 -o raytracer *.cpp";

/// A C++ file that, linked beside the well-behaved renderer, ends the process when the course's
/// command line names `scene` (glibc hands constructors the program's arguments).
fn sabotage(scene: &str, action: &str) -> String {
    format!(
        "#include <cstdio>\n#include <cstring>\n#include <csignal>\n\
         __attribute__((constructor)) static void sabotage(int argc, char** argv) {{\n\
         for (int i = 1; i < argc; i++) if (std::strstr(argv[i], \"{scene}\")) {{ {action} }}\n}}\n"
    )
}

fn student(class: &Path, name: &str, extra: &[(&str, String)]) {
    let dir = class.join(name);
    fs::create_dir_all(&dir).unwrap();
    fs::copy(
        project_file("tests/data/student_renderer/main.cpp"),
        dir.join("main.cpp"),
    )
    .unwrap();
    for (file, text) in extra {
        fs::write(dir.join(file), text).unwrap();
    }
}

/// `goldray run --programs CLASS` with the class's build and program, its renders into `out`.
fn class_run(rubric: &Path, class: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let (rubric, class, out) = (rubric.to_str().unwrap(), class.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec!["run", "--rubric", rubric, "--programs", class, "--build", BUILD];
    args.extend(["--program", "raytracer", "--out", out]);
    args.extend(extra);
    goldray(&args)
}

fn run_class(rubric: &Path, class: &Path, out: &Path) -> String {
    let output = class_run(rubric, class, out, &["--quiet"]);
    assert!(
        output.status.success(),
        "goldray run --programs failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // --quiet prints nothing; the summary is checked by a run without it.
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn grade(rubric: &Path, renders: &Path, out: &Path, cache: &Path) -> Value {
    let output = goldray(&[
        "grade",
        "--rubric",
        rubric.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--cache",
        cache.to_str().unwrap(),
        "--no-diagnose",
        "--quiet",
        renders.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_str(&fs::read_to_string(out.join("grades.json")).unwrap()).unwrap()
}

fn images<'a>(grades: &'a Value, name: &str) -> &'a Vec<Value> {
    grades["students"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no student {name} in {grades:#}"))["images"]
        .as_array()
        .unwrap()
}

fn image<'a>(grades: &'a Value, name: &str, file: &str) -> &'a Value {
    images(grades, name)
        .iter()
        .find(|i| i["file"] == file)
        .unwrap_or_else(|| panic!("{name} has no {file}"))
}

#[test]
fn a_class_is_built_run_and_graded_with_every_failure_named_and_reruns_only_what_changed() {
    let dir = scratch("class");
    let rubric = write_rubric(&dir, "wall_time = 10");
    let class = dir.join("class");
    student(&class, "alice", &[]);
    student(
        &class,
        "bob",
        &[("broken.cpp", "int broken( { return 0; }\n".to_owned())],
    );
    let crash = "std::fprintf(stderr, \"carol: about to dereference null\\n\"); std::raise(SIGSEGV);";
    student(&class, "carol", &[("crash.cpp", sabotage("scene02", crash))]);
    student(
        &class,
        "dave",
        &[("loop.cpp", sabotage("scene01", "for (volatile int k = 0;; k++) {}"))],
    );
    fs::write(class.join("notes.txt"), "not a student").unwrap();
    let renders = dir.join("renders");

    let output = class_run(&rubric, &class, &renders, &[]);
    let summary = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "{summary}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        summary.contains("4 students: 4 run, 0 unchanged, 0 failed"),
        "{summary}"
    );
    assert!(summary.contains("bob: build: FAILED"), "{summary}");
    assert!(summary.contains("not student folders, ignored: notes.txt"), "{summary}");
    assert_eq!(files_in(&renders), ["alice", "bob", "carol", "dave"]);
    let pictures = ["a01.png", "a01d.png", "a01n.png", "a02.png", "a02d.png", "a02n.png"];
    let mut alice_files: Vec<&str> = pictures.to_vec();
    alice_files.extend(["build.log", "run.json"]);
    alice_files.sort();
    assert_eq!(files_in(&renders.join("alice")), alice_files);

    // Grading reads each student's run.json.
    let cache = dir.join("cache");
    let grades = grade(&rubric, &renders, &dir.join("report"), &cache);
    for file in pictures {
        let bob = image(&grades, "bob", file);
        assert_eq!(bob["verdict"], "not_run", "{bob:#}");
        assert!(
            bob["explanation"].as_str().unwrap().contains("the build failed"),
            "{bob:#}"
        );
        assert!(
            bob["program"]["stderr_tail"].as_str().unwrap().contains("broken.cpp"),
            "the compiler's error reaches the grade: {bob:#}"
        );
        assert_eq!(bob["program"]["command"], BUILD);
    }
    for file in ["a02.png", "a02n.png", "a02d.png"] {
        let carol = image(&grades, "carol", file);
        assert_eq!(carol["verdict"], "crashed", "{carol:#}");
        assert!(
            carol["explanation"]
                .as_str()
                .unwrap()
                .starts_with("crashed: SIGSEGV after"),
            "{carol:#}"
        );
        assert!(
            carol["program"]["stderr_tail"]
                .as_str()
                .unwrap()
                .contains("about to dereference null")
        );
        let command = carol["program"]["command"].as_str().unwrap();
        assert!(
            command.starts_with("raytracer -input data/scene02_cube.txt -size 16 12"),
            "{command}"
        );
        let dave = image(&grades, "dave", file);
        assert_ne!(dave["verdict"], "timed_out", "dave's scene02 ran: {dave:#}");
    }
    for file in ["a01.png", "a01n.png", "a01d.png"] {
        let dave = image(&grades, "dave", file);
        assert_eq!(dave["verdict"], "timed_out", "{dave:#}");
        assert!(
            dave["explanation"]
                .as_str()
                .unwrap()
                .starts_with("timed out after 10 s"),
            "{dave:#}"
        );
        assert_eq!(
            image(&grades, "carol", file)["verdict"],
            image(&grades, "alice", file)["verdict"]
        );
    }
    let carol_page = fs::read_to_string(dir.join("report/students/carol.html")).unwrap();
    assert!(carol_page.contains("How your program ran") && carol_page.contains("about to dereference null"));
    let bob_page = fs::read_to_string(dir.join("report/students/bob.html")).unwrap();
    assert_eq!(
        bob_page.matches("the end of its stderr").count(),
        1,
        "a failed build is shown once, not once per image"
    );

    // Alice's program run by hand, as a TA would: the same grades, image by image.
    let hand = dir.join("hand/alice");
    fs::create_dir_all(hand.join("data/models")).unwrap();
    let binary = dir.join("hand-raytracer");
    let built = Command::new("g++")
        .args(["-O1", "-o"])
        .arg(&binary)
        .arg(class.join("alice/main.cpp"))
        .status()
        .unwrap();
    assert!(built.success());
    for file in ["scene01_plane.txt", "scene02_cube.txt", "models/cube2.obj"] {
        fs::copy(
            project_file(&format!("cases/mit6837/{file}")),
            hand.join("data").join(file),
        )
        .unwrap();
    }
    for args in [
        "-input data/scene01_plane.txt -size 16 16 -output a01.png -normals a01n.png -depth 8 18 a01d.png",
        "-input data/scene02_cube.txt -size 16 12 -bounces 2 -shadows -output a02.png -normals a02n.png -depth 8 18 a02d.png",
    ] {
        let ran = Command::new(&binary)
            .args(args.split(' '))
            .current_dir(&hand)
            .output()
            .unwrap();
        assert!(ran.status.success());
    }
    let by_hand = grade(&rubric, &dir.join("hand"), &dir.join("report-hand"), &cache);
    let graded = |grades: &Value| -> Vec<(Value, Value)> {
        images(grades, "alice")
            .iter()
            .map(|i| (i["verdict"].clone(), i["points"].clone()))
            .collect()
    };
    assert_eq!(graded(&grades), graded(&by_hand));
    assert!(images(&grades, "alice").iter().all(|i| i.get("program").is_none()));

    // Again: nothing changed, nothing runs (dave's endless loop would take its 10 s again).
    let again = class_run(&rubric, &class, &renders, &[]);
    let summary = String::from_utf8_lossy(&again.stdout);
    assert!(
        summary.contains("4 students: 0 run, 4 unchanged, 0 failed"),
        "{summary}"
    );
    // Bob fixes his file: only bob runs, and now succeeds.
    fs::write(class.join("bob/broken.cpp"), "int broken() { return 0; }\n").unwrap();
    let record_before = fs::read(renders.join("alice/run.json")).unwrap();
    run_class(&rubric, &class, &renders);
    assert_eq!(
        fs::read(renders.join("alice/run.json")).unwrap(),
        record_before,
        "alice was not run again"
    );
    let bob = goldray::sandbox::RunRecord::read(&renders.join("bob")).unwrap();
    assert!(
        bob.build
            .as_ref()
            .and_then(|b| b.outcome.as_ref())
            .is_some_and(|o| o.succeeded())
    );
    assert_eq!(files_in(&renders.join("bob")).len(), pictures.len() + 2);
}
