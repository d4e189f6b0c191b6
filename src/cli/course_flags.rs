//! The course binary's spelling of flags: one dash before a long name (`-input`, `-size 800 800`).
//! A TA pastes a grading command, so `mit6837` and `import` accept it as written.

use std::ffi::OsString;

/// The commands that take the course's flags.
const COURSE_COMMANDS: [&str; 2] = ["mit6837", "import"];

/// Rewrites `-name` to clap's `--name` after a course command, leaving one-letter flags (`-o`),
/// `--name` and negative numbers (`-depth -1 5 d.png`) alone.
pub fn rewrite(args: impl Iterator<Item = OsString>) -> Vec<OsString> {
    let args: Vec<OsString> = args.collect();
    if args.get(1).is_none_or(|a| !COURSE_COMMANDS.iter().any(|c| a == c)) {
        return args;
    }
    args.into_iter()
        .enumerate()
        .map(|(index, arg)| match arg.to_str() {
            Some(flag)
                if index > 1
                    && flag.len() > 2
                    && flag.starts_with('-')
                    && !flag.starts_with("--")
                    && flag.parse::<f64>().is_err() =>
            {
                OsString::from(format!("-{flag}"))
            }
            _ => arg,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rewritten(args: &[&str]) -> Vec<String> {
        rewrite(args.iter().map(OsString::from))
            .into_iter()
            .map(|a| a.into_string().expect("utf-8"))
            .collect()
    }

    #[test]
    fn single_dash_long_flags_become_double_dash_after_course_commands_only() {
        assert_eq!(
            rewritten(&[
                "goldray", "mit6837", "-input", "s.txt", "-depth", "-1", "5", "d.png", "--quiet"
            ]),
            [
                "goldray", "mit6837", "--input", "s.txt", "--depth", "-1", "5", "d.png", "--quiet"
            ]
        );
        assert_eq!(
            rewritten(&["goldray", "import", "s.txt", "-size", "800", "800", "-o", "c.toml"]),
            ["goldray", "import", "s.txt", "--size", "800", "800", "-o", "c.toml"]
        );
        assert_eq!(
            rewritten(&["goldray", "render", "-input"]),
            ["goldray", "render", "-input"]
        );
    }
}
