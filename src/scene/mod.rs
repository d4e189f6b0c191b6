//! A scene ready to render: built once from a case, immutable while rendering. Camera, lights and
//! materials are part of the description (peers of the geometry, as in pbrt-v4).

mod aggregate;
mod build;
pub mod camera;
mod cube_map;
pub mod light;
pub mod material;
mod object;

pub use aggregate::{Aggregate, HitLanes, Intersection};
pub use build::{build_scene, build_scene_measured};
pub use cube_map::{CubeMap, CubeMapError};
pub use object::{Object, Shape, ShapeHit, Triangle};

use super::{geometry, real};
use camera::Camera;
use light::Light;
use material::Material;
use real::{Color, Vec3};

use crate::stats::CubeMapFaces;

/// What a ray that hits nothing sees.
#[derive(Debug)]
pub enum Background {
    Color(Color),
    /// Boxed: a cube map is large and most scenes have a plain colour.
    CubeMap(Box<CubeMap>),
}

impl Background {
    pub fn radiance(&self, direction: Vec3) -> Color {
        match self {
            Background::Color(color) => *color,
            Background::CubeMap(map) => map.radiance(direction),
        }
    }
}

impl Scene {
    /// A cube map face that could not be decoded when a ray first looked at it (the ray saw
    /// black instead): a render for which this is `Some` must be discarded. Cube map faces are
    /// checked at load, so this takes a PNG whose structure and checksums are sound but whose
    /// image data is not.
    pub fn render_failure(&self) -> Option<CubeMapError> {
        match &self.background {
            Background::CubeMap(map) => map.failure(),
            Background::Color(_) => None,
        }
    }

    /// The cube map faces decoded and read from the texel cache so far; `None` without a cube map.
    pub fn cube_map_faces(&self) -> Option<CubeMapFaces> {
        match &self.background {
            Background::CubeMap(map) => Some(map.faces_loaded()),
            Background::Color(_) => None,
        }
    }

    /// Decodes every cube map face now, so that no render of the scene can fail: for callers that
    /// render one scene many times.
    pub fn decode_everything(&self) -> Result<(), CubeMapError> {
        match &self.background {
            Background::CubeMap(map) => map.decode_all(),
            Background::Color(_) => Ok(()),
        }
    }
}

#[derive(Debug)]
pub struct Scene {
    pub camera: Camera,
    pub background: Background,
    pub ambient: Color,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub geometry: Aggregate,
}
