//! Loading Wavefront OBJ meshes.
//!
//! tobj does the reading, but its errors carry no line number and its output is shaped for
//! real-time use (one mesh per object or group, each with its own vertex numbering), so the
//! text first goes through a checking pass of our own. That pass reports the first malformed
//! `v`, `vn` or `f` line by number, and hands tobj a normalised copy of the file: only `v`,
//! `vn` and `f` lines, faces with absolute `v` or `v//vn` indices, no objects, groups or
//! materials. tobj then returns a single mesh whose vertex identity is the file's `v` index,
//! which the averaged-normal rule depends on (with `single_index = true` tobj would instead
//! duplicate positions per distinct `v/vt/vn` combination, splitting the averages).
//!
//! tobj reads coordinates as `f32` unless its `use_f64` feature is on; enable it together with
//! a switch of `Real` to `f64`.

use std::fmt::Write;
use std::path::Path;

use super::mesh::{Mesh, MeshError, NormalSource, VertexNormals};
use super::real::{Real, Vec3};

impl Mesh {
    /// Loads an OBJ file, merging all of its objects and groups into one mesh and triangulating
    /// polygons as fans. Texture coordinates, materials, points and lines are ignored.
    pub fn load_obj(path: &Path, normals: NormalSource) -> Result<Mesh, MeshError> {
        let bytes = std::fs::read(path).map_err(|source| MeshError::Read {
            path: path.to_owned(),
            source,
        })?;
        let text = String::from_utf8_lossy(&bytes);
        // A byte-order mark would otherwise glue itself to the first keyword and hide that line.
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        Mesh::from_obj_text(text, path, normals)
    }

    /// Like [`Mesh::load_obj`] for text already in memory; `path` only names it in errors.
    pub fn from_obj_text(
        text: &str,
        path: &Path,
        normals: NormalSource,
    ) -> Result<Mesh, MeshError> {
        let counts = Counts::of(text);
        let use_file_normals =
            normals == NormalSource::FromFileOrAveraged && counts.every_corner_has_normal;
        let normalised =
            normalise(text, &counts, use_file_normals).map_err(|(line, problem)| {
                MeshError::Malformed {
                    path: path.to_owned(),
                    line,
                    problem,
                }
            })?;
        if counts.faces == 0 {
            return Err(MeshError::NoFaces {
                path: path.to_owned(),
            });
        }
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: false,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, _) = tobj::load_obj_buf(&mut normalised.as_bytes(), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|source| MeshError::Obj {
            path: path.to_owned(),
            source,
        })?;

        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        let mut file_normals = Vec::new();
        let mut normal_triangles = Vec::new();
        for model in models {
            let mesh = model.mesh;
            let (vertex_base, normal_base) = (positions.len() as u32, file_normals.len() as u32);
            positions.extend(mesh.positions.chunks_exact(3).map(to_vec3));
            triangles.extend(
                mesh.indices
                    .chunks_exact(3)
                    .map(|t| triangle(t, vertex_base)),
            );
            file_normals.extend(mesh.normals.chunks_exact(3).map(to_vec3));
            normal_triangles.extend(
                mesh.normal_indices
                    .chunks_exact(3)
                    .map(|t| triangle(t, normal_base)),
            );
        }
        let vertex_normals = if use_file_normals {
            VertexNormals::Indexed {
                normals: file_normals,
                triangles: normal_triangles,
            }
        } else {
            VertexNormals::Averaged
        };
        Mesh::new(&positions, &triangles, vertex_normals).map_err(|source| MeshError::InFile {
            path: path.to_owned(),
            source: Box::new(source),
        })
    }
}

fn to_vec3<F: Copy + Into<f64>>(xyz: &[F]) -> Vec3 {
    Vec3::new(
        xyz[0].into() as Real,
        xyz[1].into() as Real,
        xyz[2].into() as Real,
    )
}

fn triangle(corners: &[u32], base: u32) -> [u32; 3] {
    [corners[0] + base, corners[1] + base, corners[2] + base]
}

