//! Pieces of the JSON records that `convert --json` and `info --json` print for scripts
//! (docs/json.md): every record of a command has every key, `null` where it does not apply.

/// The rule that chose the input colour space, as records name it: `colorspace-option`
/// (--colorspace), `file-rule` (the OCIO config's explicit file rules), `declared` (what the
/// file declares), `config-default` (the config's Default rule), `one-channel` (the data-map
/// rule) or `default` (the format's default) — docs/colour.md.
pub fn colorspace_rule(rule: &specconv_conversion::Rule) -> &'static str {
    rule.kind()
}

/// Why this colour space, in words (the summary line, `info`'s `colorspace_reason`), with
/// the evidence it overruled, once.
pub fn colorspace_reason(rule: &specconv_conversion::Rule) -> String {
    use specconv_conversion::{Rule, Strength};
    let over = rule
        .overrides()
        .map(|o| format!(", over {o}"))
        .unwrap_or_default();
    match rule {
        Rule::Flag { overrides: None } => "--colorspace".into(),
        Rule::Flag { overrides: Some(d) } => format!("--colorspace, overriding {d}"),
        Rule::Declared { what, strength, .. } => format!(
            "declared {}by the file: {}{over}",
            match strength {
                Strength::Strong => "",
                Strength::Weak => "weakly ",
            },
            what.join(", ")
        ),
        Rule::FileRule { rule, .. } => format!("the OCIO config's file rule '{rule}'{over}"),
        Rule::ConfigDefault { rule, .. } => format!(
            "the OCIO config's '{rule}' file rule{over}: a config given by --ocio or $OCIO is \
             the studio's policy for files that declare nothing strongly"
        ),
        Rule::OneChannel { .. } => format!(
            "one channel, which neither --colorspace, a file rule nor a strong declaration \
             calls colour: a data map{over}"
        ),
        Rule::Default(why) => format!("default: {why}"),
    }
}

/// How to have a skipped data texture after all: `--data copy` writes it through, and
/// `--colorspace` with the colour space the library names ([`specconv_conversion::Rule::colour_after_all`]: a grey
/// map's), or with the one the texture is encoded in, uplifts it as colour.
pub fn data_remedy(rule: &specconv_conversion::Rule) -> String {
    let colour = match rule.colour_after_all() {
        Some(name) => format!("--colorspace '{name}' uplifts it as colour"),
        None => "--colorspace NAME uplifts it as colour if it is one".into(),
    };
    format!("--data copy writes it through; {colour}")
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
