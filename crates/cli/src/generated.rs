//! The references made from the library's definitions of a conversion's options
//! ([`specconv_conversion::definition`]) and the command line's arguments: the option tables of
//! docs/guide.md and README.md, every command's flags (docs/commands.md) and the keywords of
//! `convert` in the Python stub. `specconv-dev generate` writes them into their files and
//! `generate --check` (CI) fails when one is stale.

use clap::CommandFactory;
use specconv_conversion::{Key, Options, Takes, Value};

/// `convert`'s arguments, as the command line builds them.
fn convert() -> clap::Command {
    let mut cli = crate::command_line::Cli::command();
    cli.build();
    cli.find_subcommand("convert").expect("convert").clone()
}

/// Markdown table cell text.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

/// What an option is when not given: its default's text, else what unset means.
fn default_text(key: Key) -> String {
    let about = key.about();
    Options::default()
        .text(key)
        .or(about.unset.map(str::to_string))
        .unwrap_or_default()
}

/// A flag as the table shows it: `-d/--data-type half|float`, `--tile W H`, `--resize`.
fn spelt(key: Key, flag: &specconv_conversion::Flag) -> String {
    let names = match flag.short {
        Some(s) => format!("-{s}/--{}", flag.long),
        None => format!("--{}", flag.long),
    };
    match flag.takes {
        Takes::Value(name) => match key.about().choices {
            Some((choices, _)) => format!("{names} {}", choices.join("|")),
            None => format!("{names} {name}"),
        },
        Takes::Pair(a, b) => format!("{names} {a} {b}"),
        Takes::Sets(_) => names,
        Takes::MaybeBool => format!("{names}[=BOOL]"),
    }
}

/// The head of an option table.
const TABLE_HEAD: &str = "| option | default | meaning |\n|---|---|---|\n";

/// A row per option of the definitions (its flags together): (its long flags, the row).
fn option_rows() -> Vec<(Vec<String>, String)> {
    let mut rows = Vec::new();
    for key in Key::ALL {
        let about = key.about();
        if about.flags.is_empty() {
            continue;
        }
        let flags: Vec<String> = about
            .flags
            .iter()
            .map(|f| format!("`{}`", spelt(key, f)))
            .collect();
        // A flag's own help is a sentence of its own after the option's.
        let mut meaning = about.help.trim_end_matches('.').to_string();
        for flag in about.flags.iter().filter(|f| f.help.is_some()) {
            let help = flag.help.unwrap_or_default().trim_end_matches('.');
            meaning += &format!(". `--{}`: {help}", flag.long);
        }
        let row = format!(
            "| {} | {} | {} |\n",
            cell(&flags.join(", ")),
            cell(&default_text(key)),
            cell(&meaning)
        );
        rows.push((
            about.flags.iter().map(|f| f.long.to_string()).collect(),
            row,
        ));
    }
    rows
}

/// A row for an argument as clap defines it: `-j/--jobs N`, a switch bare, a positional by
/// its value names.
fn argument_row(arg: &clap::Arg) -> String {
    let values: Vec<String> = arg
        .get_value_names()
        .unwrap_or_default()
        .iter()
        .map(|v| v.to_string())
        .collect();
    let names = match (arg.get_short(), arg.get_long()) {
        (Some(s), Some(long)) => format!("-{s}/--{long}"),
        (None, Some(long)) => format!("--{long}"),
        (Some(s), None) => format!("-{s}"),
        (None, None) => values.join(" "),
    };
    let mut names = names;
    // A switch takes no value (clap still gives it a value name); a positional is its values.
    if arg.get_action().takes_values() && !arg.is_positional() {
        for value in &values {
            names += &format!(" {value}");
        }
    }
    if arg.is_positional() && arg.get_num_args().is_some_and(|n| n.max_values() > 1) {
        names += "…";
    }
    let default: Vec<String> = arg
        .get_default_values()
        .iter()
        .map(|v| v.to_string_lossy().into_owned())
        .collect();
    let help = arg
        .get_long_help()
        .or(arg.get_help())
        .map(|h| h.to_string())
        .unwrap_or_default();
    format!(
        "| `{}` | {} | {} |\n",
        cell(&names),
        cell(&default.join(" ")),
        cell(&help)
    )
}

/// The arguments a table shows: not `--help`/`--version`, not hidden ones.
fn shown(arg: &clap::Arg) -> bool {
    !arg.is_hide_set() && !matches!(arg.get_long(), Some("help" | "version"))
}

