//! `goldray review` end to end, on a small project in a temporary folder: one shipped case with
//! its golden, the case's light made 3% brighter. The golden check runs as the suite runs it
//! (insta's binary snapshot under the tolerance comparator, with insta's own file handling) in a
//! child process of this test binary, where `INSTA_UPDATE` can be set; it fails and leaves
//! insta's pending snapshot. Then the page is opened in headless Chromium and driven over the
//! DevTools protocol: a real click on Accept or Reject (`clicks`), the inspector's controls used
//! with the mouse and keyboard (`controls`); the files are compared byte for byte with what
//! insta's own accept code writes from the same pending snapshot.

// Shared with tests/grade.rs and tests/diagnose.rs.
#[allow(dead_code)]
#[path = "grade/chromium.rs"]
mod chromium;
// The golden suite's comparator; the review tests judge by insta's outcome alone, not by the
// judgement the suite reports from.
#[allow(dead_code)]
#[path = "golden/comparator.rs"]
mod comparator;
mod util;

// This test's own parts, under tests/review/ (a file right under tests/ would be a test of its own).
#[path = "review/cdp.rs"]
mod cdp;
#[path = "review/clicks.rs"]
mod clicks;
#[path = "review/controls.rs"]
mod controls;
#[path = "review/served.rs"]
mod served;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use goldray::case::{LoadOptions, load};
use goldray::film::encode_exr;
use goldray::pipeline::{provenance, render_case};

use comparator::ToleranceComparator;
use served::Served;
use util::{goldray, shipped, stderr};

const CASE: &str = "spheres_shadows";
/// The page is ready once its load handler has counted what loaded and drawn the cases.
const READY: &str = "document.body.hasAttribute('data-cases-loaded')";
const PROJECT_VAR: &str = "GOLDRAY_REVIEW_PROJECT";

/// What the comparator's messages call a path.
pub fn shown(path: &Path) -> String {
    path.display().to_string()
}

/// A project holding `CASE` and its golden, blessed here by the golden check (so that it carries
/// provenance, as a golden blessed today does), then the case's light made 3% brighter: every lit
/// pixel moves by more than the 0.01 the case allows.
fn changed_project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    fs::create_dir_all(dir.path().join("cases")).unwrap();
    fs::copy(
        shipped(&format!("{CASE}.toml")),
        dir.path().join("cases").join(format!("{CASE}.toml")),
    )
    .unwrap();
    let blessed = golden_check(dir.path(), "always");
    assert!(blessed.status.success(), "{}", stderr(&blessed));
    brighten(dir.path(), "0.9", "0.927");
    dir
}

/// Replaces the light's colour `from` with `to` in the project's case file.
fn brighten(root: &Path, from: &str, to: &str) {
    let case = root.join("cases").join(format!("{CASE}.toml"));
    let text = fs::read_to_string(&case).unwrap();
    let light = format!("color = [{from}, {from}, {from}]");
    assert_eq!(
        text.matches(&light).count(),
        1,
        "the case has one light of colour {from}"
    );
    fs::write(&case, text.replace(&light, &format!("color = [{to}, {to}, {to}]"))).unwrap();
}

