//! The scene-wide blocks: the camera, the background, the lights and the materials.

use super::Parser;
use super::lexer::{Result, Token};
use crate::case::sections::{cube_map_problem, is_parallel};
use crate::case::spec::{BackgroundSpec, CameraSpec, LightSpec, MaterialSpec};

impl Parser<'_> {
    /// The course reads the camera's fields in this fixed order and nothing else.
    pub(super) fn camera(&mut self) -> Result<CameraSpec> {
        self.lex.expect("{", "after `PerspectiveCamera`")?;
        self.lex.expect("center", "first in PerspectiveCamera")?;
        let center = self.lex.vec3("3 numbers after `center`")?.value;
        self.lex.expect("direction", "after the camera's center")?;
        let direction = self.direction("direction")?;
        self.lex.expect("up", "after the camera's direction")?;
        let up = self.direction("up")?;
        if is_parallel(direction.value, up.value) {
            return Err(self.invalid_vec(&up, "`up`", "must not be parallel to direction"));
        }
        self.lex.expect("angle", "after the camera's up vector")?;
        let (fov, token) = self.lex.number("a number after `angle`")?;
        if fov <= 0.0 || fov >= 180.0 {
            let rule = "must be strictly between 0 and 180 degrees";
            return Err(self.invalid(token, "`angle`", rule));
        }
        self.lex.expect("}", "closing PerspectiveCamera")?;
        Ok(CameraSpec {
            center,
            direction: direction.value,
            up: up.value,
            fov,
        })
    }

    /// Updates `background` in place: the course lets a later Background block change only the
    /// fields it names.
    pub(super) fn background(&mut self, background: &mut BackgroundSpec) -> Result<()> {
        const FIELDS: &[&str] = &["color", "ambientLight", "cubeMap"];
        self.lex.expect("{", "after `Background`")?;
        loop {
            let token = self.lex.word_for("a Background field or `}`")?;
            match token.text {
                "}" => return Ok(()),
                "color" => background.color = self.color("color")?,
                "ambientLight" => background.ambient = self.color("ambientLight")?,
                "cubeMap" => {
                    let written = self.lex.word_for("a directory after `cubeMap`")?;
                    let path = self.dir.join(written.text);
                    if let Some(problem) = cube_map_problem(&path) {
                        return Err(self.invalid(written, "`cubeMap`", &problem));
                    }
                    background.cube_map = Some(path);
                }
                _ => return Err(self.unknown(token, "Background field", FIELDS, "fields")),
            }
        }
    }

    /// Exactly `numLights` lights: the course reads that many and then insists on the `}`.
    /// Returns them with the count, which decides the ambient rule.
    pub(super) fn lights(&mut self) -> Result<(Vec<LightSpec>, usize)> {
        const KINDS: &[&str] = &["DirectionalLight", "PointLight"];
        self.lex.expect("{", "after `Lights`")?;
        self.lex.expect("numLights", "first in Lights")?;
        let (count, _) = self.lex.count("numLights")?;
        let mut lights = Vec::new();
        while lights.len() < count {
            let token = self.lex.word_for("a DirectionalLight or PointLight")?;
            lights.push(match token.text {
                "DirectionalLight" => {
                    self.lex.expect("{", "after `DirectionalLight`")?;
                    self.lex.expect("direction", "first in DirectionalLight")?;
                    let direction = self.direction("direction")?.value;
                    self.lex.expect("color", "after the light's direction")?;
                    let color = self.color("color")?;
                    self.lex.expect("}", "closing DirectionalLight")?;
                    LightSpec::Directional { direction, color }
                }
                "PointLight" => self.point_light(token)?,
                "}" => return Err(self.too_few(token, "numLights", count, lights.len(), "light")),
                _ => return Err(self.unknown(token, "light", KINDS, "lights")),
            });
        }
        self.lex
            .expect("}", &format!("closing Lights after its {count} (numLights) lights"))?;
        Ok((lights, count))
    }

    /// Fields in any order, each optional and the last of a repeated one winning, as the
    /// course's loop reads them. `position` and `color` default to zero as there; `falloff`
    /// defaults to 0 there too, which divides by zero and renders every lit surface black
    /// (NaN), so here it is required.
    fn point_light(&mut self, keyword: Token) -> Result<LightSpec> {
        const FIELDS: &[&str] = &["position", "color", "falloff"];
        self.lex.expect("{", "after `PointLight`")?;
        let (mut position, mut color, mut falloff) = ([0.0; 3], [0.0; 3], None);
        loop {
            let token = self.lex.word_for("a PointLight field or `}`")?;
            match token.text {
                "}" => break,
                "position" => position = self.lex.vec3("3 numbers after `position`")?.value,
                "color" => color = self.color("color")?,
                "falloff" => {
                    let (value, token) = self.lex.number("a number after `falloff`")?;
                    // As a `float`, as the course divides by it: 1e-300 is 0 there.
                    if value as f32 <= 0.0 {
                        let rule = "must be > 0 in single precision (intensity is color / (falloff · d²))";
                        return Err(self.invalid(token, "`falloff`", rule));
                    }
                    falloff = Some(value);
                }
                _ => return Err(self.unknown(token, "PointLight field", FIELDS, "fields")),
            }
        }
        let Some(falloff) = falloff else {
            let message = "this PointLight has no `falloff`: the course would divide by its \
                           default 0 and render every lit surface black; add e.g. `falloff 0.05` \
                           (intensity is color / (falloff · d²))";
            return Err(self.lex.error_at(keyword.start, message));
        };
        Ok(LightSpec::Point {
            position,
            color,
            falloff,
        })
    }

    /// Appends, as the course does: its material list grows with every block, while
    /// `numMaterials` is replaced, so `MaterialIndex k` names the k-th material of the whole
    /// file and must be below the latest block's count.
    pub(super) fn materials(&mut self) -> Result<()> {
        const KINDS: &[&str] = &["Material", "PhongMaterial"];
        self.lex.expect("{", "after `Materials`")?;
        self.lex.expect("numMaterials", "first in Materials")?;
        let (count, _) = self.lex.count("numMaterials")?;
        let first = self.materials.len();
        while self.materials.len() - first < count {
            let token = self.lex.word_for("a Material or PhongMaterial")?;
            match token.text {
                "Material" | "PhongMaterial" => {
                    let material = self.material(token)?;
                    self.materials.push(material);
                }
                "}" => {
                    let given = self.materials.len() - first;
                    return Err(self.too_few(token, "numMaterials", count, given, "material"));
                }
                _ => return Err(self.unknown(token, "material", KINDS, "materials")),
            }
        }
        self.lex.expect(
            "}",
            &format!("closing Materials after its {count} (numMaterials) materials"),
        )?;
        self.material_count = count;
        Ok(())
    }

    fn material(&mut self, keyword: Token) -> Result<MaterialSpec> {
        const FIELDS: &[&str] = &["diffuseColor", "specularColor", "shininess", "bump"];
        self.lex.expect("{", &format!("after `{}`", keyword.text))?;
        let mut material = MaterialSpec {
            name: format!("material{}", self.materials.len()),
            diffuse: [1.0; 3],
            specular: [0.0; 3],
            shininess: 0.0,
        };
        loop {
            let token = self.lex.word_for("a material field or `}`")?;
            match token.text {
                "}" => return Ok(material),
                "diffuseColor" => material.diffuse = self.color("diffuseColor")?,
                "specularColor" => material.specular = self.color("specularColor")?,
                "shininess" => {
                    let (value, token) = self.lex.number("a number after `shininess`")?;
                    if value < 0.0 {
                        return Err(self.invalid(token, "`shininess`", "must be ≥ 0"));
                    }
                    material.shininess = value;
                }
                // The reference renderer reads a bump map's name but never uses it.
                "bump" => {
                    self.lex.word_for("a file name after `bump`")?;
                }
                _ => return Err(self.unknown(token, "material field", FIELDS, "fields")),
            }
        }
    }
}
