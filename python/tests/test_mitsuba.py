"""Mitsuba 3 renders with specconv's textures, checked against references outside both.

The scene: a diffuse plate filling an orthographic camera, lit by a uniform environment whose
spectrum is a CIE illuminant (colour-science's tables), rendered to XYZ with BSDF sampling
alone. Such a plate returns reflectance × radiance exactly, so each pixel's only noise is the
sensor's wavelength sampling; `mitsuba_fixtures.Estimator` computes its per-sample standard
deviation σ from Mitsuba's own sampling functions, and every tolerance below is
    5 σ / √N  (+ δ, the measured gap between Mitsuba's continuous integral and colour-science's
               1 nm sum, itself asserted below 1e-3)
for N samples: each pixel (N = spp) and each colour patch (N = 36 pixels × spp). With 1 728
values per render (576 pixels × XYZ) a 5σ bound is crossed by chance with probability ≈ 10⁻³;
the seeds are fixed, so a run passes or fails the same way every time.

The source is a 16×16 sRGB PNG of 4×4 patches, 4 px each: bilinear filtering leaves each patch
one colour between its outer texel centres (3 texels wide), which a 32×32 render covers with
6×6 whole pixels; the pixels across patch edges are the lookup test's (against `bitmap`).
"""

from __future__ import annotations

import os
import pathlib

import numpy as np
import pytest

# CI sets SPECCONV_REQUIRE_MITSUBA: there a missing Mitsuba is a failure, not a skip.
if os.environ.get("SPECCONV_REQUIRE_MITSUBA"):
    import drjit as dr
    import mitsuba as mi
else:
    mi = pytest.importorskip("mitsuba", reason="Mitsuba 3 is not installed (pip install mitsuba)")
    dr = pytest.importorskip("drjit", reason="Dr.Jit is not installed (pip install mitsuba)")

import mitsuba_fixtures as ref  # noqa: E402  (needs colour-science and OpenImageIO)
import specconv  # noqa: E402

SPP = 256
RES = 32
TEXELS = 16
ROOT = pathlib.Path(__file__).resolve().parents[2]
PATCH = 4  # texels per patch side

# Dr.Jit's LLVM backend aborts on Debian 12's LLVM 15 and 16 (`fminimum`) and works on its
# libllvm19: run it only where DRJIT_LIBLLVM_PATH names a working one (CI: libllvm19).
VARIANTS = [
    "scalar_spectral",
    pytest.param(
        "llvm_ad_spectral",
        marks=pytest.mark.skipif(
            not os.environ.get("DRJIT_LIBLLVM_PATH"),
            reason="DRJIT_LIBLLVM_PATH unset: Dr.Jit's LLVM backend aborts on LLVM 15 and 16 "
            "(Debian 12: apt-get install libllvm19, then "
            "DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1)",
        ),
    ),
]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The source PNG (sRGB, 4×4 patches) and its conversion with specconv."""
    import OpenImageIO as oiio

    d = tmp_path_factory.mktemp("mitsuba")
    # Saturated primaries and secondaries (where metamers part most), greys, and a few others.
    patches = np.array(
        [
            [[200, 30, 30], [30, 170, 40], [30, 50, 200], [230, 200, 40]],
            [[40, 190, 200], [190, 50, 180], [240, 130, 20], [90, 40, 150]],
            [[128, 128, 128], [245, 245, 245], [50, 50, 50], [200, 150, 120]],
            [[100, 130, 60], [90, 120, 170], [170, 190, 60], [120, 80, 60]],
        ],
        dtype=np.uint8,
    )
    image = np.repeat(np.repeat(patches, PATCH, 0), PATCH, 1)
    png = str(d / "patches.png")
    out = oiio.ImageOutput.create(png)
    out.open(png, oiio.ImageSpec(TEXELS, TEXELS, 3, "uint8"))
    out.write_image(image)
    out.close()
    exr = str(d / "patches_spectral.exr")
    specconv.convert([png], exr)
    emission = str(d / "patches_emission.exr")
    specconv.convert([png], emission, emission="reference")
    wavelengths, values = ref.read_reflectance(exr)
    return dict(dir=d, png=png, exr=exr, emission=emission, wavelengths=wavelengths, values=values)


@pytest.fixture(scope="module")
def estimator():
    """Mitsuba's wavelength sampling, tabulated once (it is the same in every variant)."""
    mi.set_variant("scalar_spectral")
    return ref.Estimator(mi, mi.load_dict(_sensor(1)))


@pytest.fixture(params=VARIANTS)
def variant(request, estimator):
    mi.set_variant(request.param)
    import specconv.mitsuba

    specconv.mitsuba.register()
    return request.param


def _sensor(spp: int) -> dict:
    return {
        "type": "orthographic",
        "to_world": mi.ScalarTransform4f().look_at(
            origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]
        ),
        "film": {
            "type": "hdrfilm",
            "width": RES,
            "height": RES,
            "pixel_format": "xyz",
            "rfilter": {"type": "box"},
        },
        "sampler": {"type": "independent", "sample_count": spp},
    }


def _render(reflectance: dict, light: str, spp: int = SPP, integrator=None) -> np.ndarray:
    scene = mi.load_dict(
        {
            "type": "scene",
            # BSDF sampling only: reflectance × radiance exactly, no transport noise.
            "integrator": integrator or {"type": "direct", "emitter_samples": 0, "bsdf_samples": 1},
            "sensor": _sensor(spp),
            "emitter": ref.emitter(light),
            "plate": {"type": "rectangle", "bsdf": {"type": "diffuse", "reflectance": reflectance}},
        }
    )
    return np.array(mi.render(scene, seed=0), dtype=np.float64)


