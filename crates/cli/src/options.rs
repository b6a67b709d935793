//! The conversion's options as clap arguments, derived from the library's one description
//! ([`specconv_conversion::Key`]): a choice is parsed by the library's names
//! ([`specconv_conversion::Named`]), a default is the library's, and the test below fails when
//! `convert` accepts a flag, a name or a default the library does not define.

use clap::builder::{PossibleValue, TypedValueParser};
use specconv_conversion::{Key, Named, Options};

/// A clap parser of a library choice: help lists its names, its other spellings are accepted
/// unlisted, anything else gets the library's message.
#[derive(Clone, Copy)]
pub(crate) struct NamedParser<T>(std::marker::PhantomData<T>);

/// The parser of `T`'s names.
pub(crate) fn named<T: Named + Send + Sync>() -> NamedParser<T> {
    NamedParser(std::marker::PhantomData)
}

impl<T: Named + Send + Sync> TypedValueParser for NamedParser<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        let text = value
            .to_str()
            .ok_or_else(|| clap::Error::new(clap::error::ErrorKind::InvalidUtf8).with_cmd(cmd))?;
        T::from_name(text).map_err(|e| {
            let mut err = clap::Error::new(clap::error::ErrorKind::InvalidValue).with_cmd(cmd);
            use clap::error::{ContextKind, ContextValue};
            if let Some(arg) = arg {
                err.insert(
                    ContextKind::InvalidArg,
                    ContextValue::String(arg.to_string()),
                );
            }
            err.insert(ContextKind::InvalidValue, ContextValue::String(e.name));
            err.insert(
                ContextKind::ValidValue,
                ContextValue::Strings(e.choices.iter().map(|c| c.to_string()).collect()),
            );
            err
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(T::ALL.iter().map(|v| {
            PossibleValue::new(v.name()).aliases(v.aliases().iter().copied())
        })))
    }
}

/// The library's default of `key`, as text (for `default_value`).
pub(crate) fn default_of(key: Key) -> String {
    Options::default()
        .text(key)
        .unwrap_or_else(|| panic!("{key:?} has a default"))
}

/// The library's default tile size.
pub(crate) fn default_tile() -> [usize; 2] {
    match Options::default().blocks {
        specconv_conversion::Blocks::Tiles(w, h) => [w, h],
        specconv_conversion::Blocks::Scanlines => [64, 64],
    }
}

/// The text of `key` read by the library, for an option clap cannot type by itself.
pub(crate) fn parsed<T: 'static>(
    key: Key,
    field: fn(Options) -> Option<T>,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static {
    move |text| {
        let mut o = Options::default();
        o.set(key, Some(text)).map_err(|e| e.why)?;
        Ok(field(o).expect("set gives it a value"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};
    use std::collections::BTreeSet;

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
        let mut cli = crate::Cli::command();
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
            for flag in key.about().flags {
                assert!(
                    longs.remove(*flag),
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
        let m = crate::Cli::try_parse_from(["specconv", "convert", "a.png", "b.exr"]).unwrap();
        let crate::Command::Convert(args) = m.command.expect("a command") else {
            panic!("convert")
        };
        let (got, want) = (args.options(), Options::default());
        for key in Key::ALL {
            assert_eq!(got.text(key), want.text(key), "{key:?}");
        }
    }
}
