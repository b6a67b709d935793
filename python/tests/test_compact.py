"""Compact textures (docs/compact.md) decoded by specconv.decode, numpy from the header text,
read through OpenImageIO's Python bindings: level 0 against the spectral file convert writes
for the same input and settings, at the bands and at random wavelengths; the smaller levels'
colours against that file's filtered spectra under D65, A and F11 (colour-science's CIEDE2000).
"""
import colour
import numpy as np
import OpenImageIO as oiio
import pytest

import specconv

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
IMAGES = ROOT / "testdata" / "images"


def chart(path):
    """Colours of every kind in linear Rec.709: saturated beyond sRGB, negative, HDR, black,
    NaN, tiny, and a ramp."""
    nan = float("nan")
    rows = [
        [[0.18] * 3, [1, 1, 1], [0, 0, 0], [0.9, 0.02, 0.01], [0.01, 0.9, 0.02], [0.02, 0.01, 0.9], [1.5, 0.1, -0.2], [-0.3, 0.6, 0.2]],
        [[12, 10, 8], [300, 20, 1], [1e-4, 2e-4, 1e-4], [-0.1, -0.2, -0.05], [nan, 0.2, 0.3], [0.2, nan, nan], [0.5, 0.5, 0.0], [0.0, 0.4, 0.9]],
    ]
    rows += [[[i / 7, (7 - i) / 7, (i * 3 % 8) / 7] for i in range(8)] for _ in range(6)]
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(8, 8, 3, "float"))
    out.write_image(np.array(rows, dtype=np.float32))
    out.close()


def levels(path):
    """Every level: (channel names, float pixels, the header's string attributes)."""
    inp = oiio.ImageInput.open(str(path))
    out, level = [], 0
    while inp.seek_subimage(0, level):
        s = inp.spec()
        attrs = {a.name: a.value for a in s.extra_attribs if isinstance(a.value, str)}
        out.append((list(s.channelnames), inp.read_image(0, level, 0, s.nchannels, "float"), attrs))
        level += 1
    inp.close()
    return out


def bands(names, pixels):
    """The T. channels by increasing wavelength, as (h, w, n), and the wavelengths."""
    t = [(float(n[2:-2].replace(",", ".")), i) for i, n in enumerate(names) if n.startswith("T.")]
    t.sort()
    return pixels[..., [i for _, i in t]], np.array([w for w, _ in t])


def texels(names, pixels):
    return pixels[..., [names.index(c) for c in ("C.X", "C.Y", "C.Z", "U.0", "U.1", "U.2")]]


def half_spacing(v):
    """The spacing of half floats at |v| (their subnormals' below 2^-14)."""
    return 2.0 ** (np.floor(np.log2(np.maximum(np.abs(v), 2.0**-14))) - 10)


CASES = [
    ("photo", IMAGES / "photo.jpg", {}),
    ("alpha", IMAGES / "srgba8.png", {}),
    ("chart", None, {"non_finite": "keep"}),
    ("grid-paper", None, {"non_finite": "keep", "bands": "400:700:5", "model": "paper", "blend": 0.0}),
    ("open", None, {"non_finite": "keep", "model": "open"}),
]


@pytest.mark.parametrize("name,image,options", CASES, ids=[c[0] for c in CASES])
def test_decoded_texels_are_the_baked_spectra(tmp_path, name, image, options):
    if image is None:
        image = tmp_path / "chart.exr"
        chart(image)
    baked, compact = tmp_path / "baked.exr", tmp_path / "compact.exr"
    specconv.convert(image, baked, **options)
    specconv.convert(image, compact, layout="compact", **options)
    (bn, bp, _), (cn, cp, attrs) = levels(baked)[0], levels(compact)[0]
    want, wl = bands(bn, bp)
    got = specconv.decode(attrs["specconvCompact"], texels(cn, cp))
    nan = np.isnan(want) & np.isnan(got)
    assert np.array_equal(np.isnan(want), np.isnan(got)), name
    # At the bands: the half the file stores, within one step of the decoded value's half.
    steps = np.abs(got.astype(np.float16).astype(np.float64) - want) / half_spacing(want)
    assert np.nanmax(np.where(nan, 0, steps)) <= 1.0 + 1e-9, name
    assert np.allclose(np.nanmean(np.where(nan, 0, steps)), 0, atol=0.01), name
    # At 1,000 random wavelengths: the baked file's linear interpolation, within the half
    # step of the larger neighbour.
    rng = np.random.default_rng(34)
    at = rng.uniform(wl[0], wl[-1], 1000)
    flat = want.reshape(-1, len(wl))
    ok = ~np.isnan(flat).any(axis=1)
    mine = specconv.decode(attrs["specconvCompact"], texels(cn, cp).reshape(-1, 6)[ok], at)
    theirs = np.stack([np.interp(at, wl, row) for row in flat[ok]])
    j = np.clip(np.searchsorted(wl, at), 1, len(wl) - 1)
    step = half_spacing(np.maximum(np.abs(flat[ok][:, j]), np.abs(flat[ok][:, j - 1])))
    assert np.max(np.abs(mine - theirs) / step) <= 1.0 + 1e-9, name


