//! The `mit6837` profile against the course's own reference renderer, and the drop-in command
//! against the imported TOML case. Reads the course's scenes from `cases/mit6837/` and its
//! reference images from `tests/data/mit6837/`.

mod util;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use goldray::case::{AssignmentOptions, load_assignment_scene};
use goldray::film::{Tonemap, color_image, depth_image, normals_image};
use goldray::pipeline::render_case;
use goldray::provenance::{Group, Provenance, keys, strip};
use goldray::rgb_image::RgbImage;

/// The course's scene `file` (e.g. `scene01_plane.txt`).
fn scene_path(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/mit6837").join(file)
}

/// The course's reference image `file` (e.g. `a01.png`).
fn reference_path(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mit6837")
        .join(file)
}

/// Runs goldray and insists that it succeeded.
fn goldray(args: &[&str]) -> Output {
    let output = util::goldray(args);
    assert!(output.status.success(), "goldray {args:?}: {}", util::stderr(&output));
    output
}

/// Fraction of pixels whose every channel is within `tolerance` of the reference, and where
/// the others are.
fn agreement(ours: &RgbImage, reference: &RgbImage, tolerance: u8) -> (f64, Vec<(u32, u32)>) {
    assert_eq!(ours.dimensions(), reference.dimensions());
    let off: Vec<(u32, u32)> = ours
        .enumerate_pixels()
        .filter(|(x, y, p)| {
            p.0.iter()
                .zip(reference.get_pixel(*x, *y).0)
                .any(|(a, b)| a.abs_diff(b) > tolerance)
        })
        .map(|(x, y, _)| (x, y))
        .collect();
    (1.0 - off.len() as f64 / (ours.width() * ours.height()) as f64, off)
}

