//! The course scene parser must answer every input with a case or a located error.
#![no_main]

use std::path::Path;

use goldray::case::{AssignmentOptions, parse_assignment_scene};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_assignment_scene(text, Path::new("fuzz/scene.txt"), &AssignmentOptions::default());
    }
});
