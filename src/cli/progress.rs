//! The one way the command line shows progress: a bar on a terminal, one line per step when
//! standard error is a log (CI, `2> log`), nothing with `--quiet`.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use goldray::progress::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Work shorter than this finishes before a bar would be readable; showing one would only flicker.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// How progress reaches the user.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Quiet,
    /// A bar, drawn once the work has taken [`SHOW_AFTER`].
    Bar,
    /// A line on stderr per named step and per finished item, for logs that cannot show a bar.
    Lines,
}

/// A [`Progress`] observer for one command.
pub struct Reporter {
    mode: Mode,
    bar: ProgressBar,
    visible: AtomicBool,
    started: Mutex<Instant>,
    label: Mutex<String>,
}

impl Reporter {
    /// A bar when stderr is a terminal, lines otherwise; nothing at all when `quiet`.
    pub fn new(quiet: bool) -> Reporter {
        let mode = match (quiet, std::io::stderr().is_terminal()) {
            (true, _) => Mode::Quiet,
            (false, true) => Mode::Bar,
            (false, false) => Mode::Lines,
        };
        Reporter {
            mode,
            bar: ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden()),
            visible: AtomicBool::new(false),
            started: Mutex::new(Instant::now()),
            label: Mutex::new(String::new()),
        }
    }

    fn line(&self, text: &str) {
        if self.mode == Mode::Lines {
            eprintln!("{text}");
        }
    }

    fn elapsed(&self) -> Duration {
        self.started.lock().map(|s| s.elapsed()).unwrap_or_default()
    }
}

impl Progress for Reporter {
    fn begin(&self, label: &str, total: u64) {
        if let Ok(mut started) = self.started.lock() {
            *started = Instant::now();
        }
        if let Ok(mut current) = self.label.lock() {
            *current = label.to_owned();
        }
        self.bar.reset();
        self.bar.set_length(total);
        let template = format!("{label} [{{bar:40}}] {{percent:>3}}% {{elapsed}} (eta {{eta}}) {{msg}}");
        if let Ok(style) = ProgressStyle::with_template(&template) {
            self.bar.set_style(style.progress_chars("=> "));
        }
    }

    fn grow(&self, amount: u64) {
        self.bar.inc_length(amount);
    }

    fn step(&self, name: &str) {
        self.bar.set_message(name.to_owned());
        self.line(name);
    }

    fn advance(&self, amount: u64) {
        self.bar.inc(amount);
        if self.mode == Mode::Bar && self.elapsed() >= SHOW_AFTER && !self.visible.swap(true, Ordering::Relaxed) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    fn done(&self, name: &str) {
        if self.mode == Mode::Lines {
            let label = self.label.lock().map(|l| l.clone()).unwrap_or_default();
            let position = self.bar.position();
            let total = self.bar.length().unwrap_or(position);
            eprintln!(
                "{label} {position}/{total}: {name} ({:.1} s)",
                self.elapsed().as_secs_f64()
            );
        }
    }

    fn finish(&self) {
        if self.visible.swap(false, Ordering::Relaxed) {
            self.bar.finish_and_clear();
            self.bar.set_draw_target(ProgressDrawTarget::hidden());
        }
    }
}
