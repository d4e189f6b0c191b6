//! The catalogue's integrator mistakes (`crate::fault`, [`Injection::Integrator`]), as small
//! changes around the integrator's own steps: each takes what the correct code computed and
//! changes only what the mistake changes, so that a fault render differs from the golden one by
//! that mistake alone. With [`crate::fault::NoFaults`] every function here reduces to the
//! correct step at compile time.
//!
//! The geometry mistakes (transformed rays and normals, one-sided planes, flipped triangles) are
//! rendered by [`intersect`] and [`occluded`] with a plain loop over the scene's objects, outside
//! the BVH: slow, but only a diagnosis renders them, and the ray kernel stays untouched.
//!
//! [`Injection::Integrator`]: crate::fault::Injection::Integrator

use super::geometry::Ray;
use super::geometry::SurfaceHit;
use super::geometry::spawn::{spawn, spawn_to};
use super::real::{Color, Mat3, Real, Vec3, real};
use super::scene::light::{Incident, Light};
use super::scene::material::Material;
use super::scene::{Intersection, Object, Scene, Shape};
use crate::fault::{Fault, FaultPolicy, Flip, Length};
use crate::options::Spawn;

/// The faults [`intersect`] and [`occluded`] render.
const GEOMETRY: [Fault; 5] = [
    Fault::NormalsNotInverseTranspose,
    Fault::TransformDirectionReversed,
    Fault::TransformDirectionNormalized,
    Fault::PlaneOneSided,
    Fault::TriangleNormalFlipped,
];

#[inline(always)]
fn geometry_faults<F: FaultPolicy>(faults: F) -> bool {
    GEOMETRY.iter().any(|f| faults.has(*f))
}

/// The closest hit along `ray`, as the faulty program finds it; `flat-shading` changes the
/// normals of the hit.
#[inline(always)]
pub fn intersect<F: FaultPolicy>(scene: &Scene, ray: &Ray, faults: F) -> Option<Intersection> {
    let mut hit = if geometry_faults(faults) {
        faulty_intersect(scene, ray, faults)
    } else {
        scene.geometry.intersect(ray)
    }?;
    if faults.has(Fault::FlatShading) {
        let surface = &mut hit.surface;
        let face = surface.geometric_normal;
        let shading = surface.shading_normal;
        let oriented = if face.dot(shading) < 0.0 { -face } else { face };
        // Keep the shading normal's length (a course plane's normal keeps the length written).
        surface.shading_normal = oriented * shading.length();
    }
    Some(hit)
}

/// Whether anything blocks `ray` before `t_max`, as the faulty program tests it.
#[inline(always)]
pub fn occluded<F: FaultPolicy>(scene: &Scene, ray: &Ray, t_max: Real, faults: F) -> bool {
    if geometry_faults(faults) {
        faulty_occluded(scene, ray, t_max, faults)
    } else {
        scene.geometry.occluded(ray, t_max)
    }
}

/// Whether an object sits under a transform of the scene (a scene file's `Transform`): one that
/// does more than move it. A pure translation is indistinguishable from the camera-world move
/// every object gets, and rays through it keep their direction anyway.
fn transformed(object: &Object) -> Option<Mat3> {
    let linear = Mat3::from_mat4(*object.transform.as_ref()?.object_to_world());
    (linear != Mat3::IDENTITY).then_some(linear)
}

/// How the faulty program measures a hit at parameter `t` of `ray` on `object`: the same `t`,
/// except that with `transform-direction-normalized` a transformed object reports the distance
/// in its own space, `t·|M⁻¹D|` for a ray of direction `D`, where the others report `t·|D|`.
/// Returned as a factor on `t`, in units of `t·|D|`.
fn distance_scale<F: FaultPolicy>(object: &Object, ray: &Ray, faults: F) -> Real {
    match transformed(object) {
        Some(linear) if faults.has(Fault::TransformDirectionNormalized) => {
            let length = ray.direction.length();
            if length > 0.0 { (linear.inverse() * ray.direction).length() / length } else { 1.0 }
        }
        _ => 1.0,
    }
}

/// The ray the faulty program intersects `object` with: reversed in object space (so, in world
/// space, from the same origin the other way) with `transform-direction-reversed`.
fn object_ray<F: FaultPolicy>(object: &Object, ray: &Ray, faults: F) -> Ray {
    if faults.has(Fault::TransformDirectionReversed) && transformed(object).is_some() {
        Ray::new(ray.origin, -ray.direction)
    } else {
        *ray
    }
}

