//! What `goldray run` recorded about the program that was to write an image: `run.json` in the
//! student's folder (see [`crate::sandbox::RunRecord`]). With it, an image whose command crashed,
//! timed out, hit a limit or never ran gets a verdict that says so, with the end of what the
//! program printed on stderr, instead of a bare "missing".
//!
//! The record is read like every other file of a student's folder: a regular file of bounded
//! size, never through a link. A forged record cannot earn points (every verdict it can give
//! scores nothing); at worst it changes the words beside a zero.

use std::fs::{self, File};
use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::outcome::Outcome;
use crate::sandbox::{CommandRecord, Exit, LimitHit, RUN_RECORD, RunRecord};

/// The largest `run.json` read: a rubric's commands with two 64 KiB tails each stay far below.
const MAX_RECORD_BYTES: u64 = 16 << 20;
/// How much of a command's stderr an image's result keeps (the report repeats it per image;
/// the whole tail stays in `run.json`).
const TAIL_BYTES: usize = 4096;
const TAIL_LINES: usize = 40;

/// The command behind an image that did not come out right, as the student's page shows it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProgramRun {
    /// The command line, as run (or, for a failed build, the build's).
    pub command: String,
    /// How it ended: `crashed: SIGSEGV after 0.4 s`, `timed out after 60 s`, `not run: …`.
    pub how: String,
    /// The end of its stderr (at most 40 lines and 4 KiB).
    pub stderr_tail: String,
}

/// The record in a student's folder, when there is one that reads. Links, FIFOs and oversized
/// files are not read.
pub fn read_run_record(folder: &Path) -> Option<RunRecord> {
    let path = folder.join(RUN_RECORD);
    let meta = fs::symlink_metadata(&path).ok()?;
    if !meta.is_file() || meta.len() > MAX_RECORD_BYTES {
        return None;
    }
    let mut bytes = Vec::new();
    File::open(&path)
        .ok()?
        .take(MAX_RECORD_BYTES)
        .read_to_end(&mut bytes)
        .ok()?;
    serde_json::from_slice(&bytes).ok()
}

/// The verdict for `file`, absent from the student's folder, when the record says why: the
/// outcome, the sentence the student reads, and the command. `None` when the record has no
/// command for the file.
pub fn absent_verdict(record: &RunRecord, file: &str) -> Option<(Outcome, String, ProgramRun)> {
    let command = record.command_for(file)?;
    let program = program_run(record, command);
    let problem = command
        .outputs
        .iter()
        .find(|o| o.file == file)
        .and_then(|o| o.problem.clone())
        .unwrap_or_else(|| "not written".to_owned());
    let outcome = match (&command.not_run, &command.outcome) {
        (Some(_), _) | (None, None) => Outcome::NotRun,
        (None, Some(ran)) => match (ran.limit, &ran.exit) {
            (Some(LimitHit::WallTime), _) => Outcome::TimedOut,
            (Some(_), _) => Outcome::OverLimit,
            (None, Exit::Signal { .. }) => Outcome::Crashed,
            (None, Exit::Code(0)) => {
                let explanation = format!(
                    "the program ended normally ({}) but did not deliver {file}: {problem}",
                    program.how
                );
                return Some((Outcome::Missing, explanation, program));
            }
            (None, Exit::Code(_)) => Outcome::ExitError,
        },
    };
    let explanation = format!("{}; no {file}", program.how);
    Some((outcome, explanation, program))
}

/// For a file that is there although its command failed (it wrote the picture, then crashed): a
/// note for the result, and the command. `None` when the command succeeded.
pub fn delivered_note(record: &RunRecord, file: &str) -> Option<(String, ProgramRun)> {
    let command = record.command_for(file)?;
    if command.outcome.as_ref().is_some_and(|o| o.succeeded()) {
        return None;
    }
    let program = program_run(record, command);
    Some((
        format!("the command that wrote it did not end well: {}", program.how),
        program,
    ))
}

/// How `command` ended, with its stderr; for a command that never ran because the build failed,
/// the build's.
fn program_run(record: &RunRecord, command: &CommandRecord) -> ProgramRun {
    let build_failed = record
        .build
        .as_ref()
        .filter(|build| !build.outcome.as_ref().is_some_and(|o| o.succeeded()));
    let (shown, how) = match (&command.outcome, &command.not_run, build_failed) {
        (Some(ran), _, _) => (command, ran.describe(&record.limits)),
        (None, _, Some(build)) => {
            let ending = match (&build.outcome, &build.not_run) {
                (Some(ran), _) => ran.describe(&record.limits),
                (None, Some(why)) => why.clone(),
                (None, None) => "not run".to_owned(),
            };
            (build, format!("not run: the build failed ({ending})"))
        }
        (None, Some(why), None) => (command, why.clone()),
        (None, None, None) => (command, "not run".to_owned()),
    };
    ProgramRun {
        command: display_command(&shown.argv),
        how,
        stderr_tail: shown.outcome.as_ref().map(|o| tail(&o.stderr_tail)).unwrap_or_default(),
    }
}

