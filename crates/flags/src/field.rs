//! A command's arguments as a struct whose fields are [`Flag`]s of [`crate::defs`]
//! ([`crate::args!`]): the field's Rust type decides what clap's derive would (a switch, one
//! value, an optional value, a list), the definition all the rest.

use crate::Flag;
use clap::builder::ValueParser;
use clap::{ArgAction, ArgMatches};

/// A type a flag's value can have, read by its own parser (clap's for the type).
pub trait Value: Clone + Send + Sync + 'static {
    /// clap's parser of a value of this type.
    fn parser() -> ValueParser;
}

/// Implements [`Value`] with clap's parser of each type.
#[macro_export]
macro_rules! value_by_type {
    ($($ty:ty),* $(,)?) => {
        $(impl $crate::Value for $ty {
            fn parser() -> clap::builder::ValueParser {
                clap::value_parser!($ty).into()
            }
        })*
    };
}

value_by_type!(
    u32,
    usize,
    f64,
    String,
    std::path::PathBuf,
    specconv_colour::Observer,
    specconv_colour::Illuminant,
    specconv_colour::Grid,
    specconv_spectral::method::MethodName,
    specconv_spectral::otsu2018::terms::Commercial,
    specconv_farm::Shard,
    clap_complete::Shell,
);

/// A field of a command's arguments: how its type takes the flag's values and reads them back.
pub trait Field: Sized {
    /// The flag's clap argument for a field of this type.
    fn arg(flag: &Flag) -> clap::Arg;
    /// The field's value from what was parsed.
    fn read(matches: &ArgMatches, flag: &Flag) -> Result<Self, clap::Error>;
}

/// The parser of `flag`'s values: its own, else its type's.
fn parser<T: Value>(flag: &Flag) -> ValueParser {
    let Some(made) = flag.parser else {
        return T::parser();
    };
    let parser = made();
    // clap would panic only when the flag is given and read: say so when the command is built.
    debug_assert!(
        parser.type_id() == std::any::TypeId::of::<T>(),
        "{}: its parser reads another type than its field holds",
        flag.id
    );
    parser
}

/// A switch.
impl Field for bool {
    fn arg(flag: &Flag) -> clap::Arg {
        flag.arg().action(ArgAction::SetTrue)
    }

    fn read(matches: &ArgMatches, flag: &Flag) -> Result<bool, clap::Error> {
        Ok(matches.get_flag(flag.id))
    }
}

/// One value: required unless it has a default.
impl<T: Value> Field for T {
    fn arg(flag: &Flag) -> clap::Arg {
        let arg = flag
            .arg()
            .action(ArgAction::Set)
            .value_parser(parser::<T>(flag));
        match flag.has_default() || flag.required_unless.is_some() {
            true => arg,
            false => arg.required(true),
        }
    }

    fn read(matches: &ArgMatches, flag: &Flag) -> Result<T, clap::Error> {
        matches.get_one::<T>(flag.id).cloned().ok_or_else(|| {
            clap::Error::raw(
                clap::error::ErrorKind::MissingRequiredArgument,
                format!(
                    "the following required argument was not provided: {}",
                    flag.id
                ),
            )
        })
    }
}

/// One value, or none.
impl<T: Value> Field for Option<T> {
    fn arg(flag: &Flag) -> clap::Arg {
        flag.arg()
            .action(ArgAction::Set)
            .value_parser(parser::<T>(flag))
    }

    fn read(matches: &ArgMatches, flag: &Flag) -> Result<Option<T>, clap::Error> {
        Ok(matches.get_one::<T>(flag.id).cloned())
    }
}

/// Any number of values: the flag repeated, or split at its delimiter.
impl<T: Value> Field for Vec<T> {
    fn arg(flag: &Flag) -> clap::Arg {
        let arg = flag
            .arg()
            .action(ArgAction::Append)
            .value_parser(parser::<T>(flag));
        // As clap's derive: given by place, one occurrence takes them all.
        match flag.long {
            None => arg.num_args(1..),
            Some(_) => arg,
        }
    }

