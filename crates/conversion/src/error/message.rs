//! An error as one line of text, for every front-end.

/// An error and its causes on one line, each cause once (`cannot read F: why`), as every
/// front-end says it before naming its own remedy ([`super::Error::remedy`]).
pub fn message(e: &(dyn std::error::Error + 'static)) -> String {
    // A file name or a tool's text inside cannot make it pass for other lines.
    specconv_atomic_file::shown::escaped(&single_line(&chain(e))).into_owned()
}

/// A message of several lines (a TOML error's source snippet, a tool's standard error) on one
/// line: its lines joined by `; `, without the snippet's `N | …` and `| ^` lines.
fn single_line(text: &str) -> String {
    let snippet = |l: &str| {
        l.trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start()
            .starts_with('|')
    };
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !snippet(l))
        .collect::<Vec<_>>()
        .join("; ")
}

/// The cause chain of `e`.
fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut line = e.to_string();
    for cause in std::iter::successors(e.source(), |c| c.source()) {
        let cause = cause.to_string();
        if line.contains(&cause) {
            continue;
        }
        if let Some((head, rest)) = cause.split_once(": ") {
            if line.ends_with(head) {
                line = format!("{line}: {rest}");
                continue;
            }
        }
        // `cannot read F` and `F is not a spectral EXR`: the cause, naming the same file
        // first, says it all.
        let (before, last) = line.rsplit_once(": ").unwrap_or(("", &line));
        let named = last.split_whitespace().last().unwrap_or_default();
        let a_path = named.len() > 1 && named.contains(['/', '.']);
        line = if a_path && cause.starts_with(named) {
            if before.is_empty() {
                cause
            } else {
                format!("{before}: {cause}")
            }
        } else {
            format!("{line}: {cause}")
        };
    }
    line
}
