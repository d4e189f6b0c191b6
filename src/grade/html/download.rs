//! What the report says about a learning platform's download: which layout was read, the
//! entries refused with why, and each student's id on the platform.

use std::fmt::Write as _;

use super::super::lms::Layout;
use super::super::report::ClassReport;
use super::super::score::StudentResult;
use super::escape;

pub const STYLE: &str = r#"
.lms{color:#555;font-size:.85em;white-space:nowrap}
.late{background:#f6d28b;border-radius:3px;padding:0 .3em}
ul.refused li{font-family:monospace;font-size:.9em}
"#;

/// The class page's line on where the submissions came from, and the refused entries that
/// belong to no student.
pub fn source(body: &mut String, report: &ClassReport) {
    let _ = writeln!(
        body,
        "<p class=\"muted\">Submissions: <code>{}</code>, read as {}.</p>",
        escape(&report.submissions.display().to_string()),
        report.layout.describe()
    );
    if !report.refused.is_empty() {
        body.push_str("<p>Entries of the download that were not read:</p>\n<ul class=\"refused\">\n");
        for refusal in &report.refused {
            let _ = writeln!(body, "<li>{}</li>", escape(&refusal.note()));
        }
        body.push_str("</ul>\n");
    }
}

/// The student's id on the platform, and whether the submission was late, after their name.
pub fn identity(student: &StudentResult) -> String {
    let Some(lms) = &student.lms else {
        return String::new();
    };
    let platform = match lms.platform {
        Layout::Canvas => "Canvas user",
        Layout::Moodle => "Moodle participant",
        Layout::Folders => "id",
    };
    let late = if lms.late {
        " <span class=\"late\">late</span>"
    } else {
        ""
    };
    format!(" <span class=\"lms\">{platform} {}{late}</span>", escape(&lms.id))
}

/// The student's files that were refused, on their page.
pub fn refused(body: &mut String, student: &StudentResult) {
    if student.refused.is_empty() {
        return;
    }
    body.push_str("<p>Files of this submission that were not read:</p>\n<ul class=\"refused\">\n");
    for note in &student.refused {
        let _ = writeln!(body, "<li>{}</li>", escape(note));
    }
    body.push_str("</ul>\n");
}
