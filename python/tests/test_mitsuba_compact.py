"""Per-lookup spectra in Mitsuba 3: `specconv_compact` (a compact file) and `specconv_rgb` (any
image, made compact texels by the library at load), decoded in Dr.Jit at each lookup.

Anchored outside the decoder: the spectral file `convert` bakes from the same input (read with
OpenImageIO's Python bindings), Mitsuba's own lookup of that file (`specconv_spectral`, itself
held to `bitmap` in test_mitsuba.py), colour-science's colorimetry, and renders checked as
test_mitsuba.py checks them (within 5σ/√N of colour-science's colour of the file's spectra).
"""

from __future__ import annotations

import os

import numpy as np
import pytest

if os.environ.get("SPECCONV_REQUIRE_MITSUBA"):
    import drjit as dr
    import mitsuba as mi
else:
    mi = pytest.importorskip("mitsuba", reason="Mitsuba 3 is not installed (pip install mitsuba)")
    dr = pytest.importorskip("drjit", reason="Dr.Jit is not installed (pip install mitsuba)")

import mitsuba_fixtures as ref  # noqa: E402
import OpenImageIO as oiio  # noqa: E402
import test_compact as tc  # noqa: E402  (the cases and the chart of the numpy decoder's tests)
from test_mitsuba import (  # noqa: E402  (fixtures and helpers of the spectral texture's tests)
    SPP,
    _eval,
    _gap,
    _layout,
    _render,
    _texture,
    estimator,  # noqa: F401  (a fixture)
    files,  # noqa: F401  (a fixture)
    variant,  # noqa: F401  (a fixture)
)

import specconv  # noqa: E402

# Float32 decoding: its sums hold terms up to ~1 per unit of the texel's colour and u, so a
# value the file stores as 0 (or in the half subnormals) may come out within a few float32
# roundings of them: 2⁻²² absolute at most per unit (|c|₁ + |u|₁, at least 1). With the model
# `open` a bright chart texel (XYZ ≈ 10, u ≈ 666, 511, −180) decodes a band stored as 0 to
# 1.7e-6: 1.2e-9 of its terms.
FLOOR = 2.0**-22


def _terms(compact):
    """Per texel of level 0, |c|₁ + |u|₁ (at least 1; 1 where not finite): the scale of its sums."""
    names, pixels, attrs = tc.levels(compact)[0]
    mag = np.abs(tc.texels(names, pixels, attrs["specconvCompact"]).astype(np.float64)).sum(axis=-1)
    return np.maximum(np.nan_to_num(mag, nan=1.0, posinf=1.0), 1.0)


def _steps(got, want, floor=FLOOR):
    """|got − want| in half steps of `want` (the file's half), with an absolute floor."""
    spacing = np.maximum(tc.half_spacing(want), floor)
    return np.abs(got.astype(np.float16).astype(np.float64) - want) / spacing


@pytest.fixture(params=["palette", "per lookup"])
def decoding(request, variant, monkeypatch):
    """Both ways a JIT texture decodes: from a palette of its distinct texels' spectra (forced
    for texels that do not repeat enough: the texels tiled eight times, so that a palette
    costs less than they do, and the first copy's numbers kept) and per lookup (no palette).
    The scalar variants decode per lookup only."""
    import specconv.mitsuba as sm

    if request.param == "palette" and not dr.is_jit_v(mi.Float):
        pytest.skip("the scalar variants call numpy's decoder per lookup")
    if request.param == "per lookup":
        monkeypatch.setattr(sm, "_palette", lambda text, texels: None)
    else:

        def forced(text, texels):
            made = specconv._specconv.palette(text, np.concatenate([texels] * 8))
            assert made is not None
            return made[0][: texels.shape[0]], made[1]

        monkeypatch.setattr(sm, "_palette", forced)
    return request.param


def _decodes(tex, decoding):
    """The texture decodes the way `decoding` asked for."""
    assert (getattr(tex, "_palette", None) is not None) == (decoding == "palette"), decoding


