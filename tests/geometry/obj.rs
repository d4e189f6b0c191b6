//! OBJ loading: the assignment's normal rule, accepted face forms, and errors that point at
//! the file and line.

use std::path::{Path, PathBuf};

use goldray::geometry::mesh::{Mesh, MeshError, NormalSource};
use goldray::real::{Real, Vec3};
use proptest::prelude::*;

use super::{Rng, ray_through};

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn load(path: &Path, normals: NormalSource) -> Mesh {
    Mesh::load_obj(path, normals).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

/// Normal at the corner of `mesh` sitting at `position`, for every triangle that has one.
fn corner_normals(mesh: &Mesh, position: Vec3) -> Vec<Vec3> {
    (0..mesh.triangle_count() as u32)
        .flat_map(|t| {
            let normals = mesh.vertex_normals(t).expect("usable normals");
            mesh.triangle(t)
                .into_iter()
                .zip(normals)
                .filter(move |(p, _)| *p == position)
        })
        .map(|(_, n)| n)
        .collect()
}

/// A four-sided pyramid over an irregular base, its sides in two groups. The sides differ in
/// area, so an area-weighted average would give a different apex normal.
const PYRAMID: &str = "\
v 0 0 1
v 2 0 0
v 0 1 0
v -1 0 0
v 0 -3 0
vn 0 0 1
g first
f 1//1 2//1 3//1
f 1//1 3//1 4//1
g second
f 1//1 4//1 5//1
f 1//1 5//1 2//1
";

fn pyramid_face_normal(b: Vec3, c: Vec3) -> Vec3 {
    let apex = Vec3::Z;
    (b - apex).cross(c - apex).normalize()
}

#[test]
fn averaged_normals_are_the_unweighted_sum_across_groups() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(&dir, "pyramid.obj", PYRAMID);
    let mesh = load(&path, NormalSource::Averaged);
    assert_eq!(mesh.triangle_count(), 4);
    let base = [
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::Y,
        Vec3::NEG_X,
        Vec3::new(0.0, -3.0, 0.0),
    ];
    let faces: Vec<Vec3> = (0..4)
        .map(|i| pyramid_face_normal(base[i], base[(i + 1) % 4]))
        .collect();
    let apex_expected = faces.iter().sum::<Vec3>().normalize();
    let apex = corner_normals(&mesh, Vec3::Z);
    assert_eq!(apex.len(), 4, "the apex is shared by all four faces, in both groups");
    assert!(
        apex.iter().all(|&n| close(n, apex_expected)),
        "{apex:?} vs {apex_expected}"
    );
    for i in 0..4 {
        let expected = (faces[i] + faces[(i + 3) % 4]).normalize();
        let got = corner_normals(&mesh, base[i]);
        assert!(
            got.iter().all(|&n| close(n, expected)),
            "base {i}: {got:?} vs {expected}"
        );
    }
}

#[test]
fn file_normals_are_used_when_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(&dir, "pyramid.obj", PYRAMID);
    let mesh = load(&path, NormalSource::FromFileOrAveraged);
    assert!(corner_normals(&mesh, Vec3::Z).iter().all(|&n| n == Vec3::Z));
    let ray = ray_through(Vec3::new(0.3, 0.2, 5.0), Vec3::new(0.3, 0.2, 0.0));
    let hit = mesh.intersect(&ray, Real::INFINITY).expect("hit");
    assert_eq!(mesh.surface(&hit).shading_normal, Vec3::Z);
}

#[test]
fn faces_with_texture_coordinates_load() {
    let dir = tempfile::tempdir().unwrap();
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1/1/ 3/3 4/2\n";
    let mesh = load(&write(&dir, "textured.obj", text), NormalSource::FromFileOrAveraged);
    assert_eq!(mesh.triangle_count(), 2);
    assert!(corner_normals(&mesh, Vec3::ZERO).iter().all(|&n| close(n, Vec3::Z)));
}

fn load_error(text: &str) -> (PathBuf, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = write(&dir, "broken.obj", text);
    let error = Mesh::load_obj(&path, NormalSource::Averaged).expect_err("must not load");
    (path, error.to_string())
}

