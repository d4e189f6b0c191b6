//! Provenance end to end: what `goldray render` and `goldray mit6837` write into their EXRs and
//! PNGs (read back with the exr and png crates themselves, not goldray's reader), and what
//! `goldray diff` says about two files made differently.

mod util;

use std::collections::BTreeMap;
use std::fs;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use exr::meta::MetaData;
use exr::meta::attribute::AttributeValue;
use goldray::provenance::{ContentHash, Group, Provenance, build_commit, keys, strip};
use tempfile::TempDir;

use util::{goldray, project_file, render_on_threads, stderr};

/// A tiny case reading one mesh, so that the hash must cover an asset.
fn tiny_case(seed: u64) -> String {
    format!(
        "[render]\nsize = [12, 8]\nsamples = 4\nseed = {seed}\nshadows = true\nbounces = 1\n\n\
         [camera]\ncenter = [0, 0, 5]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 40\n\n\
         [[light]]\nkind = \"point\"\nposition = [1, 2, 4]\ncolor = [1, 1, 1]\nfalloff = 0.02\n\n\
         [[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.8\n\n\
         [[object]]\nkind = \"mesh\"\nobj = \"tri.obj\"\n"
    )
}

const TRIANGLE: &str = "v -2 -1 -1\nv 2 -1 -1\nv 0 2 -1\nf 1 2 3\n";

/// Writes `DIR/tiny.toml` (with `seed`) and `DIR/tri.obj`; returns the case file.
fn write_case(dir: &Path, seed: u64) -> PathBuf {
    fs::create_dir_all(dir).unwrap();
    fs::write(dir.join("tri.obj"), TRIANGLE).unwrap();
    let case = dir.join("tiny.toml");
    fs::write(&case, tiny_case(seed)).unwrap();
    case
}

/// Renders `case` into `out` on `threads` threads.
fn render(case: &Path, out: &Path, threads: &str) {
    render_on_threads(case, out, threads, &[]);
}

/// The EXR's `string` attributes as the exr crate reads them.
fn exr_attributes(path: &Path) -> BTreeMap<String, String> {
    let meta = MetaData::read_from_file(path, false).unwrap();
    let header = &meta.headers[0];
    header
        .own_attributes
        .other
        .iter()
        .chain(&header.shared_attributes.other)
        .filter_map(|(name, value)| match value {
            AttributeValue::Text(text) => Some((name.to_string(), text.to_string())),
            _ => None,
        })
        .collect()
}

/// The PNG's `tEXt` entries as the png crate reads them.
fn png_text(path: &Path) -> BTreeMap<String, String> {
    let bytes = fs::read(path).unwrap();
    let reader = png::Decoder::new(Cursor::new(bytes)).read_info().unwrap();
    reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect()
}

fn hash_of(files: &[&Path]) -> String {
    let mut hash = ContentHash::default();
    for file in files {
        hash.add(&fs::read(file).unwrap());
    }
    hash.finish()
}

#[test]
fn a_rendered_exr_and_png_carry_every_field() {
    let dir = TempDir::new().unwrap();
    let case = write_case(&dir.path().join("case"), 7);
    let out = dir.path().join("out");
    render(&case, &out, "1");

    let case_hash = hash_of(&[&case, &dir.path().join("case/tri.obj")]);
    let mut expected: BTreeMap<String, String> = [
        (keys::VERSION, env!("CARGO_PKG_VERSION")),
        (keys::CASE, "tiny.toml"),
        (keys::CASE_HASH, &case_hash),
        (keys::SIZE, "12x8"),
        (keys::SAMPLES, "4"),
        (keys::SEED, "7"),
        (keys::FILTER, "none"),
        (keys::BOUNCES, "1"),
        (keys::SHADOWS, "true"),
        (keys::PRECISION, "f32"),
        (keys::PROFILE, "native"),
        (keys::TONEMAP, "srgb"),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v.to_owned()))
    .collect();
    // The commit is there exactly when build.rs found one (a checkout with git).
    if let Some(commit) = build_commit(env!("GOLDRAY_GIT_COMMIT")) {
        expected.insert(keys::COMMIT.to_owned(), commit.to_owned());
    }
    // By default the files hold the stable group only: no time, threads or host.
    for (file, found) in [
        ("tiny.exr", exr_attributes(&out.join("tiny.exr"))),
        ("tiny.png", png_text(&out.join("tiny.png"))),
    ] {
        assert_eq!(found, expected, "{file}");
    }
    // `--record-run` adds the run group, and nothing else: without it the file is the default
    // file, byte for byte.
    let recorded = dir.path().join("recorded");
    render_on_threads(&case, &recorded, "1", &["--record-run"]);
    for (file, found) in [
        ("tiny.exr", exr_attributes(&recorded.join("tiny.exr"))),
        ("tiny.png", png_text(&recorded.join("tiny.png"))),
    ] {
        let mut found = found;
        let seconds = found
            .remove(keys::RUN_SECONDS)
            .unwrap_or_else(|| panic!("{file}: no render time"));
        assert!(seconds.parse::<f64>().is_ok_and(|s| s >= 0.0), "{file}: {seconds}");
        assert_eq!(found.remove(keys::RUN_THREADS).as_deref(), Some("1"), "{file}");
        assert_eq!(found.remove(keys::RUN_HOST), goldray::stats::this_host(), "{file}");
        assert_eq!(found, expected, "{file}");
        let (plain, with_run) = (
            fs::read(out.join(file)).unwrap(),
            fs::read(recorded.join(file)).unwrap(),
        );
        assert!(
            strip(&with_run, Group::Run).unwrap() == plain,
            "{file}: the run group is not all that differs"
        );
    }

    // The hash covers the mesh: changing only the mesh changes it.
    fs::write(
        dir.path().join("case/tri.obj"),
        TRIANGLE.replace("v 0 2 -1", "v 0 3 -1"),
    )
    .unwrap();
    render(&case, &out, "1");
    let rehashed = exr_attributes(&out.join("tiny.exr"))[keys::CASE_HASH].clone();
    assert_ne!(rehashed, case_hash);
    assert_eq!(rehashed, hash_of(&[&case, &dir.path().join("case/tri.obj")]));
}

