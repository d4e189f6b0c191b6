//! The `goldray` binary end to end: what it writes, its exit codes, and that failures write
//! nothing and keep existing files intact.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn goldray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(args)
        .output()
        .expect("the goldray binary runs")
}

fn case(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases").join(name)
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

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
    let png = image::open(out.path().join("directional_light.png")).unwrap();
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

#[test]
fn exr_is_bit_identical_with_one_and_two_threads() {
    for name in [
        "jitter_filter.toml",
        "mirrors.toml",
        "nested_groups.toml",
        "blob_mesh.toml",
    ] {
        let mut bytes = Vec::new();
        for threads in ["1", "2"] {
            let out = tempfile::tempdir().unwrap();
            let result = goldray(&[
                "render",
                case(name).to_str().unwrap(),
                "--out",
                out.path().to_str().unwrap(),
                "--threads",
                threads,
                "--quiet",
            ]);
            assert!(result.status.success(), "{name}: {}", stderr(&result));
            let stem = name.trim_end_matches(".toml");
            bytes.push(fs::read(out.path().join(format!("{stem}.exr"))).unwrap());
        }
        assert!(bytes[0] == bytes[1], "{name}: 1 and 2 threads differ");
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
    assert_eq!(image::open(out.join("huge.png")).unwrap().width(), 20000);
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
