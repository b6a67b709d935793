//! The `specconv*` header attributes: what made an output, written by every conversion and read
//! back by `-u`, `to-rgb`, `info` and `preview`. The one place their names are spelled.

use specconv_colour::{EmissionUnits, Illuminant, Observer};

/// The attribute that records the emission convention, beside the layout's `emissiveUnits`.
pub const EMISSION_UNITS: &str = "specconvEmissionUnits";
/// The attribute `-u` compares: every setting that makes an output what it is.
pub const SETTINGS: &str = "specconvSettings";
/// The attribute that says whether an output may be used commercially: yes, no or unstated.
pub const COMMERCIAL: &str = "specconvCommercialUse";

/// What an output records of how it was made. Fields a file lacks are `None` when read.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct Provenance {
    /// The model, described ([`crate::models::describe`]), with whether it may be used
    /// commercially.
    pub model: Option<String>,
    /// What a user of the model's training data must credit ([`crate::models::attribution`]).
    pub model_attribution: Option<String>,
    /// Whether the model's outputs may be used commercially (`yes`, `no`, `unstated`): only
    /// when every set it was trained on allows it. For machines; [`Provenance::model`] says why.
    pub commercial: Option<String>,
    /// The method stack's name (`otsu2018+bounded`, …).
    pub method: Option<String>,
    /// The blend width in use.
    pub blend: Option<String>,
    /// The observer the spectra are exact under.
    pub observer: Option<Observer>,
    /// The illuminant reflectances are exact under.
    pub illuminant: Option<Illuminant>,
    /// Every setting of the conversion, as `-u` compares it.
    pub settings: Option<String>,
    /// Emission: what S0 values mean.
    pub emission_units: Option<EmissionUnits>,
    /// The specconv version that wrote the file.
    pub version: Option<String>,
    /// The colour space the input was read in.
    pub source_colorspace: Option<String>,
    /// The OCIO config used.
    pub config: Option<String>,
    /// The input's file name.
    pub source: Option<String>,
    /// The input's size and change times when it was read ([`source_stat`]): while they
    /// stay the same, `-u` need not read the input to compare its hash.
    pub source_stat: Option<String>,
    /// The hash of the input's pixels (written by the pipeline, read here for `-u`).
    pub source_hash: Option<String>,
}

/// The attribute of [`Provenance::source_stat`].
pub const SOURCE_STAT: &str = "specconvSourceStat";

/// `size=… mtime=… ctime=…` of a file (nanoseconds): a replaced or rewritten file changes its
/// ctime, which no tool can set back; a copied library (rsync, cp -a) changes it too, and is
/// then compared by hash.
pub fn source_stat(path: &std::path::Path) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(path).ok()?;
    Some(format!(
        "size={} mtime={}.{:09} ctime={}.{:09} ino={}",
        m.size(),
        m.mtime(),
        m.mtime_nsec(),
        m.ctime(),
        m.ctime_nsec(),
        m.ino()
    ))
}

/// Why a file's emission convention is the one [`Provenance::emission_convention`] gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConventionFrom {
    /// The file records it.
    Recorded,
    /// An older specconv file (it has `specconvSettings` but no units): normalised.
    OlderSpecconv,
    /// No specconv file: the layout's reference convention.
    Layout,
}

impl ConventionFrom {
    /// In words, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            ConventionFrom::Recorded => "recorded in the file",
            ConventionFrom::OlderSpecconv => "an older specconv file, which normalised emission",
            ConventionFrom::Layout => "the layout's reference convention",
        }
    }
}

/// A recorded value that does not parse.
#[derive(Debug, thiserror::Error)]
#[error("in its {attribute} attribute")]
pub struct BadAttribute {
    /// The attribute.
    pub attribute: &'static str,
    /// Why its value is not one.
    pub source: specconv_colour::Error,
}

impl Provenance {
    /// The attributes to write, in a fixed order; fields that are `None` are left out.
    pub fn to_attributes(&self) -> Vec<(String, String)> {
        let text = |v: &Option<String>| v.clone();
        [
            ("specconvModel", text(&self.model)),
            ("specconvModelAttribution", text(&self.model_attribution)),
            (COMMERCIAL, text(&self.commercial)),
            ("specconvMethod", text(&self.method)),
            ("specconvBlend", text(&self.blend)),
            ("specconvObserver", self.observer.map(|o| o.to_string())),
            ("specconvIlluminant", self.illuminant.map(|i| i.to_string())),
            (SETTINGS, text(&self.settings)),
            (EMISSION_UNITS, self.emission_units.map(|u| u.to_string())),
            ("specconvVersion", text(&self.version)),
            ("specconvSourceColorspace", text(&self.source_colorspace)),
            ("specconvConfig", text(&self.config)),
            ("specconvSource", text(&self.source)),
            (SOURCE_STAT, text(&self.source_stat)),
        ]
        .into_iter()
        .filter_map(|(k, v)| v.map(|v| (k.to_string(), v)))
        .collect()
    }