    fn read(matches: &ArgMatches, flag: &Flag) -> Result<Vec<T>, clap::Error> {
        Ok(matches
            .get_many::<T>(flag.id)
            .map(|values| values.cloned().collect())
            .unwrap_or_default())
    }
}

/// A struct of a command's arguments, each field a flag of [`crate::defs`], the arguments of
/// another such struct (`= flatten`) or set by the command itself (`= skip`):
///
/// ```
/// use specconv_flags::defs;
///
/// specconv_flags::args! {
///     /// Shown as the command's help, as clap's derive shows it.
///     #[derive(Debug)]
///     pub struct Args {
///         pub tasks: u32 = (defs::FARM_SUBMIT_TASKS),
///         pub read: specconv_flags::OptionArgs<specconv_flags::Reading> = flatten,
///         pub ocio: Option<String> = skip,
///     }
/// }
///
/// use clap::{Args as _, FromArgMatches as _};
/// let cmd = Args::augment_args(clap::Command::new("x"));
/// let args = Args::from_arg_matches(&cmd.get_matches_from(["x", "--tasks", "4"])).unwrap();
/// assert_eq!((args.tasks, args.ocio), (4, None));
/// ```
///
/// The struct's documentation is the command's about, made by clap's derive of an empty
/// struct so that it reads exactly as before; the fields' flags come in their order.
#[macro_export]
macro_rules! args {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[doc = $doc:literal])* $fvis:vis $field:ident : $ty:ty = $source:tt ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $( $(#[doc = $doc])* $fvis $field: $ty, )*
        }

        const _: () = {
            #[derive(clap::Args)]
            #[group(skip)]
            $(#[$meta])*
            struct About {}

            impl clap::Args for $name {
                fn augment_args(cmd: clap::Command) -> clap::Command {
                    $( let cmd = $crate::__augment!(cmd, $ty, $source); )*
                    <About as clap::Args>::augment_args(cmd)
                }

                fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
                    <Self as clap::Args>::augment_args(cmd)
                }
            }

            impl clap::FromArgMatches for $name {
                fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
                    Ok($name {
                        $( $field: $crate::__read!(matches, $ty, $source), )*
                    })
                }

                fn update_from_arg_matches(
                    &mut self,
                    matches: &clap::ArgMatches,
                ) -> Result<(), clap::Error> {
                    *self = <Self as clap::FromArgMatches>::from_arg_matches(matches)?;
                    Ok(())
                }
            }
        };
    };
}

/// [`args!`]'s arguments of one field.
#[doc(hidden)]
#[macro_export]
macro_rules! __augment {
    ($cmd:ident, $ty:ty, flatten) => {
        <$ty as clap::Args>::augment_args($cmd)
    };
    ($cmd:ident, $ty:ty, skip) => {
        $cmd
    };
    ($cmd:ident, $ty:ty, $flag:tt) => {
        $cmd.arg(<$ty as $crate::Field>::arg(&$flag))
    };
}

/// [`args!`]'s reading of one field.
#[doc(hidden)]
#[macro_export]
macro_rules! __read {
    ($matches:ident, $ty:ty, flatten) => {
        <$ty as clap::FromArgMatches>::from_arg_matches($matches)?
    };
    ($matches:ident, $ty:ty, skip) => {
        <$ty as ::std::default::Default>::default()
    };
    ($matches:ident, $ty:ty, $flag:tt) => {
        <$ty as $crate::Field>::read($matches, &$flag)?
    };
}

#[cfg(test)]
mod tests {
    use crate::Flag;
    use clap::{Args, FromArgMatches};
    use std::path::PathBuf;

    const PATH: Flag = Flag::place("path", "PATH", "A path");
    const COUNT: Flag = Flag::long("count", "A count").value("N").default("3");
    const ON: Flag = Flag::long("on", "A switch").short('o');
    const NAME: Flag = Flag::long("name", "A name").value("NAME");
    const LIST: Flag = Flag::long("list", "Some numbers").value("K,…").split(',');
    const TASKS: Flag = Flag::long("tasks", "At least one")
        .value("N")
        .parser(|| clap::value_parser!(u32).range(1..).into())
        .requires("name");

    crate::args! {
        #[derive(Debug)]
        struct Inner {
            on: bool = (ON),
        }
    }

