//! The command line against the definitions (crates/flags): every argument of every command
//! is an option of the library or an entry of the commands' table, and nothing else makes
//! one; every entry is taken; an entry spelt as an option, or a long name several entries
//! share, is listed with why; `convert` takes exactly the library's options and defaults.

use clap::{CommandFactory, Parser};
use specconv_conversion::{Key, Named, Options};
use specconv_flags::defs;
use std::collections::{BTreeMap, BTreeSet};

/// Entries of the commands' table spelt as an option of the definitions: (command, flag, why
/// it is not the option). A new one fails the test below, and so does an entry that is the
/// option now, so that the list only shrinks.
const SPELT_AS_AN_OPTION: &[(&str, &str, &str)] = &[
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
    arguments()
        .into_iter()
        .filter_map(|(command, arg)| {
            let (long, help) = (arg.get_long()?, arg.get_help()?);
            Some((command, long.into(), help.to_string(), arg.is_global_set()))
        })
        .collect()
}

/// Long names that several entries of the commands' table share, each with a help of its own:
/// (flag, why the commands' flags are not one). A new one fails the test below, and so does an
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

/// Every long name that several commands take from different entries, with helps of their
/// own, is listed in [`ONE_NAME_SEVERAL_FLAGS`] with why (the definitions' options are the
/// other test's).
#[test]
fn a_name_several_entries_share_is_listed() {
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
        "long names several entries of the table share"
    );
}

/// Every command's flag that is spelt as an option of the definitions is that option
/// (its help is the definitions'), or listed in [`SPELT_AS_AN_OPTION`] with why not.
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
    let mut listed: Vec<(&str, &str)> = SPELT_AS_AN_OPTION
        .iter()
        .map(|(c, f, _)| (*c, *f))
        .collect();
    listed.sort();
    assert_eq!(
        by_hand, listed,
        "entries of the table spelt as an option (command, flag)"
    );
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

/// Every argument of every command and command of a command, as the command line builds them:
/// (the command's path, `train` or `farm submit`; the argument).
fn arguments() -> Vec<(String, clap::Arg)> {
    fn walk(cmd: &clap::Command, name: &str, out: &mut Vec<(String, clap::Arg)>) {
        out.extend(cmd.get_arguments().map(|a| (name.to_string(), a.clone())));
        for sub in cmd.get_subcommands() {
            walk(sub, format!("{name} {}", sub.get_name()).trim(), out);
        }
    }
    let mut cli = crate::command_line::Cli::command();
    cli.build();
    let mut out = Vec::new();
    walk(&cli, "", &mut out);
    out
}

/// Whether `arg` is `flag`, an entry of the commands' table: its id, long name and help.
fn is_entry(arg: &clap::Arg, flag: &specconv_flags::Flag) -> bool {
    arg.get_id() == flag.id
        && arg.get_long() == flag.long
        && arg.get_help().map(ToString::to_string) == Some(flag.help())
}

/// Whether `arg` is a flag of an option of the library's definitions (`OptionArgs` names each
/// by its long name).
fn is_option(arg: &clap::Arg) -> bool {
    Key::ALL.iter().any(|k| {
        k.about()
            .flags
            .iter()
            .any(|f| arg.get_id() == f.long && arg.get_long() == Some(f.long))
    })
}

/// Every argument of every command is an option's flag or an entry of the commands' table.
#[test]
fn every_argument_is_an_option_or_an_entry_of_the_table() {
    let mut checked = 0;
    for (command, arg) in arguments() {
        if matches!(arg.get_id().as_str(), "help" | "version") {
            continue;
        }
        assert!(
            is_option(&arg) || defs::ALL.iter().any(|f| is_entry(&arg, f)),
            "`{command}` takes {}, which is neither an option of the definitions nor an entry \
             of crates/flags/src/defs.rs",
            arg.get_id()
        );
        checked += 1;
    }
    // 14 commands, 5 farm commands, convert's options at the top, in convert, asset and submit.
    assert!(checked > 200, "{checked} arguments");
}

/// Every entry of the commands' table is taken by a command, and is defined once.
#[test]
fn every_entry_of_the_table_is_taken_and_defined_once() {
    let args = arguments();
    for (i, flag) in defs::ALL.iter().enumerate() {
        assert!(
            args.iter().any(|(_, a)| is_entry(a, flag)),
            "no command takes the entry {} ({})",
            flag.id,
            flag.long.map_or("by place".into(), |l| format!("--{l}"))
        );
        let twin = defs::ALL[..i]
            .iter()
            .find(|g| g.id == flag.id && g.long == flag.long && g.help() == flag.help());
        assert!(twin.is_none(), "{} is defined twice", flag.id);
    }
}

/// The lines of `text`'s production code that make a clap argument by hand.
fn hand_made(file: &str, text: &str) -> Vec<String> {
    specconv_testkit::sources::production(text)
        .into_iter()
        .filter(|l| {
            let code = l.trim_start();
            !code.starts_with("//")
                && (code.starts_with("#[arg")
                    || code.starts_with("#[clap(")
                    || code.contains("Arg::new("))
        })
        .map(|l| format!("{file}: {}", l.trim()))
        .collect()
}

/// Programs of the workspace that are not this command line, with flags of their own.
const OTHER_PROGRAMS: [(&str, &str); 1] = [(
    "crates/dev/",
    "the developers' own tool (`generate --check --root`), never shipped",
)];

/// No production code outside crates/flags makes a clap argument (`#[arg]`, `Arg::new`): every
/// flag is defined there once.
#[test]
fn no_argument_is_made_outside_the_flags_crate() {
    let planted = "    /// Help.\n    #[arg(long)]\n    x: bool,\n    // Arg::new(\"y\")\n";
    assert_eq!(hand_made("a.rs", planted), ["a.rs: #[arg(long)]"]);
    assert_eq!(
        hand_made("b.rs", "let a = clap::Arg::new(\"z\");\n").len(),
        1
    );
    let root = specconv_testkit::sources::root();
    let files = specconv_testkit::sources::sources();
    // The command line's three crates are among the files read.
    for dir in [
        "crates/cli/src/cmd/",
        "crates/convert-cmd/src/",
        "crates/farm-cmd/src/",
    ] {
        assert!(files.iter().any(|f| f.starts_with(dir)), "{dir}");
    }
    let found: Vec<String> = files
        .iter()
        .filter(|f| !f.starts_with("crates/flags/"))
        .filter(|f| !OTHER_PROGRAMS.iter().any(|(dir, _)| f.starts_with(dir)))
        .flat_map(|f| hand_made(f, &std::fs::read_to_string(root.join(f)).unwrap()))
        .collect();
    assert!(
        found.is_empty(),
        "flags made outside crates/flags; define them in crates/flags/src/defs.rs and name them \
         in the command's args! struct:\n{}",
        found.join("\n")
    );
}
