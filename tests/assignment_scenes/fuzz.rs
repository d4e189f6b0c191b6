//! No input makes the importer panic, and whatever it accepts exports to TOML that loads back
//! to the same case: the two formats validate alike.

use std::fs;
use std::sync::LazyLock;

use goldray::case::{LoadOptions, case_to_toml, parse};
use proptest::prelude::*;

use super::*;
use crate::export::same_case;

const WORDS: &[&str] = &[
    "PerspectiveCamera",
    "Background",
    "Lights",
    "Materials",
    "Group",
    "center",
    "direction",
    "up",
    "angle",
    "color",
    "ambientLight",
    "cubeMap",
    "tex/church",
    "numLights",
    "DirectionalLight",
    "PointLight",
    "position",
    "falloff",
    "numMaterials",
    "Material",
    "PhongMaterial",
    "diffuseColor",
    "specularColor",
    "shininess",
    "bump",
    "numObjects",
    "MaterialIndex",
    "Sphere",
    "radius",
    "Plane",
    "normal",
    "offset",
    "Triangle",
    "vertex0",
    "vertex1",
    "vertex2",
    "TriangleMesh",
    "obj_file",
    "models/cube2.obj",
    "Transform",
    "Scale",
    "UniformScale",
    "Translate",
    "XRotate",
    "YRotate",
    "ZRotate",
    "Rotate",
    "Matrix4f",
    "{",
    "}",
    "0",
    "1",
    "-1",
    "2",
    ".5",
    "-.16",
    "20}",
    "1e308",
    "1e999",
    "nan",
    "-inf",
    "99999999999999999999",
    "é",
    "\u{0}",
    "{}",
    "}}",
];

const SEPARATORS: &[&str] = &[" ", "\n", "\r\n", "\t", "  ", "\u{b}"];

/// Accepted input must also be exportable: asserted here rather than only for the course scenes
/// because mutations reach corners (zero radius, huge numbers) that the scenes never do.
fn check(source: &str, path: &Path) {
    let Ok(case) = parse_assignment_scene(source, path, &AssignmentOptions::default()) else {
        return;
    };
    let toml_path = path.with_extension("toml");
    let text = case_to_toml(&case, &toml_path);
    let loaded = parse(&text, &toml_path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}\nexported from:\n{source}\nas:\n{text}"));
    same_case(&loaded, &case);
}

static COURSE_TEXTS: LazyLock<Vec<(PathBuf, String)>> = LazyLock::new(|| {
    SCENES
        .iter()
        .map(|name| {
            let path = data_dir().join(name);
            let text = fs::read_to_string(&path).unwrap();
            (path, text)
        })
        .collect()
});

/// Byte ranges of the numbers in `text`, each without a `}` that touches it.
fn number_spans(text: &str) -> Vec<std::ops::Range<usize>> {
    let mut spans = Vec::new();
    let mut start = 0;
    for word in text.split_ascii_whitespace() {
        let offset = start + text[start..].find(word).unwrap_or(0);
        start = offset + word.len();
        let number = word.trim_end_matches('}');
        if number.parse::<f64>().is_ok() {
            spans.push(offset..offset + number.len());
        }
    }
    spans
}

fn any_number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|v| format!("{v:?}")),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        (-4i32..5).prop_map(|v| v.to_string()),
        prop::sample::select(vec!["0", "-0", ".5", "-.25", "1e-300", "1e300", "0.1", "179.99"]).prop_map(str::to_owned),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn token_soup_never_panics(
        tokens in prop::collection::vec(
            (prop::sample::select(WORDS), prop::sample::select(SEPARATORS)),
            0..120,
        ),
    ) {
        let source: String = tokens.iter().flat_map(|(w, s)| [*w, *s]).collect();
        check(&source, &synthetic_path());
    }

    #[test]
    fn arbitrary_text_never_panics(source in "\\PC{0,300}") {
        check(&source, &synthetic_path());
    }

    #[test]
    fn mutated_course_scenes_never_panic(
        scene in 0..SCENES.len(),
        position in 0usize..4000,
        cut in 0usize..12,
        insert in prop::sample::select(WORDS),
    ) {
        let (path, text) = &COURSE_TEXTS[scene];
        let mut source = text.clone();
        let mut start = position % (source.len() + 1);
        while !source.is_char_boundary(start) {
            start -= 1;
        }
        let mut end = (start + cut).min(source.len());
        while !source.is_char_boundary(end) {
            end += 1;
        }
        source.replace_range(start..end, insert);
        check(&source, path);
    }

    /// Keeps the grammar intact, so that most cases are accepted and so exported and reloaded.
    #[test]
    fn course_scenes_with_other_numbers_round_trip(
        scene in 0..SCENES.len(),
        which in any::<prop::sample::Index>(),
        number in any_number(),
    ) {
        let (path, text) = &COURSE_TEXTS[scene];
        let spans = number_spans(text);
        let mut source = text.clone();
        source.replace_range(spans[which.index(spans.len())].clone(), &number);
        check(&source, path);
    }
}