/// `goldray diff` on the two files; returns its stdout.
fn diff(expected: &Path, actual: &Path) -> String {
    let result = goldray(&["diff", expected.to_str().unwrap(), actual.to_str().unwrap()]);
    assert!(matches!(result.status.code(), Some(0..=2)), "{}", stderr(&result));
    String::from_utf8_lossy(&result.stdout).into_owned()
}

#[test]
fn diff_names_a_changed_seed_before_its_verdict() {
    let dir = TempDir::new().unwrap();
    let (seven, eight) = (dir.path().join("seven"), dir.path().join("eight"));
    render(&write_case(&seven, 7), &seven.join("out"), "2");
    render(&write_case(&eight, 8), &eight.join("out"), "2");
    let hash = |dir: &Path| hash_of(&[&dir.join("tiny.toml"), &dir.join("tri.obj")])[..12].to_owned();
    for file in ["tiny.exr", "tiny.png"] {
        let report = diff(&seven.join("out").join(file), &eight.join("out").join(file));
        let first = report.lines().next().unwrap_or_default();
        assert_eq!(
            first,
            format!(
                "made differently: expected: case hash {}, seed 7, 4 spp; actual: case hash {}, seed 8, 4 spp",
                hash(&seven),
                hash(&eight)
            ),
            "{file}:\n{report}"
        );
        assert!(
            report.lines().nth(1).is_some_and(|l| l.contains(" against ")),
            "{report}"
        );
    }

    let json = goldray(&[
        "diff",
        seven.join("out/tiny.exr").to_str().unwrap(),
        eight.join("out/tiny.exr").to_str().unwrap(),
        "--json",
    ]);
    let text = String::from_utf8_lossy(&json.stdout);
    assert!(text.starts_with("{\n  \"verdict\""), "the verdict stays first:\n{text}");
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let provenance = &json["provenance"];
    assert_eq!(provenance["expected"][keys::SEED], "7");
    assert_eq!(provenance["actual"][keys::SEED], "8");
    assert!(
        provenance["made_differently"]
            .as_str()
            .is_some_and(|line| line.ends_with("seed 8, 4 spp")),
        "{provenance}"
    );
}

#[test]
fn diff_says_nothing_of_files_made_alike_and_names_one_without_provenance() {
    let dir = TempDir::new().unwrap();
    let case = write_case(&dir.path().join("case"), 7);
    let (one, two) = (dir.path().join("one"), dir.path().join("two"));
    render(&case, &one, "1");
    render(&case, &two, "2");
    let alike = diff(&one.join("tiny.exr"), &two.join("tiny.exr"));
    assert!(alike.starts_with("PASS"), "the thread count is no difference:\n{alike}");

    // A student's PNG: the same pixels, no text chunks.
    let student = dir.path().join("student.png");
    fs::write(
        &student,
        strip(&fs::read(one.join("tiny.png")).unwrap(), Group::All).unwrap(),
    )
    .unwrap();
    assert_eq!(Provenance::read(&student).unwrap(), None);
    let report = diff(&one.join("tiny.png"), &student);
    assert_eq!(
        report.lines().next(),
        Some("made differently: expected: tiny.toml, 12x8, seed 7, 4 spp; actual: no provenance"),
        "{report}"
    );
    assert!(report.lines().nth(1).is_some_and(|l| l.starts_with("PASS")), "{report}");
}

