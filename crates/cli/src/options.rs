//! The conversion's options as clap arguments, made from the library's one definition of each
//! ([`specconv_conversion::definition`]): flags, value names, help, defaults and conflicts come
//! from there, a value is read by the library, and the tests below fail when `convert` accepts
//! a flag, a name or a default the library does not define.

use clap::builder::{PossibleValue, TypedValueParser};
use specconv_conversion::{Flag, Key, Options, Takes, Value};

/// Options of the library's definitions as a command's arguments
/// ([`specconv_conversion::definition`]): each flag, its value names, help and conflicts come
/// from there; a value is read by the library ([`Options::set_os`]), so a flag accepts exactly
/// what the library does. Which options a command takes is its [`Taken`].
#[derive(Debug, Clone)]
pub(crate) struct OptionArgs<T: Taken> {
    /// The options given (the global `--ocio` is set apart, before the subcommand).
    pub options: Options,
    /// The options given on the command line, by any of their flags.
    pub given: Vec<Key>,
    taken: std::marker::PhantomData<T>,
}

/// The options of the definitions a command takes as its own arguments.
pub(crate) trait Taken: std::fmt::Debug + Clone + Send + Sync + 'static {
    /// The options, each with all its flags.
    fn keys() -> Vec<Key>;
    /// The help of an option whose default is the command's own, not a conversion's (the
    /// library's default is then neither shown nor set).
    fn own_help(_key: Key) -> Option<&'static str> {
        None
    }
}

/// `convert`'s (and `asset`'s, `farm submit`'s): every option of a conversion but the global
/// `--ocio`.
#[derive(Debug, Clone)]
pub(crate) struct Conversion;

impl Taken for Conversion {
    fn keys() -> Vec<Key> {
        own_keys().collect()
    }
}

/// The options of a conversion as arguments.
pub(crate) type ConversionArgs = OptionArgs<Conversion>;

/// `--force` alone, for the commands that write one file of their own (a model, a picture).
#[derive(Debug, Clone)]
pub(crate) struct Replacing;

impl Taken for Replacing {
    fn keys() -> Vec<Key> {
        vec![Key::Overwrite]
    }
}

/// `--force`, as the library defines it.
pub(crate) type ForceArg = OptionArgs<Replacing>;

impl ForceArg {
    /// Whether existing outputs are replaced.
    pub fn on(&self) -> bool {
        self.options.overwrite
    }
}

impl<T: Taken> OptionArgs<T> {
    /// Whether `key` was given on the command line.
    pub fn was_given(&self, key: Key) -> bool {
        self.given.contains(&key)
    }
}

/// The flags of `key` a command takes: all, but only the first where the command's default
/// is its own (the others, such as `--checknan`, say a conversion's).
fn shown_flags<T: Taken>(key: Key) -> &'static [Flag] {
    let flags = key.about().flags;
    match T::own_help(key) {
        Some(_) => &flags[..flags.len().min(1)],
        None => flags,
    }
}

/// The options `convert` takes as its own arguments: all but the global `--ocio`.
fn own_keys() -> impl Iterator<Item = Key> {
    Key::ALL.into_iter().filter(|k| *k != Key::Ocio)
}

/// The clap argument of `flag`, one of `key`'s; `own_help` replaces the option's help and
/// default (a command whose default is its own).
fn argument(key: Key, flag: &Flag, first: &Flag, own_help: Option<&'static str>) -> clap::Arg {
    use clap::{Arg, ArgAction};
    let about = key.about();
    let help = match (flag == first, own_help) {
        (true, Some(help)) => help,
        _ => flag.help.unwrap_or(about.help),
    };
    let mut arg = Arg::new(flag.long)
        .long(flag.long)
        .visible_aliases(flag.aliases.iter().copied())
        .help(help);
    if let Some(short) = flag.short {
        arg = arg.short(short);
    }
    if flag != first {
        arg = match (flag.requires, about.value) {
            (Some(other), _) => arg.requires(other),
            // --bounded and --unbounded: the last one given counts.
            (None, Value::Switch) => arg.overrides_with(first.long),
            (None, _) => arg.conflicts_with(first.long),
        };
    }
    let default = Options::default().text(key).filter(|_| own_help.is_none());
    match flag.takes {
        Takes::Value(name) => {
            arg = arg.value_name(name).action(ArgAction::Set);
            arg = arg.value_parser(OptionParser(key));
            match (flag == first, default) {
                (true, Some(text)) => arg.default_value(text),
                _ => arg,
            }
        }
        Takes::Pair(a, b) => {
            let shown = default.unwrap_or_default();
            arg.value_names([a, b])
                .num_args(2)
                .action(ArgAction::Set)
                .value_parser(clap::value_parser!(usize))
                .default_values(shown.split('x').map(str::to_string).collect::<Vec<_>>())
        }
        Takes::Sets(_) => arg.action(ArgAction::SetTrue),
        Takes::MaybeBool => arg
            .value_name("BOOL")
            .num_args(0..=1)
            .require_equals(true)
            .default_missing_value("true")
            .action(ArgAction::Set)
            .value_parser(OptionParser(key))
            .default_value(default.unwrap_or_default()),
    }
}

