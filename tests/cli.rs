//! The `goldray` binary end to end: what it writes, its exit codes, and that failures write
//! nothing and keep existing files intact.

use std::fs;
use std::path::{Path, PathBuf};

mod util;

use util::{goldray, render_on_threads, shipped as case, stderr};

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = match fs::read_dir(dir) {
        Ok(entries) => entries
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect(),
        Err(_) => Vec::new(),
    };
    names.sort();
    names
}

#[test]
fn render_writes_exr_and_png_named_after_the_case() {
    let out = tempfile::tempdir().unwrap();
    let result = goldray(&[
        "render",
        case("directional_light.toml").to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
        "--quiet",
    ]);
    assert!(result.status.success(), "{}", stderr(&result));
    assert_eq!(files_in(out.path()), ["directional_light.exr", "directional_light.png"]);
    let png = util::read_png(&out.path().join("directional_light.png"));
    assert_eq!((png.width(), png.height()), (160, 120));
}

#[test]
fn depth_and_normal_images_are_written_when_the_case_asks() {
    let out = tempfile::tempdir().unwrap();
    let result = goldray(&[
        "render",
        case("depth_normals.toml").to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
        "--quiet",
    ]);
    assert!(result.status.success(), "{}", stderr(&result));
    assert_eq!(
        files_in(out.path()),
        [
            "depth_normals.exr",
            "depth_normals.png",
            "depth_normals_depth.png",
            "depth_normals_normals.png"
        ]
    );
}

/// The same case and binary give the same bytes, whole files with nothing stripped: twice on
/// one thread, and on two threads.
#[test]
fn renders_are_byte_identical_run_after_run_and_on_any_thread_count() {
    for name in [
        "jitter_filter.toml",
        "mirrors.toml",
        "nested_groups.toml",
        "blob_mesh.toml",
        "depth_normals.toml",
    ] {
        let mut runs: Vec<Vec<(String, Vec<u8>)>> = Vec::new();
        for threads in ["1", "1", "2"] {
            let out = tempfile::tempdir().unwrap();
            render_on_threads(&case(name), out.path(), threads, &[]);
            let files = files_in(out.path())
                .into_iter()
                .map(|file| {
                    let bytes = fs::read(out.path().join(&file)).unwrap();
                    (file, bytes)
                })
                .collect();
            runs.push(files);
        }
        assert!(runs[0].len() >= 2, "{name}: an EXR and a PNG at least");
        assert!(
            runs[0] == runs[1],
            "{name}: two runs on one thread wrote different files"
        );
        assert!(runs[0] == runs[2], "{name}: one and two threads wrote different files");
    }
}

#[test]
fn a_bad_case_fails_with_its_location_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("broken.toml");
    fs::write(&bad, "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n\n[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nraduis = 1\n").unwrap();
    let out = dir.path().join("out");
    let result = goldray(&["render", bad.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(1));
    let message = stderr(&result);
    assert!(message.contains("broken.toml:10:1"), "{message}");
    assert!(message.contains("radius"), "suggests the nearest key: {message}");
    assert!(files_in(&out).is_empty(), "nothing is written for a failed case");
}

#[test]
fn a_failed_render_leaves_existing_outputs_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    fs::create_dir(&out).unwrap();
    fs::write(out.join("scene.png"), b"previous render").unwrap();
    let case_path = dir.path().join("scene.toml");
    fs::write(&case_path, "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n\n[[object]]\nkind = \"mesh\"\nobj = \"missing.obj\"\n").unwrap();
    let result = goldray(&["render", case_path.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(1));
    assert!(stderr(&result).contains("missing.obj"), "{}", stderr(&result));
    assert_eq!(fs::read(out.join("scene.png")).unwrap(), b"previous render");
    assert_eq!(files_in(&out), ["scene.png"]);
}

