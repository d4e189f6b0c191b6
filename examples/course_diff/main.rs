//! Differential test of `goldray mit6837` against the course's reference renderer
//! (docs/differential-testing.md).
//!
//! Each seed names one random valid scene (`generate.rs`). Both binaries render it twice, as
//! the course grades: plain, and with `-shadows -bounces N`; each run writes the colour, normals
//! and depth images. An image passes when at least 99.5% of its pixels have every channel
//! within 2/255 of the reference's. The course binary is not part of the project: its path
//! comes from `GOLDRAY_COURSE_BINARY` (or `--reference`).
//!
//! ```text
//! cargo build --release --bin goldray --example course_diff
//! GOLDRAY_COURSE_BINARY=/path/to/a2 target/release/examples/course_diff --seeds 1-600
//! target/release/examples/course_diff --write-scenes DIR --seeds 1-50    # scenes only
//! ```
//!
//! Exit code 0 when every image passes, 1 when one fails or a binary fails, 2 for bad usage.

mod generate;
mod stability;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use clap::Parser;
use goldray::case::AssignmentOptions;
use goldray::rgb_image::RgbImage;

#[derive(Parser)]
#[command(about = "Render random course scenes with goldray and the course binary and compare the images")]
struct Args {
    /// Seeds to run, as FIRST-LAST (inclusive).
    #[arg(long, default_value = "1-600", value_parser = parse_seeds)]
    seeds: (u64, u64),
    /// Only write the scenes (seed-N.txt) into this directory, e.g. for a fuzzing corpus.
    #[arg(long)]
    write_scenes: Option<PathBuf>,
    /// The course binary; defaults to $GOLDRAY_COURSE_BINARY.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// The goldray binary; defaults to the one built beside this example.
    #[arg(long)]
    goldray: Option<PathBuf>,
    /// Scenes, images and report.tsv go here; the images of passing runs are deleted.
    #[arg(long, default_value = "target/course_diff")]
    work: PathBuf,
    /// A pixel agrees when every channel is within this many 8-bit steps.
    #[arg(long, default_value_t = 2)]
    tolerance: u8,
    /// An image passes when at least this fraction of its pixels agree.
    #[arg(long, default_value_t = 0.995)]
    threshold: f64,
    /// Instead of random scenes, the course's seven scenes with its grading commands (800×800).
    #[arg(long)]
    course_scenes: bool,
    /// Every Nth seed also checks that the reference ignores -jitter and -filter (0: never).
    #[arg(long, default_value_t = 25)]
    check_ignored_flags_every: u64,
}

fn parse_seeds(text: &str) -> Result<(u64, u64), String> {
    let (first, last) = text.split_once('-').ok_or("expected FIRST-LAST, e.g. 1-600")?;
    let first: u64 = first.parse().map_err(|e| format!("{first}: {e}"))?;
    let last: u64 = last.parse().map_err(|e| format!("{last}: {e}"))?;
    if first > last {
        return Err(format!("{first} > {last}"));
    }
    Ok((first, last))
}

const KINDS: [&str; 3] = ["colour", "normals", "depth"];

/// One rendering of a scene: its name and the flags it adds to the course's command line.
struct Run {
    name: String,
    flags: Vec<String>,
}

/// How one image compares with the reference's.
struct Verdict {
    seed: u64,
    run: String,
    kind: usize,
    agree: f64,
    max_difference: u8,
    /// For a failing image: how many of its differing pixels are ill-conditioned.
    unstable: Option<usize>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    if let Some(dir) = &args.write_scenes {
        return match write_scenes(dir, args.seeds) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => fail(&format!("{}: {e}", dir.display())),
        };
    }
    let Some(reference) = args
        .reference
        .clone()
        .or_else(|| std::env::var_os("GOLDRAY_COURSE_BINARY").map(PathBuf::from))
    else {
        eprintln!("set GOLDRAY_COURSE_BINARY (or --reference) to the course's reference binary");
        return ExitCode::from(2);
    };
    let goldray = args.goldray.clone().unwrap_or_else(sibling_goldray);
    for (what, path) in [("reference", &reference), ("goldray", &goldray)] {
        if !path.is_file() {
            eprintln!("the {what} binary {} does not exist", path.display());
            return ExitCode::from(2);
        }
    }
    let result = if args.course_scenes {
        course_scenes(&args, repo, &reference, &goldray)
    } else {
        run(&args, repo, &reference, &goldray)
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => fail(&e),
    }
}

fn fail(message: &str) -> ExitCode {
    eprintln!("error: {message}");
    ExitCode::from(1)
}

