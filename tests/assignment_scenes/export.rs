//! Writing an imported case as TOML: the file loads back to the same case, says only what
//! differs from the defaults, and points at the assets from where it is written.

use std::fs;

use goldray::case::{LoadOptions, case_to_toml, load, parse};

use super::*;

/// Asserts that two cases are equal in everything but their name, path and source locations,
/// comparing asset paths by the file they name rather than how they are spelled.
pub fn same_case(actual: &Case, expected: &Case) {
    assert_eq!(comparable(actual), comparable(expected));
}

fn comparable(case: &Case) -> Case {
    let mut case = case.clone();
    case.name.clear();
    case.path.clear();
    case.background.cube_map = case.background.cube_map.as_deref().map(canonical);
    case.objects.iter_mut().for_each(comparable_object);
    case
}

fn comparable_object(object: &mut ObjectSpec) {
    object.location = SourceLocation {
        file: PathBuf::new(),
        line: 0,
        column: 0,
    };
    match &mut object.shape {
        ShapeSpec::Mesh { obj } => *obj = canonical(obj),
        ShapeSpec::Group { objects } => objects.iter_mut().for_each(comparable_object),
        _ => {}
    }
}

fn canonical(path: &Path) -> PathBuf {
    fs::canonicalize(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Writes `case` to `cases/NAME.toml` in a fresh directory under the target directory, loads it
/// back, asserts that nothing changed and returns the text. Its asset paths are relative when the
/// target directory shares a parent with the course data (the default `target/` does), absolute
/// otherwise (a `CARGO_TARGET_DIR` elsewhere); either loads.
fn round_trip(case: &Case) -> String {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let path = dir.path().join("cases").join(format!("{}.toml", case.name));
    fs::create_dir_all(path.parent().unwrap()).unwrap();
    let text = case_to_toml(case, &path);
    fs::write(&path, &text).unwrap();
    let loaded =
        load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("the exported case must load: {e}\n{text}"));
    same_case(&loaded, case);
    text
}

#[test]
fn every_course_scene_round_trips_through_toml() {
    for name in SCENES {
        let case = course_scene(name);
        let text = round_trip(&case);
        assert!(text.starts_with("# Imported from "), "{text}");
        assert!(text.contains(&format!("cases/mit6837/{name} by goldray")), "{text}");
    }
}

#[test]
fn asset_paths_are_relative_to_the_case_file() {
    // Exported as if beside this test file, which shares the project root with the course data
    // wherever the target directory is; parsed from there, without writing anything.
    let case = course_scene("scene07_arch.txt");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assignment_scenes/arch.toml");
    let text = case_to_toml(&case, &path);
    same_case(&parse(&text, &path, &LoadOptions::default()).unwrap(), &case);
    let relative = |key: &str, tail: &str| {
        let line = text
            .lines()
            .find(|l| l.contains(key))
            .unwrap_or_else(|| panic!("{key} in {text}"));
        assert!(
            line.contains("= \"../") && line.ends_with(&format!("{tail}\"")),
            "{line}"
        );
        assert!(
            line.contains("\"../../"),
            "climbs out of tests/assignment_scenes/: {line}"
        );
    };
    relative("cube_map = ", "cases/mit6837/tex/church");
    relative("obj = ", "cases/mit6837/models/cube2.obj");
}

#[test]
fn paths_that_cannot_be_made_relative_are_absolute() {
    let case = course_scene("scene02_cube.txt");
    let nowhere = Path::new("/goldray-no-such-dir/cases/x.toml");
    let text = case_to_toml(&case, nowhere);
    // Absolute with `..` resolved as written, not through symlinks.
    let mut obj = PathBuf::new();
    for component in data_dir().join("models/cube2.obj").components() {
        match component {
            std::path::Component::ParentDir => {
                obj.pop();
            }
            other => obj.push(other),
        }
    }
    assert!(text.contains(&format!("obj = \"{}\"", obj.display())), "{text}");
    same_case(&parse(&text, nowhere, &LoadOptions::default()).unwrap(), &case);
}

#[test]
fn only_what_differs_from_the_defaults_is_written() {
    let text = round_trip(&course_scene("scene03_sphere.txt"));
    for expected in [
        "[render]\nprofile = \"mit6837\"\nsize = [100, 100]\n\n",
        "[camera]\ncenter = [0, 0, 10]\ndirection = [0, 0, -1]\nup = [0, 1, 0]\nfov = 20",
        "[background]\ncolor = [0.2, 0, 0.6]\n\n",
        "[materials.material0]\n\n",
        "[[object]]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"material0\"\n\
         transform = [{ rotate_z = 45 }, { scale = [1, 0.2, 1] }]\n",
    ] {
        assert!(text.contains(expected), "expected {expected:?} in:\n{text}");
    }
    for absent in ["[tolerance]", "tonemap", "samples", "ambient", "description"] {
        assert!(!text.contains(absent), "{absent} has its default:\n{text}");
    }
}

#[test]
fn every_render_flag_and_awkward_numbers_round_trip_exactly() {
    let options = AssignmentOptions {
        width: 640,
        height: 480,
        bounces: 4,
        shadows: true,
        jitter: true,
        filter: true,
        depth_range: Some((0.8, 1.0)),
        normals: true,
    };
    let source = with_camera(&format!(
        "Lights {{ numLights 1 PointLight {{ position 0.1 1e-7 -0 color 0.30000000000000004 1 1 \
         falloff 1e-30 }} }}\n\
         Materials {{ numMaterials 2 Material {{ specularColor 1 1 1 }} Material {{ diffuseColor 0.5 0.25 0.125 }} }}\n\
         Group {{ numObjects 2 MaterialIndex 1\n\
           Transform {{ Matrix4f {{ 1 0 0 0  0 1 0 0  0 0 1 0  1e20 -3.25 0.1 1 }} Rotate {{ 1 1 0 33.3 }}\n\
             Group {{ numObjects 2 Triangle {{ vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }}\n\
               Group {{ numObjects 1 MaterialIndex 0 {} }} }} }}\n\
           TriangleMesh {{ obj_file models/bunny_200.obj }} }}\n",
        sphere("123456789.123 0 3.4e38")
    ));
    let case = parse_assignment_scene(&source, &synthetic_path(), &options).unwrap();
    let text = round_trip(&case);
    assert!(
        text.contains("samples = 16\n") && text.contains("filter = \"gaussian\"\n"),
        "{text}"
    );
    assert!(text.contains("depth_range = [0.8, 1]\n"), "{text}");
    assert!(
        text.contains("1e20") && text.contains("1e-30") && text.contains("3.4e38"),
        "{text}"
    );
}

#[test]
fn a_tolerance_and_a_native_profile_are_written_when_they_differ() {
    let mut case = course_scene("scene01_plane.txt");
    case.render.profile = Profile::Native;
    case.tolerance.max = Some(0.5);
    case.tolerance.pixel = 0.02;
    case.description = Some("five spheres, \"quoted\"\nover two lines".to_owned());
    let text = round_trip(&case);
    assert!(text.contains("[tolerance]\npixel = 0.02\nmax = 0.5\n"), "{text}");
    assert!(
        text.contains("tonemap = \"clamp\""),
        "clamp is not the native default:\n{text}"
    );
}

#[test]
fn the_deepest_allowed_nesting_still_exports_to_loadable_toml() {
    let mut object = format!("Transform {{ Rotate {{ 1 1 0 30 }} {} }}", sphere("0 0 0"));
    for _ in 0..31 {
        object = format!("Group {{ numObjects 1 {object} }}");
    }
    let nested = parse_ok(&with_camera(&format!(
        "Materials {{ numMaterials 1 Material {{ }} }}\nGroup {{ numObjects 1 MaterialIndex 0 {object} }}"
    )));
    round_trip(&nested);
}
