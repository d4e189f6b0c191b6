//! Where grading time goes, so that a TA sizing a course (and whoever makes grading faster) sees
//! what one student costs and which step to attack.

use std::ops::AddAssign;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// Seconds spent in each step, summed over the images (and students) measured. Steps run on
/// several threads at once, so on a multi-core machine the sum exceeds the wall-clock time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Reading and decoding the submitted PNGs, and hashing them (for resuming and for the copy
    /// checks).
    pub decode: f64,
    /// Comparing with the golden picture, FLIP excluded.
    pub compare: f64,
    /// FLIP, measured only where pictures differ.
    pub flip: f64,
    /// Naming the mistake behind the images that lost points.
    pub diagnosis: f64,
    /// Writing the student's pictures, heatmaps and result.
    pub report: f64,
}

impl Timings {
    pub fn total(&self) -> f64 {
        self.decode + self.compare + self.flip + self.diagnosis + self.report
    }

    /// Each step divided by `n` (per student, per image).
    pub fn per(&self, n: usize) -> Timings {
        let n = n.max(1) as f64;
        Timings {
            decode: self.decode / n,
            compare: self.compare / n,
            flip: self.flip / n,
            diagnosis: self.diagnosis / n,
            report: self.report / n,
        }
    }
}

impl AddAssign for Timings {
    fn add_assign(&mut self, other: Timings) {
        self.decode += other.decode;
        self.compare += other.compare;
        self.flip += other.flip;
        self.diagnosis += other.diagnosis;
        self.report += other.report;
    }
}

/// Runs `work` and adds its duration to `slot`.
pub fn timed<T>(slot: &mut f64, work: impl FnOnce() -> T) -> T {
    let started = Instant::now();
    let result = work();
    *slot += started.elapsed().as_secs_f64();
    result
}

/// A duration as seconds, for [`Timings`].
pub fn seconds(duration: Duration) -> f64 {
    duration.as_secs_f64()
}

/// What one grading run cost: wall-clock time, students graded now and reused from an earlier
/// run, and where the graded students' time went.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunCost {
    /// Wall-clock seconds, from loading the rubric to the last file written (a merge: the sum of
    /// its shards').
    pub seconds: f64,
    /// Students graded in this run.
    pub graded: usize,
    /// Students whose result an earlier run left and whose inputs had not changed.
    pub reused: usize,
    /// Summed over the students graded now. Grading steps are thread-seconds (summed over the
    /// images graded side by side); diagnosis is the wall-clock time of diagnosing each batch
    /// of students, shared among them.
    pub timings: Timings,
    /// Shards combined (1 for a single run).
    pub shards: usize,
}

impl AddAssign<&RunCost> for RunCost {
    fn add_assign(&mut self, other: &RunCost) {
        self.seconds += other.seconds;
        self.graded += other.graded;
        self.reused += other.reused;
        self.timings += other.timings;
        self.shards += other.shards;
    }
}
