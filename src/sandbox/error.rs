//! Why a command could not be run at all (as opposed to a command that ran and failed, which is
//! an [`super::Outcome`]).

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum SandboxError {
    #[error("the program must be given by absolute path, not {}", .0.display())]
    RelativeProgram(PathBuf),

    #[error("the working folder {} is not a folder", .0.display())]
    WorkingDir(PathBuf),

    #[error("cannot start the sandbox ({}): {source}", init.display())]
    Start { init: PathBuf, source: std::io::Error },

    #[error("the sandbox could not run the command: {0}")]
    Setup(String),

    #[error("the sandbox ended ({status}) without saying what happened{}", stderr_suffix(.stderr))]
    NoReport { status: String, stderr: String },

    #[error("the sandbox was still running {0} s after the command's wall-time limit, and was killed")]
    Hung(u64),

    #[error("the job cannot be handed to the sandbox: {0}")]
    Encode(#[from] serde_json::Error),

    #[error("the sandbox needs Linux")]
    Unsupported,
}

fn stderr_suffix(stderr: &str) -> String {
    match stderr.trim() {
        "" => String::new(),
        text => format!(": {text}"),
    }
}
