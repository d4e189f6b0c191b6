//! `goldray diff` on real files, one test per exit code family.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use goldray::compare::FAILING;
use goldray::film::{Tonemap, color_image, write_exr, write_png};

use super::{case, render};

fn goldray_diff(args: &[&Path], flags: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .arg("diff")
        .args(args)
        .args(flags)
        .output()
        .expect("the goldray binary runs")
}

fn exit_code(output: &Output) -> i32 {
    output.status.code().expect("an exit code")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// A golden film, that film with one pixel nudged, with the shadows gone, and one pixel wider,
/// all written to disk as EXR and PNG.
struct Files {
    _dir: tempfile::TempDir,
    root: PathBuf,
}

impl Files {
    fn new() -> Files {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let root = dir.path().to_path_buf();
        let with = case("spheres_shadows");
        let golden = render(&with);
        let mut nudged = golden.clone();
        let at = nudged.index(100, 100);
        nudged.color[at][0] += 0.05;
        let mut without = with.clone();
        without.render.trace.shadows = false;
        let mut wider = with.clone();
        wider.render.trace.width += 1;
        for (name, film) in [
            ("golden", golden),
            ("nudged", nudged),
            ("unshadowed", render(&without)),
            ("wider", render(&wider)),
        ] {
            write_exr(&root.join(format!("{name}.exr")), &film).expect("EXR written");
            write_png(&root.join(format!("{name}.png")), &color_image(&film, Tonemap::Srgb)).expect("PNG written");
        }
        Files { _dir: dir, root }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }
}

#[test]
fn diff_exit_codes_follow_idiff() {
    let files = Files::new();
    let golden = files.path("golden.exr");
    let cases: [(&str, &[&str], i32); 7] = [
        ("golden.exr", &[], 0),
        ("nudged.exr", &[], 1),
        ("nudged.exr", &["--pixel", "0.1"], 0),
        ("unshadowed.exr", &[], 2),
        ("wider.exr", &[], 3),
        ("golden.png", &[], 3),
        ("missing.exr", &[], 4),
    ];
    for (actual, flags, code) in cases {
        let output = goldray_diff(&[&golden, &files.path(actual)], flags);
        assert_eq!(
            exit_code(&output),
            code,
            "{actual} {flags:?}:\n{}{}",
            stdout(&output),
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

#[test]
fn diff_compares_pngs_in_eight_bit_codes() {
    let files = Files::new();
    let golden = files.path("golden.png");
    let same = goldray_diff(&[&golden, &golden], &[]);
    assert_eq!(exit_code(&same), 0, "{}", stdout(&same));
    assert!(stdout(&same).contains("(8-bit codes)"), "{}", stdout(&same));
    let unshadowed = goldray_diff(&[&golden, &files.path("unshadowed.png")], &[]);
    assert_eq!(exit_code(&unshadowed), 2, "{}", stdout(&unshadowed));
    assert!(
        stdout(&unshadowed).contains("broke fail_fraction"),
        "{}",
        stdout(&unshadowed)
    );
}

#[test]
fn diff_names_an_unreadable_file_and_exits_4() {
    let files = Files::new();
    let garbage = files.path("garbage.exr");
    std::fs::write(&garbage, b"not an image at all").expect("written");
    let truncated = files.path("truncated.exr");
    let bytes = std::fs::read(files.path("golden.exr")).expect("read");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).expect("written");
    for bad in [&garbage, &truncated] {
        let output = goldray_diff(&[&files.path("golden.exr"), bad], &[]);
        assert_eq!(exit_code(&output), 4);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(&bad.display().to_string()), "{stderr}");
    }
}

#[test]
fn diff_writes_a_heatmap_and_json_on_request() {
    let files = Files::new();
    let heatmap = files.path("heat.png");
    let output = goldray_diff(
        &[&files.path("golden.exr"), &files.path("unshadowed.exr")],
        &["--json", "--diff-image", heatmap.to_str().expect("a UTF-8 path")],
    );
    assert_eq!(exit_code(&output), 2);
    let report: serde_json::Value = serde_json::from_str(&stdout(&output)).expect("JSON on stdout");
    assert_eq!(report["verdict"], "fail");
    assert_eq!(report["exit_code"], 2);
    assert_eq!(report["breaches"][0]["limit"], "fail_fraction");
    assert!(report["metrics"]["rmse"].as_f64().is_some_and(|rmse| rmse > 0.002));
    assert!(report["metrics"]["flip"].as_f64().is_some_and(|flip| flip > 0.0));
    let picture = goldray::rgb_image::read_png(&heatmap).expect("the heatmap is a PNG");
    assert_eq!(picture.dimensions(), (200, 200));
    assert!(picture.pixels().any(|p| p.0 == FAILING), "failing pixels are marked");
}

#[test]
fn diff_refuses_a_threshold_that_would_pass_everything() {
    let files = Files::new();
    let output = goldray_diff(
        &[&files.path("golden.exr"), &files.path("golden.exr")],
        &["--pixel", "NaN"],
    );
    assert_eq!(exit_code(&output), 2, "a bad command line");
    assert!(String::from_utf8_lossy(&output.stderr).contains("--pixel"));
}

#[test]
fn diff_reports_an_exr_without_depth_and_normals_as_a_channel_mismatch() {
    let files = Files::new();
    let colour_only = files.path("colour_only.exr");
    exr::prelude::write_rgb_file(&colour_only, 200, 200, |_, _| (0.0_f32, 0.0_f32, 0.0_f32)).expect("EXR written");
    let output = goldray_diff(&[&files.path("golden.exr"), &colour_only], &[]);
    assert_eq!(exit_code(&output), 3, "{}", stdout(&output));
    assert!(stdout(&output).contains("channels differ"), "{}", stdout(&output));
}