def _layout():
    """Each pixel's texel (row as stored, column) from Mitsuba's own uv, and which pixels see
    one constant patch colour (their whole footprint in a patch's constant span)."""
    uv = _render(
        {"type": "uniform", "value": 1.0},
        "D65",
        spp=64,
        integrator={"type": "aov", "aovs": "uv:uv"},
    )[..., :2]
    uv = (np.round(uv * RES - 0.5) + 0.5) / RES  # the pixel's centre: the mean of its uv
    texel = np.floor(uv * TEXELS).astype(int)  # u → column; v → row, as `bitmap` reads it
    local = (uv * TEXELS) % PATCH  # position inside the patch, in texels
    half = TEXELS / RES / 2  # half a pixel, in texels
    inside = ((local - half >= 0.5) & (local + half <= PATCH - 0.5)).all(axis=-1)
    patch = texel // PATCH
    return texel[..., 1], texel[..., 0], inside, patch[..., 1], patch[..., 0]


def _patch_means(image, inside, prow, pcol):
    n = TEXELS // PATCH
    out = np.zeros((n, n, image.shape[-1]))
    count = np.zeros((n, n))
    np.add.at(out, (prow[inside], pcol[inside]), image[inside])
    np.add.at(count, (prow[inside], pcol[inside]), 1)
    assert (count == 36).all(), count  # 6×6 whole pixels per patch
    return out / count[..., None], count


def _patch_spectra(values):
    """One spectrum per patch: the texel at the patch's middle (the patch is one colour)."""
    return values[PATCH // 2 :: PATCH, PATCH // 2 :: PATCH]


def _gap(estimator, wavelengths, spectra, light):
    """δ: Mitsuba's expected pixel (its own integration) against colour-science's 1 nm sum.

    Mitsuba's CIE 1931 table differs from the CIE's (colour-science) by up to 0.016 at single
    wavelengths, and it normalises by its own ∫ȳ (MI_CIE_Y_NORMALIZATION = 1/106.75, the table
    sums to 106.86): measured up to 0.2 % of the white's value; held below 0.5 %."""
    mean, _ = estimator.mean_and_sigma(wavelengths, spectra, light)
    predicted = ref.predicted_xyz(wavelengths, spectra, light)
    white = ref.predicted_xyz(ref.LAMBDA, np.ones(len(ref.LAMBDA)), light)
    gap = np.abs(mean - predicted)
    GAPS.append((gap / white).max())
    assert (gap <= 5e-3 * white).all(), (
        f"Mitsuba's and colour-science's integrals differ by up to {(gap / white).max():.2%} "
        "of white"
    )
    return gap


GAPS = []


def _check_render(image, wavelengths, values, light, estimator):
    """Every constant pixel and every patch mean against colour-science, within 5σ/√N + δ."""
    rows, cols, inside, prow, pcol = _layout()
    spectra = values[rows, cols]  # [RES, RES, n]: the file's texel under each pixel
    expected = ref.predicted_xyz(wavelengths, spectra, light)
    _, sigma = estimator.mean_and_sigma(wavelengths, spectra, light)
    gap = _gap(estimator, wavelengths, spectra, light)
    error = np.abs(image - expected)[inside]
    bound = (5 * sigma / np.sqrt(SPP) + gap)[inside]
    assert (error <= bound).all(), (
        f"{(error > bound).sum()} of {error.size} pixel values outside 5σ/√spp + δ; "
        f"worst error/bound {(error / bound).max():.2f}"
    )
    means, count = _patch_means(image, inside, prow, pcol)
    patch_spectra = _patch_spectra(values)
    expected = ref.predicted_xyz(wavelengths, patch_spectra, light)
    _, sigma = estimator.mean_and_sigma(wavelengths, patch_spectra, light)
    bound = 5 * sigma / np.sqrt(SPP * count[..., None]) + _gap(
        estimator, wavelengths, patch_spectra, light
    )
    assert (np.abs(means - expected) <= bound).all(), (np.abs(means - expected) / bound).max()
    return means, bound


def _eval(texture, uvs, wavelengths) -> np.ndarray:
    """A Mitsuba texture's eval at uv points [k, 2] and wavelengths [m] → [k, m]."""
    wavelengths = np.asarray(wavelengths, dtype=np.float64)
    m = len(wavelengths)
    padded = np.concatenate([wavelengths, np.full(-m % 4, wavelengths[-1])]).reshape(-1, 4)
    if dr.is_jit_v(mi.Float):
        k, c = len(uvs), len(padded)
        si = dr.zeros(mi.SurfaceInteraction3f, k * c)
        si.uv = mi.Point2f(np.repeat(uvs[:, 0], c), np.repeat(uvs[:, 1], c))
        si.wavelengths = mi.Spectrum(*(np.tile(padded[:, i], k) for i in range(4)))
        out = np.array(texture.eval(si)).reshape(4, k, c)  # [lane, uv, chunk]
        return np.moveaxis(out, 0, -1).reshape(k, -1)[:, :m]
    out = np.empty((len(uvs), len(padded) * 4))
    si = mi.SurfaceInteraction3f()
    for i, (u, v) in enumerate(uvs):
        si.uv = mi.Point2f(u, v)
        for j, chunk in enumerate(padded):
            si.wavelengths = mi.Spectrum(*chunk)
            out[i, 4 * j : 4 * j + 4] = np.array(texture.eval(si)).ravel()
    return out[:, :m]


def _texture(props: dict):
    return mi.load_dict(props)


def test_lookup_is_bitmaps_bilinear_and_the_references_linear_interpolation(variant, tmp_path):
    """Per band and texel: the spectral texture is Mitsuba's own `bitmap` (raw, one band as a
    grey image) at every uv, filter and wrap mode, and linear between bands, zero outside —
    on a file another writer made (OpenImageIO), uneven bands, a non-square size."""
    rng = np.random.default_rng(7)
    wavelengths = np.array([400.0, 412.5, 450.0, 455.0, 530.0, 610.25, 700.0])
    values = rng.random((5, 7, len(wavelengths))).astype(np.float16).astype(np.float32)
    path = str(tmp_path / "uneven.exr")
    ref.write_reflectance(path, wavelengths, values)
    uvs = np.concatenate([rng.random((60, 2)) * 3 - 1, [[0.0, 0.0], [1.0, 1.0], [0.5, 0.999]]])
    # Wavelengths: each band, between bands, and outside the file's range.
    probes = np.concatenate(
        [wavelengths, [401.0, 430.0, 452.5, 600.0, 699.9, 380.0, 399.9, 700.1, 800.0]]
    )
    for filter_type in ("bilinear", "nearest"):
        for wrap_mode in ("repeat", "clamp", "mirror"):
            ours = _eval(
                _texture(
                    {
                        "type": "specconv_spectral",
                        "filename": path,
                        "filter_type": filter_type,
                        "wrap_mode": wrap_mode,
                    }
                ),
                uvs,
                probes,
            )
            bands = np.stack(
                [
                    _eval(
                        _texture(
                            {
                                "type": "bitmap",
                                "bitmap": mi.Bitmap(values[..., [b]]),
                                "raw": True,
                                "filter_type": filter_type,
                                "wrap_mode": wrap_mode,
                            }
                        ),
                        uvs,
                        [550.0],
                    )[:, 0]
                    for b in range(len(wavelengths))
                ],
                axis=-1,
            )
            expected = np.stack(
                [np.interp(probes, wavelengths, b, left=0.0, right=0.0) for b in bands]
            )
            np.testing.assert_allclose(
                ours, expected, rtol=0, atol=2e-6, err_msg=f"{filter_type}, {wrap_mode}"
            )


def test_level_reads_that_mip_level(variant, files):
    """Mitsuba gives textures no footprint; `level` reads a coarser level the file holds."""
    wavelengths, values = ref.read_reflectance(files["exr"], level=1)
    h, w, _ = values.shape
    tex = _texture({"type": "specconv_spectral", "filename": files["exr"], "level": 1})
    assert tuple(tex.resolution()) == (w, h)
    centres = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h), axis=-1)
    ours = _eval(tex, centres.reshape(-1, 2), wavelengths).reshape(h, w, -1)
    np.testing.assert_allclose(ours, values, rtol=0, atol=2e-6)


