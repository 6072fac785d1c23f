//! docs/cli.md, the command line's whole reference, generated from the parser itself (`sunshade man --markdown`), so
//! that it cannot drift from the flags; a test compares the file with what the parser gives.

use std::fmt::Write;

/// The Markdown reference of `cmd` and its subcommands: for each, what it does, its usage line, and every flag by
/// heading with its value, default and whole help.
pub fn markdown(cmd: &clap::Command) -> String {
    let mut out = String::new();
    out.push_str("# Command-line reference\n\n");
    out.push_str(
        "Generated from sunshade's parser by `sunshade man --markdown > docs/cli.md` (`make docs`); a test keeps it \
         current. Guides by task are in [the docs' index](README.md).\n\n",
    );
    let mut cmd = cmd.clone();
    cmd.build();
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set() && s.get_name() != "help") {
        command(&mut out, &cmd, sub);
    }
    out
}

fn command(out: &mut String, root: &clap::Command, cmd: &clap::Command) {
    let name = format!("{} {}", root.get_name(), cmd.get_name());
    let _ = writeln!(out, "## `{name}`\n");
    if let Some(about) = cmd.get_long_about().or(cmd.get_about()) {
        let _ = writeln!(out, "{about}\n");
    }
    let usage = cmd.clone().bin_name(&name).render_usage().to_string();
    let _ = writeln!(out, "```text\n{}\n```\n", usage.trim_start_matches("Usage: "));
    let mut headings: Vec<Option<&str>> = Vec::new();
    for arg in cmd.get_arguments() {
        if !headings.contains(&arg.get_help_heading()) {
            headings.push(arg.get_help_heading());
        }
    }
    for heading in headings {
        let args: Vec<&clap::Arg> = cmd
            .get_arguments()
            .filter(|a| a.get_help_heading() == heading && !a.is_hide_set() && a.get_id() != "help")
            .collect();
        if args.is_empty() {
            continue;
        }
        let _ = writeln!(out, "**{}**\n", heading.unwrap_or("Options"));
        for arg in args {
            let _ = writeln!(out, "- {}", describe(arg));
        }
        out.push('\n');
    }
}

/// `` `--flag <VALUE>` ``: its whole help, then its default.
fn describe(arg: &clap::Arg) -> String {
    let values: Vec<String> = arg.get_value_names().unwrap_or_default().iter().map(|v| format!("<{v}>")).collect();
    let takes_value = arg.get_num_args().is_some_and(|n| n.takes_values());
    let value = if takes_value && !values.is_empty() { format!(" {}", values.join(" ")) } else { String::new() };
    let flag = match (arg.get_short(), arg.get_long()) {
        (_, None) => format!("`<{}>`", arg.get_id().as_str().to_uppercase()),
        (Some(s), Some(l)) => format!("`-{s}`, `--{l}{value}`"),
        (None, Some(l)) => format!("`--{l}{value}`"),
    };
    let help = arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default();
    let help = help.split("\n\n").collect::<Vec<_>>().join(" ");
    let defaults: Vec<String> =
        arg.get_default_values().iter().map(|v| v.to_string_lossy().into_owned()).filter(|v| !v.is_empty()).collect();
    let default = if defaults.is_empty() || !takes_value {
        String::new()
    } else {
        format!(" (default: `{}`)", defaults.join(","))
    };
    format!("{flag}: {help}{default}")
}

#[cfg(test)]
mod tests {
    #[test]
    fn docs_cli_md_is_what_the_parser_says() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/cli.md");
        let written = std::fs::read_to_string(path).unwrap_or_default();
        let generated = super::markdown(&super::super::command());
        assert!(
            written == generated,
            "docs/cli.md is not what the parser says: regenerate it with `sunshade man --markdown > docs/cli.md` \
             (make docs)"
        );
    }
}
