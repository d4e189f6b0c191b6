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

use std::fmt;
use std::str::FromStr;

use serde::{Serialize, Serializer};

use crate::named_enum::{NamedEnum, UnknownName, named_enum};

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
        // Outputs.
        GammaApplied = "gamma-applied",
        ColorNotClamped = "color-not-clamped",
        NormalsNotRemapped = "normals-not-remapped",
        DepthInverted = "depth-inverted",
        DepthNotClamped = "depth-not-clamped",
        DepthMissWhite = "depth-miss-white",
        CubemapFaceFlipped = "cubemap-face-flipped",
        CubemapIgnored = "cubemap-ignored",
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

impl Fault {
    pub const fn bit(self) -> u64 {
        1 << self as u32
    }

    pub const fn stage(self) -> Stage {
        use Fault::*;
        match self {
            SpecularUnnormalizedReflection
            | BlinnPhong
            | NoSpecular
            | NoAmbient
            | NoDiffuseClamp
            | LightColorIgnored
            | NothingShaded
            | FlatShading => Stage::Shading,
            FalloffLinear | FalloffPlusOne | NoFalloff | DirectionalFlipped => Stage::Lights,
            NoShadows | ShadowAcne | ShadowsBeyondLight | NoAmbientInShadow => Stage::Shadows,
            NoReflections
            | ReflectionWithoutKs
            | ReflectionOnEveryMaterial
            | ReflectionAcne
            | ReflectedMissBlack
            | WrongBounces => Stage::Reflection,
            NormalsNotInverseTranspose
            | TransformDirectionReversed
            | TransformDirectionNormalized
            | TransformOrderReversed
            | PlaneOneSided
            | TriangleNormalFlipped
            | PixelMapping
            | FovHalfAngle
            | UpOrthonormalized => Stage::Geometry,
            GammaApplied | ColorNotClamped | NormalsNotRemapped | DepthInverted | DepthNotClamped | DepthMissWhite
            | CubemapFaceFlipped | CubemapIgnored => Stage::Outputs,
        }
    }

    /// Where the fault acts. `pixel-mapping` acts on the camera (`centres`, listed here) or on
    /// the PNGs (`upside-down`, `mirrored`): see [`FaultSet::render_part`].
    pub const fn injection(self) -> Injection {
        use Fault::*;
        match self {
            NoAmbient
            | DirectionalFlipped
            | TransformOrderReversed
            | FovHalfAngle
            | UpOrthonormalized
            | CubemapIgnored
            | PixelMapping => Injection::Case,
            NoShadows | NoReflections | WrongBounces => Injection::Trace,
            GammaApplied | ColorNotClamped | NormalsNotRemapped | DepthInverted | DepthNotClamped | DepthMissWhite => {
                Injection::Output
            }
            _ => Injection::Integrator,
        }
    }

    /// The pictures this fault can change (whether it does depends on the scene).
    pub const fn pictures(self) -> Pictures {
        use Fault::*;
        match self {
            FlatShading | NormalsNotInverseTranspose | TriangleNormalFlipped => Pictures::SHADING_NORMALS,
            TransformDirectionReversed
            | TransformDirectionNormalized
            | TransformOrderReversed
            | PlaneOneSided
            | PixelMapping
            | FovHalfAngle
            | UpOrthonormalized => Pictures::ALL,
            NormalsNotRemapped => Pictures::NORMALS,
            DepthInverted | DepthNotClamped | DepthMissWhite => Pictures::DEPTH,
            _ => Pictures::COLOR,
        }
    }