/// What a first pass learns, so that the second can resolve forward references and knows
/// whether the file's normals are complete enough to use.
struct Counts {
    vertices: usize,
    texcoords: usize,
    normals: usize,
    faces: usize,
    every_corner_has_normal: bool,
}

impl Counts {
    fn of(text: &str) -> Counts {
        let mut counts = Counts {
            vertices: 0,
            texcoords: 0,
            normals: 0,
            faces: 0,
            every_corner_has_normal: true,
        };
        for line in text.lines() {
            let mut tokens = content(line).split_whitespace();
            match tokens.next() {
                Some("v") => counts.vertices += 1,
                Some("vt") => counts.texcoords += 1,
                Some("vn") => counts.normals += 1,
                Some("f") => {
                    counts.faces += 1;
                    counts.every_corner_has_normal &= tokens.all(|corner| {
                        corner
                            .split('/')
                            .nth(2)
                            .is_some_and(|normal| !normal.is_empty())
                    });
                }
                _ => {}
            }
        }
        counts.every_corner_has_normal &= counts.faces > 0;
        counts
    }
}

/// The line without its `#` comment. A plain byte scan: `split_once` goes through `memchr`,
/// whose setup dominates on lines this short.
fn content(line: &str) -> &str {
    match line.bytes().position(|byte| byte == b'#') {
        Some(hash) => &line[..hash],
        None => line,
    }
}

/// The checked and normalised text, or the first problem as (1-based line number, message).
fn normalise(text: &str, counts: &Counts, keep_normals: bool) -> Result<String, (usize, String)> {
    let mut out = String::with_capacity(text.len());
    let mut seen = Seen::default();
    for (index, line) in text.lines().enumerate() {
        let mut tokens = content(line).split_whitespace();
        let result = match tokens.next() {
            Some("v") => {
                seen.vertices += 1;
                vertex(tokens, &mut out)
            }
            Some("vt") => {
                seen.texcoords += 1;
                Ok(())
            }
            Some("vn") => {
                seen.normals += 1;
                normal(tokens, keep_normals, &mut out)
            }
            Some("f") => face(tokens, counts, &seen, keep_normals, &mut out),
            _ => Ok(()),
        };
        result.map_err(|problem| (index + 1, problem))?;
    }
    Ok(out)
}

/// How many of each element precede the current line, for OBJ's negative (relative) indices.
#[derive(Default)]
struct Seen {
    vertices: usize,
    texcoords: usize,
    normals: usize,
}

fn number(token: &str) -> Result<Real, String> {
    token
        .parse::<Real>()
        .map_err(|_| format!("`{token}` is not a number"))
}

/// Up to `N` tokens and how many there were in all, without allocating: this runs once per
/// line of files with millions of lines.
fn take_tokens<'a, const N: usize>(tokens: impl Iterator<Item = &'a str>) -> ([&'a str; N], usize) {
    let mut taken = [""; N];
    let mut count = 0;
    for token in tokens {
        if count < N {
            taken[count] = token;
        }
        count += 1;
    }
    (taken, count)
}

/// Accepts `x y z`, `x y z w` (divided through, as tobj does) and `x y z r g b`.
fn vertex<'a>(tokens: impl Iterator<Item = &'a str>, out: &mut String) -> Result<(), String> {
    let (tokens, count) = take_tokens::<4>(tokens);
    if !matches!(count, 3 | 4 | 6) {
        return Err(format!(
            "expected `v x y z`, `v x y z w` or `v x y z r g b`, found {count} values"
        ));
    }
    let w = if count == 4 { number(tokens[3])? } else { 1.0 };
    if w == 0.0 {
        return Err("the vertex has w = 0".to_owned());
    }
    let position = Vec3::new(number(tokens[0])?, number(tokens[1])?, number(tokens[2])?) / w;
    if !position.is_finite() {
        let shown = tokens[..count.min(4)].join(" ");
        return Err(format!(
            "vertex coordinates must be finite, found `{shown}`"
        ));
    }
    if count == 4 {
        let _ = writeln!(out, "v {} {} {}", position.x, position.y, position.z);
    } else {
        for part in ["v ", tokens[0], " ", tokens[1], " ", tokens[2], "\n"] {
            out.push_str(part);
        }
    }
    Ok(())
}