/// `target/release/goldray` for `target/release/examples/course_diff`.
fn sibling_goldray() -> PathBuf {
    let exe = std::env::current_exe().unwrap_or_default();
    let dir = exe.parent().and_then(Path::parent).unwrap_or(Path::new("."));
    dir.join(format!("goldray{}", std::env::consts::EXE_SUFFIX))
}

fn write_scenes(dir: &Path, (first, last): (u64, u64)) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for seed in first..=last {
        std::fs::write(dir.join(format!("seed-{seed}.txt")), generate::scene(seed).text)?;
    }
    Ok(())
}

/// Renders and compares every seed; `Ok(false)` when an image failed.
fn run(args: &Args, repo: &Path, reference: &Path, goldray: &Path) -> Result<bool, String> {
    let work = &args.work;
    std::fs::create_dir_all(work).map_err(|e| format!("{}: {e}", work.display()))?;
    // The scenes name `models/…` and `tex/church` beside themselves, as the course's do.
    for (link, target) in [("models", "cases/mit6837/models"), ("tex", "cases/mit6837/tex")] {
        let link = work.join(link);
        if std::fs::symlink_metadata(&link).is_err() {
            symlink(&repo.join(target), &link).map_err(|e| format!("{}: {e}", link.display()))?;
        }
    }
    let start = Instant::now();
    let (first, last) = args.seeds;
    let mut verdicts = Vec::new();
    let mut failures = Vec::new();
    let mut ignored_flags = (0, 0);
    for seed in first..=last {
        let scene = generate::scene(seed);
        let file = work.join(format!("seed-{seed}.txt"));
        std::fs::write(&file, &scene.text).map_err(|e| format!("{}: {e}", file.display()))?;
        let runs = [
            Run {
                name: "plain".to_owned(),
                flags: Vec::new(),
            },
            Run {
                name: format!("shadows-bounces{}", scene.bounces),
                flags: vec!["-shadows".to_owned(), "-bounces".to_owned(), scene.bounces.to_string()],
            },
        ];
        for run in &runs {
            let dir = work.join(format!("seed-{seed}-{}", run.name));
            let common = common_flags(&scene, &file);
            let quiet = ["--threads", "1", "--quiet"];
            let ours = render(goldray, &["mit6837"], &common, &run.flags, &dir.join("goldray"), &quiet);
            let theirs = render(reference, &[], &common, &run.flags, &dir.join("reference"), &[]);
            // A binary that fails fails the run: the scene is valid for the course.
            let (ours, theirs) = match (ours, theirs) {
                (Ok(ours), Ok(theirs)) => (ours, theirs),
                (ours, theirs) => {
                    for (who, result) in [("goldray", ours.err()), ("reference", theirs.err())] {
                        if let Some(e) = result {
                            failures.push(format!("seed {seed} {}: {who} failed: {e}", run.name));
                        }
                    }
                    continue;
                }
            };
            let mut passed = true;
            for kind in 0..3 {
                let context = |e: String| format!("seed {seed} {} {}: {e}", run.name, KINDS[kind]);
                let (verdict, off) = compare(&ours[kind], &theirs[kind], args.tolerance).map_err(context)?;
                let mut verdict = Verdict {
                    seed,
                    run: run.name.clone(),
                    kind,
                    ..verdict
                };
                if verdict.agree < args.threshold {
                    passed = false;
                    let options = course_options(&scene, &run.flags);
                    let own = load(&ours[kind]).map_err(context)?;
                    let unstable = stability::unstable_pixels(&scene.text, &file, &options, kind, &own, args.tolerance)
                        .map_err(context)?;
                    let ill = off.iter().filter(|p| unstable.contains(p)).count();
                    verdict.unstable = Some(ill);
                    failures.push(format!(
                        "seed {seed} {} {}: {:.4}% of pixels within {}/255; {ill} of the {} differing pixels \
                         are ill-conditioned (goldray's own picture changes there when the camera moves by \
                         1e-5 of its distance)",
                        run.name,
                        KINDS[kind],
                        100.0 * verdict.agree,
                        args.tolerance,
                        off.len(),
                    ));
                }
                verdicts.push(verdict);
            }
            if args.check_ignored_flags_every > 0 && seed % args.check_ignored_flags_every == 0 && run.flags.is_empty()
            {
                let flags = ["-jitter".to_owned(), "-filter".to_owned()];
                let again = render(
                    reference,
                    &[],
                    &common,
                    &flags,
                    &dir.join("reference-jitter-filter"),
                    &[],
                )
                .map_err(|e| format!("seed {seed}: reference with -jitter -filter: {e}"))?;
                let same = (0..3).all(|k| std::fs::read(&again[k]).ok() == std::fs::read(&theirs[k]).ok());
                ignored_flags.0 += usize::from(same);
                ignored_flags.1 += 1;
            }
            if passed {
                let _ = std::fs::remove_dir_all(&dir);
            }
        }
        if (seed - first + 1) % 50 == 0 {
            eprintln!(
                "{} scenes, {} failing images, {:.0?}",
                seed - first + 1,
                failures.len(),
                start.elapsed()
            );
        }
    }
    let report = work.join("report.tsv");
    std::fs::write(&report, tsv(&verdicts)).map_err(|e| format!("{}: {e}", report.display()))?;
    for failure in &failures {
        println!("FAIL {failure}");
    }
    print!("{}", summary(args, &verdicts, ignored_flags, start.elapsed()));
    println!("per-image figures: {}", report.display());
    Ok(failures.is_empty())
}