    /// What the student's program does, as a sentence for the student.
    pub const fn explanation(self) -> &'static str {
        use Fault::*;
        match self {
            SpecularUnnormalizedReflection => {
                "your specular highlight uses R·V with R not normalised: highlights come out the wrong size and brightness"
            }
            BlinnPhong => "your highlight uses the half vector (Blinn–Phong) instead of R·V: highlights are too wide",
            NoSpecular => "the specular (Phong) highlight is missing",
            NoAmbient => "the ambient term is missing: unlit parts are black instead of dim",
            NoDiffuseClamp => "N·L is not clamped at 0: surfaces facing away from a light get darker than ambient",
            LightColorIgnored => "the light's colour is ignored: every light shines white at full strength",
            NothingShaded => "nothing is shaded yet: every object shows its flat material colour (the starter code)",
            FlatShading => "triangles are shaded with their face normal instead of interpolated vertex normals",
            FalloffLinear => "a point light falls off as 1/(falloff·d) instead of 1/(falloff·d²)",
            FalloffPlusOne => "a point light falls off as 1/(1 + falloff·d²) instead of 1/(falloff·d²)",
            NoFalloff => "a point light does not fall off with distance",
            DirectionalFlipped => "a directional light's direction is used as the direction towards the light",
            NoShadows => "no shadow rays are cast: nothing is in shadow",
            ShadowAcne => "shadow rays start exactly at the hit point: lit surfaces are speckled with shadow (acne)",
            ShadowsBeyondLight => {
                "shadow rays to a point light are not stopped at the light: objects behind it cast shadows"
            }
            NoAmbientInShadow => "a point in shadow of every light is black: the ambient term is skipped there",
            NoReflections => "no reflected rays are traced: mirrors show only their own shading",
            ReflectionWithoutKs => {
                "the reflected colour is not multiplied by the specular colour: reflections are too strong"
            }
            ReflectionOnEveryMaterial => "every material reflects, not only those with a specular colour",
            ReflectionAcne => "reflected rays start exactly at the hit point: mirrors are speckled (reflection acne)",
            ReflectedMissBlack => "a reflected ray that hits nothing returns black instead of the background",
            WrongBounces => "the recursion stops after another number of bounces than -bounces asks for",
            NormalsNotInverseTranspose => {
                "normals of transformed objects are transformed by M instead of its inverse transpose"
            }
            TransformDirectionReversed => {
                "the ray direction in object space comes out reversed: transformed objects go missing"
            }
            TransformDirectionNormalized => {
                "the object-space ray direction is normalised, so t is no longer the world distance"
            }
            TransformOrderReversed => "transform operations are applied in the opposite order",
            PlaneOneSided => "planes are only hit from the front",
            TriangleNormalFlipped => "triangle normals point the wrong way ((v2−v0)×(v1−v0))",
            PixelMapping => "pixels map to the image wrongly (pixel centres, or the image upside down or mirrored)",
            FovHalfAngle => "the camera's angle is used as the half angle (d = 1/tan(angle)): the view is too wide",
            UpOrthonormalized => "the camera's up vector is made unit and perpendicular; the course uses it as given",
            GammaApplied => "a gamma curve is applied before writing; the course writes linear values",
            ColorNotClamped => "colours are not clamped: values above 1 wrap around to dark",
            NormalsNotRemapped => "normals are written as n instead of (n + 1)/2: negative components are black",
            DepthInverted => "the depth image is inverted: near is white and far is black",
            DepthNotClamped => "depths outside [min, max] are not clamped and wrap around",
            DepthMissWhite => "pixels that hit nothing are white in the depth image instead of black",
            CubemapFaceFlipped => "cube-map faces are read flipped",
            CubemapIgnored => "the cube map is ignored: rays that miss see the background colour",
        }
    }

    /// Where in the assignment's code the mistake usually lives.
    pub const fn hint(self) -> &'static str {
        use Fault::*;
        match self {
            SpecularUnnormalizedReflection => "Material::Shade: normalise R (and L, V) before R·V",
            BlinnPhong => "Material::Shade: R = 2(N·L)N − L, then clamp(R·V)^shininess",
            NoSpecular => "Material::Shade: add clamp(R·V)^shininess · ks · light colour",
            NoAmbient => "RayTracer::traceRay: start from ambient light · diffuse colour",
            NoDiffuseClamp => "Material::Shade: clamp N·L at 0 before multiplying",
            LightColorIgnored => "Material::Shade: multiply by the colour getIllumination returns",
            NothingShaded => {
                "RayTracer::traceRay: replace the starter's diffuse colour by the Phong sum over the lights"
            }
            FlatShading => "Triangle::intersect: interpolate the vertex normals with the barycentric coordinates",
            FalloffLinear | FalloffPlusOne | NoFalloff => "PointLight::getIllumination: colour / (falloff · d²)",
            DirectionalFlipped => "DirectionalLight::getIllumination: the direction towards the light is −direction",
            NoShadows => "RayTracer::traceRay: with -shadows, cast a shadow ray per light before shading it",
            ShadowAcne => "RayTracer::traceRay: start shadow rays a little off the surface (tmin = 1e-4, not 0)",
            ShadowsBeyondLight => "RayTracer::traceRay: count shadow-ray hits only closer than the light",
            NoAmbientInShadow => "RayTracer::traceRay: add the ambient term whatever the shadow rays find",
            NoReflections => "RayTracer::traceRay: recurse along mirrorDirection while bounces remain",
            ReflectionWithoutKs => "RayTracer::traceRay: multiply the reflected colour by the specular colour",
            ReflectionOnEveryMaterial => "RayTracer::traceRay: reflect only materials with a specular colour",
            ReflectionAcne => "RayTracer::traceRay: start reflected rays a little off the surface (tmin > 0)",
            ReflectedMissBlack => "RayTracer::traceRay: a reflected ray that misses returns the background or cube map",
            WrongBounces => "RayTracer::traceRay: recurse exactly -bounces times",
            NormalsNotInverseTranspose => "Transform::intersect: transform normals by (M⁻¹)ᵀ, then normalise",
            TransformDirectionReversed => "Transform::intersect: direction = M⁻¹·(d, 0): w = 0, same sign",
            TransformDirectionNormalized => "Transform::intersect: keep M⁻¹·d unnormalised so that t stays the world t",
            TransformOrderReversed => "SceneParser / Transform: each operation does M = M · op",
            PlaneOneSided => "Plane::intersect: accept hits whatever the sign of n·d",
            TriangleNormalFlipped => "Triangle / Mesh: normal = (v1 − v0) × (v2 − v0), in that order",
            PixelMapping => "main: pixel (x, y) → (2x/(w−1) − 1, 2y/(h−1) − 1), rows flipped when saving",
            FovHalfAngle => "PerspectiveCamera: distance to the image plane = 1/tan(angle/2)",
            UpOrthonormalized => "PerspectiveCamera: use up as the scene gives it",
            GammaApplied => "main / Image::SaveImage: write clamp(c)·255, no gamma",
            ColorNotClamped => "Image::SaveImage: clamp each channel to [0, 1] before ×255",
            NormalsNotRemapped => "main: write (n + 1)/2 per channel",
            DepthInverted => "main: grey = (t − min)/(max − min), near black",
            DepthNotClamped => "main: clamp (t − min)/(max − min) to [0, 1]",
            DepthMissWhite => "main: a pixel with no hit is black in the depth image",
            CubemapFaceFlipped => "CubeMap: the face's (u, v) and texel row order",
            CubemapIgnored => "RayTracer::traceRay: a miss returns the cube map's colour when the scene has one",
        }
    }

    /// Whether the fault comes as a family whose member must be named (or fitted).
    pub const fn is_family(self) -> bool {
        matches!(
            self,
            Fault::SpecularUnnormalizedReflection
                | Fault::WrongBounces
                | Fault::PixelMapping
                | Fault::GammaApplied
                | Fault::CubemapFaceFlipped
                | Fault::CubemapIgnored
        )
    }

    /// Whether the fault's picture is noise whose speckles an independent program draws
    /// elsewhere (acne): compared by local density, not pixel by pixel.
    pub const fn is_speckle(self) -> bool {
        matches!(self, Fault::ShadowAcne | Fault::ReflectionAcne)
    }
}

