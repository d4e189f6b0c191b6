//! `goldray tradeoff`: that the sweep measures what it claims (errors fall with samples at the
//! rate stratification promises, reflections converge with bounces, rays are exact), that its
//! report reads back, and that the command runs on every shipped case and refuses bad input
//! without writing anything. Images are tiny and timing runs single (`min_time` 0): speed is
//! measured in benchmarks, never asserted here.

mod util;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use goldray::case::{Case, LoadOptions, parse};
use goldray::options::{Filter, Precision};
use goldray::progress::Silent;
use goldray::tradeoff::{
    CSV_COLUMNS, CSV_FILE, MARKDOWN_FILE, Metric, PLOT_FILE, PLOT_HEIGHT, PLOT_WIDTH, SweepPlan, Tradeoff,
    TradeoffOptions, measure_tradeoff, pareto_front, run_tradeoff,
};
use util::{goldray, shipped, stderr};

fn case(toml: &str) -> Case {
    parse(toml, Path::new("tradeoff_test.toml"), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn plan(samples: &[u32], reference_samples: u32) -> SweepPlan {
    SweepPlan {
        samples: samples.to_vec(),
        filters: vec![Filter::None],
        precisions: vec![Precision::F32],
        reference_samples,
        min_time: Duration::ZERO,
        ..SweepPlan::default()
    }
}

fn measure(case: &Case, plan: SweepPlan) -> Tradeoff {
    let options = TradeoffOptions {
        plan,
        ..TradeoffOptions::new("unused")
    };
    measure_tradeoff(case, &options, &Silent).unwrap_or_else(|e| panic!("{e}"))
}

/// Thin dark shapes with sharp edges on a bright background, flat-lit: nearly all the error is
/// on edges, where stratified jitter should beat independent samples.
const EDGES: &str = r#"
[render]
size = [24, 24]
seed = 3

[camera]
center = [0, 0, 10]
direction = [0, 0, -1]
up = [0, 1, 0]
fov = 25

[background]
color = [0.9, 0.9, 0.9]
ambient = [1, 1, 1]

[materials.ink]
diffuse = [0.05, 0.05, 0.2]

[[object]]
kind = "sphere"
center = [-1.2, 0.8, 0]
radius = 0.9
material = "ink"

[[object]]
kind = "triangle"
vertices = [[-2.5, -2, 0], [2.5, -1.6, 0], [2.4, -1.2, 0]]
material = "ink"

[[object]]
kind = "triangle"
vertices = [[0.2, -1, 0], [2.2, 2, 0], [1.9, 2.05, 0]]
material = "ink"
"#;

#[test]
fn error_falls_with_samples_faster_than_one_over_root_n_on_edges() {
    let samples = [4, 16, 64, 256];
    let t = measure(&case(EDGES), plan(&samples, 2304));
    let rmse: Vec<f64> = samples
        .iter()
        .map(|&n| {
            t.measurements
                .iter()
                .find(|m| m.in_grid && m.setting.samples == n)
                .unwrap()
                .errors
                .rmse
        })
        .collect();
    assert!(
        rmse.windows(2).all(|w| w[1] < w[0]),
        "RMSE falls with every step: {rmse:?}"
    );
    let flips: Vec<f64> = samples
        .iter()
        .map(|&n| {
            t.measurements
                .iter()
                .find(|m| m.in_grid && m.setting.samples == n)
                .unwrap()
                .errors
                .flip
        })
        .collect();
    assert!(flips[3] < flips[0], "FLIP falls too: {flips:?}");
    // Least-squares slope of ln(RMSE) against ln(samples). Independent random samples give −½;
    // stratified jitter on edges about −¾.
    let xs: Vec<f64> = samples.iter().map(|&n| f64::from(n).ln()).collect();
    let ys: Vec<f64> = rmse.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / 4.0, ys.iter().sum::<f64>() / 4.0);
    let slope = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum::<f64>()
        / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
    assert!(
        slope < -0.6,
        "stratified jitter converges faster than 1/√n on edges: slope {slope:.3}, RMSE {rmse:?}"
    );
}

/// A camera between two parallel mirrors: every ray bounces between them forever, each bounce
/// adding half as much as the one before, so the picture converges with depth everywhere.
const MIRRORS: &str = r#"
[render]
size = [32, 24]

[camera]
center = [0, 0, 0]
direction = [0, 0, -1]
up = [0, 1, 0]
fov = 60

[background]
color = [0.2, 0.3, 0.5]
ambient = [0.3, 0.3, 0.3]

[[light]]
kind = "directional"
direction = [0.3, -1, -0.5]
color = [0.8, 0.8, 0.8]

[materials.mirror]
diffuse = [0.3, 0.25, 0.2]
specular = [0.5, 0.5, 0.5]
shininess = 10

[[object]]
kind = "plane"
normal = [0, 1, 0]
offset = -1
material = "mirror"

[[object]]
kind = "plane"
normal = [0, -1, 0]
offset = -1
material = "mirror"
"#;

#[test]
fn reflections_converge_with_bounces_and_the_bounce_sweep_stops() {
    let cap = 30;
    let t = measure(
        &case(MIRRORS),
        SweepPlan {
            max_bounces: cap,
            ..plan(&[1], 4)
        },
    );
    let mut sweep: Vec<_> = t.measurements.iter().filter(|m| m.in_bounce_sweep).collect();
    sweep.sort_by_key(|m| m.setting.bounces);
    let bounces: Vec<u32> = sweep.iter().map(|m| m.setting.bounces).collect();
    assert_eq!(
        bounces,
        (0..=t.bounces.last).collect::<Vec<_>>(),
        "every depth from 0, once"
    );
    assert!(t.bounces.settled, "the picture settles: {:?}", t.bounces);
    assert!(
        t.bounces.last < cap && t.bounces.last >= 5,
        "a geometric series of ½ needs several bounces: {:?}",
        t.bounces
    );
    assert!(t.bounces.last_change <= t.bounces.threshold);
    let rmse: Vec<f64> = sweep.iter().map(|m| m.errors.rmse).collect();
    let max: Vec<f64> = sweep.iter().map(|m| m.errors.max).collect();
    assert!(
        rmse.windows(2).all(|w| w[1] <= w[0]),
        "RMSE never grows with depth: {rmse:?}"
    );
    assert!(max.windows(2).all(|w| w[1] <= w[0]), "nor the largest error: {max:?}");
    assert!(
        rmse[0] > 10.0 * rmse[rmse.len() - 1],
        "deep enough is much better than none: {rmse:?}"
    );
    assert_eq!(
        t.reference.bounces, t.bounces.last,
        "the reference is as deep as the sweep went"
    );
    assert!(
        t.measurements
            .iter()
            .filter(|m| m.in_grid)
            .all(|m| m.setting.bounces == t.bounces.enough())
    );
    let reflections: Vec<u64> = sweep.iter().map(|m| m.rays.reflection).collect();
    assert!(
        reflections.windows(2).all(|w| w[1] > w[0]),
        "each bounce traces more reflection rays: {reflections:?}"
    );
}

/// A plane filling the whole view under one light: every sample hits it and casts one shadow ray.
const FLOOR: &str = r#"
[render]
size = [12, 10]
shadows = true

[camera]
center = [0, 5, 0]
direction = [0, -1, 0]
up = [0, 0, -1]
fov = 60

[[light]]
kind = "point"
position = [0, 3, 0]
color = [1, 1, 1]
falloff = 0.1

[[object]]
kind = "plane"
normal = [0, 1, 0]
offset = 0
"#;

#[test]
fn rays_grow_linearly_with_samples_exactly() {
    let t = measure(
        &case(FLOOR),
        SweepPlan {
            filters: vec![Filter::None, Filter::Gaussian],
            precisions: Precision::ALL.to_vec(),
            ..plan(&[1, 4, 16, 64], 256)
        },
    );
    let pixels = 12 * 10;
    let grid: Vec<_> = t.measurements.iter().filter(|m| m.in_grid).collect();
    assert_eq!(grid.len(), 16);
    for m in grid {
        let s = m.setting;
        let per_sample = u64::from(s.samples) * if s.filter == Filter::Gaussian { 9 } else { 1 };
        // One camera ray per sample, one shadow ray per hit (all of them), and one extra ray
        // through each pixel's centre for depth and normals unless its one sample is that ray.
        let aov = if per_sample == 1 { 0 } else { pixels };
        assert_eq!(m.rays.camera, per_sample * pixels, "{}", s.label());
        assert_eq!(m.rays.shadow, per_sample * pixels, "{}", s.label());
        assert_eq!(m.rays.total(), 2 * per_sample * pixels + aov, "{}", s.label());
    }
}

fn tiny_options(out: &Path) -> TradeoffOptions {
    TradeoffOptions {
        plan: SweepPlan {
            filters: vec![Filter::None, Filter::Gaussian],
            size: Some((24, 20)),
            max_bounces: 3,
            ..plan(&[1, 4], 16)
        },
        metric: Metric::Flip,
        target_flip: Some(0.5),
        ..TradeoffOptions::new(out)
    }
}

#[test]
fn the_report_reads_back_with_every_setting_and_the_plot_decodes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let (t, written) =
        run_tradeoff(&shipped("mirrors.toml"), &tiny_options(&out), &Silent).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        written,
        [out.join(CSV_FILE), out.join(MARKDOWN_FILE), out.join(PLOT_FILE)]
    );

    let csv = fs::read_to_string(out.join(CSV_FILE)).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap().split(',').collect::<Vec<_>>(), CSV_COLUMNS);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), t.measurements.len());
    let column = |name: &str| CSV_COLUMNS.iter().position(|c| *c == name).unwrap();
    let number = |row: &[&str], name: &str| {
        row[column(name)]
            .parse::<f64>()
            .unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    let mut points = Vec::new();
    for (row, m) in rows.iter().zip(&t.measurements) {
        assert_eq!(row.len(), CSV_COLUMNS.len(), "{row:?}");
        assert_eq!(row[column("setting")], m.setting.label());
        assert_eq!(number(row, "samples"), f64::from(m.setting.samples));
        assert_eq!(number(row, "rays"), m.rays.total() as f64);
        assert_eq!(number(row, "flip"), m.errors.flip, "full precision");
        assert!(number(row, "seconds") > 0.0 && number(row, "rmse") >= 0.0 && number(row, "max_error") >= 0.0);
        assert!(["grid", "bounces", "grid+bounces"].contains(&row[column("sweep")]));
        points.push((number(row, "seconds"), number(row, "flip")));
    }
    let front: Vec<bool> = rows.iter().map(|r| r[column("pareto")].parse().unwrap()).collect();
    assert_eq!(
        front,
        pareto_front(&points),
        "the pareto column is the front of the CSV's own numbers by --metric"
    );
    let expected_grid = 4; // samples 1, 4 × filters none, gaussian
    assert_eq!(
        rows.iter().filter(|r| r[column("sweep")].starts_with("grid")).count(),
        expected_grid
    );

    let markdown = fs::read_to_string(out.join(MARKDOWN_FILE)).unwrap();
    assert!(markdown.contains("# Speed and accuracy: mirrors"), "{markdown}");
    assert!(markdown.contains(&t.measurements[0].setting.label()));
    assert!(
        markdown.contains("**Target:**") && markdown.contains("FLIP mean ≤ 0.5"),
        "{markdown}"
    );
    assert!(markdown.contains("](tradeoff.png)"));

    let plot = util::read_png(&out.join(PLOT_FILE));
    assert_eq!((plot.width(), plot.height()), (PLOT_WIDTH, PLOT_HEIGHT));
    let colours: std::collections::HashSet<_> = plot.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 20,
        "the plot has curves, text and a legend, not a blank page"
    );

    // A second run replaces its own report; a file goldray did not write is refused untouched.
    run_tradeoff(&shipped("mirrors.toml"), &tiny_options(&out), &Silent).unwrap_or_else(|e| panic!("{e}"));
    fs::write(out.join(MARKDOWN_FILE), "# my notes\n").unwrap();
    let refused = run_tradeoff(&shipped("mirrors.toml"), &tiny_options(&out), &Silent).unwrap_err();
    assert!(refused.to_string().contains("--force"), "{refused}");
    assert_eq!(fs::read_to_string(out.join(MARKDOWN_FILE)).unwrap(), "# my notes\n");
    run_tradeoff(
        &shipped("mirrors.toml"),
        &TradeoffOptions {
            force: true,
            ..tiny_options(&out)
        },
        &Silent,
    )
    .unwrap();
    assert!(
        fs::read_to_string(out.join(MARKDOWN_FILE))
            .unwrap()
            .contains("Speed and accuracy")
    );
}