/// The course's grading commands (its `generate_images.sh`): scene, `-depth` range, flags.
const COURSE_SCENES: [(&str, (f64, f64), &[&str]); 7] = [
    ("scene01_plane.txt", (8.0, 18.0), &[]),
    ("scene02_cube.txt", (8.0, 18.0), &[]),
    ("scene03_sphere.txt", (8.0, 18.0), &[]),
    ("scene04_axes.txt", (8.0, 18.0), &[]),
    ("scene05_bunny_200.txt", (0.8, 1.0), &[]),
    ("scene06_bunny_1k.txt", (8.0, 18.0), &["-bounces", "4"]),
    ("scene07_arch.txt", (8.0, 18.0), &["-bounces", "4", "-shadows"]),
];

/// Renders the course's own scenes as it grades them and compares every image.
fn course_scenes(args: &Args, repo: &Path, reference: &Path, goldray: &Path) -> Result<bool, String> {
    let mut verdicts = Vec::new();
    let mut passed = true;
    for (i, (scene, depth, flags)) in COURSE_SCENES.iter().enumerate() {
        let file = repo.join("cases/mit6837").join(scene);
        let common = vec![
            "-size".to_owned(),
            "800".to_owned(),
            "800".to_owned(),
            "-input".to_owned(),
            file.display().to_string(),
            "-depth".to_owned(),
            depth.0.to_string(),
            depth.1.to_string(),
        ];
        let flags: Vec<String> = flags.iter().map(|f| f.to_string()).collect();
        let dir = args.work.join(scene.trim_end_matches(".txt"));
        let quiet = ["--threads", "1", "--quiet"];
        let ours = render(goldray, &["mit6837"], &common, &flags, &dir.join("goldray"), &quiet)?;
        let theirs = render(reference, &[], &common, &flags, &dir.join("reference"), &[])?;
        for kind in 0..3 {
            let (verdict, _) = compare(&ours[kind], &theirs[kind], args.tolerance)?;
            let off = ((1.0 - verdict.agree) * 640_000.0).round();
            println!(
                "{scene:22} {:8} {:.4}% within {}/255 ({off} pixels off, largest difference {})",
                KINDS[kind],
                100.0 * verdict.agree,
                args.tolerance,
                verdict.max_difference
            );
            passed &= verdict.agree >= args.threshold;
            verdicts.push(Verdict {
                seed: i as u64 + 1,
                run: scene.to_string(),
                kind,
                ..verdict
            });
        }
    }
    let report = args.work.join("course_scenes.tsv");
    std::fs::write(&report, tsv(&verdicts)).map_err(|e| format!("{}: {e}", report.display()))?;
    Ok(passed)
}

#[cfg(unix)]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    std::os::unix::fs::symlink(target, link)
}

#[cfg(not(unix))]
fn symlink(target: &Path, link: &Path) -> std::io::Result<()> {
    copy_dir(target, link)
}

#[cfg(not(unix))]
fn copy_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), target)?;
        }
    }
    Ok(())
}

/// `-size`, `-input` and the depth range, as both binaries take them.
fn common_flags(scene: &generate::Scene, file: &Path) -> Vec<String> {
    vec![
        "-size".to_owned(),
        scene.width.to_string(),
        scene.height.to_string(),
        "-input".to_owned(),
        file.display().to_string(),
        "-depth".to_owned(),
        scene.depth.0.to_string(),
        scene.depth.1.to_string(),
    ]
}

/// The settings `common_flags` and a run's flags give, for rendering through the library.
fn course_options(scene: &generate::Scene, flags: &[String]) -> AssignmentOptions {
    AssignmentOptions {
        width: scene.width,
        height: scene.height,
        bounces: if flags.is_empty() { 0 } else { scene.bounces },
        shadows: !flags.is_empty(),
        depth_range: Some(scene.depth),
        normals: true,
        ..AssignmentOptions::default()
    }
}

