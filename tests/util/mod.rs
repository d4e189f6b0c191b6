//! What the integration tests share: running the binary and finding the shipped cases. Each test
//! binary includes this module and uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use goldray::case::{Case, LoadOptions, load};

/// Runs the `goldray` binary with `args` and returns what it did, whatever the exit code.
pub fn goldray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(args)
        .output()
        .expect("the goldray binary runs")
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A file of the project, by its path from the root (`cases/jitter.toml`).
pub fn project_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// A shipped case file, by file name (`jitter.toml`).
pub fn shipped(file: &str) -> PathBuf {
    project_file("cases").join(file)
}

/// A shipped case, loaded, by name without the extension (`jitter`).
pub fn load_shipped(name: &str) -> Case {
    load(&shipped(&format!("{name}.toml")), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// `goldray render CASE --out OUT --threads THREADS --quiet EXTRA…`, which must succeed.
pub fn render_on_threads(case: &Path, out: &Path, threads: &str, extra: &[&str]) {
    let (case, out) = (case.to_str().expect("UTF-8 path"), out.to_str().expect("UTF-8 path"));
    let mut args = vec!["render", case, "--out", out, "--threads", threads, "--quiet"];
    args.extend(extra);
    let result = goldray(&args);
    assert!(result.status.success(), "{case}: {}", stderr(&result));
}