#[test]
fn huge_images_need_force() {
    let dir = tempfile::tempdir().unwrap();
    let case_path = dir.path().join("huge.toml");
    fs::write(&case_path, "[render]\nsize = [20000, 1]\n\n[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n").unwrap();
    let out = dir.path().join("out");
    let refused = goldray(&[
        "render",
        case_path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(stderr(&refused).contains("--force"), "{}", stderr(&refused));
    let forced = goldray(&[
        "render",
        case_path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--force",
    ]);
    assert!(forced.status.success(), "{}", stderr(&forced));
    assert_eq!(util::read_png(&out.join("huge.png")).width(), 20000);
}

#[test]
fn missing_case_file_and_zero_threads_are_errors() {
    let missing = goldray(&["render", "no/such/case.toml", "--quiet"]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(stderr(&missing).contains("no/such/case.toml"), "{}", stderr(&missing));
    let zero = goldray(&["render", case("jitter.toml").to_str().unwrap(), "--threads", "0"]);
    assert!(!zero.status.success());
    assert!(stderr(&zero).contains("threads"), "{}", stderr(&zero));
}

#[test]
fn an_unreadable_cube_map_face_is_an_error_naming_the_face() {
    let dir = tempfile::tempdir().unwrap();
    let faces = dir.path().join("sky");
    fs::create_dir(&faces).unwrap();
    for face in ["left", "right", "up", "down", "front", "back"] {
        fs::write(faces.join(format!("{face}.png")), b"not a png").unwrap();
    }
    let case_path = dir.path().join("sky.toml");
    fs::write(&case_path, "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n\n[background]\ncube_map = \"sky\"\n").unwrap();
    let out = dir.path().join("out");
    let result = goldray(&["render", case_path.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(1));
    let message = stderr(&result);
    assert!(message.contains("sky.toml") && message.contains(".png"), "{message}");
    assert!(files_in(&out).is_empty());
}

/// A minimal course scene: one red sphere in front of the camera.
const COURSE_SCENE: &str = "PerspectiveCamera {\n    center 0 0 10\n    direction 0 0 -1\n    up 0 1 0\n    angle 30\n}\nLights {\n    numLights 1\n    DirectionalLight {\n        direction -0.5 -0.5 -1\n        color 0.8 0.8 0.8\n    }\n}\nBackground {\n    color 0.1 0.1 0.1\n    ambientLight 0.1 0.1 0.1\n}\nMaterials {\n    numMaterials 1\n    Material { diffuseColor 1 0 0 }\n}\nGroup {\n    numObjects 1\n    MaterialIndex 0\n    Sphere {\n        center 0 0 0\n        radius 1\n    }\n}\n";

fn course_scene(dir: &Path) -> PathBuf {
    let path = dir.join("scene.txt");
    fs::write(&path, COURSE_SCENE).unwrap();
    path
}

#[test]
fn a_bad_command_line_exits_2_on_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene(dir.path());
    let scene = scene.to_str().unwrap();
    let nothing = goldray(&["mit6837", "-input", scene]);
    assert_eq!(nothing.status.code(), Some(2), "{}", stderr(&nothing));
    assert!(stderr(&nothing).contains("nothing to write"));
    let negative = goldray(&["mit6837", "-input", scene, "-output", "x.png", "-size", "-400", "400"]);
    assert_eq!(negative.status.code(), Some(2), "{}", stderr(&negative));
    assert!(
        stderr(&negative).contains("size -400 400: each side must be between 1 and 16384"),
        "{}",
        stderr(&negative)
    );
    let unknown = goldray(&["render", "x.toml", "--no-such-flag"]);
    assert_eq!(unknown.status.code(), Some(2));
    let bad_size = goldray(&["tradeoff", case("jitter.toml").to_str().unwrap(), "--size", "0", "10"]);
    assert_eq!(bad_size.status.code(), Some(2), "{}", stderr(&bad_size));
    assert!(stderr(&bad_size).contains("size 0 10: each side must be between 1 and 16384"));
    let bad_pixel = goldray(&["diff", "a.png", "b.png", "--pixel", "nan"]);
    assert_eq!(bad_pixel.status.code(), Some(2));
    assert!(!Path::new("x.png").exists());
}

#[test]
fn outputs_are_checked_before_rendering_and_errors_name_the_path_given() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene(dir.path());
    let blocker = dir.path().join("a file");
    fs::write(&blocker, "not a folder").unwrap();
    let target = blocker.join("x.png");
    let result = goldray(&[
        "mit6837",
        "-input",
        scene.to_str().unwrap(),
        "-output",
        target.to_str().unwrap(),
        "-size",
        "20000",
        "20000",
        "--force",
    ]);
    assert_eq!(result.status.code(), Some(1));
    let message = stderr(&result);
    assert!(message.contains(&target.display().to_string()), "{message}");
    assert!(!message.contains(".goldray-"), "no temporary name: {message}");
    let render = goldray(&[
        "render",
        case("jitter.toml").to_str().unwrap(),
        "--out",
        target.to_str().unwrap(),
    ]);
    assert_eq!(render.status.code(), Some(1));
    assert!(
        stderr(&render).contains(&target.display().to_string()),
        "{}",
        stderr(&render)
    );
}

#[test]
fn missing_output_folders_are_created_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene(dir.path());
    let png = dir.path().join("new/deeper/x.png");
    let course = goldray(&[
        "mit6837",
        "-input",
        scene.to_str().unwrap(),
        "-output",
        png.to_str().unwrap(),
    ]);
    assert!(course.status.success(), "{}", stderr(&course));
    assert!(png.exists());
    let toml = dir.path().join("cases/new/scene.toml");
    let import = goldray(&["import", scene.to_str().unwrap(), "-o", toml.to_str().unwrap()]);
    assert!(import.status.success(), "{}", stderr(&import));
    assert!(toml.exists());
}

#[test]
fn a_course_scene_given_to_render_points_to_the_course_commands() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene(dir.path());
    let result = goldray(&["render", scene.to_str().unwrap(), "--out", dir.path().to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(1));
    let message = stderr(&result);
    assert!(
        message.contains("is a course scene file")
            && message.contains("goldray mit6837")
            && message.contains("goldray import"),
        "{message}"
    );
}

#[test]
fn import_takes_the_course_flags_as_the_course_spells_them() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene(dir.path());
    for size in [&["-size", "80", "60"][..], &["--size", "80x60"][..]] {
        let mut args = vec!["import", scene.to_str().unwrap()];
        args.extend_from_slice(size);
        args.extend_from_slice(&["-shadows", "-bounces", "2"]);
        let result = goldray(&args);
        assert!(result.status.success(), "{}", stderr(&result));
        let text = String::from_utf8_lossy(&result.stdout);
        assert!(text.contains("size = [80, 60]"), "{text}");
        assert!(
            text.contains("shadows = true") && text.contains("bounces = 2"),
            "{text}"
        );
    }
}

