//! Rendering as a student's program with the catalogue's mistakes would (`crate::fault`): the
//! faults that change the scene description or the render settings are applied to a copy of the
//! case, those of the integrator are handed to the renderer, and those of the PNGs are left to
//! [`crate::film::picture_with_faults`].

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use glam::DVec3;

use super::{render_options, rendering};
use crate::case::{Case, LightSpec, ObjectSpec, ShapeSpec};
use crate::error::Error;
use crate::fault::{Fault, FaultSet, Injection, Mapping};
use crate::film::Film;
use crate::options::{Filter, Precision};
use crate::precision::{double, single};
use crate::progress::{Progress, Silent};
use crate::with_precision;

/// The film a program with `faults` renders for `case` (its PNG faults aside). With no fault
/// but PNG faults, this is the golden film.
pub fn render_case_with_faults(case: &Case, faults: &FaultSet, progress: &dyn Progress) -> Result<Film, Error> {
    let case = case_with_faults(case, faults);
    let options = render_options(&case);
    with_precision!(case.render.precision, p => {
        let scene = p::scene::build_scene(&case)?;
        Ok(rendering(&case, progress, |progress| p::render::render_with_faults(&scene, &options, *faults, progress)))
    })
}

/// Renders one case under many fault sets, building each scene once: the faults that act on
/// the integrator or the render settings share the golden scene (its meshes, BVHs and cube
/// map), and each distinct change of the description gets its own.
pub struct FaultRenderer {
    case: Case,
    scenes: Mutex<HashMap<String, Arc<Built>>>,
}

enum Built {
    Single(single::scene::Scene),
    Double(double::scene::Scene),
}

impl FaultRenderer {
    pub fn new(case: &Case) -> FaultRenderer {
        FaultRenderer {
            case: case.clone(),
            scenes: Mutex::new(HashMap::new()),
        }
    }

    /// [`render_case_with_faults`], without progress.
    pub fn render(&self, faults: &FaultSet) -> Result<Film, Error> {
        let case = case_with_faults(&self.case, faults);
        let options = render_options(&case);
        let scene = self.scene(&case, faults)?;
        Ok(match &*scene {
            Built::Single(scene) => single::render::render_with_faults(scene, &options, *faults, &Silent),
            Built::Double(scene) => double::render::render_with_faults(scene, &options, *faults, &Silent),
        })
    }

