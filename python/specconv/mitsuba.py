"""Mitsuba 3 textures that read spectral reflectance (docs/renderers.md).

    import mitsuba as mi
    mi.set_variant("scalar_spectral")          # or llvm_ad_spectral
    import specconv.mitsuba
    specconv.mitsuba.register()                # after set_variant: plugins are per variant

    {"type": "diffuse", "reflectance": {"type": "specconv_spectral", "filename": "albedo.exr"}}
    {"type": "diffuse", "reflectance": {"type": "specconv_rgb", "filename": "albedo.png"}}

``specconv_spectral`` reads a Fichet 2021 reflectance file (ours or any other writer's, any
wavelength list). ``specconv_rgb`` reads an RGB texture and uplifts every texel once, at load,
with a specconv model (``specconv.rgb_to_xyz`` then ``specconv.uplift``: the spectra ``convert``
would bake), so a scene ships the RGB file, not the 14× larger spectral one. Per texel was
chosen over per lookup by measured render time (docs/renderers.md, python/bench/render.py).

Both then evaluate alike, as Mitsuba's own ``bitmap`` does in space and as the layout's reference
(afichet/spectral-exr) integrates in wavelength:
- uv: ``to_uv`` applied, texel centres at (i + ½)/size, v = 0 at the first row the file stores
  (``bitmap``'s orientation), ``filter_type`` bilinear|nearest, ``wrap_mode`` repeat|mirror|clamp;
- wavelength: linear between the file's bands, zero outside its range (the reference integrates
  nothing there, and Mitsuba's own ``regular``/``irregular`` spectra are zero there too).
Bilinear in uv and linear in wavelength commute, so both are one trilinear lookup in a 3D
texture whose depth axis is the band index.

MIP levels: Mitsuba 3's integrators give textures no footprint (``si.duv_dx`` is zero; its
``bitmap`` has no MIP mapping either), so level 0 is read; ``level`` picks another by hand.
"""

from __future__ import annotations

import bisect

import drjit as dr
import mitsuba as mi
import numpy as np

import specconv

SPECTRAL = "specconv_spectral"
RENDER_TIME = "specconv_rgb"

_FILTERS = {"bilinear": False, "nearest": True}
_WRAPS = {
    "repeat": dr.WrapMode.Repeat,
    "mirror": dr.WrapMode.Mirror,
    "clamp": dr.WrapMode.Clamp,
}


def register() -> None:
    """Register ``specconv_spectral`` and ``specconv_rgb`` for the current Mitsuba variant."""
    variant = mi.variant()
    if variant is None or "spectral" not in variant:
        raise RuntimeError(
            f"specconv.mitsuba needs a spectral Mitsuba variant (mi.set_variant('scalar_spectral') "
            f"or 'llvm_ad_spectral'), not {variant!r}: an RGB variant never asks a texture for "
            "spectra"
        )
    spectral, render_time = _classes(variant)
    mi.register_texture(SPECTRAL, lambda props: spectral(props))
    mi.register_texture(RENDER_TIME, lambda props: render_time(props))


_CLASSES: dict = {}


def _classes(variant: str):
    """The two texture classes for one variant: ``mi.Texture`` is a different class per variant."""
    if variant not in _CLASSES:
        _CLASSES[variant] = _define(variant)
    return _CLASSES[variant]


def _choice(props, name: str, table: dict, default: str):
    value = props.get(name, default)
    if value not in table:
        raise ValueError(f"{name} = {value!r}: expected one of {', '.join(table)}")
    return table[value]


