//! Pieces of the JSON records that `convert --json` and `info --json` print for scripts
//! (docs/json.md): every record of a command has every key, `null` where it does not apply.

/// The rule that chose the input colour space, as records name it: `colorspace-option`
/// (--colorspace), `declared` (what the file declares), `file-rule` (the OCIO config's file
/// rules) or `default` (the format's default) — docs/colour.md.
pub fn colorspace_rule(rule: &specconv_conversion::Rule) -> &'static str {
    rule.kind()
}

/// Why this colour space, in words (the summary line, `info`'s `colorspace_reason`).
pub fn colorspace_reason(rule: &specconv_conversion::Rule) -> String {
    use specconv_conversion::Rule;
    match rule {
        Rule::Flag { overrides: None } => "--colorspace".into(),
        Rule::Flag { overrides: Some(d) } => format!("--colorspace, overriding the file's {d}"),
        Rule::Declared(what) => format!("declared by the file: {}", what.join(", ")),
        Rule::FileRule(name) => format!("the OCIO config's file rule '{name}'"),
        Rule::ConfigDefault(name) => format!(
            "the OCIO config's '{name}' file rule: a config given by --ocio or $OCIO is the \
             studio's policy for float files that declare nothing, before the format's default"
        ),
        Rule::Default(why) => format!("default: {why}"),
    }
}

/// A declaration of the file that was not followed, and how to choose instead.
pub fn warning(w: &specconv_conversion::Warning) -> String {
    format!("{w} (pass --colorspace to choose)")
}

/// `subimage 1 'albedo' of 2, channels R,G,B (why)`: what of an input was read.
pub fn selection(s: &specconv_conversion::Selection) -> String {
    use specconv_conversion::ChannelReason;
    let sub = s.describe_subimage();
    let why = match s.channels.reason {
        ChannelReason::Option => " (--channels)",
        ChannelReason::Named => "",
        ChannelReason::InOrder => " (in file order)",
        ChannelReason::OnlyLayer => " (the only RGB layer; --channels picks another)",
    };
    format!(
        "{}channels {}{why}",
        if sub.is_empty() { sub } else { sub + ", " },
        s.channels.names.join(",")
    )
}

pub use specconv_conversion::record::without_input;
