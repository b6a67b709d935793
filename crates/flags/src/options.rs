//! The conversion's options as clap arguments, made from the library's one definition of each
//! ([`specconv_conversion::definition`]): flags, value names, help, defaults and conflicts come
//! from there, and a value is read by the library. The CLI's tests fail when `convert` accepts
//! a flag, a name or a default the library does not define.

use clap::builder::{PossibleValue, TypedValueParser};
use specconv_conversion::{Flag, Key, Options, Takes, Value};

/// Options of the library's definitions as a command's arguments
/// ([`specconv_conversion::definition`]): each flag, its value names, help and conflicts come
/// from there; a value is read by the library ([`Options::set_os`]), so a flag accepts exactly
/// what the library does. Which options a command takes is its [`Taken`].
#[derive(Debug, Clone)]
pub struct OptionArgs<T: Taken> {
    /// The options given (the global `--ocio` is set apart, before the subcommand).
    pub options: Options,
    /// The options given on the command line, by any of their flags.
    pub given: Vec<Key>,
    taken: std::marker::PhantomData<T>,
}

/// The options of the definitions a command takes as its own arguments.
pub trait Taken: std::fmt::Debug + Clone + Send + Sync + 'static {
    /// The options, each with all its flags.
    fn keys() -> Vec<Key>;
    /// The help of an option whose default is the command's own, not a conversion's (the
    /// library's default is then neither shown nor set).
    fn own_help(_key: Key) -> Option<&'static str> {
        None
    }
    /// Whether the options are every command's, given before or after its name.
    fn global() -> bool {
        false
    }
}

/// `convert`'s (and `asset`'s, `farm submit`'s): every option of a conversion but the global
/// `--ocio`.
#[derive(Debug, Clone)]
pub struct Conversion;

impl Taken for Conversion {
    fn keys() -> Vec<Key> {
        own_keys().collect()
    }
}

/// The options of a conversion as arguments.
pub type ConversionArgs = OptionArgs<Conversion>;

/// `--force` alone, for the commands that write one file of their own (a model, a picture).
#[derive(Debug, Clone)]
pub struct Replacing;

impl Taken for Replacing {
    fn keys() -> Vec<Key> {
        vec![Key::Overwrite]
    }
}

/// `--force`, as the library defines it.
pub type ForceArg = OptionArgs<Replacing>;

/// `--subimage` and `--channels`, for the commands that read an input as `convert` does.
#[derive(Debug, Clone)]
pub struct Reading;

impl Taken for Reading {
    fn keys() -> Vec<Key> {
        vec![Key::Subimage, Key::Channels]
    }
}

/// The options of the method stack that `simulate` shares with a conversion.
#[derive(Debug, Clone)]
pub struct Stacking;

impl Taken for Stacking {
    fn keys() -> Vec<Key> {
        vec![Key::Model, Key::Blend, Key::Bounded, Key::Bands]
    }
}

/// `--blend`, for the commands that uplift with a clustered model.
#[derive(Debug, Clone)]
pub struct Blending;

impl Taken for Blending {
    fn keys() -> Vec<Key> {
        vec![Key::Blend]
    }
}

/// The global `--ocio`, before or after any command's name.
#[derive(Debug, Clone)]
pub struct Configuring;

impl Taken for Configuring {
    fn keys() -> Vec<Key> {
        vec![Key::Ocio]
    }

    fn global() -> bool {
        true
    }
}

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
            // Shells complete a path as a file name, as clap does for a path's type.
            if about.value == Value::Path {
                arg = arg.value_hint(clap::ValueHint::AnyPath);
            }
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
                cmd = cmd.arg(argument(key, flag, first, T::own_help(key)).global(T::global()));
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
