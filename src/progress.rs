//! How long-running work says how far it has got, without the library drawing anything.
//!
//! The library reports; the command line decides what a report becomes (a bar on a terminal, one
//! line per step in a log, or nothing with `--quiet`). Keeping the drawing out means a library
//! caller never finds goldray writing to its terminal.

/// Receives progress from a render, a golden preparation, a grading run or a tradeoff sweep.
/// Every method has a do-nothing default, so an observer implements only what it shows. Calls may
/// come from any worker thread.
pub trait Progress: Sync {
    /// A piece of work of `total` units begins; `label` names it ("rendering jitter", "grading").
    fn begin(&self, _label: &str, _total: u64) {}

    /// The work turned out larger: `amount` more units are expected.
    fn grow(&self, _amount: u64) {}

    /// A named step begins (a sweep's setting, a golden render): worth a line in a log.
    fn step(&self, _name: &str) {}

    /// `amount` more units are done.
    fn advance(&self, _amount: u64) {}

    /// One named item is done (a student graded): worth a line in a log.
    fn done(&self, _name: &str) {}

    /// The work is over, whether it succeeded or not.
    fn finish(&self) {}
}

/// Reports to nobody: what library calls that do not ask for progress get.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {}
