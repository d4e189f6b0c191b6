//! A rubric's `[limits]`: what `goldray run` allows each student command (wall and CPU time,
//! memory, file size, processes). Each key replaces the sandbox's default; the command line's
//! flags replace these.

use std::time::Duration;

use super::error::RubricError;
use crate::located_toml::{Field, LocatedError, Table};
use crate::sandbox::{LimitOverrides, parse_bytes, parse_duration};

const LIMIT_KEYS: &[&str] = &["wall_time", "cpu_time", "memory", "file_size", "processes"];

/// A limit's value as text, whether the rubric wrote a string (`"90s"`) or a bare number (`60`).
fn text_of(field: &Field) -> Result<String, LocatedError> {
    match field.string() {
        Ok(text) => Ok(text.to_owned()),
        Err(_) => Ok(field.number()?.to_string()),
    }
}

/// `wall_time = 60` or `"90s"`, `memory = "4GiB"` (or a number of bytes), `processes = 256`.
pub fn run_limits(table: &Table) -> Result<LimitOverrides, RubricError> {
    table.check_keys(LIMIT_KEYS)?;
    let time = |f: &Field| -> Result<Option<Duration>, LocatedError> {
        parse_duration(&text_of(f)?)
            .map(Some)
            .map_err(|e| f.error(format!("{}: {e}", f.name)))
    };
    let size = |f: &Field| -> Result<Option<u64>, LocatedError> {
        parse_bytes(&text_of(f)?)
            .map(Some)
            .map_err(|e| f.error(format!("{}: {e}", f.name)))
    };
    Ok(LimitOverrides {
        wall: table.read("wall_time", None, time)?,
        cpu: table.read("cpu_time", None, time)?,
        memory_bytes: table.read("memory", None, size)?,
        file_bytes: table.read("file_size", None, size)?,
        processes: table.read("processes", None, |f| {
            f.integer_in(1..=1_000_000, "must be a whole number from 1 to 1000000")
                .map(Some)
        })?,
    })
}