/// The bits of the faults the integrator checks.
pub const INTEGRATOR_FAULTS: u64 = mask(Injection::Integrator);
const OUTPUT_FAULTS: u64 = mask(Injection::Output);

const fn mask(injection: Injection) -> u64 {
    let mut bits = 0;
    let mut i = 0;
    while i < Fault::ALL.len() {
        let fault = Fault::ALL[i];
        if fault.injection() as u8 == injection as u8 {
            bits |= fault.bit();
        }
        i += 1;
    }
    bits
}

/// The mistakes of one imagined program: a set of faults with the values of those that come as a
/// family. Written `no-shadows+gamma-applied=srgb` (catalogue order, `+` between faults); the
/// empty set is `none`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultSet {
    bits: u64,
    gamma: Gamma,
    length: Length,
    mapping: Mapping,
    flip: Flip,
    bounces: u32,
    background: [u8; 3],
}

impl Default for FaultSet {
    fn default() -> FaultSet {
        FaultSet::NONE
    }
}

impl FaultSet {
    pub const NONE: FaultSet = FaultSet {
        bits: 0,
        gamma: Gamma::Srgb,
        length: Length::Factor(2.0),
        mapping: Mapping::Centres,
        flip: Flip::Vertical,
        bounces: 0,
        background: [0; 3],
    };

