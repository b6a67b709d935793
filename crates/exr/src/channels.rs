//! The layout's channel names: a band's name written ([`channel_name`]), a name read back
//! ([`parse_channel`]), and a list of names sorted by what they hold ([`ChannelKinds`]).

use crate::spec::Kind;

/// The channel name of a band: `T.550,000000nm` or `S0.550,000000nm`.
pub fn channel_name(kind: &Kind, wavelength_nm: f64) -> String {
    let prefix = match kind {
        Kind::Reflective => "T",
        Kind::Emissive { .. } => "S0",
        // The value's number, from 1 (`Kind::Named`).
        Kind::Named(names) => {
            let i = (wavelength_nm as usize).wrapping_sub(1);
            return names.get(i).map(|n| n.0.clone()).unwrap_or_default();
        }
    };
    format!(
        "{prefix}.{}nm",
        format!("{wavelength_nm:.6}").replace('.', ",")
    )
}

/// What a channel of the layout holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Channel {
    /// `T.<λ>`: reflectance (the diagonal of a bispectral file).
    Reflective {
        /// The wavelength, nm.
        nm: f64,
    },
    /// `S<k>.<λ>`: the Stokes component k of emission (S0 the radiance, S1–S3 polarisation).
    Stokes {
        /// The component, 0–3.
        k: u8,
        /// The wavelength, nm.
        nm: f64,
    },
    /// `T.<λi>.<λo>`: light re-radiated at λo from light received at λi (fluorescence).
    Reradiation {
        /// λi, the wavelength received, nm.
        from_nm: f64,
        /// λo, the wavelength re-radiated, nm.
        to_nm: f64,
    },
}

/// The channel a name denotes, by the reference reader's grammar: a wavelength with a comma
/// (or point) as decimal separator and an optional exponent, an SI prefix on the unit (`nm`,
/// `um`, `m`, …, `da`) and `m` or `Hz` (a frequency, turned into its wavelength in vacuum).
pub fn parse_channel(name: &str) -> Option<Channel> {
    let (prefix, rest) = name.split_once('.')?;
    match prefix {
        "T" => match rest.find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E') {
            Some(i) => {
                // Either `λ<unit>` or `λi<unit>.λo<unit>`.
                let (first, second) = match rest[i..].split_once('.') {
                    Some((unit, second)) => (&rest[..i + unit.len()], Some(second)),
                    None => (rest, None),
                };
                let from_nm = wavelength(first)?;
                match second {
                    None => Some(Channel::Reflective { nm: from_nm }),
                    Some(second) => Some(Channel::Reradiation {
                        from_nm,
                        to_nm: wavelength(second)?,
                    }),
                }
            }
            None => None,
        },
        "S0" | "S1" | "S2" | "S3" => Some(Channel::Stokes {
            k: prefix.as_bytes()[1] - b'0',
            nm: wavelength(rest)?,
        }),
        _ => None,
    }
}

/// A wavelength with its unit (`550,5nm`, `0,55um`, `545,077196THz`) in nm.
fn wavelength(text: &str) -> Option<f64> {
    let split = text.find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')?;
    let (number, unit) = text.split_at(split);
    if number.is_empty() || number.starts_with(['+', '-']) {
        return None;
    }
    let value: f64 = number.replace(',', ".").parse().ok()?;
    let (prefix, hz) = if let Some(p) = unit.strip_suffix("Hz") {
        (p, true)
    } else {
        (unit.strip_suffix('m')?, false)
    };
    // The SI prefixes the reference reader accepts, as powers of ten (exact in f64).
    let power = match prefix {
        "Y" => 24,
        "Z" => 21,
        "E" => 18,
        "P" => 15,
        "T" => 12,
        "G" => 9,
        "M" => 6,
        "k" => 3,
        "h" => 2,
        "da" => 1,
        "" => 0,
        "d" => -1,
        "c" => -2,
        "m" => -3,
        "u" => -6,
        "n" => -9,
        "p" => -12,
        _ => return None,
    };
    let nm = if hz {
        // λ = c / ν, in nm: c·10⁹⁻ᵖ / value.
        299_792_458.0 * 10f64.powi(9 - power) / value
    } else {
        value * 10f64.powi(power + 9)
    };
    (nm.is_finite() && nm > 0.0).then_some(nm)
}

/// The band a channel name denotes: (emissive?, wavelength in nm), for reflective `T.` and
/// emissive `S0.` channels only (see [`parse_channel`] for the others).
pub fn parse_channel_name(name: &str) -> Option<(bool, f64)> {
    match parse_channel(name)? {
        Channel::Reflective { nm } => Some((false, nm)),
        Channel::Stokes { k: 0, nm } => Some((true, nm)),
        _ => None,
    }
}

