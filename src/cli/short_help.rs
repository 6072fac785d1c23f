//! `render -h` and `reference -h` fit a screen: the common flags with the first sentence of their help; `--help`
//! keeps every flag and its whole help (as does docs/cli.md).

/// The flags `-h` shows for `render` and `reference` (their ids); every other flag waits for `--help`.
const COMMON: [&str; 22] = [
    "scene",
    "output",
    "width",
    "height",
    "eye",
    "target",
    "sun_dir",
    "sun_elevation",
    "sun_azimuth",
    "sun_irradiance",
    "disk_lights",
    "sky_radiance",
    "brdf",
    "shadows",
    "tolerance",
    "quantity",
    "time",
    "location",
    "exposure",
    "verbose",
    "quiet",
    "check",
];

/// `cmd` (render or reference) with its rare flags hidden from `-h` and the common ones' short help their first
/// sentence.
pub fn common_flags_first(cmd: clap::Command) -> clap::Command {
    let ids: Vec<String> = cmd.get_arguments().map(|a| a.get_id().to_string()).collect();
    let mut cmd = cmd;
    for id in ids {
        let common = COMMON.contains(&id.as_str());
        cmd = cmd.mut_arg(id, |a| {
            if !common {
                return a.hide_short_help(true);
            }
            let full = a.get_long_help().or(a.get_help()).map(|h| h.to_string()).unwrap_or_default();
            let short = summary(&full).to_string();
            a.help(short).long_help(full)
        });
    }
    cmd.after_help("Common flags only: --help shows every flag and its whole help (also docs/cli.md).")
}

/// A help's first paragraph's first sentence, and of a long one (over 120 characters) its first clause (to "; ").
fn summary(text: &str) -> &str {
    let paragraph = text.split("\n\n").next().unwrap_or(text).trim();
    let sentence = first_sentence(paragraph);
    match sentence.find("; ") {
        Some(i) if sentence.chars().count() > 120 => &sentence[..i],
        _ => sentence,
    }
}

/// The text up to its first sentence's full stop (one followed by a space, not of "e.g.", "i.e.", "vs." or
/// "Rec. 709"), or all of it.
fn first_sentence(text: &str) -> &str {
    let mut from = 0;
    while let Some(i) = text[from..].find(". ") {
        let end = from + i;
        let before = &text[..end];
        if !(before.ends_with("e.g") || before.ends_with("i.e") || before.ends_with("vs") || before.ends_with("Rec")) {
            return before;
        }
        from = end + 2;
    }
    text.trim_end_matches('.')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_sentence_skips_abbreviations() {
        assert_eq!(first_sentence("One, e.g. this. Two."), "One, e.g. this");
        assert_eq!(first_sentence("Only one."), "Only one");
        assert_eq!(first_sentence("No stop"), "No stop");
        assert_eq!(summary("First. Second.\n\nMore."), "First");
        let long = format!("{}; then more", "a".repeat(130));
        assert_eq!(summary(&long), "a".repeat(130));
    }

    #[test]
    fn render_h_fits_a_screen_and_help_keeps_every_flag() {
        let mut cmd = super::super::command();
        let render = cmd.find_subcommand_mut("render").expect("render");
        let short = render.render_help().to_string();
        let long = render.render_long_help().to_string();
        assert!(short.lines().count() <= 60, "render -h has {} lines:\n{short}", short.lines().count());
        for id in COMMON {
            assert!(render.get_arguments().any(|a| a.get_id() == id), "no flag {id}");
        }
        for flag in ["--fail-rel", "--sun-diameter", "--visibility", "--tolerance-outside-penumbrae"] {
            assert!(!short.contains(flag) && long.contains(flag), "{flag}");
        }
    }
}