impl<T: Taken> clap::Args for OptionArgs<T> {
    fn augment_args(mut cmd: clap::Command) -> clap::Command {
        for key in T::keys() {
            let flags = key.about().flags;
            let Some(first) = flags.first() else { continue };
            for flag in shown_flags::<T>(key) {
                cmd = cmd.arg(argument(key, flag, first, T::own_help(key)));
            }
        }
        cmd
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl<T: Taken> clap::FromArgMatches for OptionArgs<T> {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut args = OptionArgs {
            options: Options::default(),
            given: Vec::new(),
            taken: std::marker::PhantomData,
        };
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    /// Sets each option a flag gave on the command line, in the order of its flags
    /// (`--emissive`, then `--emission-units`); defaults are the library's already.
    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        use clap::parser::ValueSource;
        for key in T::keys() {
            for flag in shown_flags::<T>(key) {
                let id = flag.long;
                if matches.value_source(id) != Some(ValueSource::CommandLine) {
                    continue;
                }
                let text: std::ffi::OsString = match flag.takes {
                    Takes::Sets(text) if matches.get_flag(id) => text.into(),
                    Takes::Sets(_) => continue,
                    Takes::Pair(..) => {
                        let v: Vec<&usize> = matches.get_many(id).into_iter().flatten().collect();
                        format!("{}x{}", v[0], v[1]).into()
                    }
                    Takes::Value(_) | Takes::MaybeBool => matches
                        .get_one::<std::ffi::OsString>(id)
                        .cloned()
                        .unwrap_or_default(),
                };
                if !self.given.contains(&key) {
                    self.given.push(key);
                }
                self.options.set_os(key, &text).map_err(|e| {
                    clap::Error::raw(
                        clap::error::ErrorKind::ValueValidation,
                        format!("--{id}: {}\n", e.why),
                    )
                })?;
            }
        }
        Ok(())
    }
}

/// A clap parser of an option's text, read by the library ([`Options::set_os`]): a value it
/// refuses is a usage error with its message, or for a choice with its names (help lists them;
/// its other spellings are accepted unlisted).
#[derive(Clone, Copy)]
pub(crate) struct OptionParser(Key);

impl TypedValueParser for OptionParser {
    type Value = std::ffi::OsString;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<std::ffi::OsString, clap::Error> {
        let mut o = Options::default();
        let Err(e) = o.set_os(self.0, value) else {
            return Ok(value.to_owned());
        };
        let flag = arg.map_or_else(String::new, |a| a.to_string());
        let text = value.to_string_lossy().into_owned();
        let Some((names, _)) = self.0.about().choices else {
            let message = format!("invalid value '{text}' for '{flag}': {}\n", e.why);
            return Err(
                clap::Error::raw(clap::error::ErrorKind::ValueValidation, message).with_cmd(cmd),
            );
        };
        use clap::error::{ContextKind, ContextValue};
        let mut err = clap::Error::new(clap::error::ErrorKind::InvalidValue).with_cmd(cmd);
        err.insert(ContextKind::InvalidArg, ContextValue::String(flag));
        err.insert(ContextKind::InvalidValue, ContextValue::String(text));
        let names = names.iter().map(|n| n.to_string()).collect();
        err.insert(ContextKind::ValidValue, ContextValue::Strings(names));
        Err(err)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        let spellings = self.0.about().spellings?;
        Some(Box::new(spellings.into_iter().map(|(name, aliases)| {
            PossibleValue::new(name).aliases(aliases.iter().copied())
        })))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};
    use specconv_conversion::Named;
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
        let mut listed: Vec<(&str, &str)> =
            DECLARED_BY_HAND.iter().map(|(c, f, _)| (*c, *f)).collect();
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
}
