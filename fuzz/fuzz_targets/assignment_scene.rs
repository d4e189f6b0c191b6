//! The course scene parser must answer every input with a case or a located error, never a
//! panic; a scene it accepts must export to TOML that loads back, and must build and render
//! (3×3, with shadows and bounces, so that the course's secondary rays and its plane normals
//! are exercised) without panicking. The scene claims to sit in `cases/mit6837/`, so that the
//! course meshes its seeds name resolve; scenes with a cube map are not rendered, because
//! decoding its six 1024² PNGs would cost more than everything else an execution does.
#![no_main]

use std::path::Path;

use goldray::case::{AssignmentOptions, LoadOptions, case_to_toml, parse, parse_assignment_scene};
use goldray::pipeline::render_case;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let options = AssignmentOptions {
        width: 3,
        height: 3,
        bounces: 2,
        shadows: true,
        depth_range: Some((1.0, 20.0)),
        normals: true,
        ..AssignmentOptions::default()
    };
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../cases/mit6837/fuzz.txt"));
    let Ok(case) = parse_assignment_scene(text, path, &options) else {
        return;
    };
    let toml_path = path.with_extension("toml");
    let exported = case_to_toml(&case, &toml_path);
    if let Err(e) = parse(&exported, &toml_path, &LoadOptions::default()) {
        panic!("an accepted scene must export to a case that loads: {e}\n{exported}");
    }
    if case.background.cube_map.is_none() {
        let _ = render_case(&case);
    }
});