def test_plate_under_white_is_the_files_spectra(variant, files, estimator):
    image = _render({"type": "specconv_spectral", "filename": files["exr"]}, "D65")
    _check_render(image, files["wavelengths"], files["values"], "D65", estimator)


@pytest.mark.parametrize("light", ["D65", "A", "FL11"])
def test_metamerism_against_mitsubas_own_uplift(variant, files, estimator, light):
    """Under A and F11 the render is the colour-science colour of the file's spectra, and it
    parts from Mitsuba's `bitmap` (its RGB uplift of the same PNG) by what the two sets of
    spectra predict — an amount far above the noise, which ignoring the spectra would miss.
    Under D65 both are the PNG's colour, so they agree."""
    wavelengths, values = files["wavelengths"], files["values"]
    ours = _render({"type": "specconv_spectral", "filename": files["exr"]}, light)
    ours_means, _ = _check_render(ours, wavelengths, values, light, estimator)

    bitmap = {"type": "bitmap", "filename": files["png"]}
    theirs = _render(bitmap, light)
    _, _, inside, prow, pcol = _layout()
    theirs_means, count = _patch_means(theirs, inside, prow, pcol)
    # Mitsuba's uplift, sampled from its own texture at each patch's middle every nanometre.
    centres = (np.arange(PATCH // 2, TEXELS, PATCH) + 0.5) / TEXELS
    uvs = np.stack(np.meshgrid(centres, centres), axis=-1).reshape(-1, 2)  # (u, v), v = row
    their_spectra = _eval(_texture(bitmap), uvs, ref.LAMBDA).reshape(4, 4, -1)
    ours_spectra = _patch_spectra(values)
    predicted = ref.predicted_xyz(wavelengths, ours_spectra, light) - ref.predicted_xyz(
        ref.LAMBDA, their_spectra, light
    )
    # Same scene, same seed, a texture draws no random numbers: both renders see the same
    # wavelengths per sample, so the difference's noise is that of the difference of estimates.
    difference = estimator.samples(wavelengths, ours_spectra, light) - estimator.samples(
        ref.LAMBDA, their_spectra, light
    )
    gap = np.abs(difference.mean(axis=-2) - predicted)
    white = ref.predicted_xyz(ref.LAMBDA, np.ones(len(ref.LAMBDA)), light)
    assert (gap <= 5e-3 * white).all(), gap / white
    bound = 5 * difference.std(axis=-2) / np.sqrt(SPP * count[..., None]) + gap
    measured = ours_means - theirs_means
    assert (np.abs(measured - predicted) <= bound).all(), (
        f"under {light}: measured − predicted difference up to "
        f"{np.abs(measured - predicted).max():.5f}, bound {bound.min():.5f}"
    )
    if light == "D65":
        # Both uplifts keep the PNG's colour under the white they were made for.
        assert np.abs(predicted).max() < 2e-3, np.abs(predicted).max()
    else:
        # Metamerism the render resolves: several patches part by far more than the noise.
        assert (np.abs(predicted) > 4 * bound).any(axis=-1).sum() >= 4, predicted / bound


def test_render_time_texture_holds_the_baked_spectra(variant, files, tmp_path):
    """From the PNG and the default model, made compact texels by the library at load: the
    baked file's spectra (the file rounds them to half floats), also from straight alpha.
    Its renders: test_mitsuba_compact.py."""
    rgb = {"type": "specconv_rgb", "filename": files["png"]}
    wavelengths, values = files["wavelengths"], files["values"]
    centres = (np.arange(TEXELS) + 0.5) / TEXELS
    uvs = np.stack(np.meshgrid(centres, centres), axis=-1).reshape(-1, 2)
    theirs = _eval(_texture(rgb), uvs, wavelengths).reshape(TEXELS, TEXELS, -1)
    # The file rounds to the nearest half float (11 significant bits); the texture decodes
    # in float32: within one half-float step of the file, 2⁻¹⁰ relative (2⁻²⁴ among
    # subnormals).
    np.testing.assert_allclose(theirs, values, rtol=2.0**-10, atol=2.0**-24)

    # Straight alpha (PNG) is premultiplied after decoding, as convert does before uplifting.
    import OpenImageIO as oiio

    rgba = np.random.default_rng(3).random((4, 5, 4))
    rgba[..., 3] = np.linspace(0.1, 1.0, 20).reshape(4, 5)
    png = str(tmp_path / "straight_alpha.png")
    out = oiio.ImageOutput.create(png)
    out.open(png, oiio.ImageSpec(5, 4, 4, "uint8"))
    out.write_image(rgba.astype(np.float32))
    out.close()
    exr = str(tmp_path / "straight_alpha_spectral.exr")
    specconv.convert([png], exr)
    wl, expected = ref.read_reflectance(exr)
    centres = np.stack(np.meshgrid((np.arange(5) + 0.5) / 5, (np.arange(4) + 0.5) / 4), axis=-1)
    ours = _eval(_texture({"type": "specconv_rgb", "filename": png}), centres.reshape(-1, 2), wl)
    np.testing.assert_allclose(ours.reshape(4, 5, -1), expected, rtol=2.0**-10, atol=2.0**-24)


def test_the_site_default_model_reaches_the_plugins(variant, files, monkeypatch):
    """$SPECCONV_MODEL is the plugins' model when the scene names none, as everywhere else."""
    wavelengths = files["wavelengths"]
    centres = (np.arange(TEXELS) + 0.5) / TEXELS
    uvs = np.stack(np.meshgrid(centres, centres), axis=-1).reshape(-1, 2)
    rgb = {"type": "specconv_rgb", "filename": files["png"]}
    monkeypatch.setenv("SPECCONV_MODEL", "paper")
    site = _eval(_texture(rgb), uvs, wavelengths)
    monkeypatch.delenv("SPECCONV_MODEL")
    named = _eval(_texture({**rgb, "model": "paper"}), uvs, wavelengths)
    default = _eval(_texture(rgb), uvs, wavelengths)
    np.testing.assert_array_equal(site, named)
    assert not np.allclose(site, default, rtol=1e-3)


def test_emission_file_as_reflectance_is_refused(variant, files):
    with pytest.raises(Exception, match="emission"):
        _texture({"type": "specconv_spectral", "filename": files["emission"]})


def test_rgb_variant_is_refused():
    mi.set_variant("scalar_rgb")
    import specconv.mitsuba

    with pytest.raises(RuntimeError, match="spectral Mitsuba variant"):
        specconv.mitsuba.register()


# The RGB route in memory (issue 47 item 3): `specconv_rgb`'s texels are made by the library
# from the pixels Mitsuba's reader decoded, with no file written, in parallel with the GIL
# released. What a texel is does not depend on the variant: one variant is enough here.


@pytest.fixture
def scalar(estimator):
    mi.set_variant("scalar_spectral")
    import specconv.mitsuba

    specconv.mitsuba.register()


def _write(path, pixels, dtype, attributes=()):
    """An image OpenImageIO writes: `pixels` [h, w, c] stored as `dtype`."""
    import OpenImageIO as oiio

    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, dtype)
    for name, kind, value in attributes:
        spec.attribute(name, oiio.TypeDesc(kind), value)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(np.ascontiguousarray(pixels))
    out.close()
    return str(path)


def _converted(path, out, **options):
    """What `convert --layout compact -d float` stores for `path` (the texels of the unrounded
    colour, which the in-memory route keeps): its text and level-0 texels."""
    specconv.convert([path], str(out), layout="compact", sample="float", mip=False, **options)
    image = specconv.read_compact(str(out))
    return image.text, np.asarray(image.texels)


def _sources(tmp_path):
    """Images whose texels Mitsuba's reader and the library's must agree on bit for bit."""
    rng = np.random.default_rng(47)
    rgb8 = rng.integers(0, 256, (17, 33, 3), dtype=np.uint8)
    rgb8[0, :4] = [[0, 0, 0], [255, 255, 255], [255, 0, 0], [0, 0, 255]]
    rgba8 = rng.integers(0, 256, (9, 11, 4), dtype=np.uint8)
    rgba8[0, :3, 3] = [0, 1, 255]  # transparent, nearly so, opaque
    rgb16 = rng.integers(0, 65536, (8, 13, 3), dtype=np.uint16)
    linear = rng.normal(0.4, 0.5, (7, 9, 3)).astype(np.float32)  # out of gamut, negative
    linear[0, :3] = [[0, 0, 0], [30.0, 20.0, 10.0], [1e-7, 2e-7, 0.0]]  # black, HDR, tiny
    rgba = np.concatenate([linear, rng.random((7, 9, 1), dtype=np.float32)], axis=-1)
    # Few distinct pixels (made once each, then copied): with straight alpha, and 16-bit.
    palette = rng.integers(0, 256, (10, 4), dtype=np.uint8)
    palette[1, :3], palette[1, 3] = palette[0, :3], palette[0, 3] // 2  # one colour, two alphas
    palette16 = rng.integers(0, 65536, (7, 3), dtype=np.uint16)
    few = rng.integers(0, 10, (32, 24))
    # 150 distinct of 768: made once each, but too many for a renderer's palette (5/n).
    some = rng.integers(0, 256, (150, 3), dtype=np.uint8)[np.arange(768) % 150].reshape(32, 24, 3)
    return {
        "some_rgb8.png": (_write(tmp_path / "some_rgb8.png", some, "uint8"), None),
        "few_rgba8.png": (_write(tmp_path / "few_rgba8.png", palette[few], "uint8"), None),
        "few_rgb16.png": (_write(tmp_path / "few_rgb16.png", palette16[few % 7], "uint16"), None),
        # Scaled as OpenImageIO scales 8-bit values: × (1/255) in float32.
        "rgb8.png": (
            _write(tmp_path / "rgb8.png", rgb8, "uint8"),
            rgb8.astype(np.float32) * np.float32(1 / 255),
        ),
        "rgba8.png": (_write(tmp_path / "rgba8.png", rgba8, "uint8"), None),
        "rgb16.png": (_write(tmp_path / "rgb16.png", rgb16, "uint16"), None),
        "linear.exr": (_write(tmp_path / "linear.exr", linear, "float"), None),
        "premultiplied.exr": (_write(tmp_path / "premultiplied.exr", rgba, "float"), None),
        "linear_half.exr": (_write(tmp_path / "linear_half.exr", linear, "half"), None),
    }


def test_texels_made_in_memory_are_what_convert_stores(scalar, tmp_path):
    """8- and 16-bit PNG (with straight alpha too; of many distinct pixels, made one by one,
    and of few, made once each), float and half OpenEXR with colours out of gamut, HDR and
    black: the texels equal `convert --layout compact -d float`'s, bit for bit, and the
    library's `encode` of the colour (OpenColorIO's sRGB texture to XYZ) to float32's rounding
    of the working space's colour."""
    for name, (path, rgb) in _sources(tmp_path).items():
        text, texels = specconv.mitsuba.compact_texels(path)
        want_text, want = _converted(path, tmp_path / f"{name}.compact.exr")
        assert text == want_text, name
        assert texels.shape == want.shape and texels.dtype == np.float32, name
        np.testing.assert_array_equal(texels, want, err_msg=name)
        if rgb is not None:
            xyz = specconv.rgb_to_xyz(rgb.astype(np.float32), "sRGB - Texture")
            encoded_text, encoded = specconv.encode(xyz)
            assert encoded_text == text
            # The colour: OpenColorIO's sRGB texture to XYZ and the sRGB curve straight to the
            # working space (docs/compact.md) agree to float32's rounding; u, which moves
            # much with a colour's last bits near the solid's surface, is encode's of the
            # texel's own colour, bit for bit.
            np.testing.assert_allclose(texels[..., :3], encoded[..., :3], rtol=1e-5, atol=1e-6, err_msg=name)
            _, own = specconv.encode(np.ascontiguousarray(texels[..., :3]))
            np.testing.assert_array_equal(texels, own, err_msg=name)


def test_the_routes_palette_is_the_palette_of_its_texels(variant, tmp_path):
    """With a palette asked for (`specconv_rgb` in the JIT variants), the route makes it from
    the distinct pixels it finds instead of texels: each pixel's spectrum in it is, bit for
    bit, the spectrum of its texel in the library's palette of the texels the route makes
    without one. Made where the pixels repeat enough (the palette's rule), else the texels
    come back; a JIT texture of such an image holds the palette, the scalar one the texels."""
    from specconv._specconv import palette
    from specconv.mitsuba import _texels_of_image

    made = set()
    for name, (path, _) in _sources(tmp_path).items():
        text, texels = specconv.mitsuba.compact_texels(path)
        options = dict(colorspace=None, ocio=None, model=None, bounded=True)
        route_text, route = _texels_of_image(path, palette=True, **options)
        assert route_text == text, name
        want = palette(text, texels)
        if not isinstance(route, tuple):
            np.testing.assert_array_equal(route, texels, err_msg=name)
            continue
        made.add(name)
        numbers, spectra = route
        assert numbers.shape == texels.shape[:2] + (1,) and spectra.dtype == np.float32, name
        assert (numbers == np.round(numbers)).all() and numbers.max() < len(spectra), name
        ours = spectra[numbers[..., 0].astype(np.int64)]
        theirs = want[1][want[0][..., 0].astype(np.int64)]
        np.testing.assert_array_equal(ours.view(np.uint32), theirs.view(np.uint32), err_msg=name)
    # The images of few colours (8-bit with straight alpha, 16-bit) and no other.
    assert made == {"few_rgba8.png", "few_rgb16.png"}, made
    texture = _texture({"type": "specconv_rgb", "filename": _sources(tmp_path)["few_rgba8.png"][0]})
    assert (texture._palette is not None) == dr.is_jit_v(mi.Float)


def test_texels_of_an_acescg_exr_are_converts(scalar, tmp_path):
    """Mitsuba's reader moves an OpenEXR's chromaticities to Rec.709 keeping XYZ (no
    adaptation); the library reads such a file's own samples and converts them by the rule
    and route a conversion uses: the texels are convert's bit for bit, and their colour is
    not the one Mitsuba's moved pixels would give."""
    rng = np.random.default_rng(3)
    rgb = (rng.random((6, 7, 3)) * 0.8 + 0.05).astype(np.float32)
    ap1 = (0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767)
    path = _write(tmp_path / "acescg.exr", rgb, "float", [("chromaticities", "float[8]", ap1)])
    text, texels = specconv.mitsuba.compact_texels(path)
    want_text, want = _converted(path, tmp_path / "acescg.compact.exr")
    assert text == want_text
    np.testing.assert_array_equal(texels, want)
    # Read as the linear Rec.709 Mitsuba hands over, unadapted, the colour would be ≥ 1 % off.
    moved = np.array(mi.Bitmap(path), dtype=np.float32)
    unadapted = specconv.rgb_to_xyz(moved, "Linear Rec.709 (sRGB)")
    assert np.abs(unadapted - want[..., :3]).max() > 0.01


def _chunk(kind: bytes, data: bytes) -> bytes:
    import struct
    import zlib

    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _png_with_chunks(path, pixels, chunks):
    """An 8- or 16-bit RGB PNG with `chunks` (type, data) before its image data, written by
    the PNG specification (3rd ed.): for chunks OpenImageIO does not write (cHRM, gAMA)."""
    import struct
    import zlib

    h, w, _ = pixels.shape
    depth = 16 if pixels.dtype == np.uint16 else 8
    rows = b"".join(b"\0" + pixels[y].astype(">u2" if depth == 16 else np.uint8).tobytes()
                    for y in range(h))
    data = b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, 2, 0, 0, 0))
    data += b"".join(_chunk(k, v) for k, v in chunks)
    data += _chunk(b"IDAT", zlib.compress(rows)) + _chunk(b"IEND", b"")
    path.write_bytes(data)
    return str(path)


