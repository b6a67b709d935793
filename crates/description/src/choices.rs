//! The choices of a conversion's options, each with its names ([`Named`]): plain enums at the
//! bottom of the crate, so that the options, the job and the front-ends all take them from one
//! place. What each does lives with the code that does it (`Alpha::premultiply` in
//! `pipeline::colour`, a filter's weights in `pipeline::filter`, …).

use crate::named::{named, Named, UnknownName};

/// How straight and premultiplied alpha are told apart (`--alpha`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Alpha {
    /// As the file says: straight where OpenImageIO reports unassociated alpha (PNG, TIFF
    /// with unassociated extra samples), premultiplied otherwise (OpenEXR and the rest).
    #[default]
    Auto,
    /// The colour is straight: converted, then multiplied by alpha.
    Straight,
    /// The colour is premultiplied already: converted as it is.
    Premultiplied,
}

/// What happens to NaN and infinite values in the channels read (colour and alpha).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NonFinite {
    /// The input is refused (maketx `--checknan`).
    Refuse,
    /// Each such value becomes 0.
    Black,
    /// Each such value becomes the average of the finite values of that channel among its
    /// 3×3 neighbours (0 when none is finite), as OpenImageIO's `fixNonFinite` box3.
    Box3,
    /// Written as they are (their spectra are NaN, and so is every MIP level filtered from
    /// them).
    Keep,
}

impl NonFinite {
    /// The repair as OpenImageIO's `make_texture` names it (`maketx --fixnan`), for a data
    /// copy: the same `fixNonFinite` a conversion's repair follows; `None` where nothing is
    /// repaired (refused values never reach the copy: it is surveyed first).
    pub fn maketx_fixnan(self) -> Option<&'static str> {
        match self {
            NonFinite::Black => Some("black"),
            NonFinite::Box3 => Some("box3"),
            NonFinite::Refuse | NonFinite::Keep => None,
        }
    }
}

/// How the spectra are stored (`--layout`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// A band a channel, the layout of Fichet et al. 2021 (docs/spectral-exr.md).
    Spectral,
    /// Six float32 values a texel, the colour and the projection's dual unknowns, with the
    /// model in the header: the same spectra at the size of RGB (docs/compact.md);
    /// `specconv expand` writes the spectral layout from it.
    Compact,
}

/// Whether a tiled output is a MIP map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mip {
    /// Every level down to 1×1, each filtered from the spectra of the level above (module `mip`);
    /// level 0 is uplifted from the input's full-resolution level (its own smaller levels,
    /// if any, are not read).
    All,
    /// The full-resolution level only.
    Base,
}

/// A filter by its maketx name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[allow(missing_docs)]
pub enum Filter {
    /// maketx's default: not OpenImageIO's box `resize` but its bilinear `resize_block` (the
    /// 2×2 average where a size halves).
    #[default]
    Box,
    Triangle,
    Gaussian,
    SharpGaussian,
    CatmullRom,
    BlackmanHarris,
    Sinc,
    Lanczos3,
    RadialLanczos3,
    /// Nuke's name for lanczos3 (it counts the full width).
    NukeLanczos6,
    Mitchell,
    Bspline,
    Disk,
    Cubic,
    Keys,
    Simon,
    Rifman,
}

/// What a conversion does with a texture that holds data, not colour
/// (`specconv_pipeline::DataTexture`): it is never uplifted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DataPolicy {
    /// Write nothing; the report says it is data ([`crate::DataOutcome::Skipped`]). Not a
    /// failure.
    #[default]
    Skip,
    /// Write it through as a tiled, MIP-mapped data texture, its values unconverted.
    Copy,
    /// Fail, saying it is data.
    Fail,
}

/// How half samples are rounded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rounding {
    /// Each band on its own.
    Nearest,
    /// Band by band, the half below or above that moves the spectrum's XYZ least.
    Colour,
}

/// The output compressions of OpenEXR.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Compression {
    None,
    Rle,
    Zips,
    Zip,
    Piz,
    Pxr24,
    B44,
    B44a,
    Dwaa,
    Dwab,
}

impl Compression {
    /// Whether it deflates (and so takes a level).
    pub fn deflates(self) -> bool {
        matches!(self, Compression::Zip | Compression::Zips)
    }

    /// The `exr` crate's name for it.
    pub fn exr(self) -> specconv_exr::Compression {
        use specconv_exr::Compression as C;
        match self {
            Compression::None => C::Uncompressed,
            Compression::Rle => C::RLE,
            Compression::Zips => C::ZIP1,
            Compression::Zip => C::ZIP16,
            Compression::Piz => C::PIZ,
            Compression::Pxr24 => C::PXR24,
            Compression::B44 => C::B44,
            Compression::B44a => C::B44A,
            Compression::Dwaa => C::DWAA(None),
            Compression::Dwab => C::DWAB(None),
        }
    }
}

