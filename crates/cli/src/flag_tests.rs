//! The command line against the definitions: every flag spelt as an option of the library is
//! that option, a long name several commands declare is listed with why, and `convert` takes
//! exactly the library's options and defaults.

use clap::{CommandFactory, Parser};
use specconv_conversion::{Key, Named, Options};
use std::collections::{BTreeMap, BTreeSet};

/// Flags of other commands spelt as an option of the definitions but declared by hand:
/// (command, flag, why it is not the option). A new one fails the test below, and so
/// does an entry that is the definitions' now, so that the list only shrinks.
const DECLARED_BY_HAND: &[(&str, &str, &str)] = &[
    (
        "train",
        "bands",
        "the grid a model is trained on, not an output's",
    ),
    (
        "eval",
        "bands",
        "the grid measured on: by default the model's",
    ),
    (
        "eval",
        "bounded",
        "off by default: the method as named is measured",
    ),
    ("eval", "method", "a method measured, not written"),
    ("eval", "model", "conflicts with --train"),
    ("report", "bands", "the grid measured on"),
    ("report", "threads", "the threads of one cost measurement"),
    (
        "info",
        "colorspace",
        "only shown, not read as: no rule is reported",
    ),
    (
        "to-rgb",
        "colorspace",
        "the output's colour space, not the input's",
    ),
    ("simulate", "method", "repeated: several methods compared"),
    ("simulate", "force", "replaces the --image picture only"),
    (
        "expand",
        "fixnan",
        "its default is the rule the compact file recorded",
    ),
];

/// Every flag with a long name of every command and command of a command, as the command
/// line builds them: (the command's path, `train` or `farm submit`; the long name; its
/// help; whether it is global).
fn long_flags() -> Vec<(String, String, String, bool)> {
    fn walk(cmd: &clap::Command, name: &str, out: &mut Vec<(String, String, String, bool)>) {
        for arg in cmd.get_arguments() {
            if let (Some(long), Some(help)) = (arg.get_long(), arg.get_help()) {
                let global = arg.is_global_set();
                out.push((name.into(), long.into(), help.to_string(), global));
            }
        }
        for sub in cmd.get_subcommands() {
            let inner = match name {
                "" => sub.get_name().to_string(),
                _ => format!("{name} {}", sub.get_name()),
            };
            walk(sub, &inner, out);
        }
    }
    let mut cli = crate::command_line::Cli::command();
    cli.build();
    let mut out = Vec::new();
    walk(&cli, "", &mut out);
    out
}

/// Long names that several commands declare by hand, each with a help of its own: (flag,
/// why the commands' flags are not one). A new one fails the test below, and so does an
/// entry whose commands now share one definition, so that the list only shrinks.
const ONE_NAME_SEVERAL_FLAGS: &[(&str, &str)] = &[
        ("bands", "the grid trained on (train, report) or measured on (eval), not an output's"),
        ("by-set", "eval scores one method held out by set; report scores every row"),
        ("clusters", "a model's clusters (train), the one trained in place (eval), a row per count (report)"),
        ("colorspace", "the input's (info) or the output's (to-rgb) colour space, not a conversion's"),
        ("dry-run", "asset prints decisions; farm submit prints the plan and the script"),
        ("illuminant", "training's light (train, report), the baselines' (eval), the one looked under (to-rgb, preview)"),
        ("json", "each command prints its own record"),
        ("method", "the method measured (eval) or the methods compared, repeated (simulate)"),
        ("min-cluster-size", "a model's (train), the one trained in place (eval), every row's (report)"),
        ("observer", "training's (train, report) or the baselines' (eval, by default the model's)"),
        ("output", "a model file, a picture, a folder: what each command writes"),
        ("output-template", "expand names expanded files, convert and farm submit converted ones"),
        ("spectra", "spectra trained on (train) or measured (eval, report)"),
        ("tasks", "farm submit's count; retry's, by default the last submission's"),
        ("train", "eval trains one model in place, report every row's"),
        ("verbose", "asset says each decision; convert and farm submit the colour space chosen"),
    ];