def _display_p3_profile() -> bytes:
    """A Display P3 ICC profile (P3 primaries, D65, the sRGB curve: Apple's definition), made
    by Little CMS as tests/colour_rule_images.py makes it."""
    import ctypes
    import ctypes.util

    lcms = ctypes.CDLL(ctypes.util.find_library("lcms2"))
    lcms.cmsBuildParametricToneCurve.restype = ctypes.c_void_p
    lcms.cmsBuildParametricToneCurve.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double * 5]
    lcms.cmsCreateRGBProfile.restype = ctypes.c_void_p
    lcms.cmsCreateRGBProfile.argtypes = [ctypes.c_void_p] * 3
    lcms.cmsSaveProfileToMem.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint32)]
    curve = lcms.cmsBuildParametricToneCurve(
        None, 4, (ctypes.c_double * 5)(2.4, 1 / 1.055, 0.055 / 1.055, 1 / 12.92, 0.04045)
    )
    white = (ctypes.c_double * 3)(0.3127, 0.3290, 1.0)
    primaries = (ctypes.c_double * 9)(0.680, 0.320, 1.0, 0.265, 0.690, 1.0, 0.150, 0.060, 1.0)
    profile = lcms.cmsCreateRGBProfile(white, primaries, (ctypes.c_void_p * 3)(curve, curve, curve))
    size = ctypes.c_uint32(0)
    lcms.cmsSaveProfileToMem(profile, None, ctypes.byref(size))
    buf = ctypes.create_string_buffer(size.value)
    lcms.cmsSaveProfileToMem(profile, buf, ctypes.byref(size))
    return buf.raw[: size.value]


