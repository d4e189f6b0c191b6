//! The module graph of docs/ARCHITECTURE.md, checked on the sources: every import points to a
//! lower layer, and the library neither prints nor parses flags. A new module must be given a
//! layer here (and in the document) before it can be imported.

use std::fs;
use std::path::{Path, PathBuf};

/// Layer of each top-level library module, lowest first (docs/ARCHITECTURE.md, "The import graph").
const LAYERS: &[(&str, u32)] = &[
    ("atomic_write", 0),
    ("image_size", 0),
    ("progress", 0),
    ("named_enum", 0),
    ("simd", 0),
    ("html_escape", 0),
    ("rgb_image", 0),
    ("located_toml", 1),
    ("texel_cache", 1),
    ("build_error", 2),
    ("options", 2),
    ("fault", 2),
    ("stats", 2),
    ("provenance", 2),
    ("sandbox", 2),
    ("precision", 3),
    ("real", 3),
    ("geometry", 4),
    ("film", 5),
    ("compare", 6),
    ("case", 7),
    ("scene", 8),
    ("render", 9),
    ("assignment_outputs", 10),
    ("error", 10),
    ("pipeline", 11),
    ("grade", 12),
    ("tradeoff", 12),
    ("review", 12),
    ("run", 13),
    ("autograde", 14),
];

/// The modules compiled once per precision: inside them, `super::geometry` and the like name a
/// sibling module of the same instantiation.
const PER_PRECISION: [&str; 4] = ["geometry", "scene", "render", "real"];

fn layer(module: &str) -> Option<u32> {
    LAYERS.iter().find(|(name, _)| *name == module).map(|&(_, layer)| layer)
}

fn source_files(dir: &Path, files: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).expect("src is readable") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            source_files(&path, files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
}

/// The top-level module a file belongs to (`src/grade/score.rs` → `grade`), or `None` for the
/// binary (`main.rs`, `allocator.rs`, `cli/`) and the crate root.
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).expect("under src");
    let first = relative.components().next()?.as_os_str().to_string_lossy().into_owned();
    let name = first.trim_end_matches(".rs").to_owned();
    (!matches!(name.as_str(), "main" | "allocator" | "cli" | "lib")).then_some(name)
}

/// Code lines only: comment lines would name modules without depending on them.
fn code_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, line)| (i + 1, line.trim()))
        .filter(|(_, line)| !line.starts_with("//"))
}

/// The modules a line refers to: `crate::X`, and in per-precision code `super::…::X` for a sibling.
fn references(line: &str, per_precision: bool) -> Vec<String> {
    let mut found = Vec::new();
    let word = |rest: &str| -> String { rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect() };
    for (at, _) in line.match_indices("crate::") {
        found.push(word(&line[at + "crate::".len()..]));
    }
    if per_precision {
        for (at, _) in line.match_indices("super::") {
            let rest = line[at..].trim_start_matches("super::");
            let name = word(rest);
            if PER_PRECISION.contains(&name.as_str()) {
                found.push(name);
            }
        }
        if let Some(list) = line.strip_prefix("use super::{") {
            for name in list.trim_end_matches("};").split(',') {
                let name = name.trim().to_owned();
                if PER_PRECISION.contains(&name.as_str()) {
                    found.push(name);
                }
            }
        }
    }
    found
}