@pytest.mark.parametrize("name,image,options", tc.CASES, ids=[c[0] for c in tc.CASES])
def test_every_texel_is_the_baked_spectrum_at_the_bands_and_between(
    variant, tmp_path, cli, name, image, options
):
    """Each texel's lookup (`nearest`: a texel centre in float32 is not exactly one texel's,
    and bilinear weighs its neighbours by a few 10⁻⁶): within one half step of the baked file
    at its bands, and of its linear interpolation at 1,000 random wavelengths (every texel in
    the JIT variant; 150 in the scalar one, a Python call per lookup); NaN where it has NaN."""
    if image is None:
        image = tmp_path / "chart.exr"
        tc.chart(image)
    compact, baked = tc.compact_and_reference(tmp_path, image, cli, **options)
    (names, pixels, _) = tc.levels(baked)[0]
    want, wl = tc.bands(names, pixels)
    h, w, n = want.shape
    centres = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h), -1)
    tex = _texture({"type": "specconv_compact", "filename": str(compact), "filter_type": "nearest"})
    got = _eval(tex, centres.reshape(-1, 2), wl).reshape(h, w, n)
    assert np.array_equal(np.isnan(got), np.isnan(want)), name
    ok = ~np.isnan(want)
    floor = FLOOR * np.broadcast_to(_terms(compact)[..., None], want.shape)
    # Against `expand`'s half bands of the same texels (the library's float32/double decoding
    # rounded once): within one half step but for the float32 decoder's own error, which
    # rounds to the neighbouring half now and then (2 steps measured with the RGBA image in
    # llvm_ad_spectral; not investigated further).
    assert _steps(got[ok], want[ok], floor[ok]).max() <= 2.0 + 1e-9, name

    rng = np.random.default_rng(35)
    at = np.sort(rng.uniform(wl[0], wl[-1], 1000))
    flat = want.reshape(-1, n)
    rows = ~np.isnan(flat).any(axis=1)
    if not dr.is_jit_v(mi.Float):
        rows &= np.isin(np.arange(len(rows)), rng.permutation(len(rows))[:150])
    mine = _eval(tex, centres.reshape(-1, 2)[rows], at)
    theirs = np.stack([np.interp(at, wl, r) for r in flat[rows]])
    j = np.clip(np.searchsorted(wl, at), 1, n - 1)
    larger = np.maximum(np.abs(flat[rows][:, j]), np.abs(flat[rows][:, j - 1]))
    # The float32 decoder's floor scales with its sums' terms, as at the bands: an outside
    # colour's u (its regularised projection's dual) runs to 10⁵ on the chart.
    terms = _terms(compact).reshape(-1)[rows][:, None]
    step = np.maximum(tc.half_spacing(larger), FLOOR * terms)
    assert np.max(np.abs(mine - theirs) / step) <= 2.0 + 1e-9, name


def test_lookup_is_the_spectral_files_lookup_at_any_uv(variant, decoding, tmp_path):
    """Between texels, in both filters and the three wrap modes, out of [0, 1], at bands,
    between them and outside them: the compact file's lookup is Mitsuba's lookup of the float
    spectral file of the same input (bilinear over texel spectra, v as `bitmap` reads it)."""
    image = str(tc.IMAGES / "photo.jpg")
    baked, compact = tmp_path / "float.exr", tmp_path / "compact.exr"
    specconv.convert(image, baked, sample="float")
    # Float texels: the colour the float file uplifted, to a few float32 ulps.
    specconv.convert(image, compact, layout="compact", sample="float")
    wl, _ = ref.read_reflectance(str(baked))
    rng = np.random.default_rng(8)
    uvs = np.concatenate([rng.random((150, 2)) * 3 - 1, [[0.0, 0.0], [1.0, 1.0], [0.5, 0.999]]])
    probes = np.concatenate([wl[::5], [381.0, 455.5, 611.0, 729.9, 360.0, 379.9, 730.1, 830.0]])
    for filter_type in ("bilinear", "nearest"):
        for wrap_mode in ("repeat", "clamp", "mirror"):
            common = {"filter_type": filter_type, "wrap_mode": wrap_mode}
            tex = _texture({"type": "specconv_compact", "filename": str(compact), **common})
            _decodes(tex, decoding)
            ours = _eval(tex, uvs, probes)
            theirs = _eval(
                _texture({"type": "specconv_spectral", "filename": str(baked), **common}),
                uvs,
                probes,
            )
            # Both weigh the same texels alike (the spectral texture's `nearest` is its bilinear
            # lookup at the texel centre, whose float32 uv weighs a neighbour by a few 10⁻⁶);
            # the float file holds the spectra to float32, the decoder sums in float32
            # (measured up to 6·10⁻⁷ from a double sum). The compact file's colour comes from
            # the sRGB curve straight to the working space (docs/compact.md), the spectral
            # file's through OpenColorIO's XYZ: a few float32 ulps apart, which move a texel
            # near the solid's surface by up to 2.2·10⁻⁵ (measured).
            np.testing.assert_allclose(
                ours, theirs, rtol=0, atol=5e-5, err_msg=f"{filter_type}, {wrap_mode}"
            )
            outside = (probes < wl[0]) | (probes > wl[-1])
            assert (ours[:, outside] == 0).all()


