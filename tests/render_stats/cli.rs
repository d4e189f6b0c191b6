//! `--stats` and `--stats-json` from the command line, on every shipped case and on the course
//! command.

use std::fs;
use std::path::{Path, PathBuf};

use goldray::case::{LoadOptions, load};
use goldray::options::Filter;
use serde_json::Value;

use crate::util::{goldray, render_on_threads, shipped as shipped_case, stderr};

fn read_json(path: &Path) -> Value {
    serde_json::from_slice(&fs::read(path).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn count(json: &Value, kind: &str) -> u64 {
    json["rays"][kind]
        .as_u64()
        .unwrap_or_else(|| panic!("rays.{kind} in {json}"))
}

#[test]
fn stats_print_a_table_and_write_json_without_changing_the_exr() {
    let dir = tempfile::tempdir().unwrap();
    let case = shipped_case("mirrors.toml");
    let case = case.to_str().unwrap();
    let json_path = dir.path().join("stats.json");
    let mut exrs = Vec::new();
    for (run, flags) in [
        ("plain", vec![]),
        ("stats", vec!["--stats", "--stats-json", json_path.to_str().unwrap()]),
    ] {
        let out = dir.path().join(run);
        let mut args = vec!["render", case, "--out", out.to_str().unwrap(), "--quiet"];
        args.extend(flags);
        let result = goldray(&args);
        assert!(result.status.success(), "{}", stderr(&result));
        let table = stderr(&result);
        if run == "plain" {
            assert!(table.is_empty(), "nothing on stderr without --stats: {table}");
        } else {
            for expected in [
                "Statistics for mirrors (200×150",
                "parse",
                "build scene",
                "render",
                "write outputs",
                "Mrays/s",
                "camera",
                "shadow",
                "reflection",
                "Peak resident memory",
            ] {
                assert!(table.contains(expected), "{expected:?} missing from\n{table}");
            }
        }
        exrs.push(fs::read(out.join("mirrors.exr")).unwrap());
    }
    assert!(exrs[0] == exrs[1], "statistics changed the EXR");
    let json = read_json(&json_path);
    assert_eq!(json["case"], "mirrors");
    assert_eq!(json["host"].as_str().map(str::to_owned), goldray::stats::this_host());
    assert_eq!((count(&json, "camera"), count(&json, "aov")), (200 * 150, 0));
    let sum: u64 = ["camera", "aov", "shadow", "reflection"]
        .iter()
        .map(|kind| count(&json, kind))
        .sum();
    assert_eq!(count(&json, "total"), sum);
    assert!(count(&json, "shadow") > 0 && count(&json, "reflection") > 0);
    assert!(json["seconds"]["render"].as_f64().unwrap() > 0.0);
    assert!(json["cube_map_faces"].is_null(), "no cube map, no faces");
    assert!(json["mrays_per_second"]["total"].as_f64().unwrap() > 0.0);
    if cfg!(target_os = "linux") {
        assert!(json["peak_memory_bytes"].as_u64().unwrap() > 1 << 20);
    }
}

#[test]
fn json_counts_are_the_same_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let case = shipped_case("jitter_filter.toml");
    let stats: Vec<Value> = ["1", "2"]
        .into_iter()
        .map(|threads| {
            let json = dir.path().join(format!("{threads}.json"));
            let out = dir.path().join(threads);
            render_on_threads(&case, &out, threads, &["--stats-json", json.to_str().unwrap()]);
            read_json(&json)
        })
        .collect();
    assert_eq!(stats[0]["rays"], stats[1]["rays"]);
    assert_eq!(
        (stats[0]["threads"].as_u64(), stats[1]["threads"].as_u64()),
        (Some(1), Some(2))
    );
}

/// The "done when": statistics work on every shipped case, with camera and AOV ray
/// counts that follow from the case's own settings.
#[test]
fn every_shipped_case_reports_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<PathBuf> = fs::read_dir(shipped_case(""))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 13, "{cases:?}");
    for path in cases {
        let case = load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let json_path = dir.path().join(format!("{}.json", case.name));
        let result = goldray(&[
            "render",
            path.to_str().unwrap(),
            "--out",
            dir.path().to_str().unwrap(),
            "--quiet",
            "--stats",
            "--stats-json",
            json_path.to_str().unwrap(),
        ]);
        assert!(result.status.success(), "{}: {}", case.name, stderr(&result));
        assert!(
            stderr(&result).contains(&format!("Statistics for {}", case.name)),
            "{}",
            stderr(&result)
        );
        let json = read_json(&json_path);
        let settings = &case.render;
        let pixels = u64::from(settings.trace.width) * u64::from(settings.trace.height);
        let subpixels = if settings.trace.filter == Filter::Gaussian {
            9
        } else {
            1
        };
        let averaged = settings.trace.samples > 1 || settings.trace.filter == Filter::Gaussian;
        assert_eq!(
            count(&json, "camera"),
            pixels * subpixels * u64::from(settings.trace.samples),
            "{}",
            case.name
        );
        assert_eq!(count(&json, "aov"), if averaged { pixels } else { 0 }, "{}", case.name);
        assert_eq!(
            count(&json, "shadow") > 0,
            settings.trace.shadows && !case.lights.is_empty(),
            "{}",
            case.name
        );
        if settings.trace.bounces == 0 {
            assert_eq!(count(&json, "reflection"), 0, "{}", case.name);
        }
        for mesh in json["meshes"].as_array().unwrap() {
            let bvh = &mesh["bvh"];
            assert_eq!(bvh["primitives"], mesh["triangles"], "{}", case.name);
            // An 8-wide tree: each node holds two to eight children (a lone leaf is one node's only child).
            let (nodes, leaves) = (bvh["nodes"].as_u64().unwrap(), bvh["leaves"].as_u64().unwrap());
            assert!(
                nodes > 0 && nodes <= leaves && 7 * nodes + 1 >= leaves,
                "{}: {nodes} nodes, {leaves} leaves",
                case.name
            );
        }
    }
}