    crate::args! {
        /// Do a thing.
        ///
        /// More about the thing, on
        /// two lines.
        #[derive(Debug)]
        struct Outer {
            path: PathBuf = (PATH),
            count: u32 = (COUNT),
            inner: Inner = flatten,
            name: Option<String> = (NAME),
            list: Vec<usize> = (LIST),
            kept: Option<String> = skip,
            tasks: Option<u32> = (TASKS),
        }
    }

    /// The same arguments as clap's derive makes them: what the macro must give.
    #[derive(Debug, clap::Args)]
    struct DerivedInner {
        /// A switch.
        #[arg(short, long)]
        on: bool,
    }

    /// Do a thing.
    ///
    /// More about the thing, on
    /// two lines.
    #[derive(Debug, clap::Args)]
    #[group(skip)]
    struct Derived {
        /// A path.
        path: PathBuf,
        /// A count.
        #[arg(long, value_name = "N", default_value_t = 3)]
        count: u32,
        #[command(flatten)]
        inner: DerivedInner,
        /// A name.
        #[arg(long, value_name = "NAME")]
        name: Option<String>,
        /// Some numbers.
        #[arg(long, value_name = "K,…", value_delimiter = ',')]
        list: Vec<usize>,
        /// At least one.
        #[arg(long, value_name = "N", requires = "name", value_parser = clap::value_parser!(u32).range(1..))]
        tasks: Option<u32>,
    }

    fn command<A: Args>() -> clap::Command {
        A::augment_args(clap::Command::new("t"))
    }

    fn parse(words: &[&str]) -> Result<Outer, clap::Error> {
        let matches = command::<Outer>().try_get_matches_from(words)?;
        Outer::from_arg_matches(&matches)
    }

    #[test]
    fn help_and_errors_are_those_of_clap_s_derive() {
        let mut ours = command::<Outer>();
        let mut derived = command::<Derived>();
        assert_eq!(
            ours.render_long_help().to_string(),
            derived.render_long_help().to_string()
        );
        assert_eq!(
            ours.render_help().to_string(),
            derived.render_help().to_string()
        );
        assert!(ours
            .render_long_help()
            .to_string()
            .contains("More about the thing, on two lines."));
        for words in [
            &["t"][..],
            &["t", "p", "--tasks", "0", "--name", "x"],
            &["t", "p", "--tasks", "2"],
            &["t", "p", "--count", "x"],
            &["t", "p", "--list", "1,x"],
        ] {
            let ours = command::<Outer>().try_get_matches_from(words).unwrap_err();
            let derived = command::<Derived>()
                .try_get_matches_from(words)
                .unwrap_err();
            assert_eq!(ours.kind(), derived.kind(), "{words:?}");
            assert_eq!(ours.to_string(), derived.to_string(), "{words:?}");
        }
    }

    #[test]
    #[should_panic(expected = "tasks: its parser reads another type than its field holds")]
    fn a_parser_of_another_type_than_the_field_is_refused_when_built() {
        crate::args! {
            #[allow(dead_code)]
            struct Wrong {
                tasks: Option<usize> = (TASKS),
            }
        }
        command::<Wrong>();
    }

    #[test]
    fn each_field_reads_its_flag_as_its_type_says() {
        let o = parse(&["t", "p"]).unwrap();
        assert_eq!(o.path, PathBuf::from("p"));
        assert_eq!((o.count, o.inner.on), (3, false));
        assert_eq!(
            (o.name, o.list, o.kept, o.tasks),
            (None, vec![], None, None)
        );
        let words = [
            "t", "p", "-o", "--name", "x", "--list", "1,2", "--list", "3", "--count", "5",
            "--tasks", "2",
        ];
        let o = parse(&words).unwrap();
        assert_eq!(
            (o.count, o.inner.on, o.name.as_deref()),
            (5, true, Some("x"))
        );
        assert_eq!((o.list, o.tasks), (vec![1, 2, 3], Some(2)));
        let ids: Vec<String> = command::<Outer>()
            .get_arguments()
            .map(|a| a.get_id().to_string())
            .collect();
        assert_eq!(ids, ["path", "count", "on", "name", "list", "tasks"]);
    }
}
