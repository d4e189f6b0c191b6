//! The case-file contract seen from outside: a full case parses to exactly the expected values,
//! and every class of mistake is reported at its line and column with the offending value and a
//! way out.

// A test crate root resolves modules beside itself, where cargo would take them for test crates.
#[path = "case_errors/keys.rs"]
mod keys;
#[path = "case_errors/numbers.rs"]
mod numbers;
#[path = "case_errors/objects.rs"]
mod objects;
#[path = "case_errors/valid.rs"]
mod valid;

use std::fs;
use std::path::{Path, PathBuf};

use goldray::case::{Case, CaseError, LoadOptions, parse};

const CAMERA: &str = "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 30\n";

fn try_parse(source: &str) -> Result<Case, CaseError> {
    parse(source, Path::new("cases/x.toml"), &LoadOptions::default())
}

/// The error message for `source`, which must be rejected.
fn error(source: &str) -> String {
    match try_parse(source) {
        Ok(case) => panic!("expected an error, got {case:?}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `message` starts with the location and contains every fragment.
fn assert_error(message: &str, location: &str, fragments: &[&str]) {
    assert!(
        message.starts_with(&format!("cases/x.toml:{location}: ")),
        "expected location {location} in: {message}"
    );
    for fragment in fragments {
        assert!(message.contains(fragment), "expected {fragment:?} in: {message}");
    }
}

fn write(dir: &Path, relative: &str, contents: &str) -> PathBuf {
    let path = dir.join(relative);
    fs::create_dir_all(path.parent().unwrap()).unwrap();
    fs::write(&path, contents).unwrap();
    path
}
