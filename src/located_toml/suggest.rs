//! "Did you mean …?": the nearest valid name to a misspelt one.

/// The candidate closest to `word`, if close enough that suggesting it is more help than noise.
/// Case is ignored because `Radius` for `radius` is the same slip as a transposition.
pub(crate) fn nearest<'c>(word: &str, candidates: &[&'c str]) -> Option<&'c str> {
    let word = word.to_lowercase();
    let budget = (word.chars().count() / 3).max(1);
    candidates
        .iter()
        .map(|c| (strsim::damerau_levenshtein(&word, &c.to_lowercase()), *c))
        .filter(|&(distance, _)| distance <= budget)
        .min_by_key(|&(distance, _)| distance)
        .map(|(_, c)| c)
}

/// The tail of an "unknown name" message: the nearest candidate if one is close, then all of them,
/// e.g. "; did you mean `radius`? valid keys: center, radius".
pub(crate) fn suggest(word: &str, candidates: &[&str], noun: &str) -> String {
    let all = if candidates.is_empty() {
        "(none)".to_owned()
    } else {
        candidates.join(", ")
    };
    match nearest(word, candidates) {
        Some(c) => format!("; did you mean `{c}`? valid {noun}: {all}"),
        None => format!("; valid {noun}: {all}"),
    }
}
