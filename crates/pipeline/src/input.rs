//! What is read of an input: which subimage (OpenEXR part) and which of its channels carry the
//! colour and the alpha. Chosen once, by `--subimage` and `--channels` or by the rules below,
//! and reported, so that a layered file is never read as "the first three channels" unsaid.
//!
//! Without `--channels`: channels named `R`, `G`, `B` (and `A`); else, when no name has a
//! layer prefix, the first three channels that are not alpha (one grey channel is repeated), as
//! every image format names them; else, when exactly one layer holds `.R`, `.G` and `.B`, that
//! layer (and its `.A`). Any other layered file is refused with the list of its layers.

pub use crate::error::Choose;
pub use crate::report::{ChannelReason, Channels, Selection};
use specconv_oiio::{ImageInfo, ImageReader};
use std::path::Path;

/// `--subimage` and `--channels` as given.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Request {
    /// `N` or a part name.
    pub subimage: Option<String>,
    /// `R,G,B[,A]` (one to four channel names), or a layer name such as `diffuse`.
    pub channels: Option<String>,
}

impl Request {
    /// What `options` ask to read.
    pub fn of(options: &crate::Options) -> Request {
        Request {
            subimage: options.subimage.clone(),
            channels: options.channels.clone(),
        }
    }
}

/// `channels` of the subimage `info` describes.
pub fn selection(info: &ImageInfo, channels: Channels) -> Selection {
    Selection {
        subimage: info.subimage,
        subimages: info.subimages,
        subimage_name: info
            .subimage_names
            .get(info.subimage as usize)
            .cloned()
            .unwrap_or_default(),
        channels,
    }
}

/// Opens `path` on the subimage asked for and chooses its channels. A spectral image (the
/// Fichet 2021 layout: `T.` or `S0.` channels) or a compact one is refused unless channels are
/// asked for: it is already spectra, and uplifting its colour would throw them away.
pub fn open(path: &Path, request: &Request) -> crate::error::Result<(ImageReader, Selection)> {
    let reader = open_subimage(path, request.subimage.as_deref())?;
    let info = reader.info();
    if request.channels.is_none() {
        refuse_spectral(info)?;
        let layout = reader.string_attribute(crate::storage::LAYOUT_ATTRIBUTE)?;
        let names: Vec<&str> = info.channels.iter().map(|c| c.name.as_str()).collect();
        if crate::expand::is_compact(layout.as_deref(), &names) {
            return Err(crate::error::Error::Compact {
                path: info.path.clone(),
            });
        }
    }
    let channels = choose_channels(info, request.channels.as_deref())?;
    let selection = selection(info, channels);
    Ok((reader, selection))
}

/// [`crate::error::Error::Spectral`] for an image in the spectral layout.
fn refuse_spectral(info: &ImageInfo) -> crate::error::Result<()> {
    let layout = specconv_exr::ChannelKinds::of(info.channels.iter().map(|c| c.name.as_str()));
    if !layout.is_spectral() {
        return Ok(());
    }
    let (emissive, bands) = if layout.reflective.is_empty() {
        (true, &layout.stokes[0])
    } else {
        (false, &layout.reflective)
    };
    Err(crate::error::Error::Spectral {
        path: info.path.clone(),
        emissive,
        bands: bands.len(),
        range_nm: (bands[0], bands[bands.len() - 1]),
    })
}

/// Opens `path` on subimage `which` (`N` or a name; the first when `None`).
pub fn open_subimage(path: &Path, which: Option<&str>) -> crate::error::Result<ImageReader> {
    let mut reader = ImageReader::open(path)?;
    if let Some(which) = which {
        let index = reader.info().find_subimage(which)?;
        reader.select_subimage(index)?;
    }
    Ok(reader)
}

/// The first three channels that are not alpha (fewer when the image has fewer).
pub fn colour_channels(channels: usize, alpha: Option<usize>) -> Vec<usize> {
    (0..channels)
        .filter(|&c| Some(c) != alpha)
        .take(3)
        .collect()
}

/// The colour and alpha channels of `info` (see the module's rules), or `request`'s.
pub fn choose_channels(info: &ImageInfo, request: Option<&str>) -> crate::error::Result<Channels> {
    let names = Names {
        info,
        names: info.channels.iter().map(|c| c.name.as_str()).collect(),
    };
    match request {
        Some(request) => names.requested(request.trim()),
        None => names.by_rule(),
    }
}

/// The channel names of an image, and what is said about them.
struct Names<'a> {
    info: &'a ImageInfo,
    names: Vec<&'a str>,
}

