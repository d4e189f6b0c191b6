//! The report's files: `tradeoff.csv` for scripts and spreadsheets, `tradeoff.md` for people, and
//! (drawn by [`super::plot`]) `tradeoff.png`.
//!
//! Each file carries goldray's mark (the CSV's header, an HTML comment on the Markdown's first
//! line, a PNG `Software` text chunk), so that a later run can tell its own report, which it
//! replaces, from a file that happens to have the same name, which it leaves alone unless told
//! to (`--force`), as `goldray import` does.

use std::fmt::Write as _;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use super::Tradeoff;
use super::error::TradeoffError;
use super::measure::Measurement;
use super::pareto::SAME_ERROR;
use super::plot::{SOFTWARE, is_our_png, plot_png};
use crate::atomic_write::write_file_atomic;
use crate::stats::grouped;

pub const CSV_FILE: &str = "tradeoff.csv";
pub const MARKDOWN_FILE: &str = "tradeoff.md";
pub const PLOT_FILE: &str = "tradeoff.png";

/// The CSV's columns, one row per setting.
pub const CSV_COLUMNS: [&str; 15] = [
    "setting",
    "samples",
    "filter",
    "precision",
    "bounces",
    "sweep",
    "seconds",
    "runs",
    "rays",
    "camera_rays",
    "mrays_per_s",
    "rmse",
    "max_error",
    "flip",
    "pareto",
];

/// What a CSV written by goldray tradeoff starts with, whatever columns later versions add.
const CSV_MARK: &str = "setting,samples,filter,";

/// The Markdown's first line.
const MARKDOWN_MARK: &str = "<!-- written by goldray tradeoff; it replaces this file when run again -->";

/// The report's three paths in `dir`, in the order they are written.
pub fn report_paths(dir: &Path) -> [PathBuf; 3] {
    [dir.join(CSV_FILE), dir.join(MARKDOWN_FILE), dir.join(PLOT_FILE)]
}

/// Refuses, before anything renders, to replace a file goldray did not write (unless `force`).
pub fn check_replaceable(dir: &Path, force: bool) -> Result<(), TradeoffError> {
    if force {
        return Ok(());
    }
    for path in report_paths(dir) {
        let bytes = match fs::read(&path) {
            Ok(bytes) => bytes,
            Err(error) if error.kind() == io::ErrorKind::NotFound => continue,
            Err(source) if path.is_dir() => {
                return Err(TradeoffError::Inspect {
                    path,
                    source: io::Error::new(source.kind(), "it is a directory"),
                });
            }
            Err(source) => return Err(TradeoffError::Inspect { path, source }),
        };
        let ours = match path.extension().and_then(|e| e.to_str()) {
            Some("csv") => bytes.starts_with(CSV_MARK.as_bytes()),
            Some("md") => bytes.starts_with(MARKDOWN_MARK.as_bytes()),
            _ => is_our_png(&bytes),
        };
        if !ours {
            return Err(TradeoffError::NotOurs { path });
        }
    }
    Ok(())
}

/// Encodes all three files, then writes each atomically into `dir` (created if missing).
/// Nothing is written when the plot cannot be drawn.
pub fn write_report(tradeoff: &Tradeoff, dir: &Path) -> Result<Vec<PathBuf>, TradeoffError> {
    let [csv_path, markdown_path, plot_path] = report_paths(dir);
    let plot = plot_png(tradeoff)?;
    let files = [
        (csv_path, csv(tradeoff).into_bytes()),
        (markdown_path, markdown(tradeoff).into_bytes()),
        (plot_path, plot),
    ];
    for (path, bytes) in &files {
        write_file_atomic(path, bytes)?;
    }
    Ok(files.into_iter().map(|(path, _)| path).collect())
}

/// Which sweeps a measurement belongs to, as the CSV's `sweep` column says it.
fn sweeps(m: &Measurement) -> &'static str {
    match (m.in_grid, m.in_bounce_sweep) {
        (true, true) => "grid+bounces",
        (false, true) => "bounces",
        _ => "grid",
    }
}

