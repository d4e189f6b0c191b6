//! A scene ready to render: built once from a case, immutable while rendering.

mod aggregate;
mod build;
mod cube_map;
mod object;

pub use aggregate::{Aggregate, Intersection};
pub use build::{build_scene, build_scene_measured};
pub use cube_map::CubeMap;
pub use object::{Object, Shape, ShapeHit, Triangle};

use super::{geometry, real, render};
use render::camera::Camera;
use render::light::Light;
use render::material::Material;
use real::{Color, Vec3};

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

#[derive(Debug)]
pub struct Scene {
    pub camera: Camera,
    pub background: Background,
    pub ambient: Color,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub geometry: Aggregate,
}
