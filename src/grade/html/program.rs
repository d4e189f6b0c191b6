//! How the student's program ran, on the student's page: each command that did not end well
//! (or the failed build), once, with the images it cost and the end of its stderr, so that a
//! student whose program crashed reads the crash and not seven bare zeros.

use std::fmt::Write as _;

use super::super::program_run::ProgramRun;
use super::super::score::StudentResult;
use super::escape;

pub const STYLE: &str = r#"
section.program{background:#fff;border:1px solid #ccc;border-left:6px solid #6a3fb5;margin:1em 0;padding:.8em}
section.program pre{background:#222;color:#eee;padding:.5em;max-height:20em;overflow:auto;white-space:pre-wrap}
.v-crashed,.v-timed-out,.v-over-limit,.v-exit-error,.v-not-run{background:#d7c8ee}
"#;

/// The section, when any image's command did not end well; commands shared by several images
/// (a failed build costs every image) appear once.
pub fn summary(body: &mut String, student: &StudentResult) {
    let mut runs: Vec<(&ProgramRun, Vec<&str>)> = Vec::new();
    for result in &student.images {
        let Some(program) = &result.program else {
            continue;
        };
        match runs.iter_mut().find(|(known, _)| *known == program) {
            Some((_, files)) => files.push(&result.file),
            None => runs.push((program, vec![&result.file])),
        }
    }
    if runs.is_empty() {
        return;
    }
    body.push_str("<section class=\"program\" id=\"program\">\n<h2>How your program ran</h2>\n");
    for (program, files) in runs {
        let files: Vec<String> = files.iter().map(|f| escape(f)).collect();
        let _ = write!(
            body,
            "<p><strong>{}</strong> ({})</p>\n<p class=\"muted\"><code>{}</code></p>\n",
            escape(&program.how),
            files.join(", "),
            escape(&program.command)
        );
        if program.stderr_tail.is_empty() {
            body.push_str("<p class=\"muted\">It printed nothing on stderr.</p>\n");
        } else {
            let _ = writeln!(
                body,
                "<details open><summary>the end of its stderr</summary><pre>{}</pre></details>",
                escape(&program.stderr_tail)
            );
        }
    }
    body.push_str("</section>\n");
}