/// The command as the student would type it: the program by its file name (not the temporary
/// folder it ran from), a build by its own command line (not `sh -c`), arguments with spaces
/// quoted.
fn display_command(argv: &[String]) -> String {
    let words: Vec<String> = match argv {
        [shell, dash_c, command] if shell.ends_with("sh") && dash_c == "-c" => return command.clone(),
        [program, args @ ..] => std::iter::once(
            Path::new(program)
                .file_name()
                .map_or_else(|| program.clone(), |name| name.to_string_lossy().into_owned()),
        )
        .chain(args.iter().cloned())
        .collect(),
        [] => return String::new(),
    };
    words
        .iter()
        .map(|word| {
            if word.is_empty() || word.contains(char::is_whitespace) {
                format!("'{word}'")
            } else {
                word.clone()
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The last [`TAIL_LINES`] lines of `text`, within the last [`TAIL_BYTES`] bytes.
fn tail(text: &str) -> String {
    let text = text.trim_end();
    let mut start = text.len().saturating_sub(TAIL_BYTES);
    while !text.is_char_boundary(start) {
        start += 1;
    }
    let text = &text[start..];
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(TAIL_LINES)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::{absent_verdict, delivered_note, display_command, tail};
    use crate::grade::Outcome;
    use crate::sandbox::{CommandRecord, Exit, LimitHit, Limits, Outcome as Ran, OutputRecord, Protections, RunRecord};

    fn ran(exit: Exit, limit: Option<LimitHit>) -> Ran {
        Ran {
            exit,
            limit,
            wall_seconds: 0.4,
            cpu_seconds: 0.3,
            peak_memory_bytes: 1 << 20,
            stdout_tail: String::new(),
            stderr_tail: "the last words\n".to_owned(),
            stdout_bytes: 0,
            stderr_bytes: 15,
            protections: Protections::default(),
        }
    }

    /// A record of one command writing `a.png`, ended as `outcome`, which delivered it or not.
    fn record(outcome: Ran, delivered: bool) -> RunRecord {
        RunRecord {
            goldray: "test".to_owned(),
            limits: Limits::default(),
            inputs: None,
            build: None,
            commands: vec![CommandRecord {
                name: "scene".to_owned(),
                argv: vec!["/tmp/x/raytracer".to_owned(), "-output".to_owned(), "a.png".to_owned()],
                outputs: vec![OutputRecord {
                    file: "a.png".to_owned(),
                    delivered,
                    problem: (!delivered).then(|| "not written".to_owned()),
                }],
                outcome: Some(outcome),
                not_run: None,
            }],
            skipped: Vec::new(),
        }
    }

    #[test]
    fn each_ending_of_the_program_is_its_own_verdict() {
        let cases = [
            (
                ran(Exit::Code(1), None),
                Outcome::ExitError,
                "exit code 1 after 0.4 s; no a.png",
            ),
            (
                ran(Exit::signal(6), None),
                Outcome::Crashed,
                "crashed: SIGABRT after 0.4 s; no a.png",
            ),
            (
                ran(Exit::signal(9), Some(LimitHit::WallTime)),
                Outcome::TimedOut,
                "timed out after 60 s; no a.png",
            ),
            (
                ran(Exit::signal(9), Some(LimitHit::Memory)),
                Outcome::OverLimit,
                "memory limit (4 GiB); crashed: SIGKILL after 0.4 s; no a.png",
            ),
            (
                ran(Exit::Code(0), None),
                Outcome::Missing,
                "the program ended normally (exit code 0 after 0.4 s) but did not deliver a.png: not written",
            ),
        ];
        for (outcome, verdict, explanation) in cases {
            let (found, said, program) = absent_verdict(&record(outcome, false), "a.png").unwrap();
            assert_eq!((found, said.as_str()), (verdict, explanation));
            assert_eq!(program.stderr_tail, "the last words");
            assert_eq!(program.command, "raytracer -output a.png");
        }
        assert!(absent_verdict(&record(ran(Exit::Code(1), None), false), "b.png").is_none());
    }

    #[test]
    fn a_picture_written_before_a_crash_is_graded_with_a_note() {
        let crashed = record(ran(Exit::signal(11), None), true);
        let (note, _) = delivered_note(&crashed, "a.png").unwrap();
        assert!(note.contains("crashed: SIGSEGV"), "{note}");
        assert!(delivered_note(&record(ran(Exit::Code(0), None), true), "a.png").is_none());
    }

    #[test]
    fn commands_read_as_the_student_would_type_them() {
        let argv = |words: &[&str]| words.iter().map(|w| (*w).to_owned()).collect::<Vec<_>>();
        assert_eq!(
            display_command(&argv(&[
                "/tmp/goldray-run-x/submission/raytracer",
                "-input",
                "data/a b.txt"
            ])),
            "raytracer -input 'data/a b.txt'"
        );
        assert_eq!(display_command(&argv(&["sh", "-c", "make -j2"])), "make -j2");
        assert_eq!(display_command(&[]), "");
    }

    #[test]
    fn the_tail_keeps_the_last_lines_within_the_byte_cap_on_a_character_boundary() {
        let many: String = (0..100).map(|i| format!("line {i}\n")).collect();
        let kept = tail(&many);
        assert_eq!(kept.lines().count(), 40);
        assert!(kept.ends_with("line 99"));
        let wide = "é".repeat(5000);
        let kept = tail(&wide);
        assert!(kept.len() <= 4096 && kept.chars().all(|c| c == 'é'));
    }
}
