//! `goldray diff`: the golden comparison from the shell, for any two EXR or PNG files, with
//! idiff's exit codes so that scripts written for OpenImageIO keep working. Before the verdict
//! it says how the two files were made differently, when their provenance says so.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use goldray::compare::{ToleranceOverrides, compare_files};
use goldray::provenance::{Provenance, made_differently};
use goldray::review::write_diff_page;

use super::common::{parse_fraction, parse_threshold};

/// The exit code for a file that cannot be read or decoded (or a `--diff-image` or `--html` not
/// written).
const UNREADABLE: u8 = 4;

/// A threshold left out takes the default for the files' encoding.
#[derive(Clone, Debug, clap::Args)]
pub struct DiffArgs {
    /// The reference image (e.g. the golden).
    expected: PathBuf,
    /// The image under test.
    actual: PathBuf,
    /// A pixel fails when any channel differs by more than this (default: 0.01 for EXR, in
    /// linear values; 1 for PNG, in 8-bit codes).
    #[arg(long, value_parser = parse_threshold)]
    pixel: Option<f64>,
    /// At most this fraction of the pixels may fail (default 0.001).
    #[arg(long, value_parser = parse_fraction)]
    fail_fraction: Option<f64>,
    /// The colour RMSE may be at most this (default: 0.002 for EXR; 0.5 codes for PNG).
    #[arg(long, value_parser = parse_threshold)]
    rmse: Option<f64>,
    /// No channel of any pixel may differ by more than this (default: no cap).
    #[arg(long, value_parser = parse_threshold)]
    max: Option<f64>,
    /// Write a heatmap of the differences to this PNG.
    #[arg(long, value_name = "OUT.png")]
    diff_image: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Write the review page of the two images to this HTML file (pictures, values under the
    /// cursor, exposure, swipe and flip; everything inside the one file).
    #[arg(long, value_name = "OUT.html")]
    html: Option<PathBuf>,
}

/// Compares, prints the report (text or JSON) on stdout and any error on stderr, and returns the
/// exit code: 0 pass, 1 warn, 2 fail, 3 size or channel mismatch, 4 unreadable file. The verdict
/// is printed even when the heatmap or the page cannot be written; the exit code is then 4.
pub fn run(args: DiffArgs) -> ExitCode {
    let overrides = ToleranceOverrides {
        pixel: args.pixel,
        fail_fraction: args.fail_fraction,
        rmse: args.rmse,
        max: args.max,
    };
    let mut compared = match compare_files(&args.expected, &args.actual, &overrides) {
        Ok(compared) => compared,
        Err(error) => {
            if args.json {
                let report = serde_json::json!({
                    "verdict": "unreadable",
                    "exit_code": UNREADABLE,
                    "error": error.to_string(),
                });
                print_stdout(&format!("{report:#}\n"));
            }
            eprintln!("error: {error}");
            return ExitCode::from(UNREADABLE);
        }
    };
    let heatmap = args.diff_image.as_ref().map(|path| compared.write_heatmap(path));
    let page = args
        .html
        .as_ref()
        .map(|out| write_diff_page(&args.expected, &args.actual, &overrides, out));
    let comparison = &compared.comparison;
    // Both files were just decoded, so reading their headers again cannot fail in a way that
    // matters: a provenance that cannot be read is reported as none.
    let [expected, actual] = [&args.expected, &args.actual].map(|path| Provenance::read(path).ok().flatten());
    let differently = made_differently(("expected", expected.as_ref()), ("actual", actual.as_ref()));
    print_stdout(&if args.json {
        with_provenance(&comparison.to_json(), [&expected, &actual], differently.as_deref()) + "\n"
    } else {
        let line = differently.map(|line| format!("made differently: {line}\n"));
        line.unwrap_or_default() + &comparison.to_string()
    });
    if let Some(Err(error)) = page {
        eprintln!("error: {error}");
        return ExitCode::from(UNREADABLE);
    }
    match heatmap {
        Some(Err(error)) => {
            eprintln!("error: {error}");
            ExitCode::from(UNREADABLE)
        }
        Some(Ok(false)) => {
            eprintln!("note: no diff image written: the images cannot be laid over each other");
            ExitCode::from(comparison.verdict.exit_code())
        }
        Some(Ok(true)) | None => ExitCode::from(comparison.verdict.exit_code()),
    }
}

/// The comparison's JSON with a `provenance` object last: each file's `goldray.*` entries (or
/// `null`) and the `made_differently` line (or `null`). Spliced into the text so that the
/// report keeps its key order, the verdict first.
fn with_provenance(json: &str, [expected, actual]: [&Option<Provenance>; 2], differently: Option<&str>) -> String {
    let entries = |made: &Option<Provenance>| {
        made.as_ref().map(|made| {
            made.entries()
                .map(|(k, v)| (k.to_owned(), serde_json::Value::from(v)))
                .collect::<serde_json::Map<_, _>>()
        })
    };
    let provenance = serde_json::json!({
        "expected": entries(expected),
        "actual": entries(actual),
        "made_differently": differently,
    });
    let provenance = format!("{provenance:#}").replace('\n', "\n  ");
    match json.trim_end().strip_suffix('}') {
        Some(body) => format!("{},\n  \"provenance\": {provenance}\n}}", body.trim_end()),
        None => json.to_owned(),
    }
}

/// A closed pipe (`goldray diff … | head`) must not turn a verdict into a panic.
fn print_stdout(text: &str) {
    let mut stdout = std::io::stdout().lock();
    let _ = stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush());
}
