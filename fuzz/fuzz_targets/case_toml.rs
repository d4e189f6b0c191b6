//! The TOML case loader must answer every input with a case or a located error, never a panic.
#![no_main]

use std::path::Path;

use goldray::case::{LoadOptions, parse};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse(text, Path::new("fuzz/case.toml"), &LoadOptions::default());
    }
});
