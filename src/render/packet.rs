//! The Whitted integrator for eight rays at once, a ray per SIMD lane: a pixel's samples, or a
//! run of pixels, traced, shaded and spawned together, so that what every ray pays once (the
//! sphere and plane tests, the light's direction and fall-off, the spawn offset, the Phong terms)
//! is paid once per eight rays.
//!
//! Lane by lane it computes exactly what [`Whitted::trace`](super::integrator::Whitted::trace)
//! computes for that ray alone: the same operations in the same order (see
//! `geometry::lanes`), the same tie rule for hits, `powf` and the cube map called for each lane
//! that needs them. So the picture is bit-identical whichever integrator draws it, and the
//! renderer uses this one for every render without the catalogue's integrator faults.

use std::sync::atomic::{AtomicU8, Ordering};

use rayon::prelude::*;

use super::geometry::lanes::{LANES, Mask, RayLanes, V3, mask, set_lanes};
use super::geometry::spawn::{spawn_lanes, spawn_to_lanes};
use super::real::{Color, R8, Real, Vec2, Vec3};
use super::scene::light::Light;
use super::scene::{Background, CubeMap, HitLanes, Scene};
use crate::options::Spawn;
use crate::simd::{Isa, Kernel, Lanes, MaskOps, dispatch};
use crate::stats::RayCounts;

/// What up to eight primary rays saw.
struct Traced {
    color: [Color; LANES],
    /// What each primary ray hit first (its `t` and shading normal), for the AOVs; all `None`
    /// unless asked for.
    first: [Option<(Real, Vec3)>; LANES],
}

/// Rays per work item of [`WhittedLanes::cube_map_faces_seen`].
const PROBE_CHUNK: usize = 512;

pub struct WhittedLanes<'a> {
    scene: &'a Scene,
    bounces: u32,
    shadows: bool,
    spawn: Spawn,
    /// Per material, whether its hits spawn a mirror ray under `spawn`'s rule.
    mirrors: Vec<bool>,
    /// Whether rays that miss only note the cube-map faces they look at, in `faces_seen`, and
    /// see black: a probe of which faces a render will decode
    /// ([`WhittedLanes::cube_map_faces_seen`]).
    probe: bool,
    faces_seen: AtomicU8,
}

/// The materials of eight hits, lane by lane.
struct MaterialLanes<I: Isa> {
    diffuse: V3<I>,
    specular: V3<I>,
    shininess: [Real; LANES],
    /// Lanes whose material has no specular colour (whose highlight adds nothing).
    matte: u32,
    /// Lanes whose material spawns a mirror ray.
    mirror: u32,
}

impl<'a> WhittedLanes<'a> {
    pub fn new(scene: &'a Scene, bounces: u32, shadows: bool, spawn: Spawn) -> Self {
        let mirrors = scene
            .materials
            .iter()
            .map(|material| match spawn {
                // Compared as the course does: its float length widened to double, against 0.1.
                Spawn::Course => (material.specular.length() as f64) > Spawn::COURSE_MIRROR_THRESHOLD,
                _ => material.reflects(),
            })
            .collect();
        WhittedLanes { scene, bounces, shadows, spawn, mirrors, probe: false, faces_seen: AtomicU8::new(0) }
    }

    /// The cube-map faces that the camera rays through `raster` (on the raster of an image of
    /// `width × height`) look at, on their way as [`WhittedLanes::colors`] traces them, as bits
    /// (see [`CubeMap::faces_seen`]): without decoding any face, so that a render can decode
    /// them side by side first. Nothing is counted and the colours are thrown away.
    pub fn cube_map_faces_seen(&self, raster: &[Vec2], size: (u32, u32)) -> u8 {
        let probe = WhittedLanes { mirrors: self.mirrors.clone(), probe: true, faces_seen: AtomicU8::new(0), ..*self };
        raster.par_chunks(PROBE_CHUNK).for_each(|raster| {
            probe.colors(raster, size, &mut RayCounts::default(), &mut Vec::with_capacity(raster.len()), None);
        });
        probe.faces_seen.into_inner()
    }

