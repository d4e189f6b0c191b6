//! The TOML case loader must answer every input with a case or a located error, never a panic;
//! and a case it accepts must build and render (shrunk to a few pixels) in both precisions
//! without panicking.
#![no_main]

use std::path::Path;

use goldray::case::{LoadOptions, parse};
use goldray::options::Precision;
use goldray::pipeline::render_case;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(mut case) = parse(text, Path::new("fuzz/case.toml"), &LoadOptions::default()) else {
        return;
    };
    let settings = &mut case.render.trace;
    settings.width = settings.width.min(4);
    settings.height = settings.height.min(4);
    settings.samples = settings.samples.min(4);
    settings.bounces = settings.bounces.min(4);
    for precision in Precision::ALL {
        case.render.precision = precision;
        if let Ok(film) = render_case(&case) {
            assert!(
                film.color.iter().flatten().all(|c| c.is_finite()),
                "a non-finite colour reached the film"
            );
        }
    }
});