    /// One fault, a family's with its first member (`gamma-applied=srgb`,
    /// `specular-unnormalized-reflection=2`, `pixel-mapping=centres`, `cubemap-face-flipped=vertical`,
    /// `wrong-bounces=0`).
    pub fn single(fault: Fault) -> FaultSet {
        FaultSet::NONE.and(fault)
    }

    /// This set and `fault` (a family's with the value it has in this set).
    pub fn and(self, fault: Fault) -> FaultSet {
        FaultSet {
            bits: self.bits | fault.bit(),
            ..self
        }
    }

    /// This set and the family member `parameter` names.
    pub fn with(mut self, parameter: Parameter) -> FaultSet {
        let fault = match parameter {
            Parameter::Gamma(gamma) => {
                self.gamma = gamma;
                Fault::GammaApplied
            }
            Parameter::Length(length) => {
                self.length = length;
                Fault::SpecularUnnormalizedReflection
            }
            Parameter::Mapping(mapping) => {
                self.mapping = mapping;
                Fault::PixelMapping
            }
            Parameter::Flip(flip) => {
                self.flip = flip;
                Fault::CubemapFaceFlipped
            }
            Parameter::Bounces(bounces) => {
                self.bounces = bounces;
                Fault::WrongBounces
            }
            Parameter::Background(color) => {
                self.background = color;
                Fault::CubemapIgnored
            }
        };
        self.and(fault)
    }

    /// The set of `bits` with this set's values where they still apply and the defaults
    /// elsewhere, so that equal sets compare equal however they were made.
    fn keeping(&self, bits: u64) -> FaultSet {
        let has = |fault: Fault| bits & fault.bit() != 0;
        let none = FaultSet::NONE;
        FaultSet {
            bits,
            gamma: if has(Fault::GammaApplied) {
                self.gamma
            } else {
                none.gamma
            },
            length: if has(Fault::SpecularUnnormalizedReflection) {
                self.length
            } else {
                none.length
            },
            mapping: if has(Fault::PixelMapping) {
                self.mapping
            } else {
                none.mapping
            },
            flip: if has(Fault::CubemapFaceFlipped) {
                self.flip
            } else {
                none.flip
            },
            bounces: if has(Fault::WrongBounces) {
                self.bounces
            } else {
                none.bounces
            },
            background: if has(Fault::CubemapIgnored) {
                self.background
            } else {
                none.background
            },
        }
    }

    /// Both sets' faults; `other`'s values win where both have a family.
    pub fn union(self, other: FaultSet) -> FaultSet {
        let mut union = self.keeping(self.bits | other.bits);
        for parameter in other.parameters() {
            union = union.with(parameter);
        }
        union
    }

    /// The family members of this set, as parameters.
    pub fn parameters(&self) -> Vec<Parameter> {
        self.faults()
            .filter_map(|fault| match fault {
                Fault::GammaApplied => Some(Parameter::Gamma(self.gamma)),
                Fault::SpecularUnnormalizedReflection => Some(Parameter::Length(self.length)),
                Fault::PixelMapping => Some(Parameter::Mapping(self.mapping)),
                Fault::CubemapFaceFlipped => Some(Parameter::Flip(self.flip)),
                Fault::WrongBounces => Some(Parameter::Bounces(self.bounces)),
                Fault::CubemapIgnored => Some(Parameter::Background(self.background)),
                _ => None,
            })
            .collect()
    }

    pub fn contains(&self, fault: Fault) -> bool {
        self.bits & fault.bit() != 0
    }

    pub fn is_empty(&self) -> bool {
        self.bits == 0
    }

    pub fn len(&self) -> usize {
        self.bits.count_ones() as usize
    }