#[test]
fn malformed_files_name_the_path_and_line() {
    let cases = [
        ("v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n", 3, "`zero` is not a number"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n# fine so far\nf 1 2 4\n", 5, "out of range"),
        ("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", 2, "finite"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "at least 3"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, "start at 1"),
    ];
    for (text, line, problem) in cases {
        let (path, message) = load_error(text);
        let location = format!("{}:{line}:", path.display());
        assert!(message.contains(&location), "{message:?} should contain {location:?}");
        assert!(message.contains(problem), "{message:?} should mention {problem:?}");
    }
}

#[test]
fn a_file_without_faces_is_an_error() {
    let (path, message) = load_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    assert!(
        message.contains(&path.display().to_string()) && message.contains("no faces"),
        "{message}"
    );
}

#[test]
fn a_missing_file_is_named() {
    let path = Path::new("/nonexistent/goldray/missing.obj");
    let error = Mesh::load_obj(path, NormalSource::Averaged).expect_err("must not load");
    assert!(matches!(error, MeshError::Read { .. }));
    assert!(
        error.to_string().contains("/nonexistent/goldray/missing.obj"),
        "{error}"
    );
}

/// The course's meshes: counts match the files, normals are unit, and a ray aimed at any
/// triangle hits something no farther than that triangle.
#[test]
fn course_meshes_load() {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/mit6837/models");
    let entries = std::fs::read_dir(&models).unwrap_or_else(|e| panic!("cannot read {} ({e})", models.display()));
    let mut paths: Vec<PathBuf> = entries
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "obj"))
        .collect();
    paths.sort();
    assert!(
        paths.len() >= 7,
        "expected the course's 7 meshes in {}",
        models.display()
    );
    let mut rng = Rng::new(9);
    for path in paths {
        let text = std::fs::read_to_string(&path).unwrap();
        let faces = text.lines().filter(|line| line.starts_with("f ")).count();
        let mesh = load(&path, NormalSource::Averaged);
        assert_eq!(mesh.triangle_count(), faces, "{}", path.display());
        let radius = mesh.bounds().extent().length();
        for triangle in 0..mesh.triangle_count() as u32 {
            if let Some(normals) = mesh.vertex_normals(triangle) {
                assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
            }
            let [a, b, c] = mesh.triangle(triangle);
            let target = (a + b + c) / 3.0;
            let ray = ray_through(target + rng.direction() * radius, target);
            let hit = mesh.intersect(&ray, Real::INFINITY);
            assert!(hit.is_some_and(|h| h.t <= 1.0 + 1e-4), "{}: {ray:?}", path.display());
        }
    }
}

fn load_text(text: &str) -> Result<Mesh, MeshError> {
    Mesh::from_obj_text(text, Path::new("test.obj"), NormalSource::FromFileOrAveraged)
}

/// The line number of the load error, which must be a malformed-content error.
fn problem_line(text: &str) -> usize {
    match load_text(text) {
        Err(MeshError::Malformed { line, .. }) => line,
        other => panic!("expected a malformed-file error, got {other:?}"),
    }
}

#[test]
fn accepts_relative_indices_comments_quads_and_crlf() {
    let text = "# square\r\nv 0 0 0\r\nv 1 0 0 # corner\r\nv 1 1 0\r\nv 0 1 0 1\r\nf -4 -3 -2 -1\r\n";
    assert_eq!(load_text(text).unwrap().triangle_count(), 2);
}

#[test]
fn reports_the_offending_line() {
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    assert_eq!(problem_line(&format!("{v}f 1 2\n")), 4);
    assert_eq!(problem_line(&format!("{v}f 1 2 0\n")), 4);
    assert_eq!(problem_line(&format!("{v}f 1 2 -4\n")), 4);
    assert_eq!(problem_line(&format!("{v}f 1/1 2/1 3/1\n")), 4);
    assert_eq!(problem_line(&format!("{v}f 1//1 2//1 3//1\n")), 4);
    assert_eq!(problem_line(&format!("{v}f 1/2/3/4 2 3\n")), 4);
    assert_eq!(problem_line(&format!("{v}v 1 inf 0\nf 1 2 3\n")), 4);
    assert_eq!(problem_line(&format!("{v}v 1 2 3 0\nf 1 2 3\n")), 4);
    assert_eq!(problem_line(&format!("{v}vn 0 0\nf 1 2 3\n")), 4);
    assert_eq!(problem_line("v 1 2\n"), 1);
}

#[test]
fn no_faces_is_an_error() {
    assert!(matches!(load_text("v 0 0 0\n"), Err(MeshError::NoFaces { .. })));
    assert!(matches!(load_text(""), Err(MeshError::NoFaces { .. })));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn never_panics_on_arbitrary_lines(lines in prop::collection::vec(
        prop::sample::select(vec![
            "v 0 0 0", "v 1 2", "v 1e39 0 0", "v nan 0 0", "v 1 2 3 4 5", "vn 0 0 1",
            "vn nan 0 0", "vt 0 0", "f 1 2 3", "f 1//1 2//1 3//1", "f 1/1/1 2/1/1 3/1/1",
            "f -1 -2 -3", "f 1 1 1", "f 1 2 3 4 5", "f 1 /2 3", "f 0 1 2", "f 99 1 2",
            "f 1", "g part", "o thing", "usemtl x", "mtllib x.mtl", "l 1 2", "# c", "",
            "f 1//", "f a b c", "v 0 0 0 1 1 1", "s off", "\u{fffd}",
        ]),
        0..24,
    )) {
        let _ = load_text(&lines.join("\n"));
    }
}
