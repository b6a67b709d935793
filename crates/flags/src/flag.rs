//! One flag of a command, as data: what it is called, what follows it, its help, its default
//! and how it relates to the command's other flags. [`crate::Field`] turns it into clap's
//! argument for the Rust type that holds its value.

use clap::builder::ValueParser;

/// A flag's default, as shown in help and parsed like a given value.
#[derive(Debug, Clone, Copy)]
pub enum DefaultValue {
    /// None: the flag is unset, or required where its value has no `None`.
    Unset,
    /// This text.
    Text(&'static str),
    /// Texts made from the library's constants (one per value of a list).
    Made(fn() -> Vec<String>),
}

/// A command's flag (or argument, without a long name), defined once in [`crate::defs`].
#[derive(Debug, Clone, Copy)]
pub struct Flag {
    /// Its id, which the command's other flags name it by: its long name, or for an argument
    /// given by its place a name of its own.
    pub id: &'static str,
    /// Its long name, without `--`; `None` for an argument given by its place.
    pub long: Option<&'static str>,
    /// Its one-letter name, if any.
    pub short: Option<char>,
    /// The name of its value in help; `None` for a switch.
    pub value_name: Option<&'static str>,
    /// Other long names it answers to (shown in help).
    pub aliases: &'static [&'static str],
    /// What it does.
    pub help: &'static str,
    /// What it does, where the text names the library's values (it replaces `help`).
    pub help_made: Option<fn() -> String>,
    /// Its default.
    pub default: DefaultValue,
    /// The character that splits one given text into several values.
    pub delimiter: Option<char>,
    /// How its value is read, where not by its type alone (a range, a rule of its own).
    pub parser: Option<fn() -> ValueParser>,
    /// Whether it must be given (a list, which could otherwise be empty).
    pub required: bool,
    /// The flag (id) it is given with, if any.
    pub requires: Option<&'static str>,
    /// The flag (id) that makes it optional, if any; it is required otherwise.
    pub required_unless: Option<&'static str>,
    /// The flags (ids) it cannot be given with.
    pub conflicts: &'static [&'static str],
    /// The flag (id) that, given after it, replaces it.
    pub overridden_by: Option<&'static str>,
}

impl Flag {
    /// `--long`, a switch until given a value name; nothing else set.
    pub const fn long(long: &'static str, help: &'static str) -> Flag {
        Flag {
            id: long,
            long: Some(long),
            short: None,
            value_name: None,
            aliases: &[],
            help,
            help_made: None,
            default: DefaultValue::Unset,
            delimiter: None,
            parser: None,
            required: false,
            requires: None,
            required_unless: None,
            conflicts: &[],
            overridden_by: None,
        }
    }

    /// An argument given by its place, its value named `value_name` in help.
    pub const fn place(id: &'static str, value_name: &'static str, help: &'static str) -> Flag {
        Flag {
            id,
            long: None,
            value_name: Some(value_name),
            ..Flag::long("", help)
        }
    }

    /// With the one-letter name `short`.
    pub const fn short(self, short: char) -> Flag {
        Flag {
            short: Some(short),
            ..self
        }
    }

    /// Answering to the long names `aliases` too.
    pub const fn aliases(self, aliases: &'static [&'static str]) -> Flag {
        Flag { aliases, ..self }
    }

    /// With its help made from the library's values.
    pub const fn help_made(self, made: fn() -> String) -> Flag {
        Flag {
            help_made: Some(made),
            ..self
        }
    }

    /// Taking a value, named `name` in help.
    pub const fn value(self, name: &'static str) -> Flag {
        Flag {
            value_name: Some(name),
            ..self
        }
    }

    /// With the default `text`.
    pub const fn default(self, text: &'static str) -> Flag {
        Flag {
            default: DefaultValue::Text(text),
            ..self
        }
    }

    /// With defaults made from the library's constants.
    pub const fn made(self, made: fn() -> Vec<String>) -> Flag {
        Flag {
            default: DefaultValue::Made(made),
            ..self
        }
    }

    /// A list split at `delimiter`.
    pub const fn split(self, delimiter: char) -> Flag {
        Flag {
            delimiter: Some(delimiter),
            ..self
        }
    }

    /// Read by `parser` rather than by its type alone.
    pub const fn parser(self, parser: fn() -> ValueParser) -> Flag {
        Flag {
            parser: Some(parser),
            ..self
        }
    }

    /// Required.
    pub const fn required(self) -> Flag {
        Flag {
            required: true,
            ..self
        }
    }

    /// Given only with the flag `id`.
    pub const fn requires(self, id: &'static str) -> Flag {
        Flag {
            requires: Some(id),
            ..self
        }
    }

    /// Required unless the flag `id` is given.
    pub const fn required_unless(self, id: &'static str) -> Flag {
        Flag {
            required_unless: Some(id),
            ..self
        }
    }

    /// Not given with the flags `ids`.
    pub const fn conflicts(self, ids: &'static [&'static str]) -> Flag {
        Flag {
            conflicts: ids,
            ..self
        }
    }

    /// Replaced by the flag `id` given after it.
    pub const fn overridden_by(self, id: &'static str) -> Flag {
        Flag {
            overridden_by: Some(id),
            ..self
        }
    }

    /// Its clap argument, but for what its type decides: how many values it takes and how
    /// they are read ([`crate::Field`]).
    pub fn arg(&self) -> clap::Arg {
        let mut arg = clap::Arg::new(self.id).help(self.help());
        if let Some(long) = self.long {
            arg = arg.long(long).visible_aliases(self.aliases.iter().copied());
        }
        if let Some(short) = self.short {
            arg = arg.short(short);
        }
        if let Some(name) = self.value_name {
            arg = arg.value_name(name);
        }
        match self.default {
            DefaultValue::Unset => {}
            DefaultValue::Text(text) => arg = arg.default_value(text),
            DefaultValue::Made(made) => arg = arg.default_values(made()),
        }
        if let Some(delimiter) = self.delimiter {
            arg = arg.value_delimiter(delimiter);
        }
        if self.required {
            arg = arg.required(true);
        }
        if let Some(id) = self.requires {
            arg = arg.requires(id);
        }
        if let Some(id) = self.required_unless {
            arg = arg.required_unless_present(id);
        }
        for id in self.conflicts {
            arg = arg.conflicts_with(id);
        }
        if let Some(id) = self.overridden_by {
            arg = arg.overrides_with(id);
        }
        arg
    }

    /// What it does.
    pub fn help(&self) -> String {
        self.help_made
            .map_or_else(|| self.help.to_string(), |made| made())
    }

    /// Whether it has a default.
    pub fn has_default(&self) -> bool {
        !matches!(self.default, DefaultValue::Unset)
    }
}