#[test]
fn the_target_is_the_fastest_setting_that_meets_it_or_a_clear_no() {
    let options = |target| TradeoffOptions {
        plan: SweepPlan {
            size: Some((16, 16)),
            ..plan(&[1, 4, 16], 64)
        },
        target_flip: Some(target),
        ..TradeoffOptions::new("unused")
    };
    let all = measure_tradeoff(&case(EDGES), &options(1.0), &Silent).unwrap();
    let chosen = all.target.unwrap().chosen.expect("every setting meets FLIP ≤ 1");
    let fastest = all.measurements.iter().map(|m| m.seconds).fold(f64::MAX, f64::min);
    assert_eq!(all.measurements[chosen].seconds, fastest);
    let none = measure_tradeoff(&case(EDGES), &options(0.0), &Silent).unwrap();
    assert_eq!(none.target.unwrap().chosen, None);
    let sentence = none.target_sentence().unwrap();
    assert!(sentence.starts_with("no setting reached FLIP mean ≤ 0;"), "{sentence}");
}

const QUICK: [&str; 12] = [
    "--size",
    "24x20",
    "--samples",
    "1,4",
    "--reference-samples",
    "16",
    "--max-bounces",
    "3",
    "--min-time",
    "0",
    "--quiet",
    "--force",
];

