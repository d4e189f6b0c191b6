//! Records the git commit goldray is built from, for the provenance every output carries
//! (`src/provenance`). It sets `GOLDRAY_GIT_COMMIT` for the compiler: the commit's hash, with
//! `+modified` when the sources that go into the binary differ from it, or empty when there is no
//! commit to name (a source archive, no `git` on the machine, goldray inside another project's
//! repository). A packager who knows the commit can set `GOLDRAY_GIT_COMMIT` in the environment;
//! it is then taken as given.

use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

/// What decides the binary: a change here, uncommitted, makes the commit `+modified`.
const SOURCES: [&str; 4] = ["src", "build.rs", "Cargo.toml", "Cargo.lock"];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=GOLDRAY_GIT_COMMIT");
    let commit = match env::var("GOLDRAY_GIT_COMMIT") {
        Ok(given) => given,
        Err(_) => from_git().unwrap_or_default(),
    };
    println!("cargo:rustc-env=GOLDRAY_GIT_COMMIT={}", commit.trim());
}

/// The checkout's commit, or `None` when goldray is not the top of a git work tree. Asks cargo
/// to run this again when `HEAD` moves (the `HEAD` file, the branch's ref, or the packed refs it
/// may live in) or when a source file changes.
fn from_git() -> Option<String> {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR")?);
    let top = git(&manifest, &["rev-parse", "--show-toplevel"])?;
    if Path::new(&top).canonicalize().ok()? != manifest.canonicalize().ok()? {
        return None;
    }
    let mut watched = vec!["HEAD".to_owned(), "packed-refs".to_owned()];
    watched.extend(git(&manifest, &["symbolic-ref", "-q", "HEAD"]));
    for name in watched {
        if let Some(path) = git(&manifest, &["rev-parse", "--git-path", &name]) {
            let path = manifest.join(path);
            if path.exists() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
    }
    for source in SOURCES {
        println!("cargo:rerun-if-changed={source}");
    }
    let hash = git(&manifest, &["rev-parse", "HEAD"])?;
    let mut status = vec!["--no-optional-locks", "status", "--porcelain", "--"];
    status.extend(SOURCES);
    let modified = git(&manifest, &status).is_none_or(|changes| !changes.is_empty());
    Some(if modified { format!("{hash}+modified") } else { hash })
}

/// `git ARGS` in `dir`: its trimmed output when it succeeds.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let output = Command::new("git").args(args).current_dir(dir).output().ok()?;
    if !output.status.success() {
        return None;
    }
    Some(String::from_utf8(output.stdout).ok()?.trim().to_owned())
}