def test_encode_is_what_convert_stores_and_decode_reads_it_back(tmp_path):
    compact = tmp_path / "compact.exr"
    specconv.convert(IMAGES / "photo.jpg", compact, layout="compact")
    names, pixels, attrs = levels(compact)[0]
    t = texels(names, pixels)
    text, again = specconv.encode(np.ascontiguousarray(t[..., :3]))
    assert text == attrs["specconvCompact"]
    assert np.array_equal(again, t)
    assert attrs["specconvLayout"] == "compact 1"
    assert specconv.decode(text, again).shape == t.shape[:-1] + (36,)


def test_smaller_levels_keep_the_colour_under_d65_and_nearly_under_a_and_f11(tmp_path):
    """A compact level holds the filtered colour, its u solved again; the spectral file's level
    the filtered spectra. Same colour under D65 (the filtered colours are the colours of the
    filtered spectra); under A and F11 the two spectra differ a little: measured here."""
    baked, compact = tmp_path / "baked.exr", tmp_path / "compact.exr"
    specconv.convert(IMAGES / "photo.jpg", baked, sample="float")
    specconv.convert(IMAGES / "photo.jpg", compact, layout="compact")
    found = {}
    for (bn, bp, _), (cn, cp, attrs) in list(zip(levels(baked), levels(compact)))[1:]:
        want, wl = bands(bn, bp)
        got = specconv.decode(attrs["specconvCompact"], texels(cn, cp))
        for light in ("D65", "A", "FL11"):
            xyz = [specconv.spectra_to_xyz(s.reshape(-1, len(wl)), wl, illuminant=light) for s in (want, got)]
            white = specconv.spectra_to_xyz(np.ones((1, len(wl))), wl, illuminant=light)[0]
            lab = [colour.XYZ_to_Lab(x / white[1], colour.XYZ_to_xy(white)) for x in xyz]
            found.setdefault(light, []).extend(colour.delta_E(*lab, method="CIE 2000"))
    stats = {k: (float(np.mean(v)), float(np.percentile(v, 99)), float(np.max(v))) for k, v in found.items()}
    print("ΔE00 of the smaller levels (mean, 99th percentile, max):", stats)
    assert stats["D65"][2] < 1e-3, stats
    # Measured: A 0.10, 1.26, 7.4; F11 0.15, 1.97, 4.1 (a texel between two metameric
    # neighbours: the average of their spectra is no uplift of the average colour).
    for light in ("A", "FL11"):
        assert stats[light][0] < 0.3 and stats[light][1] < 3, stats


def test_read_compact_is_what_openimageio_reads(tmp_path):
    """`specconv.read_compact`, every level, against OpenImageIO's own reader of the file: the
    texels' six channels and alpha bit for bit, the text as the attribute holds it; a file
    that is not compact, and a level it does not have, refused with what is wrong."""
    compact = tmp_path / "compact.exr"
    specconv.convert(IMAGES / "srgba8.png", compact, layout="compact")
    every = levels(compact)
    for level, (names, pixels, attrs) in enumerate(every):
        image = specconv.read_compact(compact, level=level)
        assert image.levels == len(every) and image.level == level
        assert np.array_equal(image.texels, texels(names, pixels))
        assert np.array_equal(image.alpha, pixels[..., names.index("A")])
        assert image.text == attrs["specconvCompact"]
    baked = tmp_path / "baked.exr"
    specconv.convert(IMAGES / "srgba8.png", baked)
    with pytest.raises(specconv.InputError, match="not a compact texture: no specconvLayout"):
        specconv.read_compact(baked)
    with pytest.raises(specconv.Error, match=f"MIP level {len(every)} does not exist"):
        specconv.read_compact(compact, level=len(every))
    # The same rules for a header another reader read (Mitsuba's, specconv.mitsuba).
    check = specconv._specconv.check_compact_header
    names = every[0][0]
    text = every[0][2]["specconvCompact"]
    attrs = every[0][2]  # every text attribute, as OpenImageIO reads the header
    assert check(compact, attrs, names) == (
        image.text,
        [names.index(c) for c in ("C.X", "C.Y", "C.Z", "U.0", "U.1", "U.2")],
    )
    without = lambda name: {k: v for k, v in attrs.items() if k != name}  # noqa: E731
    for attributes, channels, why in [
        ({**attrs, "specconvCompact": text.replace("map 0", "map 9")}, names, "specconvCompact: "),
        ({**attrs, "specconvLayout": "compact 2"}, names, "its specconvLayout is 'compact 2'"),
        (without("specconvLayout"), names, "no specconvLayout attribute"),
        (without("specconvCompact"), names, "no specconvCompact attribute"),
        (attrs, [n for n in names if n != "U.1"], "no channel U.1"),
    ]:
        with pytest.raises(specconv.InputError, match=f"not a compact texture: {why}"):
            check(compact, attributes, channels)
