//! Canvas: the names of its "Download Submissions" zip, and the columns its gradebook imports.
//!
//! Canvas puts every file of every student at the top of one zip, each named
//! `name_[LATE_]userid_submissionid_original`: `name` is the student's sortable name with
//! everything but letters and digits dropped (`smithjohn`), `LATE_` marks a submission after the
//! due date, the two numbers are the Canvas user id and the submission id, and `original` is the
//! name the student uploaded (a zip of their own among them). The gradebook takes grades back as
//! a CSV whose first five columns identify the student (`Student`, `ID`, `SIS User ID`,
//! `SIS Login ID`, `Section`) and whose further columns are assignments by name; Canvas matches
//! rows on `ID`, so the name need not be the gradebook's `Last, First`.

/// One file of a Canvas download, its name taken apart.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CanvasFile<'a> {
    pub name: &'a str,
    pub late: bool,
    pub user_id: &'a str,
    pub submission_id: &'a str,
    /// The name the student uploaded.
    pub original: &'a str,
}

/// `name` (one file name, no folder) as Canvas names a submission's file, or `None`.
pub fn parse(file_name: &str) -> Option<CanvasFile<'_>> {
    let (name, rest) = file_name.split_once('_')?;
    let (late, rest) = match rest.strip_prefix("LATE_") {
        Some(rest) => (true, rest),
        None => (false, rest),
    };
    let (user_id, rest) = rest.split_once('_')?;
    let (submission_id, original) = rest.split_once('_')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (!name.is_empty() && digits(user_id) && digits(submission_id) && !original.is_empty()).then_some(CanvasFile {
        name,
        late,
        user_id,
        submission_id,
        original,
    })
}

/// Canvas's mark of a file uploaded again: `-N` before the extension of the name (`a01-1.png` for a
/// second `a01.png`, `a01-2.png` for a third), N a positive number without leading zeros. The name
/// as uploaded and N, or `None` for a name without the mark.
pub fn resubmission(original: &str) -> Option<(String, u32)> {
    let (stem, extension) = match original.rfind('.') {
        Some(at) if at > 0 => original.split_at(at),
        _ => (original, ""),
    };
    let (base, n) = stem.rsplit_once('-')?;
    let digits = !n.starts_with('0') && n.bytes().all(|b| b.is_ascii_digit());
    let n: u32 = n.parse().ok().filter(|_| digits && !base.is_empty())?;
    Some((format!("{base}{extension}"), n))
}

/// The gradebook import's identifying columns; the assignment's column follows them.
pub const IDENTITY_COLUMNS: [&str; 5] = ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"];

/// The import's header: the identifying columns, then the assignment (as the gradebook names it,
/// `Assignment 4 (1234)`, so that Canvas matches the column rather than making a new one).
pub fn header(assignment: &str) -> Vec<String> {
    IDENTITY_COLUMNS
        .iter()
        .map(|c| (*c).to_owned())
        .chain([assignment.to_owned()])
        .collect()
}

/// The row Canvas's own export puts second, which its import reads as the assignment's maximum.
pub fn points_possible(max_points: &str) -> Vec<String> {
    ["Points Possible", "", "", "", "", max_points]
        .map(str::to_owned)
        .to_vec()
}

/// One student's row: Canvas matches on the user id; the SIS columns and the section are left
/// for Canvas to keep as they are.
pub fn row(name: &str, user_id: &str, points: &str) -> Vec<String> {
    [name, user_id, "", "", "", points].map(str::to_owned).to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canvas_names_come_apart_with_late_and_the_original_name() {
        assert_eq!(
            parse("smithjohn_LATE_12345_67890_a01.png"),
            Some(CanvasFile {
                name: "smithjohn",
                late: true,
                user_id: "12345",
                submission_id: "67890",
                original: "a01.png",
            })
        );
        let on_time = parse("doejane_222_333_my_render_a01.png").unwrap();
        assert!(!on_time.late);
        assert_eq!(on_time.original, "my_render_a01.png");
        assert_eq!(parse("a01.png"), None);
        assert_eq!(parse("smith_x12_3_a.png"), None);
        assert_eq!(parse("smith_12_3_"), None);
    }

    #[test]
    fn a_resubmission_mark_is_a_positive_number_before_the_extension() {
        assert_eq!(resubmission("a01-1.png"), Some(("a01.png".to_owned(), 1)));
        assert_eq!(resubmission("my-render-12.png"), Some(("my-render.png".to_owned(), 12)));
        assert_eq!(resubmission("notes-2"), Some(("notes".to_owned(), 2)));
        for name in [
            "a01.png",
            "a01-0.png",
            "a01-01.png",
            "a01-.png",
            "-1.png",
            "a01-x.png",
            "a01-1a.png",
        ] {
            assert_eq!(resubmission(name), None, "{name}");
        }
        assert_eq!(resubmission("a01-99999999999.png"), None, "beyond u32: not Canvas's");
    }
}
