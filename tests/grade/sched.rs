//! The scheduler examples of docs/grading.md run as written: the Slurm script under a
//! stand-in `sbatch` that runs the array's tasks and then the dependent merge, and the scripts of
//! the Kubernetes manifest's containers with the environment Kubernetes gives them. Both grade the
//! small class and must produce the grades of one plain run.

use std::fs;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

use super::class::make_class;

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sched")
}

/// A folder to put first on PATH, holding `goldray` (the binary under test).
fn bin_dir(dir: &Path) -> PathBuf {
    let bin = dir.join("bin");
    fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_goldray"), bin.join("goldray")).unwrap();
    bin
}

fn path_with(bin: &Path) -> String {
    format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default())
}

/// `grades.csv` and `grades.json` of one plain run over `submissions` (`grades.json` names the
/// rubric, the submissions and the cache, so they are the scheduled run's).
fn plain_run(rubric: &Path, submissions: &Path, cache: &Path, dir: &Path) -> [Vec<u8>; 2] {
    let out = dir.join("plain");
    let status = Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(["grade", "--quiet", "--rubric"])
        .args([rubric, submissions])
        .arg("--out")
        .arg(&out)
        .arg("--cache")
        .arg(cache)
        .status()
        .unwrap();
    assert!(status.success());
    ["grades.csv", "grades.json"].map(|f| fs::read(out.join(f)).unwrap())
}

/// Stands in for Slurm's `sbatch`: an array job runs its tasks one after the other (with
/// `SLURM_ARRAY_TASK_ID` set), `--wrap` runs its command; every call is logged.
const FAKE_SBATCH: &str = r#"#!/usr/bin/env bash
set -euo pipefail
echo "sbatch $*" >> "$SBATCH_LOG"
array="" wrap="" args=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --array=*) array=${1#--array=} ;;
    --wrap) wrap=$2; shift ;;
    --*) ;;
    *) args+=("$1") ;;
  esac
  shift
done
if [[ -n $wrap ]]; then
  bash -c "$wrap" >&2
  echo 1002
  exit
fi
for k in $(seq "${array%-*}" "${array#*-}"); do
  SLURM_ARRAY_TASK_ID=$k SLURM_CPUS_PER_TASK=1 bash "${args[@]}" >&2
done
echo "1001;cluster"
"#;

#[test]
fn the_slurm_script_runs_the_shards_then_the_dependent_merge() {
    let class = make_class();
    let script = examples().join("grade-slurm.sh");
    assert!(Command::new("bash").arg("-n").arg(&script).status().unwrap().success());
    let bin = bin_dir(&class.dir);
    let sbatch = bin.join("sbatch");
    fs::write(&sbatch, FAKE_SBATCH).unwrap();
    fs::set_permissions(&sbatch, fs::Permissions::from_mode(0o755)).unwrap();
    let log = class.dir.join("sbatch.log");
    let out = class.dir.join("slurm");
    let run = Command::new("bash")
        .arg(&script)
        .args([&class.rubric, &class.submissions, &out])
        .arg("3")
        .env("PATH", path_with(&bin))
        .env("SBATCH_LOG", &log)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let calls = fs::read_to_string(&log).unwrap();
    assert!(calls.contains("--array=1-3"), "{calls}");
    assert!(
        calls.lines().last().unwrap().contains("--dependency=afterok:1001"),
        "the merge waits for the array: {calls}"
    );
    assert_eq!(stderr.matches("graded slice").count(), 3, "{stderr}");
    assert!(out.join("cache").is_dir(), "the cache was prepared");
    let expected = plain_run(
        &class.rubric.canonicalize().unwrap(),
        &class.submissions.canonicalize().unwrap(),
        &out.canonicalize().unwrap().join("cache"),
        &class.dir,
    );
    assert!(fs::read(out.join("grades.csv")).unwrap() == expected[0]);
    assert!(fs::read(out.join("grades.json")).unwrap() == expected[1]);
}

/// The shell scripts of the manifest's containers (each `args:` entry `- |`), in file order, with
/// the manifest's `completions` and `SHARDS`.
fn k8s_scripts(manifest: &str) -> (Vec<String>, Vec<usize>, Vec<usize>) {
    let lines: Vec<&str> = manifest.lines().collect();
    let mut scripts = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if line.trim() == "- |" {
            let indent = line.len() - line.trim_start().len();
            let body: Vec<&str> = lines[i + 1..]
                .iter()
                .take_while(|l| l.trim().is_empty() || l.len() - l.trim_start().len() > indent)
                .map(|l| l.trim_start())
                .collect();
            scripts.push(body.join("\n"));
        }
    }
    let numbers = |key: &str| -> Vec<usize> {
        lines
            .iter()
            .filter_map(|l| l.trim().strip_prefix(key))
            .map(|v| v.trim_matches(|c: char| !c.is_ascii_digit()).parse().unwrap())
            .collect()
    };
    (scripts, numbers("completions:"), numbers("- {name: SHARDS, value: "))
}

#[test]
fn the_kubernetes_jobs_scripts_prepare_grade_each_index_and_merge() {
    let class = make_class();
    let manifest = fs::read_to_string(examples().join("grade-k8s.yaml")).unwrap();
    let (scripts, completions, shards) = k8s_scripts(&manifest);
    assert_eq!(scripts.len(), 3, "prepare, grade, merge: {scripts:?}");
    assert_eq!(completions.len(), 1);
    assert!(
        shards.iter().all(|s| *s == completions[0]),
        "SHARDS {shards:?} must equal completions {completions:?}"
    );
    // The class laid out as the manifest expects it under $CLASS.
    let root = class.dir.join("volume");
    fs::create_dir_all(root.join("rubric")).unwrap();
    fs::copy(&class.rubric, root.join("rubric/rubric.toml")).unwrap();
    let status = Command::new("cp")
        .arg("-r")
        .arg(&class.submissions)
        .arg(root.join("submissions"))
        .status()
        .unwrap();
    assert!(status.success());
    let bin = bin_dir(&class.dir);
    let run = |script: &str, index: Option<usize>| {
        let mut command = Command::new("sh");
        command
            .args(["-c", script])
            .env("PATH", path_with(&bin))
            .env("CLASS", &root)
            .env("SHARDS", completions[0].to_string());
        if let Some(index) = index {
            command.env("JOB_COMPLETION_INDEX", index.to_string());
        }
        let output = command.output().unwrap();
        assert!(
            output.status.success(),
            "{script}\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    run(&scripts[0], None);
    for index in 0..completions[0] {
        run(&scripts[1], Some(index));
    }
    run(&scripts[2], None);
    let expected = plain_run(
        &root.join("rubric/rubric.toml"),
        &root.join("submissions"),
        &root.join("cache"),
        &class.dir,
    );
    let report = root.join("report");
    assert!(fs::read(report.join("grades.csv")).unwrap() == expected[0]);
    assert!(fs::read(report.join("grades.json")).unwrap() == expected[1]);
}