def _define(variant: str):
    jit = dr.is_jit_v(mi.Float)

    class _BandTexture(mi.Texture):
        """Spectra on a wavelength list, [h, w, n] rows top to bottom, looked up trilinearly."""

        def _setup(self, props, wavelengths, values, source: str) -> None:
            # Mitsuba's wavelengths are float32: a band at 400 nm must hold a lookup at 400 nm
            # even when a reader's unit conversion left it at 400.00000000000006.
            wavelengths = np.asarray(wavelengths, dtype=np.float32).astype(np.float64)
            values = np.asarray(values, dtype=np.float32)
            order = np.argsort(wavelengths)
            wavelengths, values = wavelengths[order], values[..., order]
            if len(wavelengths) < 2:
                raise ValueError(f"{source}: a spectral texture needs at least two bands")
            h, w, n = values.shape
            self._source = source
            self._size = (w, h)
            self._wl = wavelengths
            self._nearest = _choice(props, "filter_type", _FILTERS, "bilinear")
            wrap = _choice(props, "wrap_mode", _WRAPS, "repeat")
            # None for the identity: most textures have none, and a lookup saves the transform.
            self._to_uv = _to_uv(props, jit)
            # Depth = band: one Texture3f lookup is bilinear in uv and linear in wavelength.
            tensor = np.ascontiguousarray(np.moveaxis(values, 2, 0)[..., None])
            self._tex = mi.Texture3f(
                mi.TensorXf(tensor),
                use_accel=False,
                filter_mode=dr.FilterMode.Linear,
                wrap_mode=wrap,
            )
            steps = np.diff(wavelengths)
            self._regular = bool(np.allclose(steps, steps[0], rtol=0, atol=1e-6 * steps[0]))
            self._step = float(steps[0])
            if jit:
                self._wl_jit = mi.Float(wavelengths.astype(np.float32))
            self._mean = _mean(wavelengths, values)

        def _band_index(self, lam):
            """Fractional band index of each wavelength (linear between the file's samples)."""
            w0, n = float(self._wl[0]), len(self._wl)
            if self._regular:
                return (lam - w0) / self._step
            if jit:
                k = dr.binary_search(
                    0, n - 1, lambda i: dr.gather(mi.Float, self._wl_jit, i) <= lam
                )
                j = dr.minimum(dr.maximum(k, 1) - 1, n - 2)  # unsigned: never k - 1 below 0
                a = dr.gather(mi.Float, self._wl_jit, j)
                b = dr.gather(mi.Float, self._wl_jit, j + 1)
                return mi.Float(j) + (lam - a) / (b - a)
            j = min(max(bisect.bisect_right(self._wl, lam) - 1, 0), n - 2)
            a, b = self._wl[j], self._wl[j + 1]
            return j + (lam - a) / (b - a)

        def eval(self, si, active=True):
            uv = si.uv if self._to_uv is None else self._to_uv @ si.uv
            w, h = self._size
            if self._nearest:
                # Texel centres: the bilinear weights of the neighbours are then zero.
                uv = mi.Point2f((dr.floor(uv.x * w) + 0.5) / w, (dr.floor(uv.y * h) + 0.5) / h)
            lo, hi, n = float(self._wl[0]), float(self._wl[-1]), len(self._wl)
            out = []
            for i in range(len(si.wavelengths)):
                lam = si.wavelengths[i]
                inside = (lam >= lo) & (lam <= hi)
                z = (dr.clip(self._band_index(lam), 0.0, n - 1.0) + 0.5) / n
                v = self._tex.eval(mi.Point3f(uv.x, uv.y, z), active)[0]
                out.append(dr.select(inside, v, 0.0))
            return mi.UnpolarizedSpectrum(out)

        def mean(self):
            return self._mean

        def is_spatially_varying(self):
            return True

        def resolution(self):
            return mi.ScalarVector2i(*self._size)

        def wavelength_range(self):
            return mi.ScalarVector2f(self._wl[0], self._wl[-1])

        def spectral_resolution(self):
            return float(np.min(np.diff(self._wl)))

        def traverse(self, callback):
            # The spectra as a tensor [bands, h, w, 1]: scenes can swap them, never differentiate.
            callback.put("data", self._tex.tensor(), mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys=[]):
            self._tex.set_tensor(self._tex.tensor())

        def to_string(self):
            w, h = self._size
            return (
                f"{type(self).__name__}[filename={self._source!r}, resolution={w}x{h}, "
                f"bands={len(self._wl)} ({self._wl[0]:g}-{self._wl[-1]:g} nm)]"
            )

    class SpectralTexture(_BandTexture):
        """``specconv_spectral``: a Fichet 2021 reflectance file (``filename``, ``level``)."""

        def __init__(self, props):
            mi.Texture.__init__(self, props)
            path = _resolve(props["filename"])
            image = specconv.read_spectral(path, level=int(props.get("level", 0)))
            if image.kind != "reflectance":
                raise ValueError(
                    f"{path}: this file holds {image.kind} (S0 channels, units "
                    f"{image.units!r}), not reflectance (T channels); {SPECTRAL} is a "
                    "reflectance texture: light it with an emitter instead, or convert the "
                    "source without --emissive"
                )
            self._setup(props, image.wavelengths, image.values, path)

    class RenderTimeTexture(_BandTexture):
        """``specconv_rgb``: an RGB texture (``filename``) uplifted with ``model`` at load.

        ``colorspace`` names the file's OCIO colour space in ``config`` (default: "sRGB -
        Texture" for files Mitsuba reads as sRGB-encoded, else "Linear Rec.709 (sRGB)", the
        ACES config's names for what ``convert`` assumes of PNG/JPEG and of OpenEXR).
        """

        def __init__(self, props):
            mi.Texture.__init__(self, props)
            path = _resolve(props["filename"])
            xyz = texel_xyz(path, props.get("colorspace", ""), props.get("config", "aces"))
            model = _model(props.get("model", ""))
            spectra = specconv.uplift(xyz, model=model, bounded=bool(props.get("bounded", True)))
            self._setup(props, model.wavelengths, spectra, path)

    return SpectralTexture, RenderTimeTexture