/// One header line and one row per setting, numbers in full precision.
pub fn csv(tradeoff: &Tradeoff) -> String {
    let mut out = CSV_COLUMNS.join(",");
    out.push('\n');
    for (m, on_front) in tradeoff.measurements.iter().zip(&tradeoff.pareto) {
        let s = &m.setting;
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.label(),
            s.samples,
            s.filter.name(),
            s.precision.name(),
            s.bounces,
            sweeps(m),
            m.seconds,
            m.runs,
            m.rays.total(),
            m.rays.camera,
            m.mrays_per_second(),
            m.errors.rmse,
            m.errors.max,
            m.errors.flip,
            on_front
        );
    }
    out
}

/// The report a person reads: what was compared with what, a table of every setting, the
/// Pareto front, the bounce sweep's finding and the `--target-flip` answer.
pub fn markdown(t: &Tradeoff) -> String {
    let r = &t.reference;
    let mut md = format!("{MARKDOWN_MARK}\n# Speed and accuracy: {}\n\n", t.case_name);
    let _ = writeln!(
        md,
        "Case `{}` at {}×{} on {}, by {SOFTWARE} {}. Every setting is the case's own except \
         the samples per pixel, the filter, the precision and the bounces shown.\n",
        t.case_path.display(),
        t.width,
        t.height,
        plural(t.threads as u32, "thread"),
        env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        md,
        "**Reference:** {} stratified samples per pixel with no filter (the pixel-area integral), {}, \
         {}, seed {}; {} s, {} rays. Errors are against it: RMSE and the largest error on linear colour, FLIP \
         (NVIDIA's perceptual difference, 0 = identical) on the sRGB pictures.\n",
        r.samples,
        plural(r.bounces, "bounce"),
        r.precision.name(),
        r.seed,
        significant(r.seconds),
        grouped(r.rays.total()),
    );
    let _ = writeln!(md, "**Bounces:** {}\n", bounce_sentence(t));
    let _ = writeln!(
        md,
        "**Time** is wall-clock rendering only (the scene is built once): the fastest of as many runs as \
         fit in {} s (at least one, at most 50; the `runs` column of the CSV). Rays are exact counts of every \
         kind (camera, AOV, shadow, reflection).\n",
        t.min_time.as_secs_f64()
    );
    md.push_str(
        "| setting | samples | filter | precision | bounces | time (s) | rays | Mrays/s | RMSE | max error | FLIP | Pareto |\n",
    );
    md.push_str("| --- | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | :---: |\n");
    for (m, on_front) in t.measurements.iter().zip(&t.pareto) {
        let s = &m.setting;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            s.label(),
            s.samples,
            s.filter.name(),
            s.precision.name(),
            s.bounces,
            significant(m.seconds),
            grouped(m.rays.total()),
            significant(m.mrays_per_second()),
            significant(m.errors.rmse),
            significant(m.errors.max),
            significant(m.errors.flip),
            if *on_front { "★" } else { "" },
        );
    }
    let front: Vec<String> = t
        .front()
        .map(|m| format!("{} ({} s)", m.setting.label(), significant(m.seconds)))
        .collect();
    let _ = writeln!(
        md,
        "\n**Pareto front** (★, by {}): the settings no other setting beats in both time and error, fastest \
         first: {}. Any other setting has one that is at least as fast and at least as accurate (errors within \
         {}% of each other count as equal).\n",
        t.metric.title(),
        front.join(", "),
        SAME_ERROR * 100.0
    );
    if let Some(sentence) = t.target_sentence() {
        let _ = writeln!(md, "**Target:** {sentence}\n");
    }
    let _ = writeln!(
        md,
        "![{} against render time, log-log, Pareto front marked]({PLOT_FILE})",
        t.metric.title()
    );
    md
}

