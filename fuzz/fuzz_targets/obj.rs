//! The OBJ loader (validation pass, tobj, normals, BVH build) must answer every input with a
//! mesh or an error naming the line.
#![no_main]

use std::path::Path;

use goldray::geometry::mesh::{Mesh, NormalSource};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        for normals in [NormalSource::FromFileOrAveraged, NormalSource::Averaged] {
            let _ = Mesh::from_obj_text(text, Path::new("fuzz/mesh.obj"), normals);
        }
    }
});