/// Runs one binary into `dir`; returns the colour, normals and depth images' paths.
fn render(
    binary: &Path,
    command: &[&str],
    common: &[String],
    flags: &[String],
    dir: &Path,
    extra: &[&str],
) -> Result<[PathBuf; 3], String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let paths = ["colour.png", "normals.png", "depth.png"].map(|name| dir.join(name));
    let mut cmd = Command::new(binary);
    cmd.args(command)
        .args(&common[..common.len() - 3])
        .args(["-output"])
        .arg(&paths[0])
        .args(["-normals"])
        .arg(&paths[1])
        .args(&common[common.len() - 3..])
        .arg(&paths[2])
        .args(flags)
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let output = wait_with_timeout(cmd, Duration::from_secs(300))?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        return Err(format!("{}: {}", output.status, stderr.trim()));
    }
    Ok(paths)
}

fn wait_with_timeout(mut cmd: Command, limit: Duration) -> Result<std::process::Output, String> {
    let mut child = cmd.spawn().map_err(|e| e.to_string())?;
    let start = Instant::now();
    loop {
        match child.try_wait().map_err(|e| e.to_string())? {
            Some(_) => return child.wait_with_output().map_err(|e| e.to_string()),
            None if start.elapsed() > limit => {
                let _ = child.kill();
                return Err(format!("no answer after {limit:?}"));
            }
            None => std::thread::sleep(Duration::from_millis(5)),
        }
    }
}

fn load(path: &Path) -> Result<RgbImage, String> {
    goldray::rgb_image::read_png(path).map_err(|e| e.to_string())
}

/// The verdict and the differing pixels.
fn compare(ours: &Path, theirs: &Path, tolerance: u8) -> Result<(Verdict, Vec<(u32, u32)>), String> {
    let (ours, theirs) = (load(ours)?, load(theirs)?);
    if ours.dimensions() != theirs.dimensions() {
        return Err(format!("size {:?} != {:?}", ours.dimensions(), theirs.dimensions()));
    }
    let max_difference = ours
        .pixels()
        .zip(theirs.pixels())
        .flat_map(|(a, b)| a.0.into_iter().zip(b.0).map(|(x, y)| x.abs_diff(y)))
        .max()
        .unwrap_or(0);
    let off = stability::differing(&ours, &theirs, tolerance);
    let verdict = Verdict {
        seed: 0,
        run: String::new(),
        kind: 0,
        agree: 1.0 - off.len() as f64 / f64::from(ours.width() * ours.height()),
        max_difference,
        unstable: None,
    };
    Ok((verdict, off))
}

fn tsv(verdicts: &[Verdict]) -> String {
    let mut out = "seed\trun\timage\tagree\tmax_difference\till_conditioned_differing\n".to_owned();
    for v in verdicts {
        let unstable = v.unstable.map_or(String::new(), |n| n.to_string());
        let _ = writeln!(
            out,
            "{}\t{}\t{}\t{:.6}\t{}\t{unstable}",
            v.seed, v.run, KINDS[v.kind], v.agree, v.max_difference
        );
    }
    out
}

fn summary(args: &Args, verdicts: &[Verdict], ignored_flags: (usize, usize), elapsed: Duration) -> String {
    let (first, last) = args.seeds;
    let mut out = String::new();
    let failing = verdicts.iter().filter(|v| v.agree < args.threshold).count();
    let _ = writeln!(
        out,
        "seeds {first}-{last}: {} scenes, {} images, {failing} below {}% of pixels within {}/255 ({elapsed:.0?})",
        last - first + 1,
        verdicts.len(),
        100.0 * args.threshold,
        args.tolerance
    );
    for (kind, name) in KINDS.iter().enumerate() {
        let of_kind: Vec<&Verdict> = verdicts.iter().filter(|v| v.kind == kind).collect();
        let Some(worst) = of_kind.iter().min_by(|a, b| a.agree.total_cmp(&b.agree)) else {
            continue;
        };
        let identical = of_kind.iter().filter(|v| v.max_difference == 0).count();
        let within = of_kind.iter().filter(|v| v.agree == 1.0).count();
        let mean = of_kind.iter().map(|v| v.agree).sum::<f64>() / of_kind.len() as f64;
        let _ = writeln!(
            out,
            "  {name:8} {} images: worst {:.4}% (seed {} {}), mean {:.4}%, {within} with every pixel within, {identical} identical",
            of_kind.len(),
            100.0 * worst.agree,
            worst.seed,
            worst.run,
            100.0 * mean,
        );
    }
    if ignored_flags.1 > 0 {
        let _ = writeln!(
            out,
            "  the reference's images with -jitter -filter were byte-identical to those without on {} of {} scenes",
            ignored_flags.0, ignored_flags.1
        );
    }
    out
}