    /// The colours seen along the camera rays through every point of `raster`, on the raster of
    /// an image of `width × height`, appended to `colors` in order, and, when `firsts` is given,
    /// what each ray hit first (its `t` and shading normal) appended to it. The points are traced
    /// eight at a time in one call into the SIMD path for the lot, so that a run of pixels, or a
    /// pixel's samples, pay for the dispatch once. The caller counts the camera rays; the shadow
    /// and reflection rays are added to `rays`.
    pub fn colors(
        &self,
        raster: &[Vec2],
        (width, height): (u32, u32),
        rays: &mut RayCounts,
        colors: &mut Vec<Color>,
        firsts: Option<&mut Vec<Option<(Real, Vec3)>>>,
    ) {
        struct Colors<'a, 'b> {
            lanes: &'a WhittedLanes<'a>,
            raster: &'b [Vec2],
            size: (u32, u32),
            rays: &'b mut RayCounts,
            colors: &'b mut Vec<Color>,
            firsts: Option<&'b mut Vec<Option<(Real, Vec3)>>>,
        }
        impl Kernel for Colors<'_, '_> {
            type Output = ();
            #[inline(always)]
            fn run<I: Isa>(mut self) {
                let (width, height) = self.size;
                for batch in self.raster.chunks(LANES) {
                    let (x, y) = raster_lanes::<I>(batch);
                    let primaries = self.lanes.scene.camera.ray_lanes::<I>(x, y, width, height);
                    let traced = self.lanes.trace_lanes::<I>(primaries, batch.len(), self.firsts.is_some(), self.rays);
                    self.colors.extend_from_slice(&traced.color[..batch.len()]);
                    if let Some(firsts) = self.firsts.as_deref_mut() {
                        firsts.extend_from_slice(&traced.first[..batch.len()]);
                    }
                }
            }
        }
        dispatch(Colors { lanes: self, raster, size: (width, height), rays, colors, firsts })
    }