/// The golden check of the project's case, in a child process with `INSTA_UPDATE=update`.
fn golden_check(root: &Path, update: &str) -> Output {
    Command::new(std::env::current_exe().unwrap())
        .args([
            "golden_check_in_child",
            "--exact",
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(PROJECT_VAR, root)
        .env("INSTA_UPDATE", update)
        .env("INSTA_WORKSPACE_ROOT", env!("CARGO_MANIFEST_DIR"))
        .env_remove("CI")
        .env_remove("INSTA_FORCE_PASS")
        .output()
        .expect("the test binary runs")
}

/// The golden suite's check of one case, in the project named by `GOLDRAY_REVIEW_PROJECT`: the
/// same render, provenance, comparator and insta settings as `tests/golden.rs`.
#[test]
#[ignore = "a helper, not a test: the review tests run it in a child process on their own project"]
fn golden_check_in_child() {
    let root = PathBuf::from(std::env::var_os(PROJECT_VAR).expect("run by the review tests, which set the project"));
    let case = load(
        &root.join("cases").join(format!("{CASE}.toml")),
        &LoadOptions::default(),
    )
    .unwrap();
    let film = render_case(&case).unwrap();
    let exr = provenance(&case)
        .unwrap()
        .stamp(&encode_exr(&film).unwrap(), "the render")
        .unwrap();
    let golden_exr = root.join("golden").join(format!("{CASE}.snap.exr"));
    let comparator = ToleranceComparator::new(CASE, &case.tolerance, &golden_exr, &root.join("target/golden-diffs"));
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path(root.join("golden"));
    settings.set_prepend_module_to_snapshot(false);
    settings.set_omit_expression(true);
    settings.set_description(case.description.clone().unwrap_or_default());
    settings.set_comparator(Box::new(comparator));
    let name = format!("{CASE}.exr");
    settings.bind(|| insta::assert_binary_snapshot!(name.as_str(), exr));
}

/// Fails and leaves insta's pending snapshot.
fn fail_golden_check(root: &Path) {
    let output = golden_check(root, "new");
    assert!(!output.status.success(), "the changed case fails its golden");
    assert!(pending_files(root).len() == 2, "{}", stderr(&output));
}

fn pending_files(root: &Path) -> Vec<PathBuf> {
    let golden = root.join("golden");
    [format!("{CASE}.snap.new"), format!("{CASE}.snap.new.exr")]
        .into_iter()
        .map(|name| golden.join(name))
        .filter(|path| path.exists())
        .collect()
}

/// What `cargo insta accept` writes from the project's pending snapshot: insta's own code
/// (`Snapshot::from_file` of the `.snap.new`, then `save` to the `.snap`, as cargo-insta's
/// `SnapshotContainer::commit` does), run on copies in another folder.
fn insta_accepted(root: &Path) -> BTreeMap<String, Vec<u8>> {
    let scratch = tempfile::tempdir().unwrap();
    for path in pending_files(root) {
        fs::copy(&path, scratch.path().join(path.file_name().unwrap())).unwrap();
    }
    let pending = insta::Snapshot::from_file(&scratch.path().join(format!("{CASE}.snap.new"))).unwrap();
    pending.save(&scratch.path().join(format!("{CASE}.snap"))).unwrap();
    [format!("{CASE}.snap"), format!("{CASE}.snap.exr")]
        .into_iter()
        .map(|name| {
            let bytes = fs::read(scratch.path().join(&name)).unwrap();
            (format!("golden/{name}"), bytes)
        })
        .collect()
}

/// Every file of the project but the suite's pictures under `target/`, by relative path.
fn files(root: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(root).unwrap().display().to_string();
            if path.is_dir() {
                if relative != "target" {
                    walk(root, &path, out);
                }
            } else {
                out.insert(relative, fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(root, root, &mut out);
    out
}

/// After an accept: the pending files are gone, the golden is what insta writes, and nothing
/// else changed; and the golden check passes again.
fn assert_accepted_as_insta_would(root: &Path, before: &BTreeMap<String, Vec<u8>>, insta: &BTreeMap<String, Vec<u8>>) {
    let mut expected = before.clone();
    expected.retain(|path, _| !path.contains(".snap.new"));
    expected.extend(insta.clone());
    let after = files(root);
    assert_eq!(
        after.keys().collect::<Vec<_>>(),
        expected.keys().collect::<Vec<_>>(),
        "the files of the project"
    );
    for (path, bytes) in &expected {
        assert!(after[path] == *bytes, "{path} differs from what insta writes");
    }
    let output = golden_check(root, "no");
    assert!(
        output.status.success(),
        "the golden passes once accepted: {}",
        stderr(&output)
    );
}

/// A method, a path and headers.
type Request = (&'static str, String, Vec<(&'static str, String)>);

/// A project whose pending snapshot is a copy of the golden, with the header insta writes.
fn project_with_copied_pending() -> tempfile::TempDir {
    let project = changed_project();
    let golden = project.path().join("golden");
    let header = fs::read_to_string(golden.join(format!("{CASE}.snap"))).unwrap();
    let pending = header.replacen(
        "source: tests/review.rs\n",
        "source: tests/review.rs\nassertion_line: 75\n",
        1,
    );
    assert_ne!(pending, header);
    fs::write(golden.join(format!("{CASE}.snap.new")), pending).unwrap();
    fs::copy(
        golden.join(format!("{CASE}.snap.exr")),
        golden.join(format!("{CASE}.snap.new.exr")),
    )
    .unwrap();
    project
}

#[test]
fn the_server_refuses_other_paths_actions_and_origins() {
    let project = project_with_copied_pending();
    let root = project.path();
    let before = files(root);
    let served = Served::start(root);
    let own = served.url.trim_end_matches('/').to_owned();
    let accept = format!("/accept/{CASE}");
    let origin = |value: &str| vec![("Origin", value.to_owned())];
    let refused: Vec<Request> = vec![
        ("GET", "/../../etc/passwd".into(), vec![]),
        ("GET", "/img/../../../../etc/passwd".into(), vec![]),
        ("GET", "/data/%2e%2e/%2e%2e/etc/passwd".into(), vec![]),
        ("POST", "/accept/..%2F..%2Fetc%2Fpasswd".into(), origin(&own)),
        ("POST", "/accept/../../etc/passwd".into(), origin(&own)),
        ("POST", "/accept/not_pending".into(), origin(&own)),
        ("POST", format!("/delete/{CASE}"), origin(&own)),
        ("POST", accept.clone(), origin("http://evil.example")),
        ("POST", accept.clone(), vec![]),
        (
            "GET",
            "/".into(),
            vec![("Host", format!("evil.example:{}", served.port()))],
        ),
        (
            "GET",
            format!("/data/{CASE}.js"),
            vec![("Sec-Fetch-Site", "cross-site".to_owned())],
        ),
        ("DELETE", accept.clone(), origin(&own)),
    ];
    for (method, path, headers) in refused {
        let (status, body) = served.request(method, &path, &headers);
        assert!(
            (400..500).contains(&status),
            "{method} {path} {headers:?} was answered {status}: {body}"
        );
        assert!(!body.contains("root:"), "{body}");
    }
    assert_eq!(files(root), before, "a refused request changes nothing");
    // What the page itself loads is served.
    assert_eq!(served.request("GET", &format!("/data/{CASE}.js"), &[]).0, 200);
    assert_eq!(served.request("GET", &format!("/img/{CASE}.heatmap.png"), &[]).0, 200);
}

fn review(root: &Path, args: &[&str]) -> Output {
    let mut all = vec!["review", "--project", root.to_str().unwrap()];
    all.extend(args);
    goldray(&all)
}

#[test]
fn list_accept_reject_and_accept_all_from_the_command_line() {
    let project = changed_project();
    let root = project.path();
    let golden = files(root);
    fail_golden_check(root);

    let listed = review(root, &["--list"]);
    let stdout = String::from_utf8_lossy(&listed.stdout).into_owned();
    assert!(
        listed.status.success() && stdout.starts_with(&format!("{CASE}\tFAIL\t")),
        "{stdout}"
    );
    assert!(stdout.contains("made differently: golden: case hash"), "{stdout}");

    let typo = review(root, &["--accept", CASE, "spheres_shadow"]);
    assert_eq!(typo.status.code(), Some(1));
    assert!(stderr(&typo).contains("`spheres_shadow` is not a pending golden (pending: spheres_shadows)"));
    assert_eq!(pending_files(root).len(), 2, "a typo decides nothing");

    assert!(review(root, &["--reject", CASE]).status.success());
    assert_eq!(files(root), golden, "rejected: the golden as it was, nothing pending");

    fail_golden_check(root);
    let (insta, before) = (insta_accepted(root), files(root));
    let accepted = review(root, &["--accept", CASE]);
    assert!(accepted.status.success(), "{}", stderr(&accepted));
    assert_accepted_as_insta_would(root, &before, &insta);
    let nothing = review(root, &["--list"]);
    assert!(nothing.stdout.is_empty() && stderr(&nothing).contains("no pending golden"));

    brighten(root, "0.927", "0.955");
    fail_golden_check(root);
    let (insta, before) = (insta_accepted(root), files(root));
    assert!(review(root, &["--accept-all"]).status.success());
    assert_accepted_as_insta_would(root, &before, &insta);
}

/// Pixels of the red-to-yellow heat scale or the failing magenta: what tells a reviewer where
/// the pictures differ.
fn heat_pixels(shot: &goldray::rgb_image::RgbImage) -> usize {
    shot.pixels()
        .filter(|p| {
            let [r, g, b] = p.0;
            r > 200 && b < 60 && g > 40 || r > 200 && g < 40 && b > 200
        })
        .count()
}

#[test]
fn the_static_page_and_the_diff_page_show_the_case_without_buttons() {
    let project = changed_project();
    let root = project.path();
    fail_golden_check(root);
    // A pending render that does not decode is named on the page; the other case is still shown.
    let golden = root.join("golden");
    fs::copy(golden.join(format!("{CASE}.snap.new")), golden.join("broken.snap.new")).unwrap();
    fs::write(golden.join("broken.snap.new.exr"), b"not an EXR").unwrap();
    let before = files(root);
    let out = tempfile::tempdir().unwrap();
    let written = review(root, &["--static", out.path().to_str().unwrap()]);
    assert!(written.status.success(), "{}", stderr(&written));
    assert_eq!(files(root), before, "--static writes nothing into the project");
    let page = out.path().join("index.html");
    let dom = chromium::dump_dom(&page);
    for expected in [
        "data-cases-loaded=\"1\"",
        "data-images-loaded=\"3\"",
        "data-panes-drawn=\"2\"",
        "read-only copy",
        "cannot show broken: ",
    ] {
        assert!(dom.contains(expected), "the static page lacks `{expected}`:\n{dom}");
    }
    assert!(!dom.contains("<button"), "no buttons");
    assert!(
        !dom.contains(&root.display().to_string()),
        "no machine paths on the page"
    );
    let shot = chromium::screenshot(&page, 1280, 1000, &out.path().join("review.png"));
    assert!(heat_pixels(&shot) > 2000, "the heatmap shows on screen at once");

    let html = out.path().join("diff.html");
    let golden = root.join("golden");
    let diffed = goldray(&[
        "diff",
        golden.join(format!("{CASE}.snap.exr")).to_str().unwrap(),
        golden.join(format!("{CASE}.snap.new.exr")).to_str().unwrap(),
        "--html",
        html.to_str().unwrap(),
    ]);
    assert_eq!(diffed.status.code(), Some(2), "the diff fails as the suite did");
    let dom = chromium::dump_dom(&html);
    for expected in [
        "data-cases-loaded=\"1\"",
        "data-images-loaded=\"3\"",
        "broke fail_fraction",
    ] {
        assert!(dom.contains(expected), "the diff page lacks `{expected}`:\n{dom}");
    }
    assert_eq!(
        fs::read_dir(out.path()).unwrap().count(),
        5,
        "index.html, img/, data/, review.png, diff.html"
    );
}