    /// Reads a header's attributes (other attributes are ignored).
    pub fn from_attributes(attributes: &[(String, String)]) -> Result<Provenance, BadAttribute> {
        let attr = |name: &str| {
            attributes
                .iter()
                .find(|(k, _)| k == name)
                .map(|(_, v)| v.clone())
        };
        fn parse<T: std::str::FromStr<Err = specconv_colour::Error>>(
            value: Option<String>,
            attribute: &'static str,
        ) -> Result<Option<T>, BadAttribute> {
            value
                .map(|v| {
                    v.parse()
                        .map_err(|source| BadAttribute { attribute, source })
                })
                .transpose()
        }
        let observer = parse(attr("specconvObserver"), "specconvObserver")?;
        let illuminant = parse(attr("specconvIlluminant"), "specconvIlluminant")?;
        let emission_units = parse(attr(EMISSION_UNITS), EMISSION_UNITS)?;
        Ok(Provenance {
            model: attr("specconvModel"),
            model_attribution: attr("specconvModelAttribution"),
            commercial: attr(COMMERCIAL),
            method: attr("specconvMethod"),
            blend: attr("specconvBlend"),
            observer,
            illuminant,
            settings: attr(SETTINGS),
            emission_units,
            version: attr("specconvVersion"),
            source_colorspace: attr("specconvSourceColorspace"),
            config: attr("specconvConfig"),
            source: attr("specconvSource"),
            source_stat: attr(SOURCE_STAT),
            source_hash: attr(crate::pipeline::survey::SOURCE_HASH),
        })
    }

    /// The observer the file's values become colour under: recorded, else CIE 1931.
    pub fn observer_or_default(&self) -> Observer {
        self.observer.unwrap_or(Observer::Cie1931)
    }

    /// The illuminant of its reflectances: recorded, else D65.
    pub fn illuminant_or_default(&self) -> Illuminant {
        self.illuminant.unwrap_or(Illuminant::D65)
    }

    /// An emissive file's convention and why it is the one: recorded; else normalised for an
    /// older specconv file (written before the convention was recorded); else the layout's
    /// reference.
    pub fn emission_convention(&self) -> (EmissionUnits, ConventionFrom) {
        match (self.emission_units, &self.settings) {
            (Some(u), _) => (u, ConventionFrom::Recorded),
            (None, Some(_)) => (EmissionUnits::Normalised, ConventionFrom::OlderSpecconv),
            (None, None) => (EmissionUnits::Reference, ConventionFrom::Layout),
        }
    }
}

/// What a specconv output records; `None` for any other file.
pub(crate) fn recorded(output: &std::path::Path) -> Option<Provenance> {
    let attributes = specconv_exr::read_attributes(output).ok()?;
    Provenance::from_attributes(&attributes)
        .ok()
        .filter(|p| p.settings.is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_written_reads_back_and_missing_values_fall_back() {
        let p = Provenance {
            method: Some("otsu2018+bounded".into()),
            observer: Some(Observer::Cie1964),
            illuminant: Some(Illuminant::A),
            settings: Some("model=x".into()),
            emission_units: Some(EmissionUnits::Photometric),
            ..Provenance::default()
        };
        let attrs = p.to_attributes();
        assert_eq!(attrs.len(), 5);
        assert_eq!(Provenance::from_attributes(&attrs).unwrap(), p);
        assert_eq!(
            p.emission_convention(),
            (EmissionUnits::Photometric, ConventionFrom::Recorded)
        );
        let none = Provenance::from_attributes(&[]).unwrap();
        assert_eq!(none.observer_or_default(), Observer::Cie1931);
        assert_eq!(none.illuminant_or_default(), Illuminant::D65);
        assert_eq!(
            none.emission_convention(),
            (EmissionUnits::Reference, ConventionFrom::Layout)
        );
        let older = Provenance::from_attributes(&[(SETTINGS.into(), "x".into())]).unwrap();
        assert_eq!(older.emission_convention().1, ConventionFrom::OlderSpecconv);
        let bad = Provenance::from_attributes(&[(EMISSION_UNITS.into(), "lumens".into())]);
        assert!(bad
            .unwrap_err()
            .to_string()
            .starts_with("in its specconvEmissionUnits attribute"));
    }
}
