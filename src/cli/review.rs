//! `goldray review`: the pending goldens of a project, served as a page to accept or reject in
//! the browser, listed, decided from the command line, or written as a read-only page.

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::review::{
    CaseReview, Decision, Event, Project, Server, accept, accept_all, pending::relative, reject, write_static,
};

use super::Failure;

/// `println!` that a closed stdout does not turn into a panic (`goldray review --list | head`, or
/// a script that read the server's address and went away while the server goes on).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut stdout = std::io::stdout().lock();
        let _ = writeln!(stdout, $($arg)*).and_then(|()| stdout.flush());
    }};
}

#[derive(Clone, Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("task").multiple(true).args(["list", "accept", "reject", "accept_all", "static_dir"]))]
pub struct ReviewArgs {
    /// The project: the folder holding cases/ and golden/.
    #[arg(long, default_value = ".")]
    project: PathBuf,
    /// Serve on this port of 127.0.0.1 (default: a free one).
    #[arg(long, default_value_t = 0, conflicts_with = "task")]
    port: u16,
    /// Open the page in the browser.
    #[arg(long, conflicts_with = "task")]
    open: bool,
    /// List the pending goldens with their verdicts, and decide nothing.
    #[arg(long, conflicts_with_all = ["accept", "reject", "accept_all", "static_dir"])]
    list: bool,
    /// Accept these pending goldens, as `cargo insta accept` would.
    #[arg(long, value_name = "NAME", num_args = 1..)]
    accept: Vec<String>,
    /// Reject these pending goldens: their pending files are removed, the goldens kept.
    #[arg(long, value_name = "NAME", num_args = 1..)]
    reject: Vec<String>,
    /// Accept every pending golden.
    #[arg(long, conflicts_with_all = ["accept", "reject", "static_dir"])]
    accept_all: bool,
    /// Write the page into DIR, read-only (no buttons), e.g. as a CI artifact.
    #[arg(long = "static", value_name = "DIR", conflicts_with_all = ["accept", "reject"])]
    static_dir: Option<PathBuf>,
}

pub fn run(args: ReviewArgs) -> Result<ExitCode, Failure> {
    let project = Project::new(&args.project);
    if args.list {
        return list(&project);
    }
    if let Some(dir) = &args.static_dir {
        let (page, count) = write_static(&project, dir)?;
        say!("wrote the review page of {count} pending golden(s): {}", page.display());
        return Ok(ExitCode::SUCCESS);
    }
    if args.accept_all {
        let decisions = accept_all(&project)?;
        if decisions.is_empty() {
            say!("no pending golden");
        }
        decisions.iter().for_each(|d| report(&project, d));
        return Ok(ExitCode::SUCCESS);
    }
    if !args.accept.is_empty() || !args.reject.is_empty() {
        // Every name is checked before anything is decided, so a typo decides nothing.
        for name in args.accept.iter().chain(&args.reject) {
            project.find(name)?;
        }
        for name in &args.accept {
            report(&project, &accept(&project, name)?);
        }
        for name in &args.reject {
            report(&project, &reject(&project, name)?);
        }
        return Ok(ExitCode::SUCCESS);
    }
    serve(&project, args.port, args.open)
}

fn list(project: &Project) -> Result<ExitCode, Failure> {
    let list = project.pending()?;
    for (path, reason) in &list.skipped {
        eprintln!("skipped {}: {reason}", relative(&project.root, path));
    }
    if list.pending.is_empty() {
        eprintln!("no pending golden");
    }
    for pending in &list.pending {
        match CaseReview::of_pending(project, pending) {
            Ok(review) => say!("{}\t{}\t{}", pending.name, review.verdict_word(), summary(&review)),
            Err(error) => say!("{}\tUNREADABLE\t{error}", pending.name),
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// One line: the numbers that decided, then how the files were made differently.
fn summary(review: &CaseReview) -> String {
    let mut parts = Vec::new();
    if let Some(m) = review.comparison.as_ref().and_then(|c| c.metrics.as_ref()) {
        parts.push(format!(
            "{:.3}% of pixels fail, RMSE {:.5}, FLIP {:.4}",
            m.failing_fraction * 100.0,
            m.rmse,
            m.flip
        ));
    }
    if let Some(noise) = review.comparison.as_ref().and_then(|c| c.noise.as_ref()) {
        parts.push(format!("{} significant of {}", noise.significant, noise.tests));
    }
    parts.extend(review.notes.iter().cloned());
    if let Some(line) = &review.made_differently {
        parts.push(format!("made differently: {line}"));
    }
    parts.join("; ")
}

fn report(project: &Project, decision: &Decision) {
    let shown = |paths: &[PathBuf]| {
        paths
            .iter()
            .map(|p| relative(&project.root, p))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if decision.accepted {
        say!("accepted {}: wrote {}", decision.name, shown(&decision.written));
    } else {
        say!("rejected {}: removed {}", decision.name, shown(&decision.removed));
    }
}

fn serve(project: &Project, port: u16, open: bool) -> Result<ExitCode, Failure> {
    let server = Server::bind(port)?;
    let url = server.url();
    // The first line says where the page is, for a person and for scripts that start the
    // server (flushed, so that a pipe sees it at once).
    say!(
        "reviewing {} pending golden(s) at {url} (Ctrl-C to stop)",
        project.pending()?.pending.len()
    );
    if open {
        open_browser(&url);
    }
    server.serve(project, |event| match event {
        Event::Decided(decision) => report(project, &decision),
        Event::Refused { method, url, refusal } => {
            eprintln!("refused {method} {url}: {} ({})", refusal.reason, refusal.status);
        }
        Event::Failed { url, message } => eprintln!("error answering {url}: {message}"),
    })?;
    Ok(ExitCode::SUCCESS)
}

/// The system's way to open a URL; a failure is reported, the server goes on.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(error) = std::process::Command::new(opener).arg(url).spawn() {
        eprintln!("could not open a browser ({opener}: {error}); open {url}");
    }
}