fn check_against_reference(scene: &str, reference: &str, depth_range: (f64, f64)) {
    let options = AssignmentOptions {
        width: 800,
        height: 800,
        depth_range: Some(depth_range),
        normals: true,
        ..AssignmentOptions::default()
    };
    let case = load_assignment_scene(&scene_path(scene), &options).unwrap_or_else(|e| panic!("{e}"));
    let film = render_case(&case).unwrap_or_else(|e| panic!("{e}"));
    let (min, max) = (depth_range.0 as f32, depth_range.1 as f32);
    let images = [
        ("colour", color_image(&film, Tonemap::Clamp), format!("{reference}.png")),
        (
            "normals",
            normals_image(&film, Tonemap::Clamp),
            format!("{reference}n.png"),
        ),
        (
            "depth",
            depth_image(&film, min, max, Tonemap::Clamp),
            format!("{reference}d.png"),
        ),
    ];
    for (what, ours, file) in images {
        let expected = goldray::rgb_image::read_png(&reference_path(&file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let (fraction, off) = agreement(&ours, &expected, 2);
        assert!(
            fraction >= 0.995,
            "{scene} {what}: only {:.3}% of pixels within 2/255 of {file}; first off: {:?}",
            fraction * 100.0,
            &off[..off.len().min(10)]
        );
        eprintln!(
            "{scene} {what}: {:.4}% within 2/255 ({} pixels off: {:?})",
            fraction * 100.0,
            off.len(),
            &off[..off.len().min(8)]
        );
    }
}

#[test]
fn scene01_matches_the_reference_renderer() {
    check_against_reference("scene01_plane.txt", "a01", (8.0, 18.0));
}

#[test]
fn scene02_matches_the_reference_renderer() {
    check_against_reference("scene02_cube.txt", "a02", (8.0, 18.0));
}

#[test]
fn scene05_matches_the_reference_renderer() {
    check_against_reference("scene05_bunny_200.txt", "a05", (0.8, 1.0));
}

/// The course's seven grading commands (at 200×200 to keep the test quick).
const GRADING: [(&str, &[&str]); 7] = [
    ("scene01_plane", &["-depth", "8", "18"]),
    ("scene02_cube", &["-depth", "8", "18"]),
    ("scene03_sphere", &["-depth", "8", "18"]),
    ("scene04_axes", &["-depth", "8", "18"]),
    ("scene05_bunny_200", &["-depth", "0.8", "1.0"]),
    ("scene06_bunny_1k", &["-depth", "8", "18", "-bounces", "4"]),
    ("scene07_arch", &["-depth", "8", "18", "-bounces", "4", "-shadows"]),
];

#[test]
fn drop_in_command_and_imported_case_give_identical_files() {
    for (scene, flags) in GRADING {
        let dir = tempfile::tempdir().unwrap();
        let input = scene_path(&format!("{scene}.txt"));
        let at = |name: &str| dir.path().join(name).to_str().unwrap().to_string();

        let mut course = vec![
            "mit6837",
            "-input",
            input.to_str().unwrap(),
            "-size",
            "200",
            "200",
            "--quiet",
        ];
        let (depth_min, depth_max) = (flags[1], flags[2]);
        let (output, normals, depth, exr) = (at("a.png"), at("an.png"), at("ad.png"), at("a.exr"));
        course.extend(["-output", &output, "-normals", &normals, "--exr", &exr]);
        course.extend(["-depth", depth_min, depth_max, &depth]);
        course.extend(&flags[3..]);
        goldray(&course);

        let toml = at("imported.toml");
        let mut import = vec![
            "import",
            input.to_str().unwrap(),
            "-o",
            &toml,
            "--size",
            "200",
            "200",
            "--normals",
        ];
        import.extend(["--depth", depth_min, depth_max]);
        let double_dash: Vec<String> = flags[3..]
            .iter()
            .map(|f| {
                if f.starts_with('-') {
                    format!("-{f}")
                } else {
                    f.to_string()
                }
            })
            .collect();
        import.extend(double_dash.iter().map(String::as_str));
        goldray(&import);
        let out = at("out");
        goldray(&["render", &toml, "--out", &out, "--quiet"]);

        for (course_file, case_file) in [
            ("a.exr", "imported.exr"),
            ("a.png", "imported.png"),
            ("an.png", "imported_normals.png"),
            ("ad.png", "imported_depth.png"),
        ] {
            let a = fs::read(dir.path().join(course_file)).unwrap();
            let b = fs::read(dir.path().join("out").join(case_file)).unwrap();
            // The files name their own source (the scene file, the TOML) and its hash: everything
            // else, every pixel byte and every setting, is the same.
            let made = |bytes: &[u8]| Provenance::from_bytes(bytes, course_file).unwrap().expect("stamped");
            let (course_made, case_made) = (made(&a), made(&b));
            assert_eq!(course_made.get(keys::CASE), Some(format!("{scene}.txt").as_str()));
            assert_eq!(case_made.get(keys::CASE), Some("imported.toml"));
            let settings = |p: &Provenance| -> Vec<(String, String)> {
                p.entries()
                    .filter(|(k, _)| ![keys::CASE, keys::CASE_HASH].contains(k))
                    .map(|(k, v)| (k.to_owned(), v.to_owned()))
                    .collect()
            };
            assert_eq!(settings(&course_made), settings(&case_made), "{scene}: {course_file}");
            assert!(
                strip(&a, Group::All).unwrap() == strip(&b, Group::All).unwrap(),
                "{scene}: {course_file} from `goldray mit6837` differs from {case_file} of the imported case"
            );
        }
    }
}

#[test]
fn the_course_command_line_rejects_what_the_course_binary_would() {
    let input = scene_path("scene01_plane.txt");
    let run = util::goldray;
    let unknown = run(&[
        "mit6837",
        "-input",
        input.to_str().unwrap(),
        "-output",
        "x.png",
        "-antialias",
    ]);
    assert!(!unknown.status.success());
    assert!(String::from_utf8_lossy(&unknown.stderr).contains("antialias"));
    let zero = run(&[
        "mit6837",
        "-input",
        input.to_str().unwrap(),
        "-output",
        "x.png",
        "-size",
        "0",
        "10",
    ]);
    // A bad command line exits 2, like clap's own errors.
    assert_eq!(zero.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&zero.stderr).contains("size 0 10"));
    let no_input = run(&["mit6837", "-output", "x.png"]);
    assert!(!no_input.status.success());
    let bad_depth = run(&[
        "mit6837",
        "-input",
        input.to_str().unwrap(),
        "-depth",
        "18",
        "8",
        "d.png",
    ]);
    assert_eq!(bad_depth.status.code(), Some(2));
    assert!(
        !Path::new("x.png").exists() && !Path::new("d.png").exists(),
        "failed commands write nothing"
    );
}

/// Scene 7's pictures (which look at two faces of the course's cube map) rendered with
/// `GOLDRAY_TEXEL_CACHE` set to `cache`, and how many faces the render decoded and read from the
/// cache (from `--stats-json`).
fn scene07_pictures(cache: &Path, out: &Path) -> (Vec<Vec<u8>>, [u64; 2]) {
    let scene = scene_path("scene07_arch.txt");
    let files = ["a07.png", "a07n.png", "a07d.png"].map(|name| out.join(name));
    let [color, normals, depth] = files.each_ref().map(|path| path.to_str().unwrap());
    let stats = out.join("stats.json");
    let arguments = [
        "mit6837",
        "-size",
        "200",
        "200",
        "-input",
        scene.to_str().unwrap(),
        "-output",
        color,
    ];
    let rendered = Command::new(env!("CARGO_BIN_EXE_goldray"))
        .env("GOLDRAY_TEXEL_CACHE", cache)
        .args(arguments)
        .args([
            "-normals", normals, "-depth", "8", "18", depth, "-bounces", "4", "-shadows", "--quiet",
        ])
        .args(["--stats-json", stats.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(rendered.status.success(), "{}", util::stderr(&rendered));
    let stats: serde_json::Value = serde_json::from_slice(&fs::read(stats).unwrap()).unwrap();
    let faces = ["decoded", "read_from_cache"].map(|key| stats["cube_map_faces"][key].as_u64().unwrap());
    (files.iter().map(|path| fs::read(path).unwrap()).collect(), faces)
}

#[test]
fn the_texel_cache_changes_no_byte_of_any_picture() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("texels");
    let (uncached, faces) = scene07_pictures(Path::new("off"), dir.path());
    assert_eq!(faces, [2, 0], "the scene sees two faces");
    assert!(!cache.exists());
    assert_eq!(
        scene07_pictures(&cache, dir.path()),
        (uncached.clone(), [2, 0]),
        "decoded and stored"
    );
    let entries: Vec<PathBuf> = fs::read_dir(&cache)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .collect();
    assert_eq!(entries.len(), 2, "an entry per face seen: {entries:?}");
    assert_eq!(
        scene07_pictures(&cache, dir.path()),
        (uncached.clone(), [0, 2]),
        "read from the cache"
    );
    let contents = |paths: &[PathBuf]| paths.iter().map(|path| fs::read(path).unwrap()).collect::<Vec<_>>();
    let stored = contents(&entries);
    for entry in &entries {
        let mut bytes = fs::read(entry).unwrap();
        let middle = bytes.len() / 2;
        bytes[middle] ^= 0x40;
        fs::write(entry, bytes).unwrap();
    }
    assert_eq!(
        scene07_pictures(&cache, dir.path()),
        (uncached, [2, 0]),
        "damaged entries decoded again"
    );
    assert_eq!(contents(&entries), stored, "and stored again whole");
}

#[test]
fn import_refuses_to_overwrite_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("mine.toml");
    fs::write(&target, "# my own notes\n").unwrap();
    let input = scene_path("scene02_cube.txt");
    let refused = Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(["import", input.to_str().unwrap(), "-o", target.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(1));
    assert_eq!(fs::read_to_string(&target).unwrap(), "# my own notes\n");
    goldray(&[
        "import",
        input.to_str().unwrap(),
        "-o",
        target.to_str().unwrap(),
        "--force",
    ]);
    assert!(fs::read_to_string(&target).unwrap().contains("profile = \"mit6837\""));
}