#[test]
fn the_command_runs_on_every_shipped_case() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<PathBuf> = fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("cases"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 10, "{cases:?}");
    // All at once, one thread each: most of each run is starting up and loading, which two cores
    // overlap well.
    let runs: Vec<(String, PathBuf, std::process::Child)> = cases
        .iter()
        .map(|path| {
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            let out = dir.path().join(&name);
            let child = Command::new(env!("CARGO_BIN_EXE_goldray"))
                .args([
                    "tradeoff",
                    path.to_str().unwrap(),
                    "--out",
                    out.to_str().unwrap(),
                    "--target-flip",
                    "0.1",
                ])
                .args(QUICK)
                .args(["--threads", "1"])
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("the goldray binary runs");
            (name, out, child)
        })
        .collect();
    for (name, out, child) in runs {
        let result = child.wait_with_output().unwrap();
        assert!(result.status.success(), "{name}: {}", stderr(&result));
        let stdout = String::from_utf8_lossy(&result.stdout);
        assert!(
            stdout.starts_with("target: "),
            "{name}: --quiet still answers the target: {stdout}"
        );
        for file in [CSV_FILE, MARKDOWN_FILE, PLOT_FILE] {
            assert!(out.join(file).is_file(), "{name}: {file}");
        }
        let rows = fs::read_to_string(out.join(CSV_FILE)).unwrap().lines().count() - 1;
        // 1, 4 spp × none, gaussian × f32, f64, plus the bounce sweep's settings not in the grid.
        assert!(rows >= 8, "{name}: {rows} settings");
    }
}

