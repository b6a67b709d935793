//! Pieces of the JSON records that `convert --json` and `info --json` print for scripts
//! (docs/json.md): every record of a command has every key, `null` where it does not apply.

use std::path::Path;

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
    use specconv_conversion::images::ChannelReason;
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

/// An error message about an input without the leading `PATH: ` that the record (or the line)
/// already names; paths inside the message stay, so every path it names is the real one.
pub fn without_input(message: &str, input: &Path) -> String {
    let p = input.display().to_string();
    message
        .strip_prefix(&format!("{p}: "))
        .unwrap_or(message)
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_input_path_is_left_out() {
        let p = Path::new("/tex/gone.png");
        assert_eq!(
            without_input("/tex/gone.png: no such file", p),
            "no such file"
        );
        assert_eq!(
            without_input("cannot read /tex/gone.png: truncated", p),
            "cannot read /tex/gone.png: truncated"
        );
        // A path that contains the input's (`./x` holds `x`) is left whole.
        assert_eq!(
            without_input(
                "the output ./x is the input x; choose another",
                Path::new("x")
            ),
            "the output ./x is the input x; choose another"
        );
    }
}