/// Display and `FromStr` by [`Named`], for the choices this crate owns.
macro_rules! text_by_name {
    ($($ty:ty),+) => {$(
        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(Named::name(*self))
            }
        }

        impl std::str::FromStr for $ty {
            type Err = UnknownName;

            fn from_str(s: &str) -> Result<$ty, UnknownName> {
                <$ty as Named>::from_name(s)
            }
        }
    )+};
}

named!(Rounding, "half rounding", [
    Rounding::Nearest => "nearest",
    Rounding::Colour => "colour" | "color",
]);
named!(Compression, "compression", [
    Compression::None => "none",
    Compression::Rle => "rle",
    Compression::Zips => "zips",
    Compression::Zip => "zip",
    Compression::Piz => "piz",
    Compression::Pxr24 => "pxr24",
    Compression::B44 => "b44",
    Compression::B44a => "b44a",
    Compression::Dwaa => "dwaa",
    Compression::Dwab => "dwab",
]);
named!(DataPolicy, "data policy", [
    DataPolicy::Skip => "skip",
    DataPolicy::Copy => "copy",
    DataPolicy::Fail => "fail",
]);

text_by_name!(
    Layout,
    Compression,
    Rounding,
    DataPolicy,
    Alpha,
    Mip,
    NonFinite,
    Filter
);

named!(Layout, "layout", [
    Layout::Spectral => "spectral" | "fichet",
    Layout::Compact => "compact",
]);
named!(Alpha, "alpha", [
    Alpha::Auto => "auto",
    Alpha::Straight => "straight" | "unassociated",
    Alpha::Premultiplied => "premultiplied" | "associated",
]);
// `true` and `false` are Python's mip=True/False: a bool is given as its text.
named!(Mip, "MIP levels", [Mip::All => "all" | "true", Mip::Base => "0" | "false"]);
named!(NonFinite, "NaN handling", [
    NonFinite::Refuse => "refuse" | "check",
    NonFinite::Black => "black",
    NonFinite::Box3 => "box3",
    // maketx's `--fixnan none`.
    NonFinite::Keep => "keep" | "none",
]);
named!(Filter, "filter", [
    Filter::Box => "box",
    Filter::Triangle => "triangle",
    Filter::Gaussian => "gaussian",
    Filter::SharpGaussian => "sharp-gaussian",
    Filter::CatmullRom => "catmull-rom",
    Filter::BlackmanHarris => "blackman-harris",
    Filter::Sinc => "sinc",
    Filter::Lanczos3 => "lanczos3",
    Filter::RadialLanczos3 => "radial-lanczos3",
    Filter::NukeLanczos6 => "nuke-lanczos6",
    Filter::Mitchell => "mitchell",
    Filter::Bspline => "bspline",
    Filter::Disk => "disk",
    Filter::Cubic => "cubic",
    Filter::Keys => "keys",
    Filter::Simon => "simon",
    Filter::Rifman => "rifman",
]);

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::EmissionUnits;
    use specconv_exr::Sample;
    use specconv_spectral::method::MethodName;

    /// Every name reads back as its value, aliases too, and no two values share a spelling;
    /// the lower crates' own names (for their messages) are the same.
    fn round_trip<T: Named + std::fmt::Debug>() {
        let mut seen = std::collections::BTreeSet::new();
        for &v in T::ALL {
            assert_eq!(T::from_name(v.name()), Ok(v));
            assert_eq!(T::from_name(&v.name().to_uppercase()), Ok(v));
            for a in v.aliases() {
                assert_eq!(T::from_name(a), Ok(v), "{a}");
            }
            for s in std::iter::once(v.name()).chain(v.aliases().iter().copied()) {
                assert!(seen.insert(s.to_ascii_lowercase()), "{s} twice");
            }
        }
        let e = T::from_name("bogus").unwrap_err();
        assert_eq!(e.choices, T::names());
        assert!(e.to_string().contains(T::WHAT), "{e}");
    }

    #[test]
    fn every_choice_reads_its_names_back() {
        round_trip::<Alpha>();
        round_trip::<Sample>();
        round_trip::<Rounding>();
        round_trip::<Compression>();
        round_trip::<Mip>();
        round_trip::<NonFinite>();
        round_trip::<DataPolicy>();
        round_trip::<EmissionUnits>();
        round_trip::<MethodName>();
        round_trip::<Filter>();
    }

    #[test]
    fn the_lower_crates_spell_their_values_alike() {
        for &m in MethodName::ALL.iter() {
            assert_eq!(m.name(), m.as_str());
            assert_eq!(m.as_str().parse::<MethodName>().unwrap(), m);
        }
        assert_eq!(<MethodName as Named>::ALL.len(), MethodName::ALL.len());
        for &u in EmissionUnits::ALL.iter() {
            assert_eq!(Named::name(u), EmissionUnits::name(u));
        }
    }
}
