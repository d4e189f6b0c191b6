//! Locations and suggestions: the two things every message of a reader is built from.

use std::path::Path;

use super::suggest::{nearest, suggest};
use super::{SourceLocation, parse};

fn location(text: &str, offset: usize) -> (usize, usize) {
    let l = SourceLocation::from_offset(Path::new("f.toml"), text, offset);
    (l.line, l.column)
}

#[test]
fn locations_are_one_based_and_count_characters() {
    let text = "a = 1\r\nbé = \"ü\"\nc";
    assert_eq!(location(text, 0), (1, 1));
    assert_eq!(location(text, 4), (1, 5));
    assert_eq!(location(text, 7), (2, 1));
    let quote = text.find('"').unwrap();
    assert_eq!(location(text, quote), (2, 6), "é is one column, two bytes");
    assert_eq!(location(text, quote + 2), (2, 7), "inside ü falls back to its start");
    assert_eq!(location(text, 10_000), (3, 2), "past the end clamps");
    let l = SourceLocation {
        file: "cases/a.toml".into(),
        line: 3,
        column: 9,
    };
    assert_eq!(l.to_string(), "cases/a.toml:3:9");
}

#[test]
fn suggestions_are_close_or_absent() {
    let keys = ["center", "radius", "material"];
    assert_eq!(nearest("raduis", &keys), Some("radius"));
    assert_eq!(nearest("Radius", &keys), Some("radius"));
    assert_eq!(nearest("materials", &keys), Some("material"));
    assert_eq!(nearest("colour", &keys), None);
    assert_eq!(nearest("x", &[]), None);
    assert_eq!(
        suggest("raduis", &keys, "keys"),
        "; did you mean `radius`? valid keys: center, radius, material"
    );
    assert_eq!(suggest("zzz", &keys, "keys"), "; valid keys: center, radius, material");
    assert_eq!(suggest("zzz", &[], "materials"), "; valid materials: (none)");
}

#[test]
fn duplicate_keys_and_tables_name_the_key_and_where_it_was_first_given() {
    let message = |text: &str| parse(text, Path::new("c.toml")).unwrap_err().to_string();
    assert_eq!(
        message("[render]\nbounces = 1\nshadows = true\nbounces = 2\n"),
        "c.toml:4:1: invalid TOML: duplicate key `bounces`: already given on line 2 (each may appear once)"
    );
    assert_eq!(
        message("[render]\nbounces = 1\n[camera]\nfov = 30\n[render]\nseed = 2\n"),
        "c.toml:5:2: invalid TOML: duplicate table `render`: already given on line 1 (each may appear once)"
    );
    // The same key in another table is not the first occurrence.
    assert_eq!(
        message("[a]\nx = 1\n[b]\nx = 1\nx = 2\n"),
        "c.toml:5:1: invalid TOML: duplicate key `x`: already given on line 4 (each may appear once)"
    );
}