#[test]
fn the_course_command_takes_the_stats_flags_too() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("two_lights.txt");
    fs::write(
        &scene,
        "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\n\
         Lights { numLights 2\n\
           PointLight { position 0 5 5 color 1 1 1 falloff 0.1 }\n\
           PointLight { position -5 0 5 color 1 1 1 falloff 0.1 } }\n\
         Background { color 0 0 0 ambientLight 0.1 0.1 0.1 }\n\
         Materials { numMaterials 1 PhongMaterial { diffuseColor 1 0 0 } }\n\
         Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n",
    )
    .unwrap();
    let json_path = dir.path().join("stats.json");
    let png = dir.path().join("out.png");
    let normals = dir.path().join("normals.png");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "mit6837",
            "-input",
            scene.to_str().unwrap(),
            "-output",
            png.to_str().unwrap(),
            "-size",
            "10",
            "10",
            "-shadows",
            "-jitter",
            "-stats",
            "-stats-json",
            json_path.to_str().unwrap(),
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let result = goldray(&args);
        assert!(result.status.success(), "{}", stderr(&result));
        assert!(
            stderr(&result).contains("Statistics for two_lights (10×10"),
            "{}",
            stderr(&result)
        );
        read_json(&json_path)
    };
    let json = run(&[]);
    assert_eq!(
        (count(&json, "camera"), count(&json, "aov")),
        (1600, 0),
        "16 jittered samples per pixel, no AOV written"
    );
    let shadow = count(&json, "shadow");
    assert!(
        shadow > 0 && shadow.is_multiple_of(2),
        "two shadow rays per hit: {shadow}"
    );
    let json = run(&["-normals", normals.to_str().unwrap()]);
    assert_eq!(
        (count(&json, "camera"), count(&json, "aov")),
        (1600, 100),
        "the normals image needs the AOV rays"
    );
    assert_eq!(count(&json, "shadow"), shadow);
}

#[test]
fn an_unwritable_stats_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("not_a_dir");
    fs::write(&blocker, b"").unwrap();
    let json_path = blocker.join("stats.json");
    let result = goldray(&[
        "render",
        shipped_case("raw_matrix.toml").to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
        "--quiet",
        "--stats-json",
        json_path.to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(1));
    assert!(stderr(&result).contains("stats.json"), "{}", stderr(&result));
}
