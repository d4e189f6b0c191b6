//! Point and directional lights.

use super::real::{Color, Real, Vec3};

#[derive(Clone, Copy, Debug)]
pub enum Light {
    /// Intensity `color / (falloff·d²)` at distance `d`.
    Point { position: Vec3, color: Color, falloff: Real },
    /// Parallel light travelling along `direction` (unit), from infinitely far away.
    Directional { direction: Vec3, color: Color },
}

/// What a light delivers to one shading point.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit vector from the shading point towards the light.
    pub to_light: Vec3,
    pub intensity: Color,
    /// Where a shadow ray must stop: the light's position, or `None` for a light at infinity.
    pub position: Option<Vec3>,
}

impl Light {
    pub fn incident(&self, point: Vec3) -> Incident {
        match *self {
            Light::Point { position, color, falloff } => {
                let offset = position - point;
                let distance_squared = offset.length_squared();
                Incident {
                    to_light: offset.normalize_or_zero(),
                    intensity: color / (falloff * distance_squared),
                    position: Some(position),
                }
            }
            Light::Directional { direction, color } => {
                Incident { to_light: -direction, intensity: color, position: None }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_light_falls_off_with_the_square_of_distance() {
        let light = Light::Point { position: Vec3::new(0.0, 4.0, 0.0), color: Vec3::ONE, falloff: 0.5 };
        let incident = light.incident(Vec3::ZERO);
        assert_eq!(incident.to_light, Vec3::Y);
        assert!((incident.intensity.x - 1.0 / (0.5 * 16.0)).abs() < 1e-7);
        assert_eq!(incident.position, Some(Vec3::new(0.0, 4.0, 0.0)));
    }

    #[test]
    fn directional_light_points_back_along_its_direction() {
        let light = Light::Directional { direction: -Vec3::Y, color: Vec3::splat(0.5) };
        let incident = light.incident(Vec3::new(100.0, 3.0, -7.0));
        assert_eq!(incident.to_light, Vec3::Y);
        assert_eq!(incident.intensity, Vec3::splat(0.5));
        assert!(incident.position.is_none());
    }
}