def _evidence_files(tmp_path):
    """Files whose colour evidence Mitsuba's reader does not see, each with the OCIO config
    to read it under (None: the built-in one) and whether it is data. Written by OpenImageIO
    (a real writer) where it writes the evidence, else by the PNG specification."""
    import struct
    import subprocess

    rng = np.random.default_rng(470)
    rgb8 = rng.integers(0, 256, (9, 13, 3), dtype=np.uint8)
    rgb16 = rng.integers(0, 65536, (9, 13, 3), dtype=np.uint16)
    linear = (rng.random((7, 9, 3)) * 0.9 + 0.02).astype(np.float32)
    p3 = _display_p3_profile()
    icc = [("ICCProfile", f"uint8[{len(p3)}]", np.frombuffer(p3, np.uint8))]
    ap0 = (0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.077, 0.32168, 0.33767)
    gama = lambda g: (b"gAMA", struct.pack(">I", round(g * 100000)))  # noqa: E731
    p3_chrm = (b"cHRM", struct.pack(">8I", 31270, 32900, 68000, 32000, 26500, 69000, 15000, 6000))
    rules = str(ROOT / "testdata" / "ocio" / "studio_rules.ocio")
    files = {
        "srgb8.png": (_write(tmp_path / "srgb8.png", rgb8, "uint8"), None),
        "icc_p3.png": (_write(tmp_path / "icc_p3.png", rgb8, "uint8", icc), None),
        "icc_p3.jpg": (_write(tmp_path / "icc_p3.jpg", rgb8, "uint8", icc), None),
        "chrm_gama.png": (_png_with_chunks(tmp_path / "chrm_gama.png", rgb8, [gama(1 / 2.2), p3_chrm]), None),
        "gama_1.png": (_png_with_chunks(tmp_path / "gama_1.png", rgb8, [gama(1.0)]), None),
        "gama_18_16bit.png": (_png_with_chunks(tmp_path / "gama_18_16bit.png", rgb16, [gama(1 / 1.8)]), None),
        "rgb16.png": (_write(tmp_path / "rgb16.png", rgb16, "uint16"), None),
        "ap0_aces.exr": (_write(tmp_path / "ap0_aces.exr", linear, "half", [
            ("chromaticities", "float[8]", ap0), ("acesImageContainerFlag", "int", 1)]), None),
        "aces_flag_only.exr": (_write(tmp_path / "aces_flag_only.exr", linear, "float", [
            ("acesImageContainerFlag", "int", 1)]), None),
        "interop_ap1.exr": (_write(tmp_path / "interop_ap1.exr", linear, "float", [
            ("colorInteropID", "string", "lin_ap1_scene")]), None),
        "named_acescg.exr": (_write(tmp_path / "named_acescg.exr", linear, "float", [
            ("oiio:ColorSpace", "string", "ACEScg")]), None),
        "rule_acescg.png": (_write(tmp_path / "plate_acescg.png", rgb8, "uint8"), rules),
        "rule_acescg.exr": (_write(tmp_path / "wall_acescg.exr", linear, "float"), rules),
    }
    # oiiotool, the tool a studio writes textures with: an sRGB PNG and a P3 ICC one.
    made = tmp_path / "oiiotool_p3.png"
    subprocess.run(["oiiotool", files["srgb8.png"][0], "--iccread", _write_bytes(tmp_path / "p3.icc", p3),
                    "-o", str(made)], check=True)
    files["oiiotool_p3.png"] = (str(made), None)
    return files


