"""What the Mitsuba tests compare against, computed outside Mitsuba and outside specconv.

- the file's spectra, read with OpenImageIO's own bindings and the layout's channel names;
- colour from spectra by colour-science (CIE 1931 2°, its illuminant tables);
- the noise of Mitsuba's estimator, from Mitsuba's own wavelength sampling (see `Estimator`).
"""

from __future__ import annotations

import re

import colour
import numpy as np
import OpenImageIO as oiio

# The layout's channel-name expression (Fichet 2021; DESIGN.md), reflective channels only here.
_CHANNEL = re.compile(r"^T\.(\d*,?\d*([Ee][+-]?\d+)?)(nm)$")

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
# Mitsuba samples wavelengths on its CIE range; colour is integrated there too, at 1 nm.
LAMBDA = np.arange(360.0, 831.0, 1.0)
SHAPE = colour.SpectralShape(360, 830, 1)


def read_reflectance(path: str, level: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(wavelengths [n], values [h, w, n]) of a Fichet reflectance file, rows as stored."""
    inp = oiio.ImageInput.open(path)
    assert inp is not None, oiio.geterror()
    assert inp.seek_subimage(0, level), f"{path} has no MIP level {level}"
    spec = inp.spec()
    pixels = inp.read_image(0, level, 0, spec.nchannels, "float")
    inp.close()
    bands = [
        (float(m.group(1).replace(",", ".")), c)
        for c, name in enumerate(spec.channelnames)
        if (m := _CHANNEL.match(name))
    ]
    bands.sort()
    wavelengths = np.array([w for w, _ in bands])
    return wavelengths, np.asarray(pixels)[..., [c for _, c in bands]]


def write_reflectance(path: str, wavelengths, values) -> None:
    """A Fichet reflectance file written by OpenImageIO (another writer than specconv)."""
    values = np.asarray(values, dtype=np.float32)
    h, w, n = values.shape
    spec = oiio.ImageSpec(w, h, n, "half")
    spec.channelnames = tuple("T." + f"{lam:.6f}".replace(".", ",") + "nm" for lam in wavelengths)
    spec.attribute("spectralLayoutVersion", "1.0")
    out = oiio.ImageOutput.create(path)
    assert out.open(path, spec), out.geterror()
    assert out.write_image(values)
    out.close()


def illuminant(name: str) -> np.ndarray:
    """A CIE illuminant from colour-science at 1 nm over 360–830 nm (zero outside its table,
    linear between samples, as Mitsuba's `irregular` spectrum), scaled so that
    ∫ I·ȳ = ∫ ȳ: a perfect white then renders with Y = 1."""
    sd = colour.SDS_ILLUMINANTS[name]
    values = np.interp(LAMBDA, sd.wavelengths, sd.values, left=0.0, right=0.0)
    ybar = CMFS.align(SHAPE).values[:, 1]
    return values * ybar.sum() / (values * ybar).sum()


def emitter(name: str) -> dict:
    """A uniform environment with that illuminant's spectrum."""
    values = illuminant(name)
    return {
        "type": "constant",
        "radiance": {
            "type": "irregular",
            "wavelengths": ", ".join(f"{x:g}" for x in LAMBDA),
            "values": ", ".join(f"{x:.9g}" for x in values),
        },
    }


def at_1nm(wavelengths, values) -> np.ndarray:
    """Reflectance at 1 nm: linear between bands, zero outside them (the layout's reference)."""
    values = np.asarray(values, dtype=np.float64)
    flat = values.reshape(-1, values.shape[-1])
    out = np.stack([np.interp(LAMBDA, wavelengths, r, left=0.0, right=0.0) for r in flat])
    return out.reshape(*values.shape[:-1], len(LAMBDA))


def predicted_xyz(wavelengths, values, name: str) -> np.ndarray:
    """XYZ (Y = 1 white) that colour-science computes for reflectances under an illuminant."""
    sd_illuminant = colour.SpectralDistribution(illuminant(name), LAMBDA)
    xyz = colour.msds_to_XYZ(
        at_1nm(wavelengths, values),
        CMFS.align(SHAPE),
        sd_illuminant,
        method="Integration",
        shape=SHAPE,
    )
    return np.asarray(xyz) / 100.0


class Estimator:
    """Mitsuba's per-sample XYZ estimate of a diffuse plate under a uniform environment.

    With BSDF sampling alone (`direct`, emitter_samples = 0) a diffuse plate under a constant
    environment returns reflectance × radiance exactly: the only noise left is the sensor's
    choice of four wavelengths per sample. One sample's XYZ is
        mean_i cmf(λ_i) · w_i · r(λ_i) · I(λ_i) · MI_CIE_Y_NORMALIZATION,
    (λ_i, w_i) = sensor.sample_wavelengths(u): Mitsuba's own functions, tabulated on a fine
    stratified grid of u. Its mean over u is the expected pixel, its variance over u the
    per-sample variance σ² — so a pixel of N samples has standard error σ/√N.
    """

    def __init__(self, mi, sensor, grid: int = 4096):
        si = mi.SurfaceInteraction3f()
        lam, weight, cmf = [], [], []
        for k in range(grid):
            wl, w = sensor.sample_wavelengths(si, (k + 0.5) / grid)
            wl, w = np.array(wl, dtype=np.float64).ravel(), np.array(w, dtype=np.float64).ravel()
            lam.append(wl)
            weight.append(w)
            cmf.append([np.array(mi.cie1931_xyz(float(x)), dtype=np.float64).ravel() for x in wl])
        self.lam = np.array(lam)  # [grid, 4]
        self.factor = (
            np.array(cmf) * np.array(weight)[..., None] * mi.MI_CIE_Y_NORMALIZATION
        )  # [grid, 4, 3]

    def samples(self, wavelengths, spectra, name: str) -> np.ndarray:
        """[..., grid, 3]: the estimate for every u, for each reflectance in `spectra`."""
        light = np.interp(self.lam, LAMBDA, illuminant(name))
        spectra = np.asarray(spectra, dtype=np.float64)
        flat = spectra.reshape(-1, spectra.shape[-1])
        r = np.stack([np.interp(self.lam, wavelengths, s, left=0.0, right=0.0) for s in flat])
        est = np.einsum("pgi,gic->pgc", r * light, self.factor) / self.lam.shape[1]
        return est.reshape(*spectra.shape[:-1], *est.shape[1:])

    def mean_and_sigma(self, wavelengths, spectra, name: str):
        est = self.samples(wavelengths, spectra, name)
        return est.mean(axis=-2), est.std(axis=-2)
