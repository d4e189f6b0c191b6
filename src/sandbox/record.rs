//! `run.json`: what a batch of sandboxed commands did, file by file, for the grader and the
//! teaching assistant. Kept beside the sandbox (not with `goldray run`) so that grading can read
//! it without depending on the command that wrote it.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::limits::Limits;
use super::outcome::Outcome;

/// The record's file name in the output folder.
pub const RUN_RECORD: &str = "run.json";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// goldray's version that ran the commands.
    pub goldray: String,
    pub limits: Limits,
    /// The digest of what the run depended on (rubric, scenes, program, build command, the
    /// submission's files): a later run with the same digest need not run again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<String>,
    /// The build command, when there was one.
    pub build: Option<CommandRecord>,
    pub commands: Vec<CommandRecord>,
    /// What was not run and why (a render that the course's command line cannot make).
    pub skipped: Vec<Skipped>,
}

/// One command: what ran, the files it was to write, and what happened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CommandRecord {
    /// The render's name in the rubric (`scene01`), or `build`.
    pub name: String,
    pub argv: Vec<String>,
    pub outputs: Vec<OutputRecord>,
    /// `None` when it did not run; `not_run` says why.
    pub outcome: Option<Outcome>,
    pub not_run: Option<String>,
}

/// One file a command was to write.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutputRecord {
    /// Its name in the output folder (the rubric's).
    pub file: String,
    /// Whether it is there now, from this run.
    pub delivered: bool,
    /// Why not: missing, not a regular file, too large.
    pub problem: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    pub name: String,
    pub reason: String,
}

impl RunRecord {
    /// The record in `dir`, if there is one that reads.
    pub fn read(dir: &Path) -> Option<RunRecord> {
        let text = std::fs::read(dir.join(RUN_RECORD)).ok()?;
        serde_json::from_slice(&text).ok()
    }

    /// The command that was to write `file`.
    pub fn command_for(&self, file: &str) -> Option<&CommandRecord> {
        self.commands.iter().find(|c| c.outputs.iter().any(|o| o.file == file))
    }
}