    /// What the camera rays through one to eight points of the raster of an image of `width ×
    /// height` hit first: each one's `t` and shading normal, as [`WhittedLanes::colors`] gives
    /// them, without shading anything. The caller counts the rays.
    pub fn first_hits(&self, raster: &[Vec2], (width, height): (u32, u32)) -> [Option<(Real, Vec3)>; LANES] {
        struct FirstHits<'a>(&'a Scene, &'a [Vec2], (u32, u32));
        impl Kernel for FirstHits<'_> {
            type Output = [Option<(Real, Vec3)>; LANES];
            #[inline(always)]
            fn run<I: Isa>(self) -> Self::Output {
                let (scene, raster, (width, height)) = (self.0, self.1, self.2);
                let (x, y) = raster_lanes::<I>(raster);
                let hit = scene.geometry.intersect_packet::<I>(&scene.camera.ray_lanes::<I>(x, y, width, height), (1 << raster.len()) - 1);
                first_hits(&hit)
            }
        }
        debug_assert!((1..=LANES).contains(&raster.len()));
        dispatch(FirstHits(self.scene, raster, (width, height)))
    }

    /// The first `count` lanes of `rays` traced.
    #[inline(always)]
    fn trace_lanes<I: Isa>(&self, mut rays: RayLanes<I>, count: usize, first_hits: bool, counts: &mut RayCounts) -> Traced {
        let mut active = (1u32 << count) - 1;
        let mut color = V3::<I>::splat(Color::ZERO);
        let mut throughput = V3::<I>::splat(Color::ONE);
        let mut first = [None; LANES];
        for depth in 0..=self.bounces {
            let hit = self.scene.geometry.intersect_packet::<I>(&rays, active);
            let missed = active & !hit.hits;
            if missed != 0 {
                let seen = throughput * self.background::<I>(&rays, missed);
                color = V3::select(mask::<I>(missed), color + seen, color);
            }
            active &= hit.hits;
            if depth == 0 && first_hits {
                first = self::first_hits(&hit);
            }
            if active == 0 {
                break;
            }
            let materials = self.materials::<I>(&hit, active);
            let direct = throughput * self.direct_light::<I>(&rays, &hit, &materials, active, counts);
            color = V3::select(mask::<I>(active), color + direct, color);
            active &= materials.mirror;
            if depth == self.bounces || active == 0 {
                break;
            }
            throughput = throughput * materials.specular;
            let normal = hit.surface.shading_normal;
            let incoming = self.view::<I>(rays.direction);
            let reflected = incoming - normal.scale(R8::<I>::splat(2.0) * incoming.dot(normal));
            rays = spawn_lanes::<I>(self.spawn, &hit.surface, reflected);
            counts.reflection += u64::from(active.count_ones());
        }
        Traced { color: color.vectors(), first }
    }

    /// The materials of the lanes of `active`; the other lanes' are meaningless. When every
    /// lane hit the same material (a packet's samples mostly do) it is splatted, not gathered.
    #[inline(always)]
    fn materials<I: Isa>(&self, hit: &HitLanes<I>, active: u32) -> MaterialLanes<I> {
        let first = hit.material[active.trailing_zeros() as usize];
        if set_lanes(active).all(|k| hit.material[k] == first) {
            let material = &self.scene.materials[first as usize];
            let every = |flag: bool| if flag { active } else { 0 };
            return MaterialLanes {
                diffuse: V3::splat(material.diffuse),
                specular: V3::splat(material.specular),
                shininess: [material.shininess; LANES],
                matte: every(!material.reflects()),
                mirror: every(self.mirrors[first as usize]),
            };
        }
        let (mut diffuse, mut specular) = ([Vec3::ZERO; LANES], [Vec3::ZERO; LANES]);
        let (mut shininess, mut matte, mut mirror) = ([0.0; LANES], 0, 0);
        for k in set_lanes(active) {
            let index = hit.material[k];
            let material = &self.scene.materials[index as usize];
            (diffuse[k], specular[k], shininess[k]) = (material.diffuse, material.specular, material.shininess);
            matte |= u32::from(!material.reflects()) << k;
            mirror |= u32::from(self.mirrors[index as usize]) << k;
        }
        MaterialLanes { diffuse: V3::gather(&diffuse), specular: V3::gather(&specular), shininess, matte, mirror }
    }

    /// What the rays of `missed` see of the background.
    #[inline(always)]
    fn background<I: Isa>(&self, rays: &RayLanes<I>, missed: u32) -> V3<I> {
        match &self.scene.background {
            Background::Color(color) => V3::splat(*color),
            Background::CubeMap(_) if self.probe => {
                let faces = CubeMap::faces_seen(&rays.direction.vectors(), missed);
                self.faces_seen.fetch_or(faces, Ordering::Relaxed);
                V3::splat(Color::ZERO)
            }
            Background::CubeMap(map) => {
                V3::gather(&map.radiance_lanes::<I, LANES>(&rays.direction.vectors(), missed))
            }
        }
    }

    /// Ambient plus every light that reaches the points (all of them without `shadows`).
    #[inline(always)]
    fn direct_light<I: Isa>(
        &self,
        rays: &RayLanes<I>,
        hit: &HitLanes<I>,
        materials: &MaterialLanes<I>,
        active: u32,
        counts: &mut RayCounts,
    ) -> V3<I> {
        let surface = &hit.surface;
        let to_eye = -self.view::<I>(rays.direction);
        let mut color = V3::<I>::splat(self.scene.ambient) * materials.diffuse;
        for light in &self.scene.lights {
            let (to_light, intensity, position) = match *light {
                Light::Point { position, color, falloff } => {
                    let offset = V3::<I>::splat(position) - surface.point;
                    let distance_squared = offset.length_squared();
                    let intensity = V3::<I>::splat(color).divide(R8::<I>::splat(falloff) * distance_squared);
                    (offset.normalize_or_zero(), intensity, Some(position))
                }
                Light::Directional { direction, color } => (V3::splat(-direction), V3::splat(color), None),
            };
            let mut lit = active;
            if self.shadows {
                counts.shadow += u64::from(active.count_ones());
                let (shadow_rays, t_max) = match position {
                    Some(position) => spawn_to_lanes::<I>(self.spawn, surface, V3::splat(position)),
                    None => (spawn_lanes::<I>(self.spawn, surface, to_light), R8::<I>::splat(Real::INFINITY)),
                };
                lit &= !self.scene.geometry.occluded_packet::<I>(&shadow_rays, t_max, active);
            }
            if lit != 0 {
                let shaded = shade::<I>(materials, surface.shading_normal, to_light, to_eye, intensity, lit);
                color = V3::select(mask::<I>(lit), color + shaded, color);
            }
        }
        color
    }

    /// The direction a ray travels in, as [`Whitted`](super::integrator::Whitted) takes it.
    #[inline(always)]
    fn view<I: Isa>(&self, direction: V3<I>) -> V3<I> {
        match self.spawn {
            Spawn::Course => direction,
            _ => direction.normalize(),
        }
    }
}

