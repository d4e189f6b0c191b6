//! Random valid scenes in the course's text format.
//!
//! Every scene is a pure function of its seed, through a PRNG written out here rather than a
//! crate's, so that a seed names the same scene on every machine and in every later version.
//! The scenes are valid for the course's parser (`SceneParser.cpp`), and they exercise what a
//! student or TA may write: every block, field orders shuffled, optional fields left out,
//! keyword aliases, repeated blocks, nested groups and transforms, every transform op, the
//! course meshes and the cube map, numbers in every form `%f` reads, and random whitespace
//! (numbers touching `}` and the next word included). The geometry is kept in front of the
//! camera and at sizes where both renderers' single-precision arithmetic is well conditioned,
//! so that a difference in the images is a difference in the renderers.

use std::fmt::Write as _;

/// SplitMix64 (Steele, Lea and Flood 2014): tiny, fast and fully specified by its code.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `lo..=hi`.
    pub fn int(&mut self, lo: u32, hi: u32) -> u32 {
        lo + (self.next() % u64::from(hi - lo + 1)) as u32
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[(self.next() % items.len() as u64) as usize]
    }

    fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = (self.next() % (i as u64 + 1)) as usize;
            items.swap(i, j);
        }
    }

    /// A unit vector, uniform on the sphere.
    fn direction(&mut self) -> [f64; 3] {
        loop {
            let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            let length = dot(v, v).sqrt();
            if length > 0.1 && length <= 1.0 {
                return v.map(|c| c / length);
            }
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A scene and the command-line settings it is rendered with.
pub struct Scene {
    pub text: String,
    pub width: u32,
    pub height: u32,
    /// `-depth MIN MAX`, around the camera's distance to what it looks at.
    pub depth: (f64, f64),
    /// `-bounces` of the run with `-shadows`.
    pub bounces: u32,
}

/// The course meshes under `models/` and the uniform scale that makes each about 2 units wide.
const MESHES: &[(&str, f64, f64)] = &[
    ("models/cube.obj", 0.5, 1.1),
    ("models/cube2.obj", 0.5, 1.1),
    ("models/bunny_200.obj", 6.0, 9.0),
    ("models/bunny_1k.obj", 6.0, 9.0),
    ("models/c1.obj", 1.5, 2.5),
    ("models/c2.obj", 1.5, 2.5),
    ("models/c3.obj", 1.5, 2.5),
];

/// How deep groups and transforms nest at most.
const MAX_DEPTH: u32 = 4;

pub fn scene(seed: u64) -> Scene {
    let mut rng = Rng::new(seed);
    let width = rng.int(64, 128);
    let height = rng.int(64, 128);
    let bounces = rng.int(1, 4);
    let mut g = Generator {
        rng,
        text: String::new(),
        last: Last::Word,
        plane_used: false,
    };
    let distance = g.scene();
    Scene {
        text: g.text,
        width,
        height,
        // Two decimals, as the command line gets them.
        depth: (
            ((distance - 4.0).max(0.5) * 100.0).round() / 100.0,
            ((distance + 6.0) * 100.0).round() / 100.0,
        ),
        bounces,
    }
}

/// What the text ends with, which decides what may touch the next token.
#[derive(Clone, Copy, PartialEq)]
enum Last {
    Word,
    /// A decimal number, or a count: `%f`/`%d` stop before a letter other than `e`, `E`, `x`,
    /// `X`, so a word starting with another letter may follow without a space.
    Decimal,
    /// A hexadecimal number, after which only whitespace is safe.
    Hex,
}

#[derive(Clone, Copy)]
enum Block {
    Camera,
    Background,
    Lights,
    Materials,
    Group,
}

struct Generator {
    rng: Rng,
    text: String,
    last: Last,
    plane_used: bool,
}

impl Generator {
    /// Whitespace between tokens: mostly one space or a newline and indentation, sometimes
    /// tabs, CRLF, vertical tabs and form feeds (C's `isspace`).
    fn space(&mut self) {
        if self.text.is_empty() {
            return;
        }
        let space = *self.rng.pick(&[
            " ", " ", " ", " ", "\n", "\n    ", "\n\t", "  ", "\t", "\r\n", "\n\n  ", " \x0b ", "\x0c\n",
        ]);
        self.text.push_str(space);
    }

    fn word(&mut self, word: &str) {
        let glue = self.last == Last::Decimal
            && !word.starts_with(['e', 'E', 'x', 'X'])
            && word.starts_with(|c: char| c.is_ascii_alphabetic())
            && self.rng.chance(0.03);
        if !glue {
            self.space();
        }
        self.text.push_str(word);
        self.last = Last::Word;
    }

    /// `}`, touching the number before it now and then (`shininess 20}`).
    fn close(&mut self) {
        if self.last != Last::Word && self.rng.chance(0.25) {
            self.text.push('}');
            self.last = Last::Word;
        } else {
            self.word("}");
        }
    }

    /// A count, as `%d` reads it: sometimes signed or zero-padded.
    fn count(&mut self, n: u32) {
        self.space();
        let text = match self.rng.int(0, 9) {
            0 => format!("+{n}"),
            1 => format!("0{n}"),
            2 if n == 0 => "-0".to_owned(),
            _ => n.to_string(),
        };
        self.text.push_str(&text);
        self.last = Last::Decimal;
    }

    /// `value` rounded to `decimals` places, written in one of the forms `%f` reads.
    fn number(&mut self, value: f64, decimals: i32) {
        let scale = 10f64.powi(decimals);
        let value = (value * scale).round() / scale;
        self.space();
        let (text, last) = self.format(value, decimals);
        self.text.push_str(&text);
        self.last = last;
    }

    fn format(&mut self, value: f64, decimals: i32) -> (String, Last) {
        let plain = if value == 0.0 {
            "0".to_owned()
        } else {
            value.to_string()
        };
        let text = match self.rng.int(0, 19) {
            // `.5`, `-.5`
            0 | 1 if plain.starts_with("0.") || plain.starts_with("-0.") => plain.replacen("0.", ".", 1),
            // `+2`
            2 if value >= 0.0 => format!("+{plain}"),
            // `2.`
            3 if !plain.contains('.') => format!("{plain}."),
            // `125e-3`, `2E0`: the same decimal, scaled to an integer mantissa.
            4 => format!(
                "{}{}{}",
                (value * 10f64.powi(decimals)).round(),
                self.rng.pick(&["e-", "E-", "e-0"]),
                decimals
            ),
            // `1.25e-1`
            5 => format!("{value:e}"),
            // Hexadecimal: exactly the float `%f` would make of the decimal.
            6 => return (hex_float(value as f32), Last::Hex),
            // `-0`, `0.0`, `.0`
            7 if value == 0.0 => self.rng.pick(&["-0", "0.0", ".0", "0e0", "-0."]).to_string(),
            _ => plain,
        };
        (text, Last::Decimal)
    }

    fn vector(&mut self, v: [f64; 3], decimals: i32) {
        for c in v {
            self.number(c, decimals);
        }
    }

    fn color(&mut self, lo: f64, hi: f64) {
        let c = [0, 1, 2].map(|_| self.rng.range(lo, hi));
        self.vector(c, 2);
    }

    /// The whole scene; returns the camera's distance to the point it looks at.
    fn scene(&mut self) -> f64 {
        let mut blocks = vec![Block::Camera, Block::Background, Block::Lights, Block::Materials];
        self.rng.shuffle(&mut blocks);
        // MaterialIndex refers to materials read before it, so Materials precedes the Group;
        // any other order is the course's too.
        let at = self.rng.int(
            blocks.iter().position(|b| matches!(b, Block::Materials)).unwrap() as u32 + 1,
            4,
        );
        blocks.insert(at as usize, Block::Group);
        let (mut distance, mut materials) = (0.0, 0);
        for block in blocks {
            // A repeated block: a camera or Group replaces the earlier one, a Background changes
            // only the fields it names, Lights and Materials blocks add up (the last count alone
            // decides the ambient rule and which material indices are valid).
            let twice = self.rng.chance(0.05);
            for _ in 0..=u32::from(twice) {
                match block {
                    Block::Camera => distance = self.camera(),
                    Block::Background => self.background(),
                    Block::Lights => self.lights(),
                    Block::Materials => materials = self.materials(),
                    Block::Group => self.group(materials, 0, true),
                }
            }
        }
        distance
    }

    fn camera(&mut self) -> f64 {
        let look = [0, 1, 2].map(|_| self.rng.range(-1.0, 1.0));
        let elevation = self.rng.range(-20.0f64, 60.0).to_radians();
        let azimuth = self.rng.range(0.0f64, 360.0).to_radians();
        let distance = self.rng.range(9.0, 16.0);
        let toward = [
            elevation.cos() * azimuth.sin(),
            elevation.sin(),
            elevation.cos() * azimuth.cos(),
        ];
        let center = [0, 1, 2].map(|i| look[i] + distance * toward[i]);
        // Unnormalised on purpose: the course normalises the direction but uses `up` as given.
        let stretch = self.rng.range(0.5, 2.0);
        let direction = toward.map(|c| -c * stretch);
        let up_length = self.rng.range(0.6, 1.4);
        let up = [
            self.rng.range(-0.25, 0.25) * up_length,
            up_length,
            self.rng.range(-0.25, 0.25) * up_length,
        ];
        self.word("PerspectiveCamera");
        self.word("{");
        self.word("center");
        self.vector(center, 3);
        self.word("direction");
        self.vector(direction, 3);
        self.word("up");
        self.vector(up, 3);
        self.word("angle");
        let angle = self.rng.range(25.0, 60.0);
        self.number(angle, 1);
        self.close();
        distance
    }

    fn background(&mut self) {
        self.word("Background");
        self.word("{");
        if self.rng.chance(0.05) {
            self.word("color");
            self.color(0.0, 1.0);
        }
        let mut fields = vec![0, 1, 2];
        self.rng.shuffle(&mut fields);
        for field in fields {
            match field {
                0 if self.rng.chance(0.85) => {
                    self.word("color");
                    self.color(0.0, 1.0);
                }
                1 if self.rng.chance(0.85) => {
                    self.word("ambientLight");
                    self.color(0.0, 0.3);
                }
                2 if self.rng.chance(0.2) => {
                    self.word("cubeMap");
                    self.word("tex/church");
                }
                _ => {}
            }
        }
        self.close();
    }

    fn lights(&mut self) {
        let count = if self.rng.chance(0.08) { 0 } else { self.rng.int(1, 3) };
        self.word("Lights");
        self.word("{");
        self.word("numLights");
        self.count(count);
        for _ in 0..count {
            if self.rng.chance(0.5) {
                self.directional_light();
            } else {
                self.point_light();
            }
        }
        self.close();
    }

    fn directional_light(&mut self) {
        let mut direction = self.rng.direction();
        direction[1] = -direction[1].abs() - 0.2;
        let scale = self.rng.range(0.3, 3.0);
        self.word("DirectionalLight");
        self.word("{");
        self.word("direction");
        self.vector(direction.map(|c| c * scale), 3);
        self.word("color");
        self.color(0.2, 0.9);
        self.close();
    }

    /// Fields in any order, `position` and `color` sometimes left to their defaults (0),
    /// `falloff` always given: its default 0 divides by zero in the course.
    fn point_light(&mut self) {
        let distance = self.rng.range(4.0, 9.0);
        let mut toward = self.rng.direction();
        toward[1] = toward[1].abs();
        let falloff = 1.0 / (distance * distance * self.rng.range(0.5, 1.5));
        self.word("PointLight");
        self.word("{");
        // A field given twice: the course keeps the last.
        if self.rng.chance(0.05) {
            self.word("falloff");
            self.number(0.5, 1);
        }
        let mut fields = vec![0, 1, 2];
        self.rng.shuffle(&mut fields);
        for field in fields {
            match field {
                0 if self.rng.chance(0.93) => {
                    self.word("position");
                    self.vector(toward.map(|c| c * distance), 2);
                }
                1 if self.rng.chance(0.95) => {
                    self.word("color");
                    self.color(0.3, 1.2);
                }
                2 => {
                    self.word("falloff");
                    self.number(falloff, 4);
                }
                _ => {}
            }
        }
        self.close();
    }

    /// Returns the block's count.
    fn materials(&mut self) -> u32 {
        let count = self.rng.int(1, 5);
        self.word("Materials");
        self.word("{");
        self.word("numMaterials");
        self.count(count);
        for _ in 0..count {
            let keyword = *self.rng.pick(&["Material", "PhongMaterial"]);
            self.word(keyword);
            self.word("{");
            let mut fields = vec![0, 1, 2, 3];
            self.rng.shuffle(&mut fields);
            for field in fields {
                match field {
                    0 if self.rng.chance(0.9) => {
                        self.word("diffuseColor");
                        self.color(0.0, 1.0);
                    }
                    1 if self.rng.chance(0.6) => {
                        self.word("specularColor");
                        self.color(0.0, 0.8);
                    }
                    2 if self.rng.chance(0.7) => {
                        self.word("shininess");
                        let shininess = self.rng.range(1.0, 80.0);
                        self.number(shininess, 1);
                    }
                    // The course reads a bump map's name and ignores it.
                    3 if self.rng.chance(0.05) => {
                        self.word("bump");
                        self.word("tex/bump.png");
                    }
                    _ => {}
                }
            }
            self.close();
        }
        self.close();
        count
    }

    /// `MaterialIndex` is one current material for the whole file: it holds across nesting.
    fn group(&mut self, materials: u32, depth: u32, top: bool) {
        let count = self.rng.int(if top { 2 } else { 1 }, if top { 7 } else { 3 });
        self.word("Group");
        self.word("{");
        self.word("numObjects");
        self.count(count);
        for i in 0..count {
            if (top && i == 0) || self.rng.chance(0.3) {
                self.word("MaterialIndex");
                let index = self.rng.int(0, materials - 1);
                self.count(index);
            }
            self.object(materials, depth);
        }
        self.close();
    }

    fn object(&mut self, materials: u32, depth: u32) {
        let nest = depth < MAX_DEPTH;
        loop {
            match self.rng.int(0, 99) {
                0..=29 => return self.sphere(),
                30..=41 => return self.triangle(),
                42..=55 => return self.mesh(),
                56..=79 if nest => return self.transform(materials, depth),
                80..=91 if nest => return self.group(materials, depth + 1, false),
                92..=99 if !self.plane_used => return self.plane(),
                _ => {}
            }
        }
    }

    fn sphere(&mut self) {
        let center = [0, 1, 2].map(|_| self.rng.range(-2.5, 2.5));
        // A negative radius draws the sphere of radius |r| in the course.
        let sign = if self.rng.chance(0.05) { -1.0 } else { 1.0 };
        let radius = sign * self.rng.range(0.3, 1.4);
        self.word("Sphere");
        self.word("{");
        self.word("center");
        self.vector(center, 2);
        self.word("radius");
        self.number(radius, 2);
        self.close();
    }

    /// Below the other objects, facing up (give or take), so that it is a floor rather than a
    /// wall across the view; the camera may still see its unlit back.
    fn plane(&mut self) {
        self.plane_used = true;
        let normal = [self.rng.range(-0.3, 0.3), 1.0, self.rng.range(-0.3, 0.3)];
        let scale = self.rng.range(0.5, 2.0);
        let offset = self.rng.range(-3.5, -2.0) * scale;
        self.word("Plane");
        self.word("{");
        self.word("normal");
        self.vector(normal.map(|c| c * scale), 2);
        self.word("offset");
        self.number(offset, 2);
        self.close();
    }

    /// Not sliver-thin: the face normal of a near-degenerate triangle is too sensitive to
    /// rounding for two renderers to agree on it.
    fn triangle(&mut self) {
        let center = [0, 1, 2].map(|_| self.rng.range(-2.5, 2.5));
        let vertices = loop {
            let v = [0, 1, 2].map(|_| [0, 1, 2].map(|i| center[i] + self.rng.range(-1.6, 1.6)));
            let e1 = [0, 1, 2].map(|i| v[1][i] - v[0][i]);
            let e2 = [0, 1, 2].map(|i| v[2][i] - v[0][i]);
            let n = cross(e1, e2);
            let area = dot(n, n).sqrt() / 2.0;
            let longest = [dot(e1, e1), dot(e2, e2)].into_iter().fold(0.0, f64::max);
            if area > 0.5 && area / longest > 0.15 {
                break v;
            }
        };
        self.word("Triangle");
        self.word("{");
        for (i, v) in vertices.iter().enumerate() {
            self.word(&format!("vertex{i}"));
            self.vector(*v, 2);
        }
        self.close();
    }

    /// A course mesh, scaled to about 2 units and placed; the Transform is the one way to size
    /// and move a mesh in this format.
    fn mesh(&mut self) {
        let &(file, lo, hi) = self.rng.pick(MESHES);
        let scale = self.rng.range(lo, hi);
        let offset = [0, 1, 2].map(|_| self.rng.range(-2.0, 2.0));
        self.word("Transform");
        self.word("{");
        self.word("Translate");
        self.vector(offset, 2);
        if self.rng.chance(0.5) {
            let op = *self.rng.pick(&["XRotate", "YRotate", "ZRotate"]);
            self.word(op);
            let degrees = self.rng.range(-180.0, 180.0);
            self.number(degrees, 1);
        }
        self.word("UniformScale");
        self.number(scale, 2);
        self.word("TriangleMesh");
        self.word("{");
        self.word("obj_file");
        self.word(file);
        self.close();
        self.close();
    }

    /// One to four ops of every kind, then one object (which may be a group or a transform).
    fn transform(&mut self, materials: u32, depth: u32) {
        self.word("Transform");
        self.word("{");
        for _ in 0..self.rng.int(1, 4) {
            match self.rng.int(0, 7) {
                0 => {
                    self.word("Translate");
                    let v = [0, 1, 2].map(|_| self.rng.range(-2.0, 2.0));
                    self.vector(v, 2);
                }
                1 => {
                    self.word("Scale");
                    let mut v = [0, 1, 2].map(|_| self.rng.range(0.5, 1.6));
                    if self.rng.chance(0.1) {
                        v[self.rng.int(0, 2) as usize] *= -1.0;
                    }
                    self.vector(v, 2);
                }
                2 => {
                    self.word("UniformScale");
                    let s = self.rng.range(0.6, 1.5);
                    self.number(s, 2);
                }
                3..=5 => {
                    let op = ["XRotate", "YRotate", "ZRotate"][self.rng.int(0, 2) as usize];
                    self.word(op);
                    let degrees = self.rng.range(-180.0, 180.0);
                    self.number(degrees, 1);
                }
                6 => {
                    self.word("Rotate");
                    self.word("{");
                    let axis = self.rng.direction();
                    let length = self.rng.range(0.5, 3.0);
                    self.vector(axis.map(|c| c * length), 2);
                    let degrees = self.rng.range(-180.0, 180.0);
                    self.number(degrees, 1);
                    self.close();
                }
                _ => self.matrix(),
            }
        }
        self.object(materials, depth + 1);
        self.close();
    }

    /// An affine matrix (rotation, mild scale and shear, translation), written column by
    /// column as the course reads it.
    fn matrix(&mut self) {
        let axis = self.rng.direction();
        let angle = self.rng.range(-180.0f64, 180.0).to_radians();
        let (s, c) = angle.sin_cos();
        let [x, y, z] = axis;
        let rotation = [
            [
                c + x * x * (1.0 - c),
                x * y * (1.0 - c) - z * s,
                x * z * (1.0 - c) + y * s,
            ],
            [
                y * x * (1.0 - c) + z * s,
                c + y * y * (1.0 - c),
                y * z * (1.0 - c) - x * s,
            ],
            [
                z * x * (1.0 - c) - y * s,
                z * y * (1.0 - c) + x * s,
                c + z * z * (1.0 - c),
            ],
        ];
        let scale = [0, 1, 2].map(|_| self.rng.range(0.6, 1.4));
        let shear = self.rng.range(-0.3, 0.3);
        let translate = [0, 1, 2].map(|_| self.rng.range(-1.5, 1.5));
        let mut m = [[0.0; 4]; 4];
        for row in 0..3 {
            for col in 0..3 {
                m[row][col] = rotation[row][col] * scale[col] + if row == 0 && col == 1 { shear } else { 0.0 };
            }
            m[row][3] = translate[row];
        }
        m[3][3] = 1.0;
        self.word("Matrix4f");
        self.word("{");
        for col in 0..4 {
            for row in m {
                self.number(row[col], 4);
            }
        }
        self.close();
    }
}

/// `%a`-style hexadecimal of a finite float: `0x1.8p+1`, `-0x1p-3`, `0x0p+0`.
fn hex_float(value: f32) -> String {
    let sign = if value.is_sign_negative() { "-" } else { "" };
    if value == 0.0 {
        return format!("{sign}0x0p+0");
    }
    let bits = value.abs().to_bits();
    let (exponent, mantissa) = ((bits >> 23) as i32, bits & 0x7F_FFFF);
    let (lead, exponent) = if exponent == 0 { (0, -126) } else { (1, exponent - 127) };
    // 23 mantissa bits as six hex digits (24 bits), trailing zeros dropped.
    let digits = format!("{:06x}", mantissa << 1);
    let digits = digits.trim_end_matches('0');
    let point = if digits.is_empty() { "" } else { "." };
    let mut out = String::new();
    let _ = write!(out, "{sign}0x{lead}{point}{digits}p{exponent:+}");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_floats_are_exact() {
        assert_eq!(hex_float(3.0), "0x1.8p+1");
        assert_eq!(hex_float(-0.125), "-0x1p-3");
        assert_eq!(hex_float(0.0), "0x0p+0");
        assert_eq!(hex_float(0.1), "0x1.99999ap-4");
    }

    #[test]
    fn a_seed_names_one_scene() {
        assert_eq!(scene(7).text, scene(7).text);
        assert_ne!(scene(7).text, scene(8).text);
    }
}