#[test]
fn bad_input_is_a_clear_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let jitter = shipped("jitter.toml");
    let jitter = jitter.to_str().unwrap();
    let out_arg = out.to_str().unwrap();
    let cases: [(&[&str], i32, &str); 9] = [
        (
            &["tradeoff", "no/such/case.toml", "--out", out_arg],
            1,
            "no/such/case.toml",
        ),
        (
            &["tradeoff", jitter, "--out", out_arg, "--samples", "1,3"],
            2,
            "perfect square",
        ),
        (
            &["tradeoff", jitter, "--out", out_arg, "--size", "24"],
            2,
            "WIDTHxHEIGHT",
        ),
        (
            &["tradeoff", jitter, "--out", out_arg, "--target-flip", "2"],
            2,
            "from 0 to 1",
        ),
        (
            &["tradeoff", jitter, "--out", out_arg, "--filters", "box"],
            2,
            "none or gaussian",
        ),
        (
            &["tradeoff", jitter, "--out", out_arg, "--precisions", "f16"],
            2,
            "f32 or f64",
        ),
        (&["tradeoff", jitter, "--out", out_arg, "--threads", "0"], 2, "threads"),
        (
            &["tradeoff", jitter, "--out", out_arg, "--max-bounces", "2000"],
            2,
            "max-bounces",
        ),
        (
            &[
                "tradeoff",
                jitter,
                "--out",
                out_arg,
                "--samples",
                "1,64",
                "--reference-samples",
                "64",
            ],
            1,
            "more samples than every setting",
        ),
    ];
    for (args, code, message) in cases {
        let result = goldray(args);
        assert_eq!(result.status.code(), Some(code), "{args:?}: {}", stderr(&result));
        assert!(stderr(&result).contains(message), "{args:?}: {}", stderr(&result));
        assert!(!out.exists(), "{args:?} wrote {out:?}");
    }

    fs::create_dir(&out).unwrap();
    fs::write(out.join(CSV_FILE), "name,score\nada,10\n").unwrap();
    let mut args = vec!["tradeoff", jitter, "--out", out_arg];
    args.extend(&QUICK[..QUICK.len() - 1]); // everything but --force
    let refused = goldray(&args);
    assert_eq!(refused.status.code(), Some(1));
    assert!(
        stderr(&refused).contains("not written by goldray tradeoff; pass --force"),
        "{}",
        stderr(&refused)
    );
    assert_eq!(fs::read_to_string(out.join(CSV_FILE)).unwrap(), "name,score\nada,10\n");
    assert_eq!(fs::read_dir(&out).unwrap().count(), 1, "nothing else written");
}