    /// The faults, in catalogue order.
    pub fn faults(&self) -> impl Iterator<Item = Fault> + '_ {
        Fault::ALL.into_iter().filter(|f| self.contains(*f))
    }

    pub fn gamma(&self) -> Gamma {
        self.gamma
    }

    pub fn length(&self) -> Length {
        self.length
    }

    pub fn mapping(&self) -> Option<Mapping> {
        self.contains(Fault::PixelMapping).then_some(self.mapping)
    }

    pub fn flip(&self) -> Flip {
        self.flip
    }

    /// The colour of `cubemap-ignored=rrggbb`, linear.
    pub fn background(&self) -> [f64; 3] {
        self.background.map(|c| f64::from(c) / 255.0)
    }

    /// `n` of `wrong-bounces=n`, when the set has it.
    pub fn bounces(&self) -> Option<u32> {
        self.contains(Fault::WrongBounces).then_some(self.bounces)
    }

    /// Whether `fault` of this set acts on the PNGs: the output faults, and `pixel-mapping`'s
    /// flips.
    fn on_output(&self, fault: Fault) -> bool {
        match fault {
            Fault::PixelMapping => self.mapping != Mapping::Centres,
            _ => fault.injection() == Injection::Output,
        }
    }

    /// Without the faults that act on the PNGs: what has to be rendered.
    pub fn render_part(&self) -> FaultSet {
        let bits = self
            .faults()
            .filter(|f| !self.on_output(*f))
            .fold(0, |bits, f| bits | f.bit());
        self.keeping(bits)
    }

    /// Only the faults that act on the PNGs.
    pub fn output_part(&self) -> FaultSet {
        let bits = self
            .faults()
            .filter(|f| self.on_output(*f))
            .fold(0, |bits, f| bits | f.bit());
        self.keeping(bits)
    }

    /// Only the faults acting where `injection` says (`pixel-mapping` as [`Fault::injection`]).
    pub fn only(&self, injection: Injection) -> FaultSet {
        self.keeping(self.bits & mask(injection))
    }

    /// Without `fault`.
    pub fn without(&self, fault: Fault) -> FaultSet {
        self.keeping(self.bits & !fault.bit())
    }

    /// Whether the integrator has anything to check.
    pub fn checks_integrator(&self) -> bool {
        self.bits & INTEGRATOR_FAULTS != 0
    }

    /// Whether the set has faults that act on the PNGs.
    pub fn has_output_faults(&self) -> bool {
        self.bits & OUTPUT_FAULTS != 0 || self.mapping().is_some_and(|m| m != Mapping::Centres)
    }

    /// The pictures any of the faults can change.
    pub fn pictures(&self) -> Pictures {
        self.faults().fold(Pictures::default(), |p, f| p.or(f.pictures()))
    }

    /// One fault's id with its value: `gamma-applied=2.2`, `wrong-bounces=3`, `no-shadows`.
    pub fn label(&self, fault: Fault) -> String {
        let value = match fault {
            Fault::GammaApplied => match self.gamma {
                Gamma::Srgb => "srgb".to_owned(),
                Gamma::Power(g) => short(g),
            },
            Fault::SpecularUnnormalizedReflection => match self.length {
                Length::Factor(k) => short(k),
                Length::HitDistance => "t".to_owned(),
            },
            Fault::PixelMapping => match self.mapping {
                Mapping::Centres => "centres",
                Mapping::UpsideDown => "upside-down",
                Mapping::Mirrored => "mirrored",
            }
            .to_owned(),
            Fault::CubemapFaceFlipped => match self.flip {
                Flip::Vertical => "vertical",
                Flip::Horizontal => "horizontal",
            }
            .to_owned(),
            Fault::WrongBounces => self.bounces.to_string(),
            Fault::CubemapIgnored => self.background.iter().map(|c| format!("{c:02x}")).collect(),
            _ => return fault.name().to_owned(),
        };
        format!("{}={value}", fault.name())
    }

    /// The catalogue ids of the faults, without values, joined by `+`: `no-shadows+gamma-applied`.
    pub fn id(&self) -> String {
        let ids: Vec<&str> = self.faults().map(Fault::name).collect();
        if ids.is_empty() {
            "none".to_owned()
        } else {
            ids.join("+")
        }
    }

    /// What the program does, fault by fault, for the student, with the family member named.
    pub fn explain(&self) -> String {
        let parts: Vec<String> = self
            .faults()
            .map(|fault| {
                let member = match fault {
                    Fault::GammaApplied => match self.gamma {
                        Gamma::Srgb => "the sRGB curve".to_owned(),
                        Gamma::Power(g) => format!("γ = {}", short(g)),
                    },
                    Fault::SpecularUnnormalizedReflection => match self.length {
                        Length::Factor(k) => format!("|R| ≈ {}", short(k)),
                        Length::HitDistance => "|R| = the hit distance".to_owned(),
                    },
                    Fault::PixelMapping => match self.mapping {
                        Mapping::Centres => "pixel centres at (x + ½)/w".to_owned(),
                        Mapping::UpsideDown => "upside down".to_owned(),
                        Mapping::Mirrored => "mirrored left to right".to_owned(),
                    },
                    Fault::CubemapFaceFlipped => match self.flip {
                        Flip::Vertical => "rows reversed".to_owned(),
                        Flip::Horizontal => "columns reversed".to_owned(),
                    },
                    Fault::WrongBounces => format!("{} bounce(s)", self.bounces),
                    Fault::CubemapIgnored => {
                        let [r, g, b] = self.background.map(|c| short(f64::from(c) / 255.0));
                        format!("the colour {r} {g} {b}")
                    }
                    _ => return fault.explanation().to_owned(),
                };
                format!("{} ({member})", fault.explanation())
            })
            .collect();
        if parts.is_empty() {
            "no mistake".to_owned()
        } else {
            parts.join("; and ")
        }
    }
}