/// The points of `raster` (one to eight) as lanes of `x` and `y`; lanes past the end repeat the
/// last point.
#[inline(always)]
fn raster_lanes<I: Isa>(raster: &[Vec2]) -> (R8<I>, R8<I>) {
    let mut axes = [[0.0; LANES]; 2];
    for lane in 0..LANES {
        let point = raster[lane.min(raster.len() - 1)];
        (axes[0][lane], axes[1][lane]) = (point.x, point.y);
    }
    (R8::<I>::load(&axes[0]), R8::<I>::load(&axes[1]))
}

/// Each lane's `t` and shading normal, for the lanes that hit something.
#[inline(always)]
fn first_hits<I: Isa>(hit: &HitLanes<I>) -> [Option<(Real, Vec3)>; LANES] {
    let (normals, mut t, mut first) = (hit.surface.shading_normal.vectors(), [0.0; LANES], [None; LANES]);
    hit.surface.t.store(&mut t);
    for k in set_lanes(hit.hits) {
        first[k] = Some((t[k], normals[k]));
    }
    first
}

/// [`Material::shade`](super::scene::material::Material::shade) lane by lane, for the lanes of
/// `lit`: `powf` runs only for lanes whose highlight counts.
#[inline(always)]
fn shade<I: Isa>(
    materials: &MaterialLanes<I>,
    normal: V3<I>,
    to_light: V3<I>,
    to_eye: V3<I>,
    intensity: V3<I>,
    lit: u32,
) -> V3<I> {
    let zero = R8::<I>::splat(0.0);
    let cos_light = to_light.dot(normal);
    let diffuse = materials.diffuse.scale(cos_light.max(zero));
    let reflected = normal.scale(R8::<I>::splat(2.0) * cos_light) - to_light;
    let cos_view = reflected.dot(to_eye).max(zero);
    let plain: Mask<I> = cos_view.le(R8::<I>::splat(1.0));
    let without_highlight = materials.matte & plain.bits();
    let highlighted = lit & !without_highlight;
    if highlighted == 0 {
        return diffuse * intensity;
    }
    let mut highlight = [0.0; LANES];
    cos_view.store(&mut highlight);
    for k in set_lanes(highlighted) {
        let shininess = materials.shininess[k];
        if shininess != 1.0 {
            highlight[k] = highlight[k].powf(shininess);
        }
    }
    let with_highlight = (diffuse + materials.specular.scale(R8::<I>::load(&highlight))) * intensity;
    V3::select(mask::<I>(without_highlight), diffuse * intensity, with_highlight)
}