/// What the bounce sweep found, in one sentence.
pub fn bounce_sentence(t: &Tradeoff) -> String {
    let b = &t.bounces;
    let of = format!(
        "at the case's {} spp, filter {}, {}",
        t.base.samples,
        t.base.filter.name(),
        t.base.precision.name()
    );
    let asks = format!("The case asks for {}.", plural(t.base.bounces, "bounce"));
    match (b.settled, b.last) {
        (true, last) => format!(
            "{of}, bounce {last} changed no pixel by more than {} (largest change {}), so {} {} enough; the \
             grid is rendered at that depth. {asks}",
            b.threshold,
            significant(b.last_change),
            plural(last - 1, "bounce"),
            if last == 2 { "is" } else { "are" },
        ),
        (false, 0) => {
            format!("{of}, only 0 bounces were rendered (--max-bounces 0): the sweep says nothing about depth. {asks}")
        }
        (false, last) => format!(
            "{of}, the picture was still changing at the cap of {} (the last bounce moved a pixel by {}, over the \
             threshold {}); the grid is rendered at the cap. {asks}",
            plural(last, "bounce"),
            significant(b.last_change),
            b.threshold,
        ),
    }
}

/// `1 bounce`, `2 bounces`.
fn plural(n: u32, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
}

/// Three significant digits, switching to scientific notation for tiny values, so that the
/// table's columns stay narrow whatever the scale.
pub fn significant(value: f64) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let magnitude = value.abs().log10().floor() as i32;
    if magnitude < -3 {
        format!("{value:.2e}")
    } else {
        format!("{value:.*}", (2 - magnitude).max(0) as usize)
    }
}

/// What the terminal shows: the sweep's size, the bounce finding and the Pareto front.
pub fn summary(t: &Tradeoff) -> String {
    let front: Vec<String> = t
        .front()
        .map(|m| {
            format!(
                "{} ({} s, {} {})",
                m.setting.label(),
                significant(m.seconds),
                t.metric.column(),
                significant(t.metric.of(&m.errors))
            )
        })
        .collect();
    format!(
        "{} at {}×{}: {} settings against a {} spp reference ({} bounces, {} s)\nbounces: {}\nPareto front: {}",
        t.case_name,
        t.width,
        t.height,
        t.measurements.len(),
        t.reference.samples,
        t.reference.bounces,
        significant(t.reference.seconds),
        bounce_sentence(t),
        front.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_readable() {
        assert_eq!(significant(0.012345), "0.0123");
        assert_eq!(significant(1.5), "1.50");
        assert_eq!(significant(123.4), "123");
        assert_eq!(significant(0.0), "0");
        assert_eq!(significant(0.00001234), "1.23e-5");
    }

    #[test]
    fn foreign_files_are_refused_and_our_own_replaced() {
        let dir = tempfile::tempdir().unwrap();
        assert!(check_replaceable(dir.path(), false).is_ok(), "nothing there yet");
        fs::write(dir.path().join(CSV_FILE), "setting,samples,filter,bounces\n").unwrap();
        fs::write(dir.path().join(MARKDOWN_FILE), format!("{MARKDOWN_MARK}\n# old\n")).unwrap();
        assert!(check_replaceable(dir.path(), false).is_ok(), "our own earlier report");
        fs::write(dir.path().join(PLOT_FILE), b"someone's holiday photo").unwrap();
        let error = check_replaceable(dir.path(), false).unwrap_err();
        assert!(
            matches!(&error, TradeoffError::NotOurs { path } if path.ends_with(PLOT_FILE)),
            "{error}"
        );
        assert!(error.to_string().contains("--force"), "{error}");
        assert!(check_replaceable(dir.path(), true).is_ok());
        fs::write(dir.path().join(PLOT_FILE), b"").unwrap();
        fs::write(dir.path().join(MARKDOWN_FILE), "# my notes\n").unwrap();
        assert!(matches!(
            check_replaceable(dir.path(), false),
            Err(TradeoffError::NotOurs { .. })
        ));
    }
}