fn plane_visible<F: FaultPolicy>(normal: Vec3, ray: &Ray, faults: F) -> bool {
    !(faults.has(Fault::PlaneOneSided) && normal.dot(ray.direction) > 0.0)
}

fn faulty_intersect<F: FaultPolicy>(scene: &Scene, ray: &Ray, faults: F) -> Option<Intersection> {
    let mut best = Real::INFINITY;
    let mut closest: Option<Intersection> = None;
    for (plane, material) in scene.geometry.planes() {
        if let Some(t) = plane.intersect(ray, best)
            && plane_visible(plane.normal, ray, faults)
        {
            best = t;
            closest = Some(Intersection { surface: plane.surface(ray, t), material: *material });
        }
    }
    for object in scene.geometry.objects() {
        let scale = distance_scale(object, ray, faults);
        let object_ray = object_ray(object, ray, faults);
        let Some(hit) = object.intersect(&object_ray, best / scale) else { continue };
        best = hit.t() * scale;
        let mut surface = object.surface(&object_ray, &hit);
        surface.t = best;
        adjust_normals(object, &mut surface, faults);
        closest = Some(Intersection { surface, material: object.material });
    }
    closest
}

fn faulty_occluded<F: FaultPolicy>(scene: &Scene, ray: &Ray, t_max: Real, faults: F) -> bool {
    let planes = scene.geometry.planes().iter();
    planes.into_iter().any(|(plane, _)| plane.intersect(ray, t_max).is_some() && plane_visible(plane.normal, ray, faults))
        || scene.geometry.objects().iter().any(|object| {
            let scale = distance_scale(object, ray, faults);
            object.occluded(&object_ray(object, ray, faults), t_max / scale)
        })
}

/// `normals-not-inverse-transpose`: a transformed object's normals by `M` instead of `M⁻ᵀ`. The
/// world normal is `M⁻ᵀn`, so `M·n` is `M·Mᵀ` times it. `triangle-normal-flipped`: triangles'
/// normals reversed.
fn adjust_normals<F: FaultPolicy>(object: &Object, surface: &mut SurfaceHit, faults: F) {
    if faults.has(Fault::NormalsNotInverseTranspose)
        && let Some(linear) = transformed(object)
    {
        let by_matrix = linear * linear.transpose();
        let moved = |n: Vec3| (by_matrix * n).try_normalize().unwrap_or(n);
        surface.geometric_normal = moved(surface.geometric_normal);
        surface.shading_normal = moved(surface.shading_normal);
    }
    if faults.has(Fault::TriangleNormalFlipped) && matches!(object.shape, Shape::Triangle(_) | Shape::Mesh(_)) {
        surface.geometric_normal = -surface.geometric_normal;
        surface.shading_normal = -surface.shading_normal;
    }
}

/// What a ray that hits nothing sees: `cubemap-face-flipped` reads each face with one texel
/// axis reversed, which is the direction mirrored in that axis's component (the face stays the
/// same: only the largest component decides it); `reflected-miss-black` for reflected rays.
#[inline(always)]
pub fn background<F: FaultPolicy>(scene: &Scene, direction: Vec3, depth: u32, faults: F) -> Color {
    if depth > 0 && faults.has(Fault::ReflectedMissBlack) {
        return Color::ZERO;
    }
    if !faults.has(Fault::CubemapFaceFlipped) {
        return scene.background.radiance(direction);
    }
    let a = direction.abs();
    let x_face = a.x >= a.y && a.x >= a.z;
    let y_face = !x_face && a.y >= a.z;
    let mut d = direction;
    match (faults.set().flip(), y_face) {
        (Flip::Vertical, false) => d.y = -d.y,
        (Flip::Vertical, true) => d.z = -d.z,
        (Flip::Horizontal, _) if x_face => d.z = -d.z,
        (Flip::Horizontal, _) => d.x = -d.x,
    }
    scene.background.radiance(d)
}

/// The falloff and colour mistakes of a light's intensity at `point`.
#[inline(always)]
pub fn fall_off<F: FaultPolicy>(faults: F, light: &Light, point: Vec3, incident: &mut Incident) {
    let faulty = [Fault::FalloffLinear, Fault::FalloffPlusOne, Fault::NoFalloff, Fault::LightColorIgnored];
    if !faulty.iter().any(|f| faults.has(*f)) {
        return;
    }
    let white = faults.has(Fault::LightColorIgnored);
    match *light {
        Light::Point { position, color, falloff } => {
            let color = if white { Color::ONE } else { color };
            let d2 = (position - point).length_squared();
            incident.intensity = if faults.has(Fault::NoFalloff) {
                color
            } else if faults.has(Fault::FalloffLinear) {
                color / (falloff * d2.sqrt())
            } else if faults.has(Fault::FalloffPlusOne) {
                color / (1.0 + falloff * d2)
            } else {
                color / (falloff * d2)
            };
        }
        Light::Directional { .. } if white => incident.intensity = Color::ONE,
        Light::Directional { .. } => {}
    }
}

