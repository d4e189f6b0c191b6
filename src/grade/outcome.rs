//! The verdict on one submitted file: what grading and reading a submission both produce.

use serde::{Deserialize, Serialize};

/// The verdict on one expected file. Only the first three come from a comparison; the others say
/// why there was nothing to compare, and score nothing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Outcome {
    /// Within the rule's pass limits: full points.
    Pass,
    /// Within the partial limits only: `partial_credit × points`.
    Partial,
    /// Beyond the partial limits: no points.
    Fail,
    /// No such file in the student's folder.
    Missing,
    /// A readable PNG of another size than the golden image.
    WrongSize { expected: [u32; 2], actual: [u32; 2] },
    /// Not a PNG: an EXR, a JPEG, a text file…
    WrongFormat { found: String },
    /// Refused before decoding: a huge file, or a PNG declaring a huge picture.
    TooLarge { reason: String },
    /// A PNG that cannot be decoded (truncated, corrupt), or a file that cannot be read.
    Unreadable { reason: String },
    /// A symbolic link, or a file that resolves outside the student's folder: not read, because
    /// it is not the student's own file. The reason says where it points.
    Linked { reason: String },
    /// From `goldray run`'s record: the program that was to write the file was killed by a
    /// signal (a segfault, an abort).
    Crashed,
    /// From the record: the program ran out of wall-clock time.
    TimedOut,
    /// From the record: the program hit a limit other than time (memory, CPU, file size,
    /// processes).
    OverLimit,
    /// From the record: the program exited with a non-zero code.
    ExitError,
    /// From the record: the program never ran (its build failed, or it was not there).
    NotRun,
}

impl Outcome {
    pub fn word(&self) -> &'static str {
        match self {
            Outcome::Pass => "pass",
            Outcome::Partial => "partial",
            Outcome::Fail => "fail",
            Outcome::Missing => "missing",
            Outcome::WrongSize { .. } => "wrong size",
            Outcome::WrongFormat { .. } => "wrong format",
            Outcome::TooLarge { .. } => "too large",
            Outcome::Unreadable { .. } => "unreadable",
            Outcome::Linked { .. } => "linked",
            Outcome::Crashed => "crashed",
            Outcome::TimedOut => "timed out",
            Outcome::OverLimit => "over limit",
            Outcome::ExitError => "exit error",
            Outcome::NotRun => "not run",
        }
    }
}