def test_level_reads_that_levels_texels(variant, tmp_path):
    """`level` reads a smaller level's texels (the filtered colour, u solved again):
    numpy's decoder of that level's texels, from the header text."""
    compact = tmp_path / "compact.exr"
    specconv.convert(str(tc.IMAGES / "photo.jpg"), compact, layout="compact")
    image = specconv.read_compact(compact, level=2)
    h, w, _ = image.texels.shape
    tex = _texture({"type": "specconv_compact", "filename": str(compact), "level": 2})
    assert tuple(tex.resolution()) == (w, h)
    header = specconv.compact.parse(image.text)
    centres = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h), -1)
    got = _eval(tex, centres.reshape(-1, 2), header.wavelengths).reshape(h, w, -1)
    want = specconv.decode(image.text, image.texels)
    np.testing.assert_allclose(got, want, rtol=0, atol=FLOOR + 2.0**-20)


def test_compact_and_rgb_textures_render_the_baked_image(variant, files, estimator, tmp_path):
    """Under illuminant A (where metamers part), with the same seed: the compact file's and the
    PNG's renders are colour-science's colour of the baked file's spectra within the noise,
    and each other's within the noise of a difference."""
    compact = str(tmp_path / "patches_compact.exr")
    specconv.convert([files["png"]], compact, layout="compact")
    wavelengths, values = files["wavelengths"], files["values"]
    rows, cols, inside, _, _ = _layout()
    light = "A"
    # The scalar variant runs Python per lookup: a quarter of the samples (the bounds follow).
    spp = SPP if dr.is_jit_v(mi.Float) else SPP // 4
    expected = ref.predicted_xyz(wavelengths, values[rows, cols], light)
    _, sigma = estimator.mean_and_sigma(wavelengths, values[rows, cols], light)
    gap = _gap(estimator, wavelengths, values[rows, cols], light)[inside]
    bound = (5 * sigma / np.sqrt(spp))[inside] + gap
    renders = {}
    for kind, path in (("specconv_compact", compact), ("specconv_rgb", files["png"])):
        renders[kind] = _render({"type": kind, "filename": path}, light, spp=spp)
        error = np.abs(renders[kind] - expected)[inside]
        assert (error <= bound).all(), (kind, (error / bound).max())
    baked = _render({"type": "specconv_spectral", "filename": files["exr"]}, light, spp=spp)
    noise = (5 * np.sqrt(2) * sigma / np.sqrt(spp))[inside]
    for kind, image in renders.items():
        assert (np.abs(image - baked)[inside] <= noise).all(), kind


def _acescg_exr(path, rgb):
    """A float OpenEXR whose chromaticities are ACEScg's (AP1, ACES white)."""
    h, w, _ = rgb.shape
    spec = oiio.ImageSpec(w, h, 3, "float")
    ap1 = (0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767)
    spec.attribute("chromaticities", oiio.TypeDesc("float[8]"), ap1)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(rgb.astype(np.float32))
    out.close()


def test_rgb_route_reads_an_acescg_exr_as_acescg(variant, tmp_path):
    """The file's chromaticities decide its colour (not Mitsuba's conversion to Rec.709): the
    spectra are the baked file's, and their colour under D65 is colour-science's XYZ of the
    texels as ACEScg."""
    import colour

    rng = np.random.default_rng(11)
    rgb = rng.random((6, 7, 3)) * 0.5 + 0.1  # inside the object colours: the colour is kept
    exr = tmp_path / "plate_acescg.exr"
    _acescg_exr(exr, rgb)
    baked = tmp_path / "plate_spectral.exr"
    specconv.convert(exr, baked)
    (names, pixels, _) = tc.levels(baked)[0]
    want, wl = tc.bands(names, pixels)
    centres = np.stack(np.meshgrid((np.arange(7) + 0.5) / 7, (np.arange(6) + 0.5) / 6), -1)
    texture = _texture({"type": "specconv_rgb", "filename": str(exr)})
    got = _eval(texture, centres.reshape(-1, 2), wl)
    assert _steps(got, want.reshape(-1, len(wl))).max() <= 1.0 + 1e-9
    # Colour under D65, the uplift's white: colour-science's ACEScg → XYZ of the texels.
    cs = colour.RGB_COLOURSPACES["ACEScg"]
    d65 = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    xyz = colour.RGB_to_XYZ(
        rgb.reshape(-1, 3), cs, d65, chromatic_adaptation_transform="Bradford"
    )
    ours = ref.predicted_xyz(wl, got, "D65")
    # Measured 2.9·10⁻⁵ (Bradford, as the ACES config adapts); read as Rec.709 instead (what
    # Mitsuba's own reader made of it before) the same texels are ≥ 0.01 away.
    assert np.abs(ours - xyz).max() < 2e-4, np.abs(ours - xyz).max()
    rec709 = colour.RGB_COLOURSPACES["ITU-R BT.709"]
    wrong = colour.RGB_to_XYZ(rgb.reshape(-1, 3), rec709, d65)
    assert np.abs(ours - wrong).max() > 0.01