#[test]
fn diff_prints_its_verdict_even_when_the_heatmap_cannot_be_written() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene(dir.path());
    let png = dir.path().join("a.png");
    let made = goldray(&[
        "mit6837",
        "-input",
        scene.to_str().unwrap(),
        "-output",
        png.to_str().unwrap(),
    ]);
    assert!(made.status.success(), "{}", stderr(&made));
    let blocked = dir.path().join("a.png/heat.png");
    let result = goldray(&[
        "diff",
        png.to_str().unwrap(),
        png.to_str().unwrap(),
        "--diff-image",
        blocked.to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(4));
    assert!(String::from_utf8_lossy(&result.stdout).contains("PASS"), "{:?}", result);
    assert!(stderr(&result).contains("heat.png"), "{}", stderr(&result));
}

#[test]
fn help_speaks_each_command_s_own_syntax() {
    for args in [
        &["mit6837", "--help"][..],
        &["mit6837", "-help"][..],
        &["help", "mit6837"][..],
    ] {
        let help = goldray(args);
        assert!(help.status.success());
        let text = String::from_utf8_lossy(&help.stdout);
        assert!(
            text.contains(" -input <scene.txt>") && !text.contains("--input"),
            "{text}"
        );
        assert!(text.contains("--exr"), "goldray's own flags keep two dashes: {text}");
    }
    let tradeoff = goldray(&["tradeoff", "--help"]);
    let text = String::from_utf8_lossy(&tradeoff.stdout);
    assert!(
        text.contains("[default: 1,4,16,64,256]") && text.contains("[default: none,gaussian]"),
        "{text}"
    );
    let grade = goldray(&["grade", "--help"]);
    let text = String::from_utf8_lossy(&grade.stdout);
    assert!(
        text.contains("--threads") && !text.contains("--jobs"),
        "--jobs is a hidden alias: {text}"
    );
}

/// `goldray import scene.txt > anywhere/case.toml` must give a case that loads where it is saved,
/// so asset paths written to standard output are absolute, and the header says so.
#[test]
fn import_to_standard_output_works_wherever_the_output_is_saved() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/mit6837/scene05_bunny_200.txt");
    let result = goldray(&["import", scene.to_str().unwrap(), "-size", "40", "40"]);
    assert!(result.status.success(), "{}", stderr(&result));
    let text = String::from_utf8(result.stdout).unwrap();
    assert!(text.contains("# Paths are absolute"), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("sub/deeper/case.toml");
    fs::create_dir_all(saved.parent().unwrap()).unwrap();
    fs::write(&saved, &text).unwrap();
    let out = dir.path().join("out");
    let render = goldray(&[
        "render",
        saved.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(render.status.success(), "{}", stderr(&render));
    assert!(out.join("case.png").is_file());
}