#[test]
fn every_import_points_to_a_lower_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    source_files(&src, &mut files);
    let mut violations = Vec::new();
    for file in &files {
        let Some(module) = module_of(&src, file) else { continue };
        let Some(own) = layer(&module) else {
            violations.push(format!("{}: module `{module}` has no layer", file.display()));
            continue;
        };
        let text = fs::read_to_string(file).expect("readable");
        for (number, line) in code_lines(&text) {
            for target in references(line, PER_PRECISION.contains(&module.as_str())) {
                if target == module || target.is_empty() {
                    continue;
                }
                match layer(&target) {
                    Some(theirs) if theirs < own => {}
                    Some(theirs) => violations.push(format!(
                        "{}:{number}: `{module}` (layer {own}) imports `{target}` (layer {theirs})",
                        file.display()
                    )),
                    None => {}
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "imports against the layering:\n{}",
        violations.join("\n")
    );
}

#[test]
fn the_library_neither_prints_nor_parses_flags() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    source_files(&src, &mut files);
    let forbidden = ["println!", "eprintln!", "print!(", "eprint!(", "clap::", "indicatif"];
    let mut found = Vec::new();
    for file in files.iter().filter(|f| module_of(&src, f).is_some()) {
        let text = fs::read_to_string(file).expect("readable");
        for (number, line) in code_lines(&text) {
            if let Some(word) = forbidden.iter().find(|w| line.contains(*w)) {
                found.push(format!("{}:{number}: {word}", file.display()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "printing or flag parsing in the library:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_checker_sees_imports_it_must_refuse() {
    assert_eq!(references("use crate::case::{Case, Tolerance};", false), ["case"]);
    assert_eq!(references("use super::render::camera::Camera;", true), ["render"]);
    assert_eq!(
        references("use super::{geometry, real, render};", true),
        ["geometry", "real", "render"]
    );
    assert!(references("use super::integrator::Whitted;", true).is_empty());
    assert!(layer("compare") < layer("case") && layer("scene") < layer("render"));
}

/// A file's module path below the crate root (`src/grade/diagnose/decide.rs` → `grade`,
/// `diagnose`, `decide`; a `mod.rs` names its folder), or `None` outside the library.
fn module_path(src: &Path, file: &Path) -> Option<Vec<String>> {
    module_of(src, file)?;
    let relative = file.strip_prefix(src).expect("under src").with_extension("");
    let mut path: Vec<String> = relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if path.last().is_some_and(|last| last == "mod") {
        path.pop();
    }
    Some(path)
}

/// The paths a code line names through `crate::` or `super::`, resolved against the module
/// `at` (one `{a, b::c}` group expanded), as segments: `super::score::judge` in `grade::diagnose`
/// gives `grade`, `score`, `judge`.
fn named_paths(line: &str, at: &[String]) -> Vec<Vec<String>> {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let mut found = Vec::new();
    for (start, _) in line.match_indices("crate::").chain(line.match_indices("super::")) {
        if line[..start].ends_with("super::") || line[..start].chars().last().is_some_and(is_word) {
            continue;
        }
        let mut rest = &line[start..];
        let mut base: Vec<String> = Vec::new();
        if let Some(after) = rest.strip_prefix("crate::") {
            rest = after;
        } else {
            base = at[..at.len().saturating_sub(1)].to_vec();
            rest = &rest["super::".len()..];
            while let Some(after) = rest.strip_prefix("super::") {
                base.pop();
                rest = after;
            }
        }
        let words: String = rest.chars().take_while(|&c| is_word(c) || c == ':').collect();
        let mut prefix = base.clone();
        prefix.extend(words.split("::").filter(|w| !w.is_empty()).map(str::to_owned));
        let group = rest[words.len()..]
            .strip_prefix('{')
            .map(|g| g.split('}').next().unwrap_or(""));
        match group {
            Some(group) => {
                for item in group.split(',') {
                    let mut path = prefix.clone();
                    path.extend(
                        item.trim()
                            .split("::")
                            .filter(|w| !w.is_empty() && w.chars().all(is_word))
                            .map(str::to_owned),
                    );
                    found.push(path);
                }
            }
            None => found.push(prefix),
        }
    }
    found
}

#[test]
fn no_two_files_of_a_module_import_each_other() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    source_files(&src, &mut files);
    let modules: Vec<(PathBuf, Vec<String>)> = files
        .iter()
        .filter_map(|file| Some((file.clone(), module_path(&src, file)?)))
        .collect();
    let known = |path: &[String]| modules.iter().any(|(_, m)| m.as_slice() == path);
    // Sibling edges: `a` and `b` share a parent, and something in `a`'s subtree names something
    // in `b`'s. A parent and its own children may use each other (they are one concept).
    let mut edges: Vec<(Vec<String>, Vec<String>, String)> = Vec::new();
    for (file, module) in &modules {
        let text = fs::read_to_string(file).expect("readable");
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for (number, line) in code_lines(code) {
            for path in named_paths(line, module) {
                let Some(target) = (1..=path.len()).rev().map(|n| &path[..n]).find(|p| known(p)) else {
                    continue;
                };
                let common = module.iter().zip(target).take_while(|(a, b)| a == b).count();
                if common < module.len() && common < target.len() {
                    let (from, to) = (module[..=common].to_vec(), target[..=common].to_vec());
                    edges.push((from, to, format!("{}:{number}", file.display())));
                }
            }
        }
    }
    let mut circles = Vec::new();
    for (from, to, at) in &edges {
        if from < to
            && let Some((_, _, back)) = edges.iter().find(|(f, t, _)| f == to && t == from)
        {
            circles.push(format!("{} <-> {} ({at}; {back})", from.join("::"), to.join("::")));
        }
    }
    circles.dedup();
    assert!(
        circles.is_empty(),
        "files of one module that import each other:\n{}",
        circles.join("\n")
    );
}

#[test]
fn the_circle_checker_resolves_paths() {
    let at: Vec<String> = ["grade", "diagnose", "decide"].map(str::to_owned).to_vec();
    assert_eq!(
        named_paths("use super::super::score::{judge, ImageResult};", &at),
        [
            ["grade", "score", "judge"].map(str::to_owned).to_vec(),
            ["grade", "score", "ImageResult"].map(str::to_owned).to_vec(),
        ]
    );
    assert_eq!(
        named_paths("let x = crate::compare::diff(a);", &at),
        [["compare", "diff"].map(str::to_owned).to_vec()]
    );
}