def _write_bytes(path, data: bytes) -> str:
    path.write_bytes(data)
    return str(path)


def test_rgb_route_decides_colour_by_converts_rule(scalar, tmp_path):
    """The RGB route weighs the evidence Mitsuba's reader does not see (ICC profiles in PNG
    and JPEG, PNG cHRM and gAMA, 16-bit PNG, OpenEXR chromaticities with the ACES flag, the
    flag alone, colorInteropID, a name in oiio:ColorSpace, an OCIO file rule) by the library
    function `convert` uses: its texels equal `convert --layout compact -d float`'s bit for
    bit. Never a silent difference; and the evidence matters (the same samples read as the
    reader's default would give other texels)."""
    files = _evidence_files(tmp_path)
    for name, (path, ocio) in files.items():
        text, texels = specconv.mitsuba.compact_texels(path, ocio=ocio)
        want_text, want = _converted(path, tmp_path / f"{name}.compact.exr", ocio=ocio)
        assert text == want_text, name
        np.testing.assert_array_equal(texels, want, err_msg=name)
    for name in ("icc_p3.png", "chrm_gama.png", "gama_1.png", "interop_ap1.exr", "rule_acescg.png"):
        path, ocio = files[name]
        default = "Linear Rec.709 (sRGB)" if path.endswith(".exr") else "sRGB - Texture"
        _, texels = specconv.mitsuba.compact_texels(path, ocio=ocio)
        _, as_default = specconv.mitsuba.compact_texels(path, ocio=ocio, colorspace=default)
        assert np.abs(texels[..., :3] - as_default[..., :3]).max() > 1e-3, name


