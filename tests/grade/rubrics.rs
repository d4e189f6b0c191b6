//! Rubric files: located mistakes, and the shipped course rubric.

use std::path::Path;

use goldray::grade::{Output, load_rubric, parse_rubric};

use crate::class;

#[test]
fn rubric_mistakes_are_located_and_explained() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.toml");
    let scene = class::scene_path();
    let good = class::rubric_text(&scene);
    let cases = [
        (
            good.replace("render = \"spheres\"\npoints = 2", "render = \"sphere\"\npoints = 2"),
            "r.toml:16:10",
            "did you mean `spheres`",
        ),
        (
            good.replace("partial_fraction = 0.05", "partial_fraction = 0.001"),
            "r.toml:3:1",
            "below pass_fraction",
        ),
        (
            good.replace("output = \"normals\"", "output = \"normal\""),
            "r.toml:21:10",
            "did you mean `normals`",
        ),
        (
            good.replace("depth = [6, 14]", "depth = [14, 6]"),
            "r.toml:26:9",
            "min below max",
        ),
        (
            good.replace("[image.\"color.png\"]", "[image.\"../color.png\"]"),
            "r.toml:15:8",
            "PNG file name",
        ),
        (
            good.replace("size = [100, 100]", "size = [100, 100]\nshadows = true"),
            "r.toml:14:1",
            "course-scene flag",
        ),
        (
            good.replace("pass_flip = 0.1\n", ""),
            "r.toml:3:1",
            "both pass_flip and partial_flip",
        ),
        (
            good.replace(&format!("{scene:?}"), "\"nowhere.toml\""),
            "r.toml:11:9",
            "nowhere.toml",
        ),
    ];
    for (text, location, hint) in cases {
        assert_ne!(text, good, "the mistake for {hint} was not made");
        let message = parse_rubric(&text, &path).map(|_| ()).unwrap_err().to_string();
        assert!(
            message.contains(location) && message.contains(hint),
            "want {location} … {hint}, got: {message}"
        );
    }
}

#[test]
fn the_shipped_course_rubric_grades_the_21_images_of_the_seven_commands() {
    let rubric = load_rubric(&Path::new(env!("CARGO_MANIFEST_DIR")).join("rubrics/mit6837.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let files: Vec<&str> = rubric.images.iter().map(|i| i.file.as_str()).collect();
    let expected: Vec<String> = (1..=7)
        .flat_map(|n| [format!("a0{n}.png"), format!("a0{n}n.png"), format!("a0{n}d.png")])
        .collect();
    assert_eq!(files, expected);
    assert_eq!(rubric.renders.len(), 7);
    for render in &rubric.renders {
        assert_eq!(
            (render.case.render.trace.width, render.case.render.trace.height),
            (800, 800),
            "{}",
            render.name
        );
    }
    let scene07 = &rubric.renders[6].case.render;
    assert!(scene07.trace.shadows && scene07.trace.bounces == 4);
    assert_eq!(rubric.renders[5].case.render.trace.bounces, 4);
    assert!(!rubric.renders[5].case.render.trace.shadows);
    let depth05 = &rubric.images[14];
    assert_eq!(depth05.output, Output::Depth { min: 0.8, max: 1.0 });
    assert_eq!(rubric.images.iter().map(|i| i.points).sum::<f64>(), 28.0);

    let class_rubric = parse_rubric(&class::rubric_text(&class::scene_path()), Path::new("class.toml")).unwrap();
    assert!(
        rubric.images.iter().all(|i| i.rule == class_rubric.images[0].rule),
        "the synthetic class is graded by the shipped rules"
    );
}
