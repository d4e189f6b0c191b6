//! What the sandbox's processes tell each other: the request the library hands to
//! `goldray __sandbox-init`, its reply, and the lines its child processes write on the status
//! pipe while they set up and run the command.

use serde::{Deserialize, Serialize};

use super::Job;
use super::limits::Limits;
use super::outcome::{Exit, Outcome, Protections};

/// The library → the sandbox's init, as JSON on the init's standard input.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Request {
    pub job: Job,
    pub limits: Limits,
}

/// The sandbox's init → the library, as JSON on the init's standard output.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Reply {
    Done(Box<Outcome>),
    /// The sandbox itself failed (not the command): a pipe, a fork.
    Failed(String),
}

/// One line of the status pipe, from the namespace's first process or the command's process.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Status {
    /// The protections in force so far: sent by the first process after its mounts, and again by
    /// the command's process with its own confinement just before it becomes the program.
    Protections(Protections),
    /// The program could not be started (exec failed).
    ExecFailed(String),
    /// How the program's process ended.
    Exited(Exit),
}