def test_rgb_route_refuses_what_it_cannot_read(scalar, tmp_path):
    """A header whose evidence cannot be read (a PNG iCCP chunk that does not decompress) is
    refused naming it, not read as sRGB; a data map by a file rule is refused as data, as
    convert skips it."""
    rng = np.random.default_rng(5)
    rgb8 = rng.integers(0, 256, (4, 5, 3), dtype=np.uint8)
    bad = _png_with_chunks(tmp_path / "bad_icc.png", rgb8, [(b"iCCP", b"P3\0\0not zlib at all")])
    with pytest.raises(Exception, match=r"PNG iCCP.*cannot be read.*(zlib|decompress)"):
        specconv.mitsuba.compact_texels(bad)
    rules = str(ROOT / "testdata" / "ocio" / "studio_rules.ocio")
    normal = _write(tmp_path / "rock_normal.png", rgb8, "uint8")
    with pytest.raises(Exception, match=r"data texture.*file rule 'normals'"):
        specconv.mitsuba.compact_texels(normal, ocio=rules)


def test_no_file_is_written_to_make_texels(scalar, files, tmp_path, monkeypatch):
    """No temporary file, in TMPDIR or beside the image: Python's tempfile is out of reach,
    and both folders hold what they held before."""
    import tempfile

    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setenv("TMPDIR", str(scratch))
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))

    def refused(*args, **kwargs):
        raise AssertionError("a temporary file was asked for")

    for name in ("mkstemp", "mkdtemp", "NamedTemporaryFile", "TemporaryDirectory", "TemporaryFile"):
        monkeypatch.setattr(tempfile, name, refused)
    image = tmp_path / "in"
    image.mkdir()
    png = image / "patches.png"
    png.write_bytes(open(files["png"], "rb").read())
    texture = _texture({"type": "specconv_rgb", "filename": str(png)})
    assert list(texture.resolution()) == [TEXELS, TEXELS]
    assert os.listdir(scratch) == []
    assert os.listdir(image) == ["patches.png"]