    fn scene(&self, case: &Case, faults: &FaultSet) -> Result<Arc<Built>, Error> {
        let key = faults.only(Injection::Case).to_string();
        if let Some(scene) = self.lock().get(&key) {
            return Ok(scene.clone());
        }
        let built = Arc::new(match case.render.precision {
            Precision::F32 => Built::Single(single::scene::build_scene(case)?),
            Precision::F64 => Built::Double(double::scene::build_scene(case)?),
        });
        self.lock().insert(key, built.clone());
        Ok(built)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, Arc<Built>>> {
        self.scenes.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// The case as the faulty program understands it: the faults that change the description
/// (ambient, lights, camera, transforms, cube map) and the render settings (shadows, bounces)
/// applied.
pub fn case_with_faults(case: &Case, faults: &FaultSet) -> Case {
    let mut case = case.clone();
    let trace = &mut case.render.trace;
    if faults.contains(Fault::NoShadows) {
        trace.shadows = false;
    }
    if faults.contains(Fault::NoReflections) {
        trace.bounces = 0;
    }
    if let Some(bounces) = faults.bounces() {
        trace.bounces = bounces;
    }
    if faults.contains(Fault::NoJitter) {
        trace.samples = 1;
    }
    if faults.contains(Fault::NoFilter) {
        trace.filter = Filter::None;
    }
    if faults.contains(Fault::NoAmbient) {
        case.background.ambient = [0.0; 3];
    }
    if faults.contains(Fault::CubemapIgnored) && case.background.cube_map.is_some() {
        // The course's scene gives a colour beside the cube map, which the import drops (a case
        // has one or the other); the family's member says which colour the program showed.
        case.background.cube_map = None;
        case.background.color = faults.background();
    }
    if faults.contains(Fault::BackgroundMissing) {
        case.background.cube_map = None;
        case.background.color = [0.0; 3];
    }
    if faults.contains(Fault::PointLightMissing) {
        // The starter's getIllumination leaves its outputs as the caller made them: no light.
        case.lights.retain(|l| !matches!(l, LightSpec::Point { .. }));
    }
    // The starter's intersections of these shapes find no hit: the objects are not there.
    if faults.contains(Fault::PlaneMissing) {
        remove_objects(&mut case.objects, &|o| matches!(o.shape, ShapeSpec::Plane { .. }));
    }
    if faults.contains(Fault::TriangleMissing) {
        remove_objects(&mut case.objects, &|o| {
            matches!(o.shape, ShapeSpec::Triangle { .. } | ShapeSpec::Mesh { .. })
        });
    }
    if faults.contains(Fault::TransformMissing) {
        remove_objects(&mut case.objects, &|o| !o.transform.is_empty());
    }
    if faults.contains(Fault::DirectionalFlipped) {
        for light in &mut case.lights {
            if let LightSpec::Directional { direction, .. } = light {
                *direction = direction.map(|c| -c);
            }
        }
    }
    let (width, height) = (f64::from(trace.width), f64::from(trace.height));
    let camera = &mut case.camera;
    if faults.contains(Fault::FovHalfAngle) {
        // d = 1/tan(angle) is the camera of the full angle 2·angle (while that is an angle).
        camera.fov = (2.0 * camera.fov).min(179.0);
    }
    if faults.contains(Fault::UpOrthonormalized) {
        camera.up = orthonormal_up(camera.direction, camera.up);
    }
    if faults.mapping() == Some(Mapping::Centres) && width > 1.0 && height > 1.0 {
        // ndc = 2(x + ½)/w − 1 is the course's 2x/(w − 1) − 1 times (w − 1)/w: the image plane
        // moved out by w/(w − 1) along x, and up (used as given) scaled for the rows.
        let (sx, sy) = ((width - 1.0) / width, (height - 1.0) / height);
        let half = (camera.fov.to_radians() / 2.0).tan() * sx;
        camera.fov = 2.0 * half.atan().to_degrees();
        camera.up = camera.up.map(|c| c * sy / sx);
    }
    if faults.contains(Fault::TransformOrderReversed) {
        reverse_transforms(&mut case.objects);
    }
    case
}

/// `up` made unit and perpendicular to `direction`, as most camera code does.
pub fn orthonormal_up(direction: [f64; 3], up: [f64; 3]) -> [f64; 3] {
    let d = DVec3::from(direction).normalize();
    let up = DVec3::from(up);
    (up - d * d.dot(up)).normalize().to_array()
}

/// Every object `missing` says, at any depth of the groups, left out.
fn remove_objects(objects: &mut Vec<ObjectSpec>, missing: &dyn Fn(&ObjectSpec) -> bool) {
    objects.retain(|o| !missing(o));
    for object in objects {
        if let ShapeSpec::Group { objects } = &mut object.shape {
            remove_objects(objects, missing);
        }
    }
}

fn reverse_transforms(objects: &mut [ObjectSpec]) {
    for object in objects {
        object.transform.reverse();
        if let ShapeSpec::Group { objects } = &mut object.shape {
            reverse_transforms(objects);
        }
    }
}

/// Whether `fault` can change anything `case` renders: the scene has what the fault acts on (a
/// shadow fault needs shadows on and a light, a reflection fault a mirror and bounces…).
/// Conservative: `true` unless the fault certainly changes nothing.
pub fn fault_applies(case: &Case, fault: Fault) -> bool {
    use Fault::*;
    let trace = &case.render.trace;
    let lights = !case.lights.is_empty();
    let point_lights = case.lights.iter().any(|l| matches!(l, LightSpec::Point { .. }));
    let directional = case.lights.iter().any(|l| matches!(l, LightSpec::Directional { .. }));
    let coloured_lights = case.lights.iter().any(|l| match l {
        LightSpec::Point { .. } => true,
        LightSpec::Directional { color, .. } => *color != [1.0; 3],
    });
    let specular = case.materials.iter().any(|m| m.specular != [0.0; 3]);
    let matte =
        case.materials.iter().any(|m| m.specular == [0.0; 3]) || has_object(&case.objects, &|o| o.material.is_none());
    let ambient = case.background.ambient != [0.0; 3];
    let mirrors = trace.bounces > 0 && specular;
    let shadows = trace.shadows && lights;
    let transformed = has_object(&case.objects, &|o| !o.transform.is_empty());
    let triangles = has_object(&case.objects, &|o| {
        matches!(o.shape, ShapeSpec::Mesh { .. } | ShapeSpec::Triangle { .. })
    });
    let planes = has_object(&case.objects, &|o| matches!(o.shape, ShapeSpec::Plane { .. }));
    match fault {
        SpecularUnnormalizedReflection | BlinnPhong | NoSpecular => specular && lights,
        NoAmbient => ambient,
        NoDiffuseClamp => lights,
        LightColorIgnored => coloured_lights,
        NothingShaded => true,
        FlatShading => has_object(&case.objects, &|o| {
            matches!(
                o.shape,
                ShapeSpec::Mesh { .. } | ShapeSpec::Triangle { normals: Some(_), .. }
            )
        }),
        FalloffLinear | FalloffPlusOne | NoFalloff => point_lights,
        DirectionalFlipped => directional,
        NoShadows | ShadowAcne => shadows,
        ShadowsBeyondLight => shadows && point_lights,
        NoAmbientInShadow => shadows && ambient,
        NoReflections | ReflectionWithoutKs | ReflectionAcne | ReflectedMissBlack => mirrors,
        ReflectionOnEveryMaterial => trace.bounces > 0 && matte,
        // Another bounce count can turn reflections on in a scene rendered without them.
        WrongBounces => specular,
        NormalsNotInverseTranspose | TransformDirectionReversed | TransformDirectionNormalized => transformed,
        TransformOrderReversed => has_object(&case.objects, &|o| o.transform.len() > 1),
        PlaneOneSided => planes,
        TriangleNormalFlipped => triangles,
        FovHalfAngle => case.camera.fov < 179.0,
        UpOrthonormalized => {
            let up = DVec3::from(case.camera.up);
            DVec3::from(orthonormal_up(case.camera.direction, case.camera.up)).distance(up) > 1e-9
        }
        CubemapFaceFlipped | CubemapIgnored => case.background.cube_map.is_some(),
        PointLightMissing => point_lights,
        PlaneMissing => planes,
        TriangleMissing => triangles,
        TransformMissing => has_object(&case.objects, &|o| !o.transform.is_empty()),
        BackgroundMissing => case.background.color != [0.0; 3] || case.background.cube_map.is_some(),
        NoJitter => trace.samples > 1,
        NoFilter => trace.filter == Filter::Gaussian,
        PixelMapping | GammaApplied | ColorNotClamped | NormalsNotRemapped => true,
        DepthInverted | DepthNotClamped | DepthMissWhite => true,
    }
}

fn has_object(objects: &[ObjectSpec], test: &dyn Fn(&ObjectSpec) -> bool) -> bool {
    objects
        .iter()
        .any(|o| test(o) || matches!(&o.shape, ShapeSpec::Group { objects } if has_object(objects, test)))
}