/// The spectral content of a list of channel names: what [`read`](crate::read) reads, and what
/// `info` reports without reading pixels.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChannelKinds {
    /// Wavelengths (nm, increasing) of `T.` channels.
    pub reflective: Vec<f64>,
    /// Wavelengths of S0, S1, S2, S3 channels.
    pub stokes: [Vec<f64>; 4],
    /// (λi, λo) pairs of re-radiation channels, sorted.
    pub reradiation: Vec<(f64, f64)>,
    /// Channels outside the layout, `A` excepted (e.g. an RGB preview stored beside spectra), in
    /// the order given (a file's, alphabetical).
    pub other: Vec<String>,
    /// Whether there is an `A` channel.
    pub alpha: bool,
}

impl ChannelKinds {
    /// Sorts channel names into the layout by [`parse_channel`]: wavelengths in nm, each list
    /// increasing, whatever the order or the units of the names.
    ///
    /// ```
    /// use specconv_exr::{channel_name, parse_channel_name, Kind, ChannelKinds};
    ///
    /// // OpenEXR lists channels by name, so 1000 nm comes before 380 nm.
    /// let names = ["A", "RGB.R", "T.1000,000000nm", "T.380,000000nm", "T.0,55um"];
    /// let kinds = ChannelKinds::of(names);
    /// assert_eq!(kinds.reflective, [380.0, 550.0, 1000.0]);
    /// assert!(kinds.alpha && kinds.is_spectral() && !kinds.polarised());
    /// assert_eq!(kinds.other, ["RGB.R"]);
    ///
    /// // The writer's names, and back.
    /// let name = channel_name(&Kind::Reflective, 380.0);
    /// assert_eq!(name, "T.380,000000nm");
    /// assert_eq!(parse_channel_name(&name), Some((false, 380.0)));
    /// ```
    pub fn of<'a>(names: impl IntoIterator<Item = &'a str>) -> ChannelKinds {
        let mut l = ChannelKinds::default();
        for name in names {
            match parse_channel(name) {
                Some(Channel::Reflective { nm }) => l.reflective.push(nm),
                Some(Channel::Stokes { k, nm }) => l.stokes[k as usize].push(nm),
                Some(Channel::Reradiation { from_nm, to_nm }) => {
                    l.reradiation.push((from_nm, to_nm))
                }
                None if name == "A" => l.alpha = true,
                None => l.other.push(name.to_string()),
            }
        }
        l.reflective.sort_by(f64::total_cmp);
        l.stokes.iter_mut().for_each(|s| s.sort_by(f64::total_cmp));
        l.reradiation
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        l
    }

    /// Whether the names hold a spectrum [`read`](crate::read) can read: any `T.` or `S0.`
    /// channel.
    pub fn is_spectral(&self) -> bool {
        !self.reflective.is_empty() || !self.stokes[0].is_empty()
    }

    /// Whether any Stokes component beyond S0 (polarisation) is present.
    pub fn polarised(&self) -> bool {
        self.stokes[1..].iter().any(|s| !s.is_empty())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_names_follow_the_layout() {
        assert_eq!(channel_name(&Kind::Reflective, 380.0), "T.380,000000nm");
        assert_eq!(
            channel_name(
                &Kind::Emissive {
                    units: "W.m^-2.sr^-1".into()
                },
                552.5
            ),
            "S0.552,500000nm"
        );
        assert_eq!(parse_channel_name("T.380,000000nm"), Some((false, 380.0)));
        assert_eq!(parse_channel_name("S0.552,5nm"), Some((true, 552.5)));
        assert_eq!(parse_channel_name("T.0,55um"), Some((false, 550.0)));
        assert_eq!(parse_channel_name("T.5.5e2nm"), Some((false, 550.0)));
        let (_, nm) = parse_channel_name("T.545,077196THz").unwrap();
        assert!((nm - 550.0).abs() < 1e-3, "{nm}");
        for bad in [
            "R", "A", "T.nm", "T.-5nm", "S1.500nm", "T.500", "T.500xm", "S4.500nm",
        ] {
            assert_eq!(parse_channel_name(bad), None, "{bad}");
        }
        assert_eq!(parse_channel("T.5daHz").map(|_| ()), Some(()));
        assert_eq!(
            parse_channel("S2.550,000000nm"),
            Some(Channel::Stokes { k: 2, nm: 550.0 })
        );
        assert_eq!(
            parse_channel("T.380,000000nm.450,5nm"),
            Some(Channel::Reradiation {
                from_nm: 380.0,
                to_nm: 450.5
            })
        );
        assert_eq!(
            parse_channel("T.0,38um.4,505e2nm"),
            Some(Channel::Reradiation {
                from_nm: 380.0,
                to_nm: 450.5
            })
        );
        let l = ChannelKinds::of(["R", "G", "B", "A", "S0.500nm", "S1.500nm", "T.400nm.500nm"]);
        assert_eq!(l.other, ["R", "G", "B"]);
        assert!(l.alpha && l.polarised());
        assert_eq!(l.reradiation, [(400.0, 500.0)]);
    }
}