def test_rgb_route_refuses_a_data_map(variant, tmp_path):
    """A roughness map (one channel, no colour declared) is data, which convert never uplifts:
    the texture is refused with the library's reason, as convert refuses it."""
    path = tmp_path / "roughness.exr"
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(8, 8, 1, "half"))
    assert out.write_image(np.full((8, 8, 1), 0.4, dtype=np.float32))
    out.close()
    with pytest.raises(Exception, match="data"):
        _texture({"type": "specconv_rgb", "filename": str(path)})


def test_a_file_that_is_not_compact_is_refused(variant, files):
    with pytest.raises(Exception, match="not a compact texture"):
        _texture({"type": "specconv_compact", "filename": files["exr"]})


def test_mitsubas_reader_and_the_librarys_read_the_same_texels(variant, tmp_path):
    """The plugin's texels are the library's reader's (which gives OpenImageIO's texels,
    test_compact.py) and the same text; a damaged text is refused by the library's parser,
    with its line and reason."""
    import specconv.mitsuba as sm

    compact = tmp_path / "compact.exr"
    specconv.convert(str(tc.IMAGES / "srgba8.png"), compact, layout="compact")
    text, texels = sm.compact_file(str(compact))
    image = specconv.read_compact(compact)
    assert text == image.text
    assert np.array_equal(texels, image.texels)

    damaged = tmp_path / "damaged.exr"
    buf = oiio.ImageBuf(str(compact))
    buf.specmod().attribute("specconvCompact", text.replace("\nclip 1", "\nclip 1\nclip 1"))
    assert buf.write(str(damaged))
    with pytest.raises(Exception, match="specconvCompact: .*a second .clip. line"):
        _texture({"type": "specconv_compact", "filename": str(damaged)})