/// `convert`'s rows: one per option of the definitions, then one per argument of its own
/// (not its paths): (the row's long flags, the row).
fn convert_rows() -> Vec<(Vec<String>, String)> {
    let mut rows = option_rows();
    let options: Vec<String> = rows.iter().flat_map(|(longs, _)| longs.clone()).collect();
    for arg in convert().get_arguments() {
        match arg.get_long() {
            Some(long) if shown(arg) && !options.iter().any(|o| o == long) => {
                rows.push((vec![long.to_string()], argument_row(arg)));
            }
            _ => {}
        }
    }
    rows
}

/// The option table of docs/guide.md: every argument of `convert` but its paths, a row per
/// option (its flags together), then the command's own arguments.
pub fn guide_table() -> String {
    let mut out = TABLE_HEAD.to_string();
    for (_, row) in convert_rows() {
        out += &row;
    }
    out
}

/// The options README.md's table shows (the ones most used), by a long flag of each.
const README_OPTIONS: &[&str] = &[
    "ocio",
    "colorspace",
    "method",
    "model",
    "emissive",
    "data",
    "filter",
    "data-type",
    "tile",
    "threads",
    "force",
    "update",
    "json",
];

/// README.md's option table: the rows of the guide's table for `README_OPTIONS`.
pub fn readme_table() -> String {
    let mut out = TABLE_HEAD.to_string();
    for (longs, row) in convert_rows() {
        if longs.iter().any(|l| README_OPTIONS.contains(&l.as_str())) {
            out += &row;
        }
    }
    out
}

/// docs/commands.md: every command's flags as `--help` defines them, a section per command
/// (and per command of a command, as `farm submit`); `convert`'s options are the guide's.
pub fn commands_page() -> String {
    let mut top = crate::command_line::Cli::command().disable_help_subcommand(true);
    top.build();
    let mut out = String::from(
        "# Every command's flags\n\n<!-- Made by `cargo run -p specconv-dev -- generate` from the command \
         line's definitions: edit those, not this file. -->\n\nWhat `specconv COMMAND --help` \
         says, as tables. `convert` (the default command) takes the options of \
         [the guide's table](guide.md#options). Every command takes the global flags:\n\n",
    );
    out += TABLE_HEAD;
    for arg in top
        .get_arguments()
        .filter(|a| a.is_global_set() && shown(a))
    {
        out += &argument_row(arg);
    }
    for sub in top.get_subcommands().filter(|s| !s.is_hide_set()) {
        if sub.get_name() == "convert" {
            continue;
        }
        out += &command_section(sub, &format!("specconv {}", sub.get_name()), "##");
    }
    out
}

/// One command's section: its name, what it does, a table of its own arguments, then its
/// commands' sections one level down.
fn command_section(cmd: &clap::Command, name: &str, level: &str) -> String {
    let about = cmd.get_about().map(|a| a.to_string()).unwrap_or_default();
    let mut out = format!("\n{level} `{name}`\n\n{}\n", cell(&about));
    let args: Vec<&clap::Arg> = cmd
        .get_arguments()
        .filter(|a| shown(a) && !a.is_global_set())
        .collect();
    if !args.is_empty() {
        out += "\n";
        out += TABLE_HEAD;
        for arg in args {
            out += &argument_row(arg);
        }
    }
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        let inner = format!("{name} {}", sub.get_name());
        out += &command_section(sub, &inner, &format!("{level}#"));
    }
    out
}

/// An option's Python annotation: what `convert` takes for it.
fn annotation(key: Key) -> String {
    let about = key.about();
    let base = match about.value {
        Value::Text => "str".to_string(),
        Value::Path if key == Key::Model => "Union[_Path, Model]".to_string(),
        Value::Path => "_Path".to_string(),
        Value::Switch => "bool".to_string(),
        Value::Number => "float".to_string(),
        Value::Count => "int".to_string(),
        Value::Size => "Union[tuple[int, int], Literal[\"scanline\"]]".to_string(),
        Value::Choice => {
            let (names, aliases) = about.choices.clone().unwrap_or_default();
            let all: Vec<String> = names
                .iter()
                .chain(&aliases)
                .map(|n| format!("\"{n}\""))
                .collect();
            let literal = format!("Literal[{}]", all.join(", "));
            // A choice of two spelt true and false takes a bool too (mip=True).
            match aliases.contains(&"true") && aliases.contains(&"false") {
                true => format!("Union[{literal}, bool]"),
                false => literal,
            }
        }
    };
    match Options::default().text(key) {
        None => format!("Optional[{base}]"),
        Some(_) => base,
    }
}