/// Every long name that several commands declare by hand with helps of their own is listed
/// in [`ONE_NAME_SEVERAL_FLAGS`] with why (the definitions' options are the other test's).
#[test]
fn a_name_several_commands_declare_is_listed() {
    let mut helps: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (_, long, help, global) in long_flags() {
        if !global {
            helps.entry(long).or_default().insert(help);
        }
    }
    let definitions: BTreeSet<String> = Key::ALL
        .iter()
        .flat_map(|k| {
            let about = k.about();
            about
                .flags
                .iter()
                .map(move |f| f.help.unwrap_or(about.help).to_string())
        })
        .collect();
    let mut several: Vec<&str> = helps
        .iter()
        .filter(|(long, _)| !matches!(long.as_str(), "help" | "version"))
        .filter(|(_, h)| h.iter().filter(|h| !definitions.contains(*h)).count() > 1)
        .map(|(long, _)| long.as_str())
        .collect();
    several.sort();
    let listed: Vec<&str> = ONE_NAME_SEVERAL_FLAGS.iter().map(|(f, _)| *f).collect();
    assert_eq!(
        several, listed,
        "long names several commands declare by hand"
    );
}

/// Every command's flag that is spelt as an option of the definitions is that option
/// (its help is the definitions'), or listed in [`DECLARED_BY_HAND`] with why not.
#[test]
fn a_flag_spelt_as_an_option_is_the_option() {
    let args = long_flags();
    let mut by_hand = Vec::new();
    for (command, long, help, _) in &args {
        for key in Key::ALL {
            let about = key.about();
            let Some(flag) = about.flags.iter().find(|f| f.long == long) else {
                continue;
            };
            if *help != flag.help.unwrap_or(about.help) {
                by_hand.push((command.as_str(), long.as_str()));
            }
        }
    }
    by_hand.sort();
    by_hand.dedup();
    let mut listed: Vec<(&str, &str)> = DECLARED_BY_HAND.iter().map(|(c, f, _)| (*c, *f)).collect();
    listed.sort();
    assert_eq!(by_hand, listed, "flags declared by hand (command, flag)");
}

/// `convert`'s arguments that are not options of a conversion: what to convert, where to,
/// and how the command reports.
const FRONT_END: &[&str] = &[
    "paths",
    "output",
    "output-template",
    "update",
    "json",
    "progress",
    "quiet",
    "shard",
    "verbose",
    "help",
];

fn convert() -> clap::Command {
    let mut cli = crate::command_line::Cli::command();
    cli.build();
    cli.find_subcommand("convert").expect("convert").clone()
}

/// Every option of the library has its flags, and every flag of `convert` is an option's
/// or the front-end's own: an option cannot be added to the command line alone.
#[test]
fn convert_has_exactly_the_librarys_options() {
    let cmd = convert();
    let mut longs: BTreeSet<String> = cmd
        .get_arguments()
        .filter_map(|a| {
            a.get_long()
                .map(str::to_string)
                .or(Some(a.get_id().to_string()))
        })
        .collect();
    // The global --ocio is parsed before the subcommand.
    longs.insert("ocio".into());
    for key in Key::ALL {
        for flag in key.about().flags.iter().map(|f| f.long) {
            assert!(
                longs.remove(flag),
                "--{flag} ({key:?}) is missing from convert"
            );
        }
    }
    for f in FRONT_END {
        longs.remove(*f);
    }
    assert!(
        longs.is_empty(),
        "flags the library does not define: {longs:?}"
    );
}

