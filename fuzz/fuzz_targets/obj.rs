//! The OBJ loader (validation pass, tobj, normals, BVH build) must answer every input with a
//! mesh or an error naming the line, in both precisions.
#![no_main]

use std::path::Path;

use goldray::precision::{double, single};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = Path::new("fuzz/mesh.obj");
    for normals in [
        single::geometry::mesh::NormalSource::FromFileOrAveraged,
        single::geometry::mesh::NormalSource::Averaged,
    ] {
        let _ = single::geometry::mesh::Mesh::from_obj_text(text, path, normals);
    }
    for normals in [
        double::geometry::mesh::NormalSource::FromFileOrAveraged,
        double::geometry::mesh::NormalSource::Averaged,
    ] {
        let _ = double::geometry::mesh::Mesh::from_obj_text(text, path, normals);
    }
});