impl Names<'_> {
    fn find(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| *n == name)
    }

    /// The channels `colour` and `alpha`, with their names and why they were chosen.
    fn channels(
        &self,
        colour: Vec<usize>,
        alpha: Option<usize>,
        reason: ChannelReason,
    ) -> Channels {
        let mut listed: Vec<String> = colour.iter().map(|&c| self.names[c].to_owned()).collect();
        listed.extend(alpha.map(|a| self.names[a].to_owned()));
        Channels {
            colour,
            alpha,
            names: listed,
            reason,
        }
    }

    /// [`crate::error::Error::Channels`]: `what` is wrong, and what naming would settle it.
    fn refuse_as(&self, what: String, choose: Option<Choose>) -> crate::error::Error {
        crate::error::Error::Channels {
            path: self.info.path.clone(),
            what,
            channels: format!("{}{}", self.names.join(", "), describe_layers(&self.names)),
            choose,
        }
    }

    fn refuse(&self, what: String) -> crate::error::Error {
        self.refuse_as(what, None)
    }

    /// A layer's R, G, B (or Y) and A, if it has them.
    fn layer(&self, prefix: &str) -> Option<(Vec<usize>, Option<usize>)> {
        let of = |c: &str| self.find(&format!("{prefix}{c}"));
        let alpha = of("A");
        match (of("R"), of("G"), of("B"), of("Y")) {
            (Some(r), Some(g), Some(b), _) => Some((vec![r, g, b], alpha)),
            (_, _, _, Some(y)) => Some((vec![y], alpha)),
            _ => None,
        }
    }

    /// The channels `request` names: a list, a layer, or one grey channel.
    fn requested(&self, request: &str) -> crate::error::Result<Channels> {
        if request.contains(',') {
            return self.listed(request);
        }
        if let Some((colour, alpha)) = self.layer(&format!("{request}.")) {
            return Ok(self.channels(colour, alpha, ChannelReason::Option));
        }
        match self.find(request) {
            Some(grey) => Ok(self.channels(vec![grey], None, ChannelReason::Option)),
            None => Err(self.refuse(format!(
                "it has no layer or channel '{request}' (a layer needs {request}.R, .G and .B, or {request}.Y)"
            ))),
        }
    }

    /// The channels of a list of names: one grey, grey and alpha, RGB, or RGBA.
    fn listed(&self, request: &str) -> crate::error::Result<Channels> {
        let mut picked = Vec::new();
        for name in request.split(',').map(str::trim) {
            picked.push(
                self.find(name)
                    .ok_or_else(|| self.refuse(format!("it has no channel '{name}'")))?,
            );
        }
        let (colour, alpha) = match picked.len() {
            2 => (vec![picked[0]], Some(picked[1])),
            3 => (picked, None),
            4 => (picked[..3].to_vec(), Some(picked[3])),
            n => {
                let hint = "give R,G,B or R,G,B,A (or Y or Y,A for grey)";
                return Err(self.refuse(format!("{n} channels were asked for; {hint}")));
            }
        };
        Ok(self.channels(colour, alpha, ChannelReason::Option))
    }

    /// The channels the module's rules choose: R, G, B; the first channels of an image
    /// without layers; the only layer with R, G and B.
    fn by_rule(&self) -> crate::error::Result<Channels> {
        if let (Some(r), Some(g), Some(b)) = (self.find("R"), self.find("G"), self.find("B")) {
            return Ok(self.channels(vec![r, g, b], self.find("A"), ChannelReason::Named));
        }
        if !self.names.iter().any(|n| n.contains('.')) {
            return self.in_order();
        }
        let rgb_layers: Vec<&str> = layers(&self.names)
            .into_iter()
            .filter(|l| {
                ["R", "G", "B"]
                    .iter()
                    .all(|c| self.find(&format!("{l}.{c}")).is_some())
            })
            .collect();
        match rgb_layers.as_slice() {
            [only] => {
                let (colour, alpha) = self
                    .layer(&format!("{only}."))
                    .expect("the layer has R, G, B");
                Ok(self.channels(colour, alpha, ChannelReason::OnlyLayer))
            }
            [] => Err(self.refuse_as(
                "its channels are in layers and none holds R, G and B".into(),
                Some(Choose::ChannelsOrLayer),
            )),
            several => Err(self.refuse_as(
                format!("several layers hold R, G and B ({})", several.join(", ")),
                Some(Choose::OneLayer),
            )),
        }
    }

    /// The first three channels that are not alpha, or the first as grey.
    fn in_order(&self) -> crate::error::Result<Channels> {
        let alpha = self.info.alpha_channel;
        let colour = colour_channels(self.names.len(), alpha);
        if colour.is_empty() {
            return Err(self.refuse("it has no colour channel".into()));
        }
        // Two channels that are not alpha are not a colour: read the first as grey.
        let colour = if colour.len() == 3 {
            colour
        } else {
            colour[..1].to_vec()
        };
        Ok(self.channels(colour, alpha, ChannelReason::InOrder))
    }
}