def test_texels_honour_the_site_default_model(scalar, files, tmp_path, monkeypatch):
    """$SPECCONV_MODEL decides the texels' model where the scene names none, through the
    library's one rule: convert's texels under the same variable, the named model's, and
    not the built-in default's. A site default that cannot be used is refused by name."""
    monkeypatch.setenv("SPECCONV_MODEL", "paper")
    text, texels = specconv.mitsuba.compact_texels(files["png"])
    want_text, want = _converted(files["png"], tmp_path / "site.exr")
    assert text == want_text
    np.testing.assert_array_equal(texels, want)
    monkeypatch.delenv("SPECCONV_MODEL")
    named_text, named = specconv.mitsuba.compact_texels(files["png"], model="paper")
    assert named_text == text
    np.testing.assert_array_equal(named, texels)
    default_text, default = specconv.mitsuba.compact_texels(files["png"])
    assert default_text != text and not np.array_equal(default, texels)
    monkeypatch.setenv("SPECCONV_MODEL", str(tmp_path / "no_such_model.json"))
    with pytest.raises(Exception, match="SPECCONV_MODEL"):
        _texture({"type": "specconv_rgb", "filename": files["png"]})


def test_texels_are_made_with_the_gil_released(scalar):
    """Another Python thread keeps running while the library makes a 2048² image's texels:
    its longest stall during the call is a fraction of the call (holding the GIL, it would
    stall for all of it)."""
    import threading
    import time

    from specconv._specconv import compact_texels

    pixels = np.random.default_rng(1).integers(0, 256, (2048, 2048, 3), dtype=np.uint8)
    stalls = []  # (from, to) of each pause of the thread over 2 ms
    stop = threading.Event()

    def spin():
        last = time.perf_counter()
        while not stop.is_set():
            now = time.perf_counter()
            if now - last > 0.002:
                stalls.append((last, now))
            last = now

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    time.sleep(0.05)
    # The file's header says what the pixels are (an 8-bit sRGB PNG's): the pixels are these.
    png = str(ROOT / "testdata" / "images" / "srgb8.png")
    start = time.perf_counter()
    try:
        _, texels, colorspace = compact_texels(pixels, png)
    finally:
        end = time.perf_counter()
        stop.set()
    thread.join()
    assert texels.shape == (2048, 2048, 6) and colorspace == "sRGB - Texture"
    call = end - start
    longest = max((min(b, end) - max(a, start) for a, b in stalls), default=0.0)
    assert call > 0.1, f"the call took {call:.3f} s: too short to tell"
    assert longest < 0.5 * call, f"the other thread stalled {longest:.3f} s of {call:.3f} s"


def test_rgb_route_refuses_bad_input_clearly(scalar, files, tmp_path):
    """What a careless scene gives `specconv_rgb`: each refused with what is wrong."""
    nan = np.full((4, 4, 3), 0.5, dtype=np.float32)
    nan[2, 1, 0] = np.nan
    (tmp_path / "notes.png").write_text("not an image")
    bad = {
        "missing": (str(tmp_path / "missing.png"), "missing|no such|not found|exist"),
        "a folder": (str(tmp_path), "directory|folder|not a file"),
        "NaN": (_write(tmp_path / "nan.exr", nan, "float"), "NaN or infinite.*x 1, y 2"),
        "one channel": (
            _write(tmp_path / "grey.png", np.full((4, 4, 1), 90, np.uint8), "uint8"),
            "data texture",
        ),
        "a spectral file": (files["exr"], "grey or RGB"),
        "a TIFF": (_write(tmp_path / "a.tif", nan[..., :3] * 0 + 0.5, "uint8"), "specconv_compact"),
        "not an image": (str(tmp_path / "notes.png"), "cannot read it"),
    }
    for what, (path, message) in bad.items():
        with pytest.raises(Exception, match=message):
            _texture({"type": "specconv_rgb", "filename": path})
    for props, message in (
        ({"colorspace": "no such space"}, "no such space"),
        ({"model": "no_such_model"}, "no_such_model"),
        ({"colorspace": "Raw"}, "data texture"),
    ):
        with pytest.raises(Exception, match=message):
            _texture({"type": "specconv_rgb", "filename": files["png"], **props})
    # Pixels handed to the library directly: a shape or type it cannot take, refused.
    from specconv._specconv import compact_texels

    for pixels, message in (
        (np.zeros((2, 2, 5), np.uint8), "1 to 4 channels"),
        (np.zeros(4, np.uint8), "shape"),
        (np.zeros((2, 2, 3), np.int64), "dtype"),
        ([[0.5, 0.5, 0.5]], "numpy array"),
    ):
        with pytest.raises(specconv.Error, match=message):
            compact_texels(pixels, "x.png")
    # A grey image named colour is uplifted as grey, as convert does.
    grey = _write(tmp_path / "grey_colour.png", np.full((4, 4, 1), 90, np.uint8), "uint8")
    text, texels = specconv.mitsuba.compact_texels(grey, colorspace="sRGB - Texture")
    _, want = _converted(grey, tmp_path / "grey.compact.exr", colorspace="sRGB - Texture")
    np.testing.assert_array_equal(texels, want)
