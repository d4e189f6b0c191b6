//! The PNG decoding that comparison and grading use must reject any malformed, truncated or
//! hostile file with an error.
#![no_main]

use goldray::compare::Image;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = Image::from_png_bytes(data, "fuzz/student.png");
});
