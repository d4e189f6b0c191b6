//! Moodle: the names of its "Download all submissions" zip, and the columns its offline grading
//! worksheet imports.
//!
//! Moodle puts each student's files in a folder `Full Name_ID_assignsubmission_file_` (and the
//! online text in `Full Name_ID_assignsubmission_onlinetext_`), or, with folders turned off,
//! prefixes each file's name with the same. `ID` is the participant id the assignment gives the
//! student, which the worksheet names `Participant ID`. The worksheet's import reads the grade
//! and the feedback comments by that identifier; the other columns are Moodle's own.

use crate::html_escape::escape;

/// A Moodle submission folder (or a file prefixed like one), its name taken apart.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MoodleName<'a> {
    pub full_name: &'a str,
    pub participant: &'a str,
    /// The submission plugin: `file`, `onlinetext`.
    pub plugin: &'a str,
    /// What follows the prefix: empty for a folder, the original name for a prefixed file.
    pub rest: &'a str,
}

const MARK: &str = "_assignsubmission_";

/// `component` (one folder or file name) as Moodle names a submission, or `None`.
pub fn parse(component: &str) -> Option<MoodleName<'_>> {
    let at = component.find(MARK)?;
    let (before, after) = (&component[..at], &component[at + MARK.len()..]);
    let (full_name, participant) = before.rsplit_once('_')?;
    let (plugin, rest) = after.split_once('_')?;
    let valid = !full_name.is_empty()
        && !participant.is_empty()
        && participant.bytes().all(|b| b.is_ascii_digit())
        && !plugin.is_empty()
        && plugin.bytes().all(|b| b.is_ascii_lowercase());
    valid.then_some(MoodleName {
        full_name,
        participant,
        plugin,
        rest,
    })
}

/// The offline grading worksheet's columns, as Moodle writes them (without groups).
pub const HEADER: [&str; 10] = [
    "Identifier",
    "Full name",
    "Email address",
    "Status",
    "Grade",
    "Maximum Grade",
    "Grade can be changed",
    "Last modified (submission)",
    "Last modified (grade)",
    "Feedback comments",
];

/// One student's worksheet row. What goldray does not know (the e-mail address, the status and
/// the dates) is left empty; the import reads the identifier, the grade and the feedback.
pub fn row(participant: &str, full_name: &str, grade: &str, maximum: &str, feedback: &str) -> Vec<String> {
    [
        &format!("Participant {participant}"),
        full_name,
        "",
        "",
        grade,
        maximum,
        "Yes",
        "",
        "",
        feedback,
    ]
    .map(str::to_owned)
    .to_vec()
}

/// A student's feedback (the self-check's plain text, [`crate::grade::student_feedback`]) as the
/// worksheet's `Feedback comments`. Moodle stores an imported comment as HTML (the comments
/// plugin keeps `FORMAT_HTML`), where a newline is a space and a `<` starts a tag: so the text is
/// escaped (a compiler's `expected '<'` stays text), each line ends in `<br>` and a line's
/// leading spaces are kept as no-break spaces, and the student reads in Moodle the very lines
/// `goldray check` and Gradescope show.
pub fn feedback_comments(plain: &str) -> String {
    plain
        .lines()
        .map(|line| {
            let text = line.trim_start_matches(' ');
            "&nbsp;".repeat(line.len() - text.len()) + &escape(text)
        })
        .collect::<Vec<_>>()
        .join("<br>\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feedback_comments_keep_the_lines_and_escape_what_html_would_read() {
        let plain =
            "2 / 4 points\ncolor.png: fail, 0 / 2\n  your program: exited 1\n  | main.cpp:3: expected '<' & \"x\"";
        assert_eq!(
            feedback_comments(plain),
            "2 / 4 points<br>\ncolor.png: fail, 0 / 2<br>\n&nbsp;&nbsp;your program: exited 1<br>\n\
             &nbsp;&nbsp;| main.cpp:3: expected &#39;&lt;&#39; &amp; &quot;x&quot;"
        );
    }

    #[test]
    fn moodle_folders_and_prefixed_files_come_apart() {
        assert_eq!(
            parse("Ada Lovelace_1234567_assignsubmission_file_"),
            Some(MoodleName {
                full_name: "Ada Lovelace",
                participant: "1234567",
                plugin: "file",
                rest: "",
            })
        );
        let prefixed = parse("Jean_Luc Picard_42_assignsubmission_file_a01.png").unwrap();
        assert_eq!((prefixed.full_name, prefixed.participant), ("Jean_Luc Picard", "42"));
        assert_eq!(prefixed.rest, "a01.png");
        assert_eq!(parse("Ada_x_assignsubmission_file_").map(|m| m.plugin), None);
        assert_eq!(parse("alice"), None);
    }
}
