//! `goldray run` end to end: a C++ "student renderer" built with `--build` and run through a small
//! rubric; hostile programs (an endless loop, a fork bomb, 20 GB of memory, a 10 GB file, endless
//! output, writes outside the working folder, reads of another student's folder, a connection to
//! the host, a process left behind), each contained and reported while the other render is
//! still done; crashes and exit codes recorded with their stderr. Where the machine lacks a
//! protection, the tests check that the report says so instead.

#[path = "run/autograde.rs"]
mod autograde;
#[path = "run/class.rs"]
mod class;
#[path = "run/hostile.rs"]
mod hostile;
#[path = "run/student.rs"]
mod student;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use goldray::sandbox::{CommandRecord, Outcome, RunRecord};

/// A fresh folder for one test, under the target folder (not `/tmp`, which the sandbox hides:
/// there only Landlock stands between a program and these files).
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("run-tests").join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

pub fn project_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// A rubric of two course renders at 16×16 (scene01: a plane and a sphere; scene02: a mesh, with
/// bounces and shadows), colour, normals and depth each, with `limits` as its `[limits]` table.
pub fn write_rubric(dir: &Path, limits: &str) -> PathBuf {
    let scene = |name: &str| project_file(&format!("cases/mit6837/{name}")).display().to_string();
    let mut text = format!(
        "[render.scene01]\nscene = \"{}\"\nsize = [16, 16]\n\n\
         [render.scene02]\nscene = \"{}\"\nsize = [16, 12]\nbounces = 2\nshadows = true\n\n",
        scene("scene01_plane.txt"),
        scene("scene02_cube.txt")
    );
    for n in ["01", "02"] {
        text += &format!(
            "[image.\"a{n}.png\"]\nrender = \"scene{n}\"\n\
             [image.\"a{n}n.png\"]\nrender = \"scene{n}\"\noutput = \"normals\"\n\
             [image.\"a{n}d.png\"]\nrender = \"scene{n}\"\noutput = \"depth\"\ndepth = [8, 18]\n"
        );
    }
    text += &format!("\n[limits]\n{limits}\n");
    let path = dir.join("rubric.toml");
    fs::write(&path, text).expect("rubric written");
    path
}

pub fn goldray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(args)
        .output()
        .expect("the goldray binary runs")
}

/// `goldray run` that must succeed, and the run.json it wrote.
pub fn run_ok(args: &[&str], out: &Path) -> (RunRecord, String) {
    let output = goldray(args);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "goldray {args:?} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let record = RunRecord::read(out).unwrap_or_else(|| panic!("no readable run.json in {}", out.display()));
    (record, stdout)
}

pub fn command<'a>(record: &'a RunRecord, name: &str) -> &'a CommandRecord {
    record
        .commands
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no command {name} in {record:#?}"))
}

pub fn outcome<'a>(record: &'a RunRecord, name: &str) -> &'a Outcome {
    let command = command(record, name);
    command
        .outcome
        .as_ref()
        .unwrap_or_else(|| panic!("{name} did not run: {:?}", command.not_run))
}

/// The files of `dir`, sorted by name.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .expect("listable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Every process of the machine whose command line contains `token`.
pub fn processes_with(token: &str) -> Vec<String> {
    let mut found = Vec::new();
    for entry in fs::read_dir("/proc").expect("/proc").flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if !name.chars().all(|c| c.is_ascii_digit()) {
            continue;
        }
        if let Ok(bytes) = fs::read(entry.path().join("cmdline")) {
            let line = String::from_utf8_lossy(&bytes).replace('\0', " ");
            if line.contains(token) {
                found.push(format!("{name}: {line}"));
            }
        }
    }
    found
}

/// Compiles a test program with `g++ -O1` once per test binary.
pub fn compiled(source: &str, name: &str, cell: &'static OnceLock<PathBuf>) -> &'static Path {
    cell.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join("run-tests")
            .join(format!("bin-{}", std::process::id()));
        fs::create_dir_all(&dir).expect("bin folder");
        let binary = dir.join(name);
        let status = Command::new("g++")
            .args(["-O1", "-o"])
            .arg(&binary)
            .arg(project_file(source))
            .status()
            .expect("g++ runs (the tests need a C++ compiler)");
        assert!(status.success(), "g++ could not build {source}");
        binary
    })
}
