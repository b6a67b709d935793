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
