//! `precision = "f64"`: every position, direction, error bound and colour in double precision.

instantiate!(f64, glam::DVec2, glam::DVec3, glam::DMat3, glam::DMat4);
