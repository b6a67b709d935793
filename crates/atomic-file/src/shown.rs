//! How text from users and input files is shown: one value, one line. File names, attribute
//! values, model licences and channel names are printed by `info`, `models`, `train` and
//! errors beside specconv's own lines; a line break, a carriage return, an escape sequence, a
//! Unicode line separator or a bidirectional override inside one would let it pass for other
//! lines (a forged `specconvSource:` or `commercial use: yes`) or rewrite the terminal. Every
//! printer shows such text through [`escaped`], which writes those characters as visible
//! escapes and leaves everything else as it is.

use std::borrow::Cow;

/// Whether `c` must not reach a terminal as itself: a control character (C0, DEL, C1), a
/// line or paragraph separator, or a bidirectional control (embeddings, overrides,
/// isolates, marks) that can reorder what is shown.
pub fn hidden(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{2028}' | '\u{2029}' | '\u{200E}' | '\u{200F}' | '\u{061C}' | '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}'
        )
}

/// `text` as one line: each control, separator or bidirectional character written as an
/// escape (`\n`, `\r`, `\t`, else `\u{…}`), everything else unchanged; borrowed when nothing
/// needed escaping.
pub fn escaped(text: &str) -> Cow<'_, str> {
    if !text.chars().any(hidden) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if hidden(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_hidden_character_is_escaped_and_other_text_kept() {
        let forged = "ours\nspecconvSource: FORGED.png\r\ncommercial use: yes";
        assert_eq!(
            escaped(forged),
            "ours\\nspecconvSource: FORGED.png\\r\\ncommercial use: yes"
        );
        for c in (0u32..0x20)
            .chain(0x7f..0xa0)
            .chain([0x2028, 0x2029, 0x200e, 0x200f, 0x61c])
            .chain(0x202a..0x202f)
            .chain(0x2066..0x206a)
            .filter_map(char::from_u32)
        {
            let text = format!("a{c}b");
            let shown = escaped(&text);
            assert!(!shown.chars().any(hidden), "U+{:04X}: {shown:?}", c as u32);
            assert!(shown.starts_with('a') && shown.ends_with('b'));
            assert_eq!(shown.lines().count(), 1);
        }
        for kept in [
            "山田 太郎 — Café ☃",
            "C:\\textures\\a.png",
            "studio:名前",
            "",
        ] {
            assert!(matches!(escaped(kept), Cow::Borrowed(k) if k == kept));
        }
    }
}
