//! One renderer, compiled in two precisions.
//!
//! Geometry, scenes and shading are written once against the names `Real`, `Vec3`, `Mat4`, …
//! and compiled twice: [`single`] binds them to `f32` and glam's `Vec3`, [`double`] to `f64` and
//! `DVec3`. glam has no trait shared by `Vec3` and `DVec3`, so a type parameter would mean
//! wrapping every vector operation and every literal; binding the names per module keeps the
//! code as plain as single-precision code and costs nothing at run time. Each instantiation is
//! monomorphic, so `f32` renders are exactly what they were before `f64` existed.
//!
//! Precision-free parts (options, ray counting, progress, errors, the film) live outside, so a
//! render returns the same types whichever precision drew it;
//! [`with_precision!`](crate::with_precision) picks the instantiation a case asks for.

// Loading the same files as modules of both instantiations is the point, not an accident.
#![allow(clippy::duplicate_mod)]
// Casts between `Real` and `f32`/`f64` are conversions in one instantiation and no-ops in the
// other; the code must say them for the instantiation where they convert.
#![allow(clippy::unnecessary_cast)]

/// Runs `$body` with `$module` naming the instantiation for `$precision`.
#[macro_export]
macro_rules! with_precision {
    ($precision:expr, $module:ident => $body:expr) => {
        match $precision {
            $crate::options::Precision::F32 => {
                use $crate::precision::single as $module;
                $body
            }
            $crate::options::Precision::F64 => {
                use $crate::precision::double as $module;
                $body
            }
        }
    };
}

/// Declares one instantiation: the names bound to its types, then the shared source files.
macro_rules! instantiate {
    ($real:ty, $vec2:ty, $vec3:ty, $mat3:ty, $mat4:ty) => {
        pub type Real = $real;
        pub type Vec2 = $vec2;
        pub type Vec3 = $vec3;
        pub type Mat3 = $mat3;
        pub type Mat4 = $mat4;

        #[path = "../geometry/mod.rs"]
        pub mod geometry;
        #[path = "../real.rs"]
        pub mod real;
        #[path = "../render/mod.rs"]
        pub mod render;
        #[path = "../scene/mod.rs"]
        pub mod scene;
    };
}

pub mod double;
pub mod single;