/// A number as short as it reads: `2.2`, `1.85`, `3`.
fn short(value: f64) -> String {
    let text = format!("{value:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

impl fmt::Display for FaultSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("none");
        }
        let labels: Vec<String> = self.faults().map(|fault| self.label(fault)).collect();
        f.write_str(&labels.join("+"))
    }
}

impl Serialize for FaultSet {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

/// Why a fault set could not be read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FaultSetError {
    #[error(transparent)]
    Unknown(#[from] UnknownName),
    #[error("`{0}` takes no value")]
    TakesNoValue(Fault),
    #[error("`{text}` is not a member of {fault}: {expected}")]
    BadValue {
        fault: Fault,
        text: String,
        expected: &'static str,
    },
}

impl FromStr for FaultSet {
    type Err = FaultSetError;

    /// `none`, or faults joined by `+` (or `,`), each `id` or `id=value`.
    fn from_str(text: &str) -> Result<FaultSet, FaultSetError> {
        let mut set = FaultSet::NONE;
        if text.trim() == "none" {
            return Ok(set);
        }
        for part in text.split(['+', ',']).map(str::trim) {
            let (name, value) = match part.split_once('=') {
                Some((name, value)) => (name.trim(), Some(value.trim())),
                None => (part, None),
            };
            let fault: Fault = name.parse()?;
            let Some(value) = value else {
                set = set.and(fault);
                continue;
            };
            let bad = |expected| FaultSetError::BadValue {
                fault,
                text: value.to_owned(),
                expected,
            };
            let number = value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0 && *v <= 100.0);
            let parameter = match fault {
                Fault::GammaApplied => match (value, number) {
                    ("srgb", _) => Parameter::Gamma(Gamma::Srgb),
                    (_, Some(g)) => Parameter::Gamma(Gamma::Power(g)),
                    _ => return Err(bad("srgb, or a positive number")),
                },
                Fault::SpecularUnnormalizedReflection => match (value, number) {
                    ("t", _) => Parameter::Length(Length::HitDistance),
                    (_, Some(k)) => Parameter::Length(Length::Factor(k)),
                    _ => return Err(bad("t, or a positive number")),
                },
                Fault::PixelMapping => Parameter::Mapping(match value {
                    "centres" | "centers" => Mapping::Centres,
                    "upside-down" => Mapping::UpsideDown,
                    "mirrored" => Mapping::Mirrored,
                    _ => return Err(bad("centres, upside-down or mirrored")),
                }),
                Fault::CubemapFaceFlipped => Parameter::Flip(match value {
                    "vertical" => Flip::Vertical,
                    "horizontal" => Flip::Horizontal,
                    _ => return Err(bad("vertical or horizontal")),
                }),
                Fault::WrongBounces => match value.parse::<u32>() {
                    Ok(n) if n <= 1024 => Parameter::Bounces(n),
                    _ => return Err(bad("a whole number from 0 to 1024")),
                },
                Fault::CubemapIgnored => match u32::from_str_radix(value, 16) {
                    Ok(rgb) if value.len() == 6 => {
                        Parameter::Background([(rgb >> 16) as u8, (rgb >> 8) as u8, rgb as u8])
                    }
                    _ => return Err(bad("a colour as six hex digits, rrggbb")),
                },
                _ => return Err(FaultSetError::TakesNoValue(fault)),
            };
            set = set.with(parameter);
        }
        Ok(set)
    }
}