/// A choice accepts the library's names and spellings and no other; a default is the
/// library's.
#[test]
fn convert_accepts_the_librarys_names_and_defaults() {
    let cmd = convert();
    for key in Key::ALL {
        let about = key.about();
        let [flag, ..] = about.flags else { continue };
        let flag = flag.long;
        let arg = cmd
            .get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .unwrap_or_else(|| panic!("--{flag}"));
        // --emissive is a switch; its units are the choice.
        let arg = match key {
            Key::Emission => cmd
                .get_arguments()
                .find(|a| a.get_long() == Some("emission-units"))
                .expect("--emission-units"),
            _ => arg,
        };
        let values = arg.get_possible_values();
        let listed: Vec<&str> = values.iter().map(|v| v.get_name()).collect();
        if let Some((names, aliases)) = &about.choices {
            let accepted: BTreeSet<&str> = values
                .iter()
                .flat_map(|v| v.get_name_and_aliases())
                .collect();
            assert_eq!(&listed, names, "--{flag}'s names");
            let want: BTreeSet<&str> = names.iter().chain(aliases).copied().collect();
            assert_eq!(accepted, want, "--{flag}'s spellings");
        } else {
            // A switch's `=true|false` is clap's own.
            assert!(
                listed.is_empty() || listed == ["true", "false"],
                "--{flag} lists {listed:?}, which the library does not name"
            );
        }
        // Reflectance by default; asked for, emission's units default to the library's.
        let default = match key {
            Key::Emission => Some(specconv_colour::EmissionUnits::default().name().into()),
            _ => Options::default().text(key),
        };
        let shown: Vec<String> = arg
            .get_default_values()
            .iter()
            .map(|v| v.to_string_lossy().into_owned())
            .collect();
        if !shown.is_empty() && arg.get_num_args().is_none_or(|n| n.max_values() == 1) {
            assert_eq!(Some(shown.join("")), default, "--{flag}'s default");
        }
    }
}

/// The command line with no option set gives the library's defaults, every one.
#[test]
fn no_flag_is_the_librarys_default() {
    let m = crate::command_line::Cli::try_parse_from(["specconv", "convert", "a.png", "b.exr"])
        .unwrap();
    let crate::command_line::Command::Convert(args) = m.command.expect("a command") else {
        panic!("convert")
    };
    let (got, want) = (args.options(), Options::default());
    for key in Key::ALL {
        assert_eq!(got.text(key), want.text(key), "{key:?}");
    }
}

/// Flags that set an option together: `--emissive` gives the library's default units,
/// `--emission-units` others; `--scanline`, `--checknan` and `--unbounded` their words.
#[test]
fn flags_set_what_the_definitions_say() {
    let options = |extra: &[&str]| {
        let words = ["specconv", "convert", "a.png", "b.exr"]
            .iter()
            .chain(extra);
        let m = crate::command_line::Cli::try_parse_from(words).unwrap();
        let Some(crate::command_line::Command::Convert(args)) = m.command else {
            panic!("convert")
        };
        args.options()
    };
    let units = specconv_colour::EmissionUnits::default();
    assert_eq!(options(&["--emissive"]).emission, Some(units));
    let photometric = options(&["--emissive", "--emission-units", "photometric"]);
    assert_eq!(photometric.emission.map(Named::name), Some("photometric"));
    assert!(crate::command_line::Cli::try_parse_from([
        "specconv",
        "convert",
        "a",
        "b",
        "--emission-units",
        "photometric"
    ])
    .is_err());
    let o = options(&[
        "--checknan",
        "--unbounded",
        "-d",
        "float",
        "--tile",
        "32",
        "16",
    ]);
    assert_eq!(o.text(Key::Tile).as_deref(), Some("32x16"));
    assert!(!o.bounded);
    assert_eq!(o.text(Key::Sample).as_deref(), Some("float"));
    assert_eq!(
        options(&["--scanline"]).text(Key::Tile).as_deref(),
        Some("scanline")
    );
    assert_eq!(
        options(&["--fixnan", "box3"])
            .text(Key::NonFinite)
            .as_deref(),
        Some("box3")
    );
    assert!(!options(&["--constant-color-detect=false"]).constant_detect);
    assert!(crate::command_line::Cli::try_parse_from([
        "specconv",
        "convert",
        "a",
        "b",
        "--tile",
        "8",
        "8",
        "--scanline"
    ])
    .is_err());
    assert!(crate::command_line::Cli::try_parse_from([
        "specconv",
        "convert",
        "a",
        "b",
        "--fixnan",
        "box3",
        "--checknan"
    ])
    .is_err());
}