/// Whether the shading itself is faulty (else [`Material::shade`] is called as it is).
#[inline(always)]
pub fn faulty_shading<F: FaultPolicy>(faults: F) -> bool {
    faults.has(Fault::NoSpecular)
        || faults.has(Fault::BlinnPhong)
        || faults.has(Fault::NoDiffuseClamp)
        || faults.has(Fault::SpecularUnnormalizedReflection)
}

/// Phong shading with `no-specular`, `blinn-phong`, `specular-unnormalized-reflection` and
/// `no-diffuse-clamp`, built on [`Material::shade`] so that the rest stays the reference's.
/// `distance` is the hit distance (one family member of the unnormalised reflection).
pub fn shade<F: FaultPolicy>(
    faults: F,
    material: &Material,
    normal: Vec3,
    to_light: Vec3,
    to_eye: Vec3,
    intensity: Color,
    distance: Real,
) -> Color {
    let own_highlight = faults.has(Fault::NoSpecular)
        || faults.has(Fault::BlinnPhong)
        || faults.has(Fault::SpecularUnnormalizedReflection);
    let mut color = if own_highlight {
        Material { specular: Color::ZERO, ..*material }.shade(normal, to_light, to_eye, intensity)
    } else {
        material.shade(normal, to_light, to_eye, intensity)
    };
    let cos_light = to_light.dot(normal);
    if own_highlight && !faults.has(Fault::NoSpecular) && material.reflects() {
        let cosine = if faults.has(Fault::BlinnPhong) {
            normal.dot((to_light + to_eye).normalize_or_zero()).clamp(0.0, 1.0)
        } else {
            // R = 2(N·L)N − L scaled to the length the student's vector has; only negative
            // cosines are clamped, so a long R brightens and sharpens the highlight.
            let length = match faults.set().length() {
                Length::Factor(k) => real(k),
                Length::HitDistance => distance,
            };
            (length * (2.0 * cos_light * normal - to_light).dot(to_eye)).max(0.0)
        };
        color += cosine.powf(material.shininess) * material.specular * intensity;
    }
    if faults.has(Fault::NoDiffuseClamp) && cos_light < 0.0 {
        color += cos_light * material.diffuse * intensity;
    }
    color
}

/// A ray leaving the surface the way a program without any offset starts it: on the surface as
/// computed, which rounding puts above or below it about equally often. Rounding is modelled by
/// a hash of the point: half of the points start a little behind the surface (10⁻⁴ of their
/// distance from the origin, relative), and the ray then meets the surface it leaves. The
/// speckles are goldray's, not the student's: only their density can be compared.
fn acne_origin(surface: &SurfaceHit, direction: Vec3) -> Option<Vec3> {
    let bits = surface.point.to_array().iter().fold(0x9e37_79b9_u64, |h, c| {
        (h ^ (*c as f64).to_bits()).wrapping_mul(0xbf58_476d_1ce4_e5b9).rotate_left(29)
    });
    if bits & (1 << 40) == 0 {
        return None;
    }
    let normal = surface.geometric_normal;
    let behind = if normal.dot(direction) > 0.0 { -normal } else { normal };
    Some(surface.point + behind * (real(1.0e-4) * surface.point.abs().max_element().max(1.0)))
}

/// `shadow-acne`: the shadow ray towards a light (`position`, or the direction `to_light`).
pub fn acne_shadow_ray(policy: Spawn, hit: &Intersection, to_light: Vec3, position: Option<Vec3>) -> (Ray, Real) {
    let surface = &hit.surface;
    let (ray, t_max) = match position {
        Some(position) => spawn_to(policy, surface, position),
        None => (spawn(policy, surface, to_light), Real::INFINITY),
    };
    match (acne_origin(surface, to_light), position) {
        (None, _) => (ray, t_max),
        (Some(origin), Some(position)) => (Ray::new(origin, position - origin), t_max),
        (Some(origin), None) => (Ray::new(origin, ray.direction), t_max),
    }
}

/// `reflection-acne`: the reflected ray `ray` spawned from `hit`, moved like a shadow ray's.
pub fn acne_reflected_ray(hit: &Intersection, ray: Ray) -> Ray {
    match acne_origin(&hit.surface, ray.direction) {
        Some(origin) => Ray::new(origin, ray.direction),
        None => ray,
    }
}