def _to_uv(props, jit: bool):
    """``to_uv`` as ``bitmap`` takes it: a 4×4 transform whose x, y and translation act on uv."""
    if "to_uv" not in props:
        return None
    m = np.array(props["to_uv"].matrix, dtype=np.float64)[np.ix_([0, 1, 3], [0, 1, 3])]
    return mi.Transform3f(m) if jit else mi.ScalarTransform3f(m)


def texel_xyz(path: str, colorspace: str = "", config: str = "aces") -> np.ndarray:
    """CIE XYZ [h, w, 3] of an RGB texture's texels, rows as stored, as ``specconv_rgb`` reads
    them: Mitsuba's reader, then the colour space through OCIO (``colorspace`` empty: "sRGB -
    Texture" for sRGB-encoded files, else "Linear Rec.709 (sRGB)"), premultiplied by alpha as
    ``convert`` uplifts it (straight colour decoded first; OpenEXR's is premultiplied already)."""
    bitmap = mi.Bitmap(path)
    alpha = bitmap.has_alpha()
    fmt = mi.Bitmap.PixelFormat.RGBA if alpha else mi.Bitmap.PixelFormat.RGB
    # Code values as stored: the colour space (through OCIO) decodes them, not Mitsuba.
    pixels = np.array(
        bitmap.convert(fmt, mi.Struct.Type.Float32, bitmap.srgb_gamma()), dtype=np.float32
    )
    if not colorspace:
        colorspace = "sRGB - Texture" if bitmap.srgb_gamma() else "Linear Rec.709 (sRGB)"
    rgb = np.ascontiguousarray(pixels[..., :3])
    xyz = np.asarray(specconv.rgb_to_xyz(rgb, colorspace, config=config), dtype=np.float32)
    if alpha and not bitmap.premultiplied_alpha():
        xyz *= pixels[..., 3:]
    return xyz


def _model(name: str):
    """A built-in model by name ("" for the default), else a model file by path."""
    if not name or not (name.endswith(".json") or "/" in name):
        return specconv.Model.builtin(name or None)
    return specconv.Model.load(_resolve(name))


def _resolve(path: str) -> str:
    """A scene's relative path, found as Mitsuba finds its own (the scene's folder first)."""
    return str(mi.file_resolver().resolve(path))


def _mean(wavelengths: np.ndarray, values: np.ndarray) -> float:
    """Mean over texels and over Mitsuba's wavelength range, zero outside the bands (as eval)."""
    lam = np.arange(mi.MI_CIE_MIN, mi.MI_CIE_MAX + 0.5, 1.0)
    spectrum = values.reshape(-1, values.shape[-1]).mean(axis=0, dtype=np.float64)
    return float(np.interp(lam, wavelengths, spectrum, left=0.0, right=0.0).mean())
