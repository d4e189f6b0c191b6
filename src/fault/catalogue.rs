//! What each fault is: its stage, where it acts, which pictures it can change, the sentence a
//! student reads and where in the assignment's code the mistake usually lives.

use super::*;

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
            FalloffLinear | FalloffPlusOne | NoFalloff | DirectionalFlipped | PointLightMissing => Stage::Lights,
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
            | UpOrthonormalized
            | PlaneMissing
            | TriangleMissing
            | TransformMissing => Stage::Geometry,
            NoJitter | NoFilter => Stage::Sampling,
            GammaApplied | ColorNotClamped | NormalsNotRemapped | DepthInverted | DepthNotClamped | DepthMissWhite
            | CubemapFaceFlipped | CubemapIgnored | BackgroundMissing => Stage::Outputs,
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
            | PixelMapping
            | PointLightMissing
            | PlaneMissing
            | TriangleMissing
            | TransformMissing
            | BackgroundMissing => Injection::Case,
            NoShadows | NoReflections | WrongBounces | NoJitter | NoFilter => Injection::Trace,
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
            | UpOrthonormalized
            | PlaneMissing
            | TriangleMissing
            | TransformMissing => Pictures::ALL,
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
            PointLightMissing => {
                "point lights are not implemented (PointLight::getIllumination is left empty): they shine nothing"
            }
            PlaneMissing => "planes are not implemented (Plane::intersect finds no hit): every plane is missing",
            TriangleMissing => {
                "triangles are not implemented (Triangle::intersect finds no hit): every triangle and mesh is missing"
            }
            TransformMissing => {
                "transforms are not implemented (Transform::intersect finds no hit): every transformed object is missing"
            }
            BackgroundMissing => {
                "the background is not implemented: rays that hit nothing are black instead of the background colour \
                 or cube map"
            }
            NoJitter => "-jitter is not implemented: one ray per pixel instead of 16 jittered samples",
            NoFilter => "-filter is not implemented: no 3× supersampling and Gaussian down-filter",
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
            DepthMissWhite => {
                "Renderer::Render: a pixel with no hit is black in the depth image (the starter's loop writes \
                 (t − min)/(max − min) for a miss too, from t = FLT_MAX: its conversion to a code overflows, \
                 which x86 writes as 0 and ARM as 255)"
            }
            CubemapFaceFlipped => "CubeMap: the face's (u, v) and texel row order",
            CubemapIgnored => "RayTracer::traceRay: a miss returns the cube map's colour when the scene has one",
            PointLightMissing => {
                "PointLight::getIllumination: tolight = normalised (position − p), intensity = colour / (falloff · d²), \
                 distToLight = d"
            }
            PlaneMissing => "Plane::intersect: t = (offset − n·origin)/(n·direction), kept if tmin < t < h.t",
            TriangleMissing => {
                "Triangle::intersect: solve for t and the barycentric coordinates (Cramer's rule), kept if inside and \
                 tmin < t < h.t"
            }
            TransformMissing => {
                "Transform::intersect: intersect the object with the ray moved by M⁻¹ (direction with w = 0), then \
                 bring the normal back by (M⁻¹)ᵀ"
            }
            BackgroundMissing => {
                "RayTracer::traceRay: a ray that hits nothing returns the background colour or cube map"
            }
            NoJitter => "Renderer::Render: with -jitter, average 16 stratified random samples in each pixel",
            NoFilter => {
                "Renderer::Render: with -filter, render at 3× and weight each 3×3 block by [1 2 1; 2 4 2; 1 2 1]/16"
            }
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

    /// The part of the assignment a fault leaves unwritten, when the fault is the starter code's
    /// `TODO` as shipped (or a feature of the command line never begun, or the starter's own render
    /// loop left as it is: it never handles a miss in the depth image, whose `t = FLT_MAX` overflows
    /// the conversion to a code, black on x86 by luck and white on ARM) rather than a mistake in
    /// code that was written: a student with several of them is told once that the work is
    /// unfinished, with the parts, instead of one mistake per part. `nothing-shaded` stands for
    /// all of the shading (lights, Phong, shadows, reflections), which a flat colour hides.
    pub const fn unfinished_part(self) -> Option<&'static str> {
        use Fault::*;
        Some(match self {
            NothingShaded => "shading",
            NoSpecular => "the specular highlight",
            NoShadows => "shadows",
            NoReflections => "reflections",
            PointLightMissing => "point lights",
            PlaneMissing => "planes",
            TriangleMissing => "triangles",
            TransformMissing => "transforms",
            BackgroundMissing => "the background",
            DepthMissWhite => "misses in the depth image",
            NoJitter => "jitter",
            NoFilter => "the filter",
            _ => return None,
        })
    }

    /// Whether the fault's picture is noise whose speckles an independent program draws
    /// elsewhere (acne): compared by local density, not pixel by pixel.
    pub const fn is_speckle(self) -> bool {
        matches!(self, Fault::ShadowAcne | Fault::ReflectionAcne)
    }
}

/// The bits of the faults the integrator checks.
pub const INTEGRATOR_FAULTS: u64 = mask(Injection::Integrator);
pub(super) const OUTPUT_FAULTS: u64 = mask(Injection::Output);

pub(super) const fn mask(injection: Injection) -> u64 {
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

/// Every fault's id, for messages and help.
pub fn ids() -> &'static [&'static str] {
    <Fault as NamedEnum>::NAMES
}