/// The distinct layer prefixes of the channel names, in order of first appearance.
fn layers<'a>(names: &[&'a str]) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for n in names {
        if let Some((prefix, _)) = n.rsplit_once('.') {
            if !out.contains(&prefix) {
                out.push(prefix);
            }
        }
    }
    out
}

fn describe_layers(names: &[&str]) -> String {
    let l = layers(names);
    if l.is_empty() {
        String::new()
    } else {
        format!(" (layers {})", l.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_oiio::{Channel, PixelFormat};

    fn info(names: &[&str], alpha: Option<usize>) -> ImageInfo {
        ImageInfo {
            path: "x.exr".into(),
            format_name: "openexr".into(),
            channels: names
                .iter()
                .map(|n| Channel {
                    name: (*n).into(),
                    format: PixelFormat::Half,
                })
                .collect(),
            alpha_channel: alpha,
            levels: Vec::new(),
            subimages: 1,
            subimage: 0,
            subimage_names: vec![String::new()],
            declared_color_space: None,
            unassociated_alpha: false,
        }
    }

    fn chosen(
        names: &[&str],
        alpha: Option<usize>,
        request: Option<&str>,
    ) -> Result<String, String> {
        choose_channels(&info(names, alpha), request)
            .map(|c| format!("{:?} {:?} {:?}", c.colour, c.alpha, c.reason))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn named_rgb_wins_in_any_order_and_layers_are_never_the_first_three() {
        assert_eq!(
            chosen(&["A", "B", "G", "R"], Some(0), None).unwrap(),
            "[3, 2, 1] Some(0) Named"
        );
        assert_eq!(
            chosen(&["diffuse.R", "R", "G", "B", "A"], None, None).unwrap(),
            "[1, 2, 3] Some(4) Named"
        );
        assert_eq!(chosen(&["Y"], None, None).unwrap(), "[0] None InOrder");
        assert_eq!(
            chosen(&["Y", "A"], Some(1), None).unwrap(),
            "[0] Some(1) InOrder"
        );
        assert_eq!(
            chosen(
                &["diffuse.R", "diffuse.G", "diffuse.B", "rough.Y"],
                None,
                None
            )
            .unwrap(),
            "[0, 1, 2] None OnlyLayer"
        );
        assert_eq!(
            chosen(
                &[
                    "rough.Y",
                    "diffuse.B",
                    "diffuse.G",
                    "diffuse.R",
                    "diffuse.A"
                ],
                None,
                None
            )
            .unwrap(),
            "[3, 2, 1] Some(4) OnlyLayer"
        );
        let two = chosen(
            &[
                "diffuse.R",
                "diffuse.G",
                "diffuse.B",
                "spec.R",
                "spec.G",
                "spec.B",
            ],
            None,
            None,
        )
        .unwrap_err();
        assert!(
            two.contains("several layers hold R, G and B (diffuse, spec)"),
            "{two}"
        );
        let none =
            chosen(&["rough.Y", "normal.X", "normal.Y", "normal.Z"], None, None).unwrap_err();
        // The library names no option: the front-end adds its own (Choose says what).
        assert!(
            none.contains("none holds R, G and B") && !none.contains("--"),
            "{none}"
        );
    }

    #[test]
    fn the_option_takes_a_layer_a_channel_or_a_list() {
        let names = [
            "diffuse.R",
            "diffuse.G",
            "diffuse.B",
            "rough.Y",
            "spec.R",
            "spec.G",
            "spec.B",
        ];
        assert_eq!(
            chosen(&names, None, Some("spec")).unwrap(),
            "[4, 5, 6] None Option"
        );
        assert_eq!(
            chosen(&names, None, Some("rough")).unwrap(),
            "[3] None Option"
        );
        assert_eq!(
            chosen(&names, None, Some("rough.Y")).unwrap(),
            "[3] None Option"
        );
        assert_eq!(
            chosen(&names, None, Some("spec.B,diffuse.G,rough.Y,spec.R")).unwrap(),
            "[6, 1, 3] Some(4) Option"
        );
        let bad = chosen(&names, None, Some("diffuse.R,diffuse.X,diffuse.B")).unwrap_err();
        assert!(
            bad.contains("no channel 'diffuse.X'") && bad.contains("layers diffuse, rough, spec"),
            "{bad}"
        );
        let bad = chosen(&names, None, Some("normal")).unwrap_err();
        assert!(bad.contains("no layer or channel 'normal'"), "{bad}");
    }
}
