//! Opening the HTML report in Debian's headless Chromium, from the file system, with every
//! network feature off: what a TA's browser sees, without a display. (tests/review/cdp.rs drives
//! the same browser, with the same flags, through a page's clicks and keys.)

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const CHROMIUM: &str = "/usr/bin/chromium";
/// Long enough for a cold start on a loaded CI machine, short enough that a hang fails the test.
const TIMEOUT: Duration = Duration::from_secs(90);

/// Debian's Chromium; panics saying how to install it where it is missing.
pub fn chromium() -> PathBuf {
    let path = PathBuf::from(CHROMIUM);
    assert!(
        path.exists(),
        "{CHROMIUM} is missing: the tests that open pages need Debian's chromium \
         (`apt-get install -y chromium`; .ci/run installs it)"
    );
    path
}

/// The flags of every run here: headless, no GPU, no network feature, no first-run work.
pub const FLAGS: [&str; 9] = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
];

/// Runs Chromium headless on `page` with `extra` arguments and returns its standard output.
fn run(page: &Path, extra: &[String]) -> Vec<u8> {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(chromium())
        .args(FLAGS)
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(&url)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromium starts");
    // Read while it runs: a DOM larger than the pipe's buffer would otherwise block Chromium.
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        stdout.read_to_end(&mut bytes).map(|_| bytes)
    });
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish {url} within {TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "chromium failed on {url}: {status:?}");
    reader.join().unwrap().unwrap()
}

/// The DOM after the page's load handlers ran (they count the pictures that loaded).
pub fn dump_dom(page: &Path) -> String {
    let stdout = run(
        page,
        &["--virtual-time-budget=5000".to_owned(), "--dump-dom".to_owned()],
    );
    String::from_utf8(stdout).expect("the DOM is UTF-8")
}

/// Fails, naming `page`, unless every picture of the page loaded: the reports count the pictures
/// that loaded and broke (`data-images-broken`) in their load handlers.
pub fn assert_pictures_loaded(dom: &str, page: &str) {
    assert!(
        dom.contains("data-images-broken=\"0\""),
        "{page}: a picture did not load:\n{dom}"
    );
}

/// [`dump_dom`] in a `width`×`height` window, for what depends on layout.
pub fn dump_dom_at(page: &Path, width: u32, height: u32) -> String {
    let stdout = run(
        page,
        &[
            "--virtual-time-budget=5000".to_owned(),
            format!("--window-size={width},{height}"),
            "--dump-dom".to_owned(),
        ],
    );
    String::from_utf8(stdout).expect("the DOM is UTF-8")
}

/// A screenshot of the page in a `width`×`height` window.
pub fn screenshot(page: &Path, width: u32, height: u32, file: &Path) -> goldray::rgb_image::RgbImage {
    run(
        page,
        &[
            "--virtual-time-budget=5000".to_owned(),
            format!("--window-size={width},{height}"),
            format!("--screenshot={}", file.display()),
        ],
    );
    goldray::rgb_image::read_png(file).unwrap_or_else(|e| panic!("{e}"))
}
