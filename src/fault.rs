//! The fault catalogue: the mistakes students typically make in the ray-tracing assignment, each
//! one a small, named change to what goldray renders or writes.
//!
//! A [`Fault`] is one mistake ("the specular highlight is left out", "the depth image is
//! inverted"); a [`FaultSet`] is the mistakes of one imagined student program, with the value of
//! those that come as a family (`gamma-applied=srgb` or `=2.2`, `wrong-bounces=3`). Rendering
//! with a set (`pipeline::render_case_with_faults`) shows what that program would have drawn,
//! which is what `grade` compares a student's picture with to say what went wrong.
//!
//! Each fault acts at one of four places, so that rendering without faults is the code it was
//! before the catalogue existed:
//!
//! - [`Injection::Case`]: the scene description is changed before it is built (ambient left
//!   out, transform lists in the wrong order, the camera's up vector made orthonormal).
//! - [`Injection::Trace`]: the render settings are changed (no shadow rays, another bounce count).
//! - [`Injection::Integrator`]: a check in the integrator. The integrator is generic over a
//!   [`FaultPolicy`]; every render but a diagnosis's uses [`NoFaults`], whose checks are the
//!   constant `false`, so its instantiation compiles to the code without any check.
//! - [`Injection::Output`]: the 8-bit quantisation of the PNGs (gamma, normals not remapped,
//!   depth inverted…), or the picture's orientation.
//!
//! This module is precision-free and knows nothing of scenes: it names the faults and says
//! where each one acts; the layers that act on them import it.

mod catalogue;
mod policy;
mod set;

use std::fmt;
use std::str::FromStr;

use serde::{Serialize, Serializer};

use crate::named_enum::{NamedEnum, UnknownName, named_enum};
pub use catalogue::{INTEGRATOR_FAULTS, ids};
pub use policy::{FaultPolicy, NoFaults};
pub use set::{FaultSet, FaultSetError};

named_enum! {
    /// One mistake of the catalogue, by the id reports, rubrics and flags use.
    pub enum Fault: "fault" {
        // Shading.
        SpecularUnnormalizedReflection = "specular-unnormalized-reflection",
        BlinnPhong = "blinn-phong",
        NoSpecular = "no-specular",
        NoAmbient = "no-ambient",
        NoDiffuseClamp = "no-diffuse-clamp",
        LightColorIgnored = "light-color-ignored",
        NothingShaded = "nothing-shaded",
        FlatShading = "flat-shading",
        // Lights.
        FalloffLinear = "falloff-linear",
        FalloffPlusOne = "falloff-plus-one",
        NoFalloff = "no-falloff",
        DirectionalFlipped = "directional-flipped",
        PointLightMissing = "point-light-missing",
        // Shadows.
        NoShadows = "no-shadows",
        ShadowAcne = "shadow-acne",
        ShadowsBeyondLight = "shadows-beyond-light",
        NoAmbientInShadow = "no-ambient-in-shadow",
        // Reflection.
        NoReflections = "no-reflections",
        ReflectionWithoutKs = "reflection-without-ks",
        ReflectionOnEveryMaterial = "reflection-on-every-material",
        ReflectionAcne = "reflection-acne",
        ReflectedMissBlack = "reflected-miss-black",
        WrongBounces = "wrong-bounces",
        // Geometry and camera.
        NormalsNotInverseTranspose = "normals-not-inverse-transpose",
        TransformDirectionReversed = "transform-direction-reversed",
        TransformDirectionNormalized = "transform-direction-normalized",
        TransformOrderReversed = "transform-order-reversed",
        PlaneOneSided = "plane-one-sided",
        TriangleNormalFlipped = "triangle-normal-flipped",
        PixelMapping = "pixel-mapping",
        FovHalfAngle = "fov-half-angle",
        UpOrthonormalized = "up-orthonormalized",
        PlaneMissing = "plane-missing",
        TriangleMissing = "triangle-missing",
        TransformMissing = "transform-missing",
        // Sampling.
        NoJitter = "no-jitter",
        NoFilter = "no-filter",
        // Outputs.
        GammaApplied = "gamma-applied",
        ColorNotClamped = "color-not-clamped",
        NormalsNotRemapped = "normals-not-remapped",
        DepthInverted = "depth-inverted",
        DepthNotClamped = "depth-not-clamped",
        DepthMissWhite = "depth-miss-white",
        CubemapFaceFlipped = "cubemap-face-flipped",
        CubemapIgnored = "cubemap-ignored",
        BackgroundMissing = "background-missing",
    }
}

/// Which part of the assignment a fault belongs to, for reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    Shading,
    Lights,
    Shadows,
    Reflection,
    Geometry,
    Sampling,
    Outputs,
}

/// Where a fault acts (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Injection {
    Case,
    Trace,
    Integrator,
    Output,
}

/// Which of the course binary's pictures a fault can change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize)]
pub struct Pictures {
    pub color: bool,
    pub normals: bool,
    pub depth: bool,
}

impl Pictures {
    const COLOR: Pictures = Pictures {
        color: true,
        normals: false,
        depth: false,
    };
    const ALL: Pictures = Pictures {
        color: true,
        normals: true,
        depth: true,
    };
    const SHADING_NORMALS: Pictures = Pictures {
        color: true,
        normals: true,
        depth: false,
    };
    const NORMALS: Pictures = Pictures {
        color: false,
        normals: true,
        depth: false,
    };
    const DEPTH: Pictures = Pictures {
        color: false,
        normals: false,
        depth: true,
    };

    fn or(self, other: Pictures) -> Pictures {
        Pictures {
            color: self.color || other.color,
            normals: self.normals || other.normals,
            depth: self.depth || other.depth,
        }
    }
}

/// `gamma-applied=…`: the curve applied before quantising.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gamma {
    /// The sRGB transfer curve.
    Srgb,
    /// `c^(1/γ)`.
    Power(f64),
}

/// `specular-unnormalized-reflection=…`: the length of the unnormalised reflection vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Length {
    /// A constant factor (2 when `R = 2(N·L)N − L` is built from an `N·L` taken twice).
    Factor(f64),
    /// The hit distance `t` (R built from the hit point instead of a direction).
    HitDistance,
}

/// `pixel-mapping=…`: how pixels map to the image plane and the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mapping {
    /// Pixel centres at `(x + ½)/w` instead of the course's `x/(w − 1)`.
    Centres,
    /// Rows not flipped when saving: the picture is upside down.
    UpsideDown,
    /// `horizontal = up × direction`: the picture is mirrored left to right.
    Mirrored,
}

/// `cubemap-face-flipped=…`: which texel axis of each face is read backwards.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flip {
    Vertical,
    Horizontal,
}

/// The value of a fault that comes as a family.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Parameter {
    Gamma(Gamma),
    Length(Length),
    Mapping(Mapping),
    Flip(Flip),
    /// `cubemap-ignored=rrggbb`: the flat colour a miss shows instead of the cube map, in
    /// 8-bit codes (the course writes linear values, so a code is the colour times 255).
    Background([u8; 3]),
    /// `wrong-bounces=n`: the recursion stops after `n` reflections instead of the command's.
    Bounces(u32),
}

#[cfg(test)]
mod tests;
