//! Saying how two files were made differently, in the words `goldray diff` and the golden suite
//! print before their verdict: "expected: seed 7, 16 spp; actual: seed 8, 16 spp".

use super::{Provenance, RUN_PREFIX, keys};

/// A stable entry: its name, how its value reads, and what a missing one is called.
type Field = (&'static str, fn(&str) -> String, &'static str);

/// The stable entries in the order they are named.
const FIELDS: [Field; 13] = [
    (keys::VERSION, |v| format!("goldray {v}"), "version"),
    (keys::COMMIT, |v| format!("commit {}", short_commit(v)), "commit"),
    (keys::CASE, |v| format!("case {v}"), "case name"),
    (keys::CASE_HASH, |v| format!("case hash {}", first_12(v)), "case hash"),
    (keys::SIZE, |v| v.to_owned(), "size"),
    (keys::SEED, |v| format!("seed {v}"), "seed"),
    (keys::SAMPLES, |v| format!("{v} spp"), "sample count"),
    (keys::FILTER, |v| format!("filter {v}"), "filter"),
    (keys::BOUNCES, |v| format!("{v} bounces"), "bounce count"),
    (keys::SHADOWS, |v| format!("shadows {}", on_off(v)), "shadows setting"),
    (keys::PRECISION, |v| format!("precision {v}"), "precision"),
    (keys::PROFILE, |v| format!("profile {v}"), "profile"),
    (keys::TONEMAP, |v| format!("tonemap {v}"), "tone map"),
];

/// What a file without provenance is said to be.
const NONE: &str = "no provenance";

/// The line that says how two files were made differently, each side under its label, naming
/// every stable entry that differs (a run's time and thread count never do: they do not change
/// the pixels); `None` when both were made the same way or neither says how.
///
/// A differing seed is shown with the sample count, which gives it its meaning, and a file
/// without provenance is "no provenance" beside a summary of the other.
pub fn made_differently(
    (expected_label, expected): (&str, Option<&Provenance>),
    (actual_label, actual): (&str, Option<&Provenance>),
) -> Option<String> {
    let (expected_side, actual_side) = match (expected, actual) {
        (None, None) => return None,
        (Some(one), None) => (summary(one), NONE.to_owned()),
        (None, Some(other)) => (NONE.to_owned(), summary(other)),
        (Some(a), Some(b)) => {
            let differing = differing_keys(a, b);
            if differing.is_empty() {
                return None;
            }
            (describe(a, &differing), describe(b, &differing))
        }
    };
    Some(format!(
        "{expected_label}: {expected_side}; {actual_label}: {actual_side}"
    ))
}

/// The stable keys whose values differ, in [`FIELDS`] order, then any other `goldray.*` name
/// (from a newer goldray) in name order.
fn differing_keys<'a>(a: &'a Provenance, b: &'a Provenance) -> Vec<&'a str> {
    let differs = |key: &str| a.get(key) != b.get(key);
    let mut keys: Vec<&str> = FIELDS.iter().map(|(key, ..)| *key).filter(|key| differs(key)).collect();
    if keys.contains(&keys::SEED) && !keys.contains(&keys::SAMPLES) && a.get(keys::SAMPLES).is_some() {
        let at = keys.iter().position(|&k| k == keys::SEED).expect("present") + 1;
        keys.insert(at, keys::SAMPLES);
    }
    let known = |key: &str| FIELDS.iter().any(|(k, ..)| *k == key);
    let mut others: Vec<&str> = a
        .entries()
        .chain(b.entries())
        .map(|(key, _)| key)
        .filter(|key| !known(key) && !key.starts_with(RUN_PREFIX) && differs(key))
        .collect();
    others.sort_unstable();
    others.dedup();
    keys.extend(others);
    keys
}

