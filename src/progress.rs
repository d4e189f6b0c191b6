//! A progress bar that only appears for work that takes long enough to need one.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Renders shorter than this finish before a bar would be readable; showing one would only
/// flicker.
const SHOW_AFTER: Duration = Duration::from_secs(1);

pub struct Progress {
    bar: ProgressBar,
    enabled: bool,
    visible: AtomicBool,
    started: Instant,
}

impl Progress {
    /// `enabled = false` (the CLI's `--quiet`, and every library caller that doesn't ask) never
    /// draws anything.
    pub fn new(total: u64, message: &str, enabled: bool) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed} (eta {eta})") {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(message.to_string());
        Progress {
            bar,
            enabled,
            visible: AtomicBool::new(false),
            started: Instant::now(),
        }
    }

    pub fn hidden() -> Progress {
        Progress::new(0, "", false)
    }

    pub fn advance(&self, amount: u64) {
        self.bar.inc(amount);
        if self.enabled && self.started.elapsed() >= SHOW_AFTER && !self.visible.swap(true, Ordering::Relaxed) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    pub fn finish(&self) {
        if self.visible.load(Ordering::Relaxed) {
            self.bar.finish_and_clear();
        }
    }
}
