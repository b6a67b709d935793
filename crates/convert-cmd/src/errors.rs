//! How every command's failure is said: one line, `specconv: error: WHAT: CAUSE: …`, each cause
//! once, with the fix in this program's flags.

/// An error in how the command was asked for, which no input can fix: exit status 2.
#[derive(Debug)]
pub struct Usage(pub String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// Turns any error into a usage error (exit status 2), keeping its one-line text.
pub fn usage(e: impl Into<anyhow::Error>) -> anyhow::Error {
    Usage(one_line(e.into().as_ref())).into()
}

/// An error and its causes on one line, `WHAT: CAUSE: …`, each said once: a cause whose text
/// the line already holds is left out (wrappers that display their source would repeat it);
/// a cause's leading `NAME: ` is left out when the line ends with NAME (`cannot read F` and
/// `F: no such file` make `cannot read F: no such file`); and a cause that names what the
/// line's last part ends with replaces that part (`cannot read F` and `F is not a spectral
/// EXR` make `F is not a spectral EXR`).
pub fn one_line(e: &(dyn std::error::Error + 'static)) -> String {
    let hint = std::iter::successors(Some(e), |c| c.source()).find_map(hint);
    specconv_conversion::message(e) + hint.as_deref().unwrap_or_default()
}

/// A library error as the command line says it: [`one_line`] (with the option that would fix
/// it), or for the errors of one option, that option's own words.
pub fn explain(e: &specconv_conversion::Error) -> String {
    use specconv_conversion::Error;
    match e {
        Error::ZipLevelWithoutZip { compression } => format!(
            "--zip-level sets the deflate level of zip and zips; --compression {compression} \
             has none (drop --zip-level or use --compression zip)"
        ),
        Error::EmptyTile { width, height } => {
            format!("--tile {width} {height}: tiles must be at least 1×1")
        }
        Error::NoThreads => "-j/--threads must be at least 1".into(),
        _ => one_line(e),
    }
}

/// What to pass to fix a cause, in this program's flags: the libraries say which setting
/// ([`specconv_conversion::remedy_of`]) and word it ([`specconv_conversion::Remedy::advice`]),
/// spelt by [`Flags`]; the command line words the remedies that are its own.
fn hint(cause: &(dyn std::error::Error + 'static)) -> Option<String> {
    use specconv_conversion::{Key, Remedy};
    let remedy = specconv_conversion::remedy_of(cause)?;
    match remedy {
        // to-rgb's and preview's option, not a conversion's.
        Remedy::DropIlluminant => Some("; drop --illuminant".into()),
        // Output naming, the command line's own.
        Remedy::TileTemplate => Some(", or use --output-template with {udim}".into()),
        Remedy::AlreadySpectral => Some(format!(
            "; use it as it is (`specconv info` shows its bands), `specconv to-rgb` gives its \
             colour, and converting its colour source with {} START:END:STEP gives another grid \
             ({} R,G,B reads a colour preview it holds instead)",
            flag(Key::Bands),
            flag(Key::Channels)
        )),
        Remedy::ExpandCompact => Some(format!(
            "; `specconv expand` writes its spectra as a spectral OpenEXR ({} R,G,B reads its \
             colour as an image instead)",
            flag(Key::Channels)
        )),
        // A training setting, not a conversion's.
        Remedy::OneClusterModel => Some(" (`specconv train --clusters 1`)".into()),
        // [`explain`] words these errors whole, in the option's own terms.
        Remedy::DropZipLevel | Remedy::NonEmptyTiles | Remedy::SomeThreads => None,
        _ => remedy.advice(&Flags),
    }
}

/// The command line's spelling of the options a remedy names: its flags.
struct Flags;

impl specconv_conversion::Spelling for Flags {
    fn option(&self, key: specconv_conversion::Key) -> String {
        flag(key)
    }
    fn given(&self, key: specconv_conversion::Key, value: &str) -> String {
        format!("{} {value}", flag(key))
    }
    fn value(&self, value: &str) -> String {
        value.to_string()
    }
    fn on(&self, key: specconv_conversion::Key) -> String {
        flag(key)
    }
    fn update(&self) -> String {
        "-u".into()
    }
}

/// How the command line spells an option: its first flag as `convert` defines it, with its
/// short form and the names of its values where it takes several (`-j/--threads`,
/// `--tile W H`, `--fixnan`).
pub fn flag(key: specconv_conversion::Key) -> String {
    use specconv_conversion::Takes;
    let Some(first) = key.about().flags.first() else {
        return String::new();
    };
    let long = format!("--{}", first.long);
    let named = match first.short {
        Some(short) => format!("-{short}/{long}"),
        None => long,
    };
    match first.takes {
        Takes::Pair(a, b) => format!("{named} {a} {b}"),
        _ => named,
    }
}

/// A command-line error from clap as one line: its message, value lists and tips, without
/// the usage block (`--help` shows it).
pub fn clap_error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut parts = Vec::new();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    while let Some(line) = lines.next() {
        if line.starts_with("Usage:") {
            // The usage block runs to the next blank line, already dropped; skip its lines.
            for next in lines.by_ref() {
                if next.starts_with("For more information") {
                    parts.push(next.to_string());
                    break;
                }
            }
            continue;
        }
        parts.push(line.strip_prefix("error: ").unwrap_or(line).to_string());
    }
    parts.join("; ")
}

/// The one error format of every command: `specconv: error: ` and one line.
pub fn print_error(line: &str) {
    // A file name in it cannot make it pass for other lines.
    errln!(
        "specconv: error: {}",
        specconv_atomic_file::shown::escaped(line)
    );
}

/// An asset error for the command line: the caller's fault is a usage error (exit 2).
pub fn asset_error(e: specconv_asset::Error) -> anyhow::Error {
    if e.is_usage() {
        usage(e)
    } else {
        e.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_of_several_lines_is_one() {
        let e = std::io::Error::other("TOML parse error at line 1, column 5\n  |\n1 | a = \n  |     ^\nstring values must be quoted\n");
        assert_eq!(
            one_line(&e),
            "TOML parse error at line 1, column 5; string values must be quoted"
        );
    }

    #[test]
    fn options_are_spelt_by_their_flags() {
        use specconv_conversion::Key;
        assert_eq!(flag(Key::Threads), "-j/--threads");
        assert_eq!(flag(Key::Tile), "--tile W H");
        assert_eq!(flag(Key::Overwrite), "--force");
        assert_eq!(flag(Key::NonFinite), "--fixnan");
        // Every option the command line has a flag for is spelt by one it accepts.
        for key in Key::ALL {
            let Some(long) = key.about().flags.first() else {
                continue;
            };
            assert!(flag(key).contains(&format!("--{}", long.long)), "{key:?}");
        }
    }

    #[test]
    fn the_remedies_of_the_library_are_said_in_flags() {
        use specconv_conversion::Error;
        let said = |e: &(dyn std::error::Error + 'static)| one_line(e);
        let threads = Error::TooManyThreads {
            threads: 9,
            limit: 8,
            cores: 2,
        };
        assert!(
            said(&threads).ends_with("; lower -j/--threads"),
            "{}",
            said(&threads)
        );
        let memory = Error::TooMuchMemory {
            needed: 1 << 40,
            have: 1 << 30,
        };
        assert!(said(&memory).ends_with(" (--bands, --tile W H, -j/--threads)"));
        let grid = specconv_colour::Error::NotCovered {
            what: "the cie1931 observer".into(),
            first: 360.0,
            last: 830.0,
            grid: "300:700:10".parse().unwrap(),
        };
        assert!(
            said(&grid).ends_with("; choose bands inside that range (e.g. --bands 360:700:10)"),
            "{}",
            said(&grid)
        );
        let pca = specconv_spectral::Error::NeedsOneCluster { clusters: 8 };
        assert!(said(&pca).ends_with(" (`specconv train --clusters 1`)"));
        // Errors whose whole message the command line words itself take no hint.
        assert_eq!(said(&Error::NoThreads), Error::NoThreads.to_string());
        assert_eq!(
            explain(&Error::NoThreads),
            "-j/--threads must be at least 1"
        );
    }

    #[test]
    fn errors_read_as_one_line_with_each_cause_once() {
        let e = anyhow::anyhow!("/t/a.exr: no such file").context("cannot read /t/a.exr");
        assert_eq!(one_line(e.as_ref()), "cannot read /t/a.exr: no such file");
        let e = anyhow::anyhow!("/t/a.exr is not a spectral EXR").context("cannot read /t/a.exr");
        assert_eq!(one_line(e.as_ref()), "/t/a.exr is not a spectral EXR");
        let e = anyhow::anyhow!("OpenEXR: truncated")
            .context("cannot read /t/a.exr")
            .context("patch 2");
        assert_eq!(
            one_line(e.as_ref()),
            "patch 2: cannot read /t/a.exr: OpenEXR: truncated"
        );
        // A word is not a file name: `patch tex` and `cannot read the texture…` both stay.
        let e = anyhow::anyhow!("/t/a.png: no such file")
            .context("cannot read the texture /t/a.png")
            .context("patch tex");
        assert_eq!(
            one_line(e.as_ref()),
            "patch tex: cannot read the texture /t/a.png: no such file"
        );
        // A wrapper that displays its source (thiserror's `#[error("{0}")]` with `#[from]`).
        #[derive(Debug)]
        struct Wrap(std::io::Error);
        impl std::fmt::Display for Wrap {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                self.0.fmt(f)
            }
        }
        impl std::error::Error for Wrap {
            fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
                Some(&self.0)
            }
        }
        let e =
            anyhow::Error::new(Wrap(std::io::Error::other("disk full"))).context("cannot write x");
        assert_eq!(one_line(e.as_ref()), "cannot write x: disk full");
        let u = usage(e);
        assert!(u.is::<Usage>());
        assert_eq!(u.to_string(), "cannot write x: disk full");
    }
}