/// When stderr is a log rather than a terminal, a long sweep still says what it is doing: one
/// line per setting and one for the reference; `--quiet` silences them.
#[test]
fn progress_is_a_line_per_setting_when_stderr_is_not_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let case = shipped("mirrors.toml");
    let args = |out: &str| -> Vec<String> {
        let mut args: Vec<String> = ["tradeoff", case.to_str().unwrap(), "--out", out]
            .iter()
            .map(|s| s.to_string())
            .collect();
        args.extend(QUICK.iter().filter(|a| **a != "--quiet").map(|s| s.to_string()));
        args
    };
    let out = dir.path().join("talking");
    let talking = goldray(
        &args(out.to_str().unwrap())
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(talking.status.success(), "{}", stderr(&talking));
    let log = stderr(&talking);
    let rows = fs::read_to_string(out.join(CSV_FILE)).unwrap().lines().count() - 1;
    assert!(log.lines().any(|l| l.starts_with("reference (16 spp)")), "{log}");
    // Setting labels read like `4spp gaussian 1b f32`.
    let setting_lines = log
        .lines()
        .filter(|l| l.contains("spp ") && (l.ends_with(" f32") || l.ends_with(" f64")))
        .count();
    assert!(setting_lines >= rows, "one line per setting ({rows}):\n{log}");

    let quiet_out = dir.path().join("quiet");
    let mut quiet_args = args(quiet_out.to_str().unwrap());
    quiet_args.push("--quiet".to_owned());
    let quiet = goldray(&quiet_args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(quiet.status.success());
    assert!(stderr(&quiet).is_empty(), "{}", stderr(&quiet));
}