def test_hostile_texels_decode_as_numpy_decodes_them(variant, decoding, tmp_path):
    """Texels no conversion writes (another writer's, or damaged): NaN and infinite u, huge and
    negative colours, X+Y+Z = 0 with u ≠ 0. Each lookup is numpy's decoding of that texel
    (NaN where it is NaN), never a crash."""
    compact = tmp_path / "compact.exr"
    specconv.convert(str(tc.IMAGES / "photo.jpg"), compact, layout="compact", mip=False)
    buf = oiio.ImageBuf(str(compact))
    pixels = buf.get_pixels(oiio.FLOAT)
    names = list(buf.spec().channelnames)
    cols = [names.index(c) for c in tc.STORED]
    nan, inf = float("nan"), float("inf")
    # Stored values (R G B, U, UF), as another writer might store them.
    hostile = [
        [0.2, 0.3, 0.1, nan, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.2, 0.3, 0.1, 0.0, 0.0, 0.0, inf, 0.0, 0.0],
        [0.2, 0.3, 0.1, -inf, 1.0, 0.0, 0.0, 0.0, 0.0],
        [1e30, 1e30, 1e30, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [-0.5, 0.2, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 5.0, -3.0, 1.0, 0.0, 0.0, 0.0],
        [3e38, -3e38, 3e38, 0.0, 0.0, 0.0, 1e30, 0.0, -1e30],
        [0.2, 0.3, 0.1, 0.5, 0.0, 0.0, 0.25, 0.0, 0.0],
    ]
    for i, t in enumerate(hostile):
        pixels[0, i, cols] = t
    damaged = tmp_path / "hostile.exr"
    out = oiio.ImageBuf(buf.spec())  # the header as convert wrote it, these pixels
    assert out.set_pixels(out.roi, pixels)
    assert out.write(str(damaged))
    image = specconv.read_compact(damaged)
    np.testing.assert_array_equal(
        image.texels[0, : len(hostile)], specconv.compact.unstore(image.text, np.float32(hostile))
    )
    h, w, _ = image.texels.shape
    wl = specconv.compact.parse(image.text).wavelengths
    uvs = (np.stack([np.arange(len(hostile)), np.zeros(len(hostile))], -1) + 0.5) / [w, h]
    tex = _texture({"type": "specconv_compact", "filename": str(damaged), "filter_type": "nearest"})
    _decodes(tex, decoding)
    got = _eval(tex, uvs, wl)
    want = specconv.decode(image.text, image.texels[0, : len(hostile)])
    assert np.array_equal(np.isnan(got), np.isnan(want))
    ok = ~np.isnan(want)
    np.testing.assert_allclose(got[ok], want[ok], rtol=1e-5, atol=1e-6)


def test_a_fifo_is_refused_by_kind_not_waited_on(variant, tmp_path):
    """A FIFO named as a texture (a planted name in a shared folder): refused before Mitsuba's
    reader or the library opens it, which would wait for a writer for ever."""
    fifo = tmp_path / "albedo_compact.exr"
    os.mkfifo(fifo)
    for kind in ("specconv_compact", "specconv_rgb"):
        with pytest.raises(Exception, match="FIFO|fifo|not a regular file|special"):
            _texture({"type": kind, "filename": str(fifo)})


@pytest.mark.parametrize("bounded", [True, False], ids=["clip", "unbounded"])
def test_lookups_decode_100000_random_texels_as_the_other_decoders(
    variant, decoding, tmp_path, bounded
):
    """Dr.Jit's decoder (float32, per lookup) on test_compact.py's 100,000 random texels (one
    in 50 in the scalar variant, which runs in Python): at each texel's centre (nearest) and
    each band, numpy's decoding within the float32 bound the library and the C header are held
    to there, NaN in the same texels. It found an infinite u decoding to NaN in some bands
    only, and colours above 10³⁸ decoding to the wrong side of the clip (float32 overflow)."""
    path, text, t = tc.random_compact_file(tmp_path, bounded)
    want = specconv.decode(text, t)
    bound = tc.float32_bound(text, t)
    h, w = len(t) // 400, 400
    rows = np.arange(len(t))[:: 1 if dr.is_jit_v(mi.Float) else 50]
    rows = np.union1d(rows, np.arange(len(t) - len(tc.HUGE), len(t)))
    uvs = np.stack([rows % w + 0.5, rows // w + 0.5], -1) / [w, h]
    tex = _texture({"type": "specconv_compact", "filename": str(path), "filter_type": "nearest"})
    _decodes(tex, decoding)
    got = _eval(tex, uvs, specconv.compact.parse(text).wavelengths)
    want, bound = want[rows], bound[rows]
    nan = np.isnan(want)
    assert np.array_equal(np.isnan(got), nan)
    err = np.abs(got[~nan] - want[~nan])
    worst = float(np.max(err / bound[~nan]))
    print(f"{variant}, {decoding}, bounded {bounded}: the largest error is {worst:.3g} of the bound")
    assert np.all(err <= bound[~nan]), worst


def test_drjit_meets_the_reference_texels(variant, decoding, tmp_path):
    """Item 47.4: Dr.Jit's decoder (the scalar variant: numpy's, which it calls) on the
    library's reference texels, both clip headers and both precisions, read from a compact
    file by Mitsuba's reader: each band within the float32 bound numpy and the C header are
    held to, NaN where the library's is NaN."""
    for name, text, stored, six, want in tc.reference_tables():
        path = tc.reference_file(tmp_path, name, text, stored)
        n = len(stored)
        uvs = np.stack([np.arange(n) + 0.5, np.full(n, 0.5)], -1) / [n, 1]
        tex = _texture({"type": "specconv_compact", "filename": str(path), "filter_type": "nearest"})
        _decodes(tex, decoding)
        got = _eval(tex, uvs, specconv.compact.parse(text).wavelengths)
        assert np.array_equal(np.isnan(got), np.isnan(want)), name
        ok = ~np.isnan(want)
        bound = np.broadcast_to(tc.reference_bound(six), want.shape)
        err = np.abs(got - want.astype(np.float64))
        print(f"{variant} {name}: the largest error is {float((err[ok] / bound[ok]).max()):.3g} of the bound")
        assert np.all(err[ok] <= bound[ok]), name


def test_a_palette_numbers_each_texel_to_its_spectrum(variant, tiled_compact, tmp_path):
    """The library's palette of the texels of a photograph tiled 4×4 (`specconv._specconv.
    palette`): texels with the same values share a number and others do not, numbered in the
    order of their first texel, the numbers whole and naming spectra within the float32 bound
    of numpy's decoding of each texel; a texture of these texels holds a palette, and one of
    100,000 random texels (too few repeats) none."""
    image = specconv.read_compact(tiled_compact)
    numbers, spectra = specconv._specconv.palette(image.text, image.texels)
    h, w, _ = image.texels.shape
    assert numbers.shape == (h, w, 1) and numbers.dtype == np.float32
    k = numbers.ravel().astype(np.int64)
    assert np.array_equal(k, numbers.ravel())
    texels = image.texels.reshape(-1, 6)
    distinct, first, back = np.unique(
        texels.view(np.dtype((np.void, 24))).ravel(), return_index=True, return_inverse=True
    )
    assert len(spectra) == len(distinct) <= len(texels) / 16
    # One number per distinct texel, in the order of their first texels.
    assert np.array_equal(k[first[back.ravel()]], k)
    assert np.array_equal(k[np.sort(first)], np.arange(len(distinct)))
    want = specconv.decode(image.text, texels)
    got = spectra[k].astype(np.float64)
    assert np.array_equal(np.isnan(got), np.isnan(want))
    assert np.all(np.abs(got - want) <= tc.float32_bound(image.text, texels))
    if dr.is_jit_v(mi.Float):
        assert _texture({"type": "specconv_compact", "filename": str(tiled_compact)})._palette is not None
        path, _, _ = tc.random_compact_file(tmp_path)
        assert _texture({"type": "specconv_compact", "filename": str(path)})._palette is None


def test_a_palette_refuses_what_is_not_texels(variant, tiled_compact):
    """A text that is not a compact header, texels without six values, and texels not in C
    order: each refused with what is wrong, never read past."""
    text = specconv.read_compact(tiled_compact).text
    t = np.zeros((4, 4, 6), np.float32)
    with pytest.raises(specconv.OptionError, match="compact"):
        specconv._specconv.palette("specconv compact 2\n", t)
    with pytest.raises(specconv.OptionError, match="six values"):
        specconv._specconv.palette(text, np.zeros((4, 4, 5), np.float32))
    with pytest.raises(Exception, match="contiguous"):
        specconv._specconv.palette(text, np.zeros((4, 8, 6), np.float32)[:, ::2])
    assert specconv._specconv.palette(text, np.zeros((0, 0, 6), np.float32))[1].shape[0] == 0


def test_the_mean_is_the_same_from_a_palette(variant, tiled_compact, monkeypatch):
    """`mean()` (Mitsuba's albedo estimate) of a texture holding a palette: the mean of its
    texels' decoded spectra, as without one."""
    import specconv.mitsuba as sm

    if not dr.is_jit_v(mi.Float):
        pytest.skip("the scalar variants hold no palette")
    props = {"type": "specconv_compact", "filename": str(tiled_compact)}
    with_palette = _texture(props)
    assert with_palette._palette is not None
    monkeypatch.setattr(sm, "_palette", lambda text, texels: None)
    without = _texture(props)
    assert without._palette is None
    assert abs(with_palette.mean() - without.mean()) <= 1e-6 * without.mean()


@pytest.fixture(scope="module")
def tiled_compact(tmp_path_factory):
    """testdata's photograph tiled 4×4 as an 8-bit PNG, made a compact file once: its texels
    repeat (1/16 of them distinct), as a large photograph's do."""
    folder = tmp_path_factory.mktemp("palette")
    photo = oiio.ImageBuf(str(tc.IMAGES / "photo.jpg")).get_pixels(oiio.UINT8)
    tiled = np.ascontiguousarray(np.tile(photo, (4, 4, 1)))
    png, path = folder / "tiled.png", folder / "tiled_compact.exr"
    out = oiio.ImageBuf(oiio.ImageSpec(tiled.shape[1], tiled.shape[0], tiled.shape[2], "uint8"))
    assert out.set_pixels(out.roi, tiled)
    assert out.write(str(png))
    specconv.convert(str(png), path, layout="compact")
    return path