/// An option's default as Python writes it.
fn python_default(key: Key) -> String {
    let Some(text) = Options::default().text(key) else {
        return "None".into();
    };
    match key.about().value {
        Value::Switch => {
            if text == "true" {
                "True".into()
            } else {
                "False".into()
            }
        }
        Value::Number | Value::Count => text,
        Value::Size => match text.split_once('x') {
            Some((w, h)) => format!("({w}, {h})"),
            None => format!("\"{text}\""),
        },
        _ => format!("\"{text}\""),
    }
}

/// `convert`'s definition in the stub (_specconv.pyi).
pub fn python_stub() -> String {
    let mut out = String::from(
        "def convert(\n    inputs: Union[_Path, Sequence[_Path]],\n    outputs: Union[None, _Path, Sequence[_Path]] = None,\n    *,\n    output_template: Optional[str] = None,\n    update: bool = False,\n    errors: Literal[\"raise\", \"record\"] = \"raise\",\n    progress: Optional[Callable[[int, Path, int, int], Any]] = None,\n",
    );
    for key in Key::ALL {
        let name = key.about().name;
        out += &format!(
            "    {name}: {} = {},\n",
            annotation(key),
            python_default(key)
        );
    }
    out + ") -> list[dict[str, Any]]: ...\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The guide as written, read back: every switch of `convert` (an argument that takes
    /// no value) is shown without a value name (the guide once showed `-u/--update UPDATE`
    /// and `--json JSON`), every argument that takes one with it.
    #[test]
    fn the_guide_shows_switches_without_values() {
        let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
        let guide = std::fs::read_to_string(root.join("docs/guide.md")).unwrap();
        let cells: Vec<String> = guide
            .lines()
            .filter(|l| l.starts_with("| `-"))
            .flat_map(|l| {
                let first = l
                    .split(" | ")
                    .next()
                    .unwrap_or_default()
                    .trim_start_matches("| ");
                first
                    .split(", ")
                    .map(|c| c.trim_matches('`').to_owned())
                    .collect::<Vec<_>>()
            })
            .collect();
        let mut checked = 0;
        for arg in convert().get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            if long == "help" || arg.is_hide_set() {
                continue;
            }
            let name = format!("--{long}");
            let Some(cell) = cells
                .iter()
                .find(|c| c.split([' ', '[']).next().unwrap().ends_with(&name))
            else {
                panic!("{name} is not in the guide's table");
            };
            let shows_value = cell.contains(' ') || cell.contains("[=");
            assert_eq!(
                shows_value,
                arg.get_action().takes_values(),
                "{cell}: {name} takes values: {}",
                arg.get_action().takes_values()
            );
            checked += 1;
        }
        assert!(checked > 40, "{checked} arguments checked");
    }

    /// Each option README.md names is a flag of `convert`, shown once in its table.
    #[test]
    fn the_readme_s_options_are_convert_s_flags() {
        let table = readme_table();
        for option in README_OPTIONS {
            let rows = table
                .lines()
                .filter(|l| {
                    let flags = l.split(" | ").next().unwrap_or_default();
                    flags.contains(&format!("--{option}`"))
                        || flags.contains(&format!("--{option} "))
                })
                .count();
            assert_eq!(rows, 1, "--{option} in the README's table:\n{table}");
        }
    }

    /// Every shown command and command of a command has its section in docs/commands.md.
    #[test]
    fn the_commands_page_has_every_command() {
        let page = commands_page();
        let mut cli = crate::command_line::Cli::command();
        cli.build();
        let mut n = 0;
        for sub in cli.get_subcommands().filter(|s| !s.is_hide_set()) {
            if sub.get_name() == "convert" || sub.get_name() == "help" {
                continue;
            }
            assert!(page.contains(&format!("## `specconv {}`", sub.get_name())));
            for inner in sub.get_subcommands().filter(|s| !s.is_hide_set()) {
                let name = format!("### `specconv {} {}`", sub.get_name(), inner.get_name());
                assert!(page.contains(&name), "{name}");
            }
            n += 1;
        }
        assert!(n >= 12, "{n} commands");
    }

    /// The defaults that depend on another option say so (the guide once said `nearest`).
    #[test]
    fn the_table_says_what_an_unset_option_means() {
        let table = guide_table();
        let row = table
            .lines()
            .find(|l| l.contains("--half-rounding"))
            .unwrap();
        assert!(
            row.contains("nearest for reflectance, colour for emission"),
            "{row}"
        );
        assert!(python_stub().contains(
            "    rounding: Optional[Literal[\"nearest\", \"colour\", \"color\"]] = None,\n"
        ));
        assert!(python_stub()
            .contains("    tile: Union[tuple[int, int], Literal[\"scanline\"]] = (64, 64),\n"));
    }
}