#[test]
fn course_outputs_carry_the_scene_and_the_course_settings() {
    let dir = TempDir::new().unwrap();
    let scene = project_file("cases/mit6837/scene01_plane.txt");
    let at = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let result = goldray(&[
        "mit6837",
        "-input",
        scene.to_str().unwrap(),
        "-size",
        "16",
        "12",
        "-shadows",
        "-jitter",
        "-output",
        &at("a.png"),
        "-depth",
        "8",
        "18",
        &at("ad.png"),
        "--exr",
        &at("a.exr"),
        "--quiet",
    ]);
    assert!(result.status.success(), "{}", stderr(&result));
    let expected_hash = hash_of(&[&scene]);
    for (file, found) in [
        ("a.exr", exr_attributes(&dir.path().join("a.exr"))),
        ("a.png", png_text(&dir.path().join("a.png"))),
        ("ad.png", png_text(&dir.path().join("ad.png"))),
    ] {
        for (key, value) in [
            (keys::CASE, "scene01_plane.txt"),
            (keys::CASE_HASH, expected_hash.as_str()),
            (keys::SIZE, "16x12"),
            (keys::SAMPLES, "16"),
            (keys::SHADOWS, "true"),
            (keys::BOUNCES, "0"),
            (keys::PROFILE, "mit6837"),
            (keys::TONEMAP, "clamp"),
        ] {
            assert_eq!(found.get(key).map(String::as_str), Some(value), "{file}: {key}");
        }
    }
}

#[test]
fn stamping_replaces_and_stripping_restores_the_encoded_bytes() {
    let film = goldray::film::Film::new(5, 40);
    let exr = goldray::film::encode_exr(&film).unwrap();
    let png = goldray::film::encode_png(&goldray::film::color_image(&film, goldray::film::Tonemap::Srgb)).unwrap();
    let made = Provenance::this_build()
        .with(keys::CASE, "naïve.toml")
        .with_run(1.5, 3, Some("host"));
    for (name, bytes) in [("exr", &exr), ("png", &png)] {
        let stamped = made.stamp(bytes, name).unwrap();
        assert_eq!(
            Provenance::from_bytes(&stamped, name).unwrap().as_ref(),
            Some(&made),
            "{name}"
        );
        // Stamping again replaces rather than adds.
        let other = Provenance::this_build().with(keys::SEED, 3);
        let restamped = other.stamp(&stamped, name).unwrap();
        assert_eq!(Provenance::from_bytes(&restamped, name).unwrap(), Some(other), "{name}");
        assert_eq!(&strip(&stamped, Group::All).unwrap(), bytes, "{name}");
        let stable = strip(&stamped, Group::Run).unwrap();
        let kept = Provenance::from_bytes(&stable, name).unwrap().unwrap();
        assert_eq!(kept.get(keys::RUN_THREADS), None, "{name}");
        assert_eq!(kept.get(keys::CASE), Some("naïve.toml"), "{name}");
        // Damaged files are errors, never panics.
        for cut in (0..stamped.len()).step_by(7) {
            let _ = Provenance::from_bytes(&stamped[..cut], name);
            let _ = strip(&stamped[..cut], Group::Run);
        }
    }
    let film_back = goldray::film::decode_exr(&made.stamp(&exr, "exr").unwrap()).unwrap();
    assert_eq!(film_back, film);
}

#[test]
fn a_render_hashes_the_case_text_it_parsed_even_if_the_file_changes_after() {
    let dir = TempDir::new().unwrap();
    let case_path = write_case(dir.path(), 7);
    let loaded = goldray::case::load_keeping_source(&case_path, &Default::default()).unwrap();
    let as_loaded = hash_of(&[&case_path, &dir.path().join("tri.obj")]);
    // Another seed on disk after the load: the render in hand is still of seed 7.
    fs::write(&case_path, tiny_case(8)).unwrap();
    let hash = |provenance: Provenance| provenance.get(keys::CASE_HASH).map(str::to_owned);
    let kept = goldray::pipeline::provenance_of(&loaded.case, &loaded.source).unwrap();
    assert_eq!(hash(kept), Some(as_loaded.clone()));
    let read_again = goldray::pipeline::provenance(&loaded.case).unwrap();
    assert_ne!(
        hash(read_again),
        Some(as_loaded),
        "reading the file again sees the new seed"
    );
}