/// Non-finite normals are accepted here; the mesh falls back to geometric normals for them.
fn normal<'a>(
    tokens: impl Iterator<Item = &'a str>,
    keep: bool,
    out: &mut String,
) -> Result<(), String> {
    let (tokens, count) = take_tokens::<3>(tokens);
    if count != 3 {
        return Err(format!("expected `vn x y z`, found {count} values"));
    }
    for token in tokens {
        number(token)?;
    }
    if keep {
        for part in ["vn ", tokens[0], " ", tokens[1], " ", tokens[2], "\n"] {
            out.push_str(part);
        }
    }
    Ok(())
}

/// Accepts corners `v`, `v/vt`, `v/vt/vn` and `v//vn`, checking every index against the
/// file's counts; writes `v` or `v//vn` with absolute 1-based indices. On error the partly
/// written line is left behind, which does not matter because loading stops.
fn face<'a>(
    tokens: impl Iterator<Item = &'a str>,
    counts: &Counts,
    seen: &Seen,
    keep_normals: bool,
    out: &mut String,
) -> Result<(), String> {
    out.push('f');
    let mut corner_count = 0;
    for corner in tokens {
        corner_count += 1;
        let mut parts = corner.split('/');
        let vertex = parts.next().filter(|v| !v.is_empty());
        let (texcoord, normal) = (parts.next(), parts.next());
        let (Some(vertex), None) = (vertex, parts.next()) else {
            return Err(format!(
                "`{corner}` is not a face vertex (v, v/vt, v/vt/vn or v//vn)"
            ));
        };
        let vertex = resolve(vertex, "vertex", seen.vertices, counts.vertices)?;
        if let Some(texcoord) = texcoord.filter(|t| !t.is_empty()) {
            resolve(
                texcoord,
                "texture coordinate",
                seen.texcoords,
                counts.texcoords,
            )?;
        }
        let normal = match normal.filter(|n| !n.is_empty()) {
            Some(normal) => Some(resolve(normal, "normal", seen.normals, counts.normals)?),
            None => None,
        };
        out.push(' ');
        push_index(out, vertex + 1);
        if let Some(normal) = normal.filter(|_| keep_normals) {
            out.push_str("//");
            push_index(out, normal + 1);
        }
    }
    if corner_count < 3 {
        return Err(format!(
            "a face needs at least 3 vertices, found {corner_count}"
        ));
    }
    out.push('\n');
    Ok(())
}

/// Appends the decimal digits of `n`; `write!` costs several times more, per index.
fn push_index(out: &mut String, mut n: usize) {
    let mut digits = [0u8; 20];
    let mut start = digits.len();
    loop {
        start -= 1;
        digits[start] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    digits[start..]
        .iter()
        .for_each(|&digit| out.push(digit as char));
}

/// The 0-based index an OBJ index refers to: positive ones count from the start of the file
/// (forward references allowed), negative ones back from the last element read so far.
fn resolve(token: &str, what: &str, seen: usize, total: usize) -> Result<usize, String> {
    let index: i64 = token
        .parse()
        .map_err(|_| format!("`{token}` is not a {what} index"))?;
    let resolved = match index {
        0 => return Err(format!("{what} index 0 is invalid: OBJ indices start at 1")),
        i if i > 0 => (i - 1) as u64,
        i => (seen as i64 + i) as u64,
    };
    if resolved >= total as u64 {
        let plural = if what == "vertex" {
            "vertices".to_owned()
        } else {
            format!("{what}s")
        };
        return Err(format!(
            "{what} index {index} is out of range: the file has {total} {plural}"
        ));
    }
    Ok(resolved as usize)
}