fn describe(provenance: &Provenance, keys: &[&str]) -> String {
    keys.iter()
        .map(|&key| phrase(key, provenance.get(key)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What a file that says how it was made is, beside one that does not: its case and the
/// settings that most often explain a difference.
fn summary(provenance: &Provenance) -> String {
    let mut parts: Vec<String> = provenance.get(keys::CASE).map(str::to_owned).into_iter().collect();
    for key in [keys::SIZE, keys::SEED, keys::SAMPLES] {
        if let Some(value) = provenance.get(key) {
            parts.push(phrase(key, Some(value)));
        }
    }
    if parts.is_empty() {
        parts.push(phrase(keys::VERSION, provenance.get(keys::VERSION)));
    }
    parts.join(", ")
}

fn phrase(key: &str, value: Option<&str>) -> String {
    let field = FIELDS.iter().find(|(k, ..)| *k == key);
    match (field, value) {
        (Some((_, read, _)), Some(value)) => read(value),
        (Some((_, _, missing)), None) => format!("no {missing}"),
        (None, Some(value)) => format!("{} {value}", key.trim_start_matches(super::PREFIX)),
        (None, None) => format!("no {}", key.trim_start_matches(super::PREFIX)),
    }
}

/// A commit as people quote it: twelve hex digits, and whether the sources were modified.
fn short_commit(commit: &str) -> String {
    let (hash, modified) = match commit.split_once('+') {
        Some((hash, rest)) => (hash, format!("+{rest}")),
        None => (commit, String::new()),
    };
    format!("{}{modified}", first_12(hash))
}

/// Hashes are quoted by their first twelve characters, as git does.
fn first_12(text: &str) -> String {
    text.chars().take(12).collect()
}

fn on_off(value: &str) -> &str {
    match value {
        "true" => "on",
        "false" => "off",
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn made(seed: u64, samples: u32) -> Provenance {
        Provenance::default()
            .with(keys::VERSION, "0.1.0")
            .with(keys::CASE, "jitter.toml")
            .with(keys::SIZE, "200x200")
            .with(keys::SEED, seed)
            .with(keys::SAMPLES, samples)
            .with(keys::SHADOWS, true)
    }

    fn line(a: Option<&Provenance>, b: Option<&Provenance>) -> Option<String> {
        made_differently(("golden", a), ("candidate", b))
    }

    #[test]
    fn a_changed_seed_is_named_with_its_sample_count() {
        assert_eq!(
            line(Some(&made(7, 16)), Some(&made(8, 16))).as_deref(),
            Some("golden: seed 7, 16 spp; candidate: seed 8, 16 spp")
        );
    }

    #[test]
    fn every_differing_setting_is_named_and_nothing_else() {
        let b = made(7, 4)
            .with(keys::SHADOWS, false)
            .with(keys::COMMIT, "0123456789abcdef0123+modified");
        assert_eq!(
            line(Some(&made(7, 16)), Some(&b)).as_deref(),
            Some("golden: no commit, 16 spp, shadows on; candidate: commit 0123456789ab+modified, 4 spp, shadows off")
        );
    }

    #[test]
    fn the_same_making_or_only_a_different_run_says_nothing() {
        let a = made(7, 16).with_run(0.5, 1, Some("a"));
        let b = made(7, 16).with_run(2.25, 2, Some("b"));
        assert_eq!(line(Some(&a), Some(&b)), None);
        assert_eq!(line(None, None), None);
    }

    #[test]
    fn a_file_without_provenance_is_said_to_have_none() {
        assert_eq!(
            line(Some(&made(7, 16)), None).as_deref(),
            Some("golden: jitter.toml, 200x200, seed 7, 16 spp; candidate: no provenance")
        );
        assert_eq!(
            line(None, Some(&Provenance::default().with(keys::VERSION, "9.0"))).as_deref(),
            Some("golden: no provenance; candidate: goldray 9.0")
        );
    }

    #[test]
    fn names_from_a_newer_goldray_are_compared_too() {
        let b = made(7, 16).with("goldray.sampler", "sobol");
        assert_eq!(
            line(Some(&made(7, 16)), Some(&b)).as_deref(),
            Some("golden: no sampler; candidate: sampler sobol")
        );
    }
}