/// What the integrator asks while rendering: is this fault in force, and with which value?
/// Implemented by [`NoFaults`], whose every answer is the constant `false` (so that a render
/// without faults compiles to the code without any check), and by [`FaultSet`].
pub trait FaultPolicy: Copy + Send + Sync {
    fn has(&self, fault: Fault) -> bool;
    /// The values of the families; only read after [`FaultPolicy::has`] said yes.
    fn set(&self) -> FaultSet;
}

/// No fault: every check is `false` at compile time.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoFaults;

impl FaultPolicy for NoFaults {
    #[inline(always)]
    fn has(&self, _: Fault) -> bool {
        false
    }

    #[inline(always)]
    fn set(&self) -> FaultSet {
        FaultSet::NONE
    }
}

impl FaultPolicy for FaultSet {
    #[inline(always)]
    fn has(&self, fault: Fault) -> bool {
        self.contains(fault)
    }

    #[inline(always)]
    fn set(&self) -> FaultSet {
        *self
    }
}

/// Every fault's id, for messages and help.
pub fn ids() -> &'static [&'static str] {
    <Fault as NamedEnum>::NAMES
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_read_and_write_the_same_text() {
        for text in [
            "none",
            "no-shadows",
            "no-shadows+gamma-applied=1.8",
            "no-specular+wrong-bounces=3",
            "gamma-applied=srgb",
            "specular-unnormalized-reflection=t",
            "pixel-mapping=upside-down+cubemap-face-flipped=horizontal",
            "cubemap-ignored=330099",
        ] {
            let set: FaultSet = text.parse().unwrap();
            assert_eq!(set.to_string(), text);
        }
        let set: FaultSet = "gamma-applied, no-shadows".parse().unwrap();
        assert_eq!(
            set.to_string(),
            "no-shadows+gamma-applied=srgb",
            "catalogue order, first member"
        );
        assert_eq!(set.id(), "no-shadows+gamma-applied");
        assert_eq!(set.len(), 2);
    }

    #[test]
    fn bad_sets_say_what_is_wrong() {
        let error = |text: &str| text.parse::<FaultSet>().unwrap_err().to_string();
        assert!(error("no-shadow").contains("is not a fault"), "{}", error("no-shadow"));
        assert!(error("no-shadows=1").contains("takes no value"));
        assert!(error("gamma-applied=x").contains("srgb, or a positive number"));
        assert!(error("pixel-mapping=sideways").contains("upside-down"));
    }

    #[test]
    fn every_fault_has_a_bit_a_sentence_and_a_hint() {
        let mut bits = 0;
        for fault in Fault::ALL {
            assert_eq!(bits & fault.bit(), 0, "{fault}");
            bits |= fault.bit();
            assert!(!fault.explanation().is_empty() && !fault.hint().is_empty());
            let p = fault.pictures();
            assert!(p.color || p.normals || p.depth, "{fault} changes no picture");
            let single = FaultSet::single(fault);
            assert!(single.to_string().starts_with(fault.name()));
            assert_eq!(single.to_string().contains('='), fault.is_family(), "{fault}");
        }
        assert!(Fault::ALL.len() <= 64);
        assert_eq!(INTEGRATOR_FAULTS & OUTPUT_FAULTS, 0);
    }

    #[test]
    fn parts_split_where_the_faults_act() {
        let set: FaultSet = "no-specular+no-shadows+gamma-applied=2+pixel-mapping=upside-down"
            .parse()
            .unwrap();
        assert_eq!(set.render_part().to_string(), "no-specular+no-shadows");
        assert_eq!(
            set.output_part().to_string(),
            "pixel-mapping=upside-down+gamma-applied=2"
        );
        let centres: FaultSet = "pixel-mapping=centres".parse().unwrap();
        assert_eq!(centres.render_part(), centres);
        assert!(centres.output_part().is_empty() && !centres.has_output_faults());
        assert!(set.checks_integrator());
        assert!(!set.only(Injection::Trace).checks_integrator());
        assert!(!NoFaults.has(Fault::NoSpecular));
        assert!(set.has(Fault::NoSpecular));
        assert_eq!(set.without(Fault::GammaApplied).union(set), set);
    }
}
