"""Mitsuba 3 textures that read spectral reflectance (docs/renderers.md).

    import mitsuba as mi
    mi.set_variant("scalar_spectral")          # or llvm_ad_spectral
    import specconv.mitsuba
    specconv.mitsuba.register()                # after set_variant: plugins are per variant

    {"type": "diffuse", "reflectance": {"type": "specconv_spectral", "filename": "albedo.exr"}}
    {"type": "diffuse", "reflectance": {"type": "specconv_compact", "filename": "albedo_c.exr"}}
    {"type": "diffuse", "reflectance": {"type": "specconv_rgb", "filename": "albedo.png"}}

``specconv_spectral`` reads a Fichet 2021 reflectance file (ours or any other writer's, any
wavelength list) and looks it up as one trilinear fetch of a 3D texture whose depth axis is the
band: bilinear in uv and linear in wavelength commute.

``specconv_compact`` holds a compact file's six values per texel (docs/compact.md) and decodes
the model's spectra at each lookup in Dr.Jit: the four nearest texels' spectra at the path's
wavelengths, weighted bilinearly as ``bitmap`` weighs its texels'. Where the texels repeat (an
8-bit photograph's), it holds instead each texel's number in a palette of the distinct texels'
spectra at the bands, decoded once at load by the library, and a lookup reads two bands a
texel and wavelength. ``specconv_rgb`` makes those
texels at load, in memory: Mitsuba's reader decodes the image as ``bitmap``'s does, and the
library makes the texels of its pixels (a conversion's colour, alpha, data-map and NaN rules)
in parallel with the GIL released, so a scene ships the RGB file itself.

All evaluate alike, as Mitsuba's own ``bitmap`` does in space and as the layout's reference
(afichet/spectral-exr) integrates in wavelength:
- uv: ``to_uv`` applied, texel centres at (i + ½)/size, v = 0 at the first row the file stores
  (``bitmap``'s orientation), ``filter_type`` bilinear|nearest, ``wrap_mode`` repeat|mirror|clamp;
- wavelength: linear between the bands, zero outside their range (the reference integrates
  nothing there, and Mitsuba's own ``regular``/``irregular`` spectra are zero there too).

MIP levels: Mitsuba 3's integrators give textures no footprint (``si.duv_dx`` is zero; its
``bitmap`` has no MIP mapping either), so level 0 is read; ``level`` picks another by hand.
"""

from __future__ import annotations

import bisect

import drjit as dr
import mitsuba as mi
import numpy as np

import specconv
from specconv import compact
from specconv._specconv import check_readable
from specconv._specconv import compact_texels as _compact_texels
from specconv._specconv import palette as _palette

SPECTRAL = "specconv_spectral"
COMPACT = "specconv_compact"
# The largest float32: where the unbounded rule's sums saturate.
F32_MAX = compact.F32_MAX
RENDER_TIME = "specconv_rgb"

_FILTERS = {"bilinear": False, "nearest": True}
_WRAPS = {
    "repeat": dr.WrapMode.Repeat,
    "mirror": dr.WrapMode.Mirror,
    "clamp": dr.WrapMode.Clamp,
}


def register() -> None:
    """Register ``specconv_spectral``, ``specconv_compact`` and ``specconv_rgb`` for the current
    Mitsuba variant."""
    variant = mi.variant()
    if variant is None or "spectral" not in variant:
        raise RuntimeError(
            f"specconv.mitsuba needs a spectral Mitsuba variant (mi.set_variant('scalar_spectral') "
            f"or 'llvm_ad_spectral'), not {variant!r}: an RGB variant never asks a texture for "
            "spectra"
        )
    spectral, compact_, rgb = _classes(variant)
    mi.register_texture(SPECTRAL, lambda props: spectral(props))
    mi.register_texture(COMPACT, lambda props: compact_(props))
    mi.register_texture(RENDER_TIME, lambda props: rgb(props))


_CLASSES: dict = {}


def _classes(variant: str):
    """The texture classes for one variant: ``mi.Texture`` is a different class per variant."""
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

    class _Lookup(mi.Texture):
        """What both kinds of texture share: uv as ``bitmap`` takes it, the bands, the tensor."""

        def _common(self, props, size, wavelengths, source: str) -> None:
            self._source = source
            self._size = size
            self._bands = _Bands(wavelengths, jit)
            self._wl = self._bands.wavelengths
            self._nearest = _choice(props, "filter_type", _FILTERS, "bilinear")
            self._wrap = _choice(props, "wrap_mode", _WRAPS, "repeat")
            # None for the identity: most textures have none, and a lookup saves the transform.
            self._to_uv = _to_uv(props, jit)

        def _uv(self, si):
            return si.uv if self._to_uv is None else self._to_uv @ si.uv

        def is_spatially_varying(self):
            return True

        def resolution(self):
            return mi.ScalarVector2i(*self._size)

        def wavelength_range(self):
            return mi.ScalarVector2f(self._wl[0], self._wl[-1])

        def spectral_resolution(self):
            return float(np.min(np.diff(self._wl)))

        def traverse(self, callback):
            # The texture's tensor: scenes can swap it, never differentiate.
            callback.put("data", self._tex.tensor(), mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys=[]):
            self._tex.set_tensor(self._tex.tensor())

        def to_string(self):
            w, h = self._size
            return (
                f"{type(self).__name__}[filename={self._source!r}, resolution={w}x{h}, "
                f"bands={len(self._wl)} ({self._wl[0]:g}-{self._wl[-1]:g} nm)]"
            )

    class _BandTexture(_Lookup):
        """Spectra on a wavelength list, [h, w, n] rows top to bottom, looked up trilinearly
        (a tensor [bands, h, w, 1])."""

        def _setup(self, props, wavelengths, values, source: str) -> None:
            wavelengths = np.asarray(wavelengths, dtype=np.float64)
            values = np.asarray(values, dtype=np.float32)
            order = np.argsort(wavelengths)
            wavelengths, values = wavelengths[order], values[..., order]
            if len(wavelengths) < 2:
                raise ValueError(f"{source}: a spectral texture needs at least two bands")
            h, w, _ = values.shape
            self._common(props, (w, h), wavelengths, source)
            # Depth = band: one Texture3f lookup is bilinear in uv and linear in wavelength.
            tensor = np.ascontiguousarray(np.moveaxis(values, 2, 0)[..., None])
            self._tex = mi.Texture3f(
                mi.TensorXf(tensor),
                use_accel=False,
                filter_mode=dr.FilterMode.Linear,
                wrap_mode=self._wrap,
            )
            self._mean = _mean(self._wl, values)

        def eval(self, si, active=True):
            uv = self._uv(si)
            w, h = self._size
            if self._nearest:
                # Texel centres: the bilinear weights of the neighbours are then zero.
                uv = mi.Point2f((dr.floor(uv.x * w) + 0.5) / w, (dr.floor(uv.y * h) + 0.5) / h)
            lo, hi, n = float(self._wl[0]), float(self._wl[-1]), len(self._wl)
            out = []
            for i in range(len(si.wavelengths)):
                lam = si.wavelengths[i]
                inside = (lam >= lo) & (lam <= hi)
                z = (dr.clip(self._bands.index(lam), 0.0, n - 1.0) + 0.5) / n
                v = self._tex.eval(mi.Point3f(uv.x, uv.y, z), active)[0]
                out.append(dr.select(inside, v, 0.0))
            return mi.UnpolarizedSpectrum(out)

        def mean(self):
            return self._mean

    class _CompactTexture(_Lookup):
        """Compact texels [h, w, 6] (docs/compact.md), decoded at the path's wavelengths per
        lookup: the four nearest texels' spectra (one with ``nearest``) weighted bilinearly,
        as ``bitmap`` weighs its texels' spectra. In the JIT variants, where the texels repeat
        enough, the texture holds each texel's number in a palette of the distinct texels'
        spectra at the bands (``_Palette``) instead of the texels: ``traverse``'s ``data`` is
        then those numbers."""

        def _setup(self, props, text: str, texels, source: str) -> None:
            """``texels``: [h, w, 6], or a palette already made, ``(numbers, spectra)``."""
            header = compact.parse(text)
            if isinstance(texels, tuple):
                made = texels
            else:
                texels = np.ascontiguousarray(texels, dtype=np.float32)
                # Where the texels repeat (an 8-bit photograph's), their distinct spectra
                # decoded once and each texel's number: a lookup reads bands instead of
                # summing leaves.
                made = _palette(text, texels) if jit else None
            h, w, _ = (texels if made is None else made[0]).shape
            self._common(props, (w, h), header.wavelengths, source)
            self._decoder = _Decoder(header, self._bands, jit)
            self._palette = None if made is None else _Palette(made[1], self._decoder)
            data = texels if made is None else made[0]
            del texels, made
            self._tex = mi.Texture2f(
                mi.TensorXf(data),
                use_accel=False,
                filter_mode=dr.FilterMode.Nearest if self._nearest else dr.FilterMode.Linear,
                wrap_mode=self._wrap,
            )
            self._mean = None

        def eval(self, si, active=True):
            uv = self._uv(si)
            if self._nearest:
                texels, weights = [self._tex.eval(uv, active)], [1.0]
            else:
                # Bilinear weights as the texture places its texels: centres at (i + ½)/size.
                w, h = self._size
                fx, fy = _fraction(uv.x, w), _fraction(uv.y, h)
                texels = self._tex.eval_fetch(uv, active)  # (x0,y0) (x1,y0) (x0,y1) (x1,y1)
                weights = [(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy]
            lams = [si.wavelengths[i] for i in range(len(si.wavelengths))]
            if self._palette is not None:
                numbers = [t[0] for t in texels]
                return mi.UnpolarizedSpectrum(self._palette.weighted(numbers, weights, lams))
            return mi.UnpolarizedSpectrum(self._decoder.weighted(texels, weights, lams))

        def mean(self):
            if self._mean is None and self._palette is not None:
                numbers = np.array(self._tex.tensor(), dtype=np.float32).ravel()
                spectra = np.array(self._palette.values, dtype=np.float64)
                spectra = spectra.reshape(-1, self._palette.n)
                counts = np.bincount(numbers.astype(np.int64), minlength=len(spectra))
                self._mean = _mean_of(self._wl, counts @ spectra / max(len(numbers), 1))
            if self._mean is None:
                texels = np.array(self._tex.tensor(), dtype=np.float32).reshape(-1, 6)
                total = np.zeros(len(self._wl))
                for start in range(0, len(texels), 1 << 16):
                    chunk = texels[start : start + (1 << 16)]
                    total += compact.decode(self._decoder.header, chunk).sum(axis=0)
                self._mean = _mean_of(self._wl, total / max(len(texels), 1))
            return self._mean

        def parameters_changed(self, keys=[]):
            super().parameters_changed(keys)
            self._mean = None

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

    class CompactTexture(_CompactTexture):
        """``specconv_compact``: a compact texture (``filename``, ``level``), decoded per lookup."""

        def __init__(self, props):
            mi.Texture.__init__(self, props)
            path = _resolve(props["filename"])
            text, texels = compact_file(path, level=int(props.get("level", 0)))
            self._setup(props, text, texels, path)

    class RgbTexture(_CompactTexture):
        """``specconv_rgb``: an image (``filename``) made compact texels in memory at load
        (``compact_texels``), then decoded per lookup. In the JIT variants, where the pixels
        repeat enough, the route makes the palette straight from the distinct pixels it
        finds: no texel per pixel is made or hashed again."""

        def __init__(self, props):
            mi.Texture.__init__(self, props)
            path = _resolve(props["filename"])
            text, texels = _texels_of_image(
                path,
                colorspace=props.get("colorspace", "") or None,
                ocio=props.get("config", "") or None,
                model=_model_argument(props.get("model", "")),
                bounded=bool(props.get("bounded", True)),
                palette=jit,
            )
            self._setup(props, text, texels, path)

    return SpectralTexture, CompactTexture, RgbTexture


def _fraction(coordinate, size: int):
    """The bilinear weight of the upper texel, computed as Dr.Jit's texture computes the texel
    it fetches, ``fma(coordinate, size, -0.5)`` in float32, so that both name the same texels
    (a texel centre in double would land on the texel before)."""
    if dr.is_jit_v(type(coordinate)):
        p = dr.fma(coordinate, size, -0.5)
        return p - dr.floor(p)
    p = np.float32(float(coordinate) * size - 0.5)  # exact in double, then rounded once: fused
    return float(p - np.floor(p))


class _Bands:
    """A texture's band wavelengths and the fractional band index of a path's wavelength
    (linear between bands), as Dr.Jit code (JIT variants) or Python floats (scalar)."""

    def __init__(self, wavelengths, jit: bool):
        # Mitsuba's wavelengths are float32: a band at 400 nm must hold a lookup at 400 nm
        # even when a reader's unit conversion left it at 400.00000000000006.
        wl = np.asarray(wavelengths, dtype=np.float32).astype(np.float64)
        if len(wl) < 2:
            raise ValueError("a spectral texture needs at least two bands")
        self.wavelengths, self.jit = wl, jit
        steps = np.diff(wl)
        self.regular = bool(np.allclose(steps, steps[0], rtol=0, atol=1e-6 * steps[0]))
        self.step = float(steps[0])
        if jit:
            self.wl_jit = mi.Float(wl.astype(np.float32))

    def index(self, lam):
        """The fractional band index of each wavelength, unclipped."""
        wl, n = self.wavelengths, len(self.wavelengths)
        if self.regular:
            return (lam - float(wl[0])) / self.step
        if self.jit:
            k = dr.binary_search(0, n - 1, lambda i: dr.gather(mi.Float, self.wl_jit, i) <= lam)
            j = dr.minimum(dr.maximum(k, 1) - 1, n - 2)  # unsigned: never k - 1 below 0
            a = dr.gather(mi.Float, self.wl_jit, j)
            b = dr.gather(mi.Float, self.wl_jit, j + 1)
            return mi.Float(j) + (lam - a) / (b - a)
        j = min(max(bisect.bisect_right(wl, lam) - 1, 0), n - 2)
        return j + (lam - wl[j]) / (wl[j + 1] - wl[j])


class _Palette:
    """The spectra of a texture's distinct texels at the bands, each decoded once at load by
    the library's rule (``specconv._specconv.palette``): a lookup reads each texel's two bands
    around each wavelength and interpolates them, as ``_Decoder`` does once it has summed
    them, so the spectra are the rule's (in double where u ≠ 0, as ``expand`` writes them)."""

    def __init__(self, spectra: np.ndarray, decoder: "_Decoder"):
        self.n = spectra.shape[1]
        self.values = mi.Float(np.ascontiguousarray(spectra, dtype=np.float32).ravel())
        self.position = decoder._position

    def weighted(self, numbers, weights, lams):
        """Σ weight × spectrum of each texel, by its number, at each wavelength of ``lams``:
        a NaN texel NaN even at weight 0, zero outside the bands, as ``_Decoder.weighted``."""
        firsts = [mi.UInt32(number) * self.n for number in numbers]
        out = []
        for lam in lams:
            j, f, inside = self.position(lam)
            total = mi.Float(0.0)
            for first, w in zip(firsts, weights):
                r0 = dr.gather(mi.Float, self.values, first + j)
                r1 = dr.gather(mi.Float, self.values, first + j + 1)
                total = dr.fma(w, dr.fma(f, r1, (1 - f) * r0), total)
            out.append(dr.select(inside, total, 0.0))
        return out


class _Decoder:
    """docs/compact.md's rule on Dr.Jit values, for one header. In the JIT variants it is traced
    into the lookup's kernel, each leaf a branch that runs for packets where some texel weighs
    it: Python's only decoder besides numpy's, which the scalar variants call per lookup. Per
    wavelength the two bands around it are decoded and interpolated linearly (the clip acts per
    band, before); zero outside the bands, as the spectral file's lookup."""

    def __init__(self, header: compact.Header, bands: "_Bands", jit: bool):
        self.header, self.bands, self.jit = header, bands, jit
        self.wavelengths = bands.wavelengths
        leaves = header.maps.shape[0]
        self.leaves = leaves
        # A band's row: each leaf's (Tx, Ty, Tz, o), then (a_X, a_Y, a_Z, 0): 4-value packets.
        rows = np.zeros((len(self.wavelengths), leaves + 1, 4))
        rows[:, :leaves, :] = header.maps.transpose(2, 0, 1)
        rows[:, leaves, :3] = header.b.T
        if jit:
            self.table = mi.Float(rows.astype(np.float32).ravel())

    def weighted(self, texels, weights, lams):
        """Σ weight × spectrum of each texel (6 values), at each wavelength of ``lams``.

        Leaf by leaf, each leaf a branch that a packet of lanes skips when none of its texels
        weighs that leaf (Dr.Jit runs a symbolic branch only for packets with an active lane):
        neighbouring lookups mostly share one to three of the model's leaves."""
        if not self.jit:
            return self._weighted_numpy(texels, weights, lams)
        forms = [self._texel(t) for t in texels]
        stride = self.leaves + 1
        positions = [self._position(lam) for lam in lams]
        # Each wavelength's two bands: the first index of their rows in the table.
        firsts = [r for j, _, _ in positions for r in (j * stride, (j + 1) * stride)]
        sums = tuple(mi.Float(0.0) for _ in range(len(forms) * len(firsts)))
        for leaf in range(self.leaves):
            used = forms[0][0][leaf] > 0
            for form in forms[1:]:
                used |= form[0][leaf] > 0

            def add(*acc, leaf=leaf):
                acc = list(acc)
                for e, first in enumerate(firsts):
                    g = dr.gather(mi.Vector4f, self.table, first + leaf)
                    for t, form in enumerate(forms):
                        a, b, c, d = form[1][leaf]
                        i = t * len(firsts) + e
                        v = dr.fma(c, g.z, dr.fma(d, g.w, acc[i]))
                        acc[i] = dr.fma(a, g.x, dr.fma(b, g.y, v))
                return tuple(acc)

            sums = dr.if_stmt(sums, used, add, lambda *acc: acc, mode="symbolic")
        huge = forms[0][4] != 1.0
        for form in forms[1:]:
            huge |= form[4] != 1.0

        def scale_back(*acc):
            return tuple(v * forms[i // len(firsts)][4] for i, v in enumerate(acc))

        sums = dr.if_stmt(sums, huge, scale_back, lambda *acc: acc, mode="symbolic")
        if self.header.clip:
            # B·u, a branch of its own: u = 0 for the texels already in [0, 1].
            projected = mi.Bool(False)
            for form in forms:
                projected |= (form[2][0] != 0) | (form[2][1] != 0) | (form[2][2] != 0)

            def add_bu(*acc):
                acc = list(acc)
                for e, first in enumerate(firsts):
                    g = dr.gather(mi.Vector4f, self.table, first + self.leaves)
                    for t, form in enumerate(forms):
                        u, i = form[2], t * len(firsts) + e
                        acc[i] = dr.fma(u[0], g.x, dr.fma(u[1], g.y, dr.fma(u[2], g.z, acc[i])))
                return tuple(acc)

            sums = dr.if_stmt(sums, projected, add_bu, lambda *acc: acc, mode="symbolic")
            sums = tuple(dr.clip(v, 0.0, 1.0) for v in sums)
        else:
            # Unbounded, a sum beyond float32 saturates at its largest value, as the reference.
            sums = tuple(dr.clip(v, -F32_MAX, F32_MAX) for v in sums)
        out = []
        for p, (_, f, inside) in enumerate(positions):
            total = mi.Float(0.0)
            for t, ((_, _, _, finite, _), w) in enumerate(zip(forms, weights)):
                r0, r1 = (sums[t * len(firsts) + 2 * p + h] for h in (0, 1))
                # (1 − f)·r0 + f·r1: no r1 − r0 to overflow (unbounded bands near the
                # largest float), and a band's own value where f is 0 or 1.
                r = dr.select(finite, dr.fma(f, r1, (1 - f) * r0), dr.nan)
                total = dr.fma(w, r, total)
            out.append(dr.select(inside, total, 0.0))
        return out

    def _weighted_numpy(self, texels, weights, lams):
        """The scalar variants: numpy's decoder (compact.decode) on the lookup's texels, a
        NaN texel NaN even at weight 0, as in the traced path."""
        lams = np.array([float(lam) for lam in lams])
        r = compact.decode(self.header, np.array([list(t) for t in texels]), lams)
        total = np.array([float(w) for w in weights]) @ r
        wl = self.wavelengths
        return np.where((lams >= wl[0]) & (lams <= wl[-1]), total, 0.0).tolist()

    def _texel(self, t):
        """A texel's leaf weights wᵢ, per-leaf factors (wᵢX, wᵢY, wᵢZ, wᵢλ_dark), u, and
        whether it is finite."""
        h = self.header
        finite = dr.isfinite(t[0]) & dr.isfinite(t[1]) & dr.isfinite(t[2])
        if h.clip:
            # A u that is not finite makes every band NaN (docs/compact.md).
            finite &= dr.isfinite(t[3]) & dr.isfinite(t[4]) & dr.isfinite(t[5])
        x_, y_, z_ = (dr.select(finite, t[i], 0.0) for i in range(3))
        # The reference's overflow guard: a colour so large that X+Y+Z or T·c would overflow
        # float32 is summed scaled down and the sums scaled back (`weighted`). The scale is
        # the power of two 2ᵏ that brings the largest component below 2¹⁰¹ (k = 0 below it):
        # exact, and two multiplies where a division would cost more.
        m = dr.maximum(dr.maximum(dr.abs(x_), dr.abs(y_)), dr.abs(z_))
        k = dr.maximum(dr.reinterpret_array(mi.UInt32, m) >> 23, 227) - 227
        up = dr.reinterpret_array(mi.Float, (127 + k) << 23)
        down = dr.reinterpret_array(mi.Float, (127 - k) << 23)
        x_, y_, z_ = x_ * down, y_ * down, z_ * down
        s = x_ + y_ + z_
        lit = s > 0
        safe = dr.select(lit, s, 1.0)
        x = dr.select(lit, x_ / safe, h.white[0])
        y = dr.select(lit, y_ / safe, h.white[1])
        dark = dr.select(lit, dr.minimum(s * up / h.dark, 1.0), 0.0) * down
        scale = up
        leaf = [mi.Float(0.0) for _ in range(self.leaves)]

        def add(i, weight):
            node = h.nodes[i]
            if node[0] == "leaf":
                leaf[node[1]] = leaf[node[1]] + weight
                return
            _, axis, v, below, above, width = node
            p = x if axis == 0 else y
            if h.blend > 0 and width > 0:
                q = dr.clip((p - v + width) / (2 * width), 0.0, 1.0)
                step = q * q * (3 - 2 * q)
            else:
                step = dr.select(p >= v, 1.0, 0.0)
            add(above, weight * step)
            add(below, weight * (1 - step))

        add(0, mi.Float(1.0))
        k = [(w * x_, w * y_, w * z_, w * dark) for w in leaf]
        return leaf, k, (t[3], t[4], t[5]), finite, scale

    def _position(self, lam):
        """Band j, fraction f towards band j + 1, and whether lam is within the bands."""
        wl, n = self.wavelengths, len(self.wavelengths)
        index = dr.clip(self.bands.index(lam), 0.0, n - 1.0)
        j = dr.minimum(mi.UInt32(index), n - 2)
        inside = (lam >= float(wl[0])) & (lam <= float(wl[-1]))
        return j, index - mi.Float(j), inside


def compact_texels(
    path: str,
    *,
    colorspace: str | None = None,
    ocio: str | None = None,
    model=None,
    bounded: bool = True,
) -> tuple[str, np.ndarray]:
    """The decoding text and level-0 texels [h, w, 6] of an image Mitsuba reads, made in
    memory by the library (no file written): ``bitmap``'s reader decodes it, and the library
    makes the texels of its pixels in parallel with the GIL released, as a conversion with
    these options makes them (``specconv._specconv.compact_texels``): the colour space chosen
    from the file's header by the rule ``convert`` uses (``colorspace``, the config's file
    rules, ICC profiles, OpenEXR chromaticities and names, PNG chunks, the defaults), the
    file's samples as stored (an OpenEXR whose chromaticities ``mi.Bitmap`` converts is read
    by the library), straight alpha multiplied once converted, one channel refused as data
    unless declared colour, NaN refused."""
    return _texels_of_image(
        path, colorspace=colorspace, ocio=ocio, model=model, bounded=bounded, palette=False
    )


def _texels_of_image(path: str, *, colorspace, ocio, model, bounded: bool, palette: bool):
    """``compact_texels``; with ``palette``, where the pixels repeat enough, the texels are a
    palette, ``(numbers, spectra)`` (``specconv._specconv.palette``'s form)."""
    check_readable(path)  # a FIFO would hold Mitsuba's reader for ever
    try:
        bitmap = mi.Bitmap(path)
    except RuntimeError as e:
        raise ValueError(
            f"{path}: Mitsuba's reader cannot read it ({e}); for a format it does not read "
            "(TIFF, .tx), convert the file with specconv convert --layout compact and use "
            f"{COMPACT}"
        ) from e
    fmt = bitmap.pixel_format()
    formats = (mi.Bitmap.PixelFormat.Y, mi.Bitmap.PixelFormat.YA)
    formats += (mi.Bitmap.PixelFormat.RGB, mi.Bitmap.PixelFormat.RGBA)
    if fmt not in formats:
        raise ValueError(
            f"{path}: Mitsuba reads it as {fmt.name} pixels ({bitmap.channel_count()} channels); "
            f"{RENDER_TIME} takes grey or RGB images, with or without alpha: convert it with "
            "specconv convert --layout compact (naming its channels or layer) and use "
            f"{COMPACT}"
        )
    pixels = np.array(bitmap, copy=False)
    options = {"colorspace": colorspace, "ocio": ocio, "bounded": bounded}
    if model is not None:
        options["model"] = model
    text, texels, _ = _compact_texels(
        pixels,
        path,
        straight_alpha=not bitmap.premultiplied_alpha(),
        moved=True,
        palette=palette,
        **options,
    )
    return text, texels


def compact_file(path: str, level: int = 0) -> tuple[str, np.ndarray]:
    """The decoding text and texels [h, w, 6] of level ``level`` of a compact file, read by
    the library's own OpenEXR reader (``specconv.read_compact``: blocks decompressed in
    parallel, no OpenImageIO in the process). Not ``mi.Bitmap``: it reads a file of half and
    float channels (the default) all as half, rounding the float u, and reading the file with
    it first to find out cost a second read of every default file."""
    image = specconv.read_compact(path, level=level)
    return image.text, image.texels


def _to_uv(props, jit: bool):
    """``to_uv`` as ``bitmap`` takes it: a 4×4 transform whose x, y and translation act on uv."""
    if "to_uv" not in props:
        return None
    m = np.array(props["to_uv"].matrix, dtype=np.float64)[np.ix_([0, 1, 3], [0, 1, 3])]
    return mi.Transform3f(m) if jit else mi.ScalarTransform3f(m)


def _model_argument(name: str):
    """``model``: "" for the model in force (``$SPECCONV_MODEL``, else the built-in default, as
    the library decides), a built-in name, or a model file (``.json``) found as
    the scene's files are."""
    if not name:
        return None
    if name.endswith(".json") or "/" in name:
        return _resolve(name)
    return name


def _resolve(path: str) -> str:
    """A scene's relative path, found as Mitsuba finds its own (the scene's folder first)."""
    return str(mi.file_resolver().resolve(path))


def _mean(wavelengths: np.ndarray, values: np.ndarray) -> float:
    """Mean over texels and over Mitsuba's wavelength range, zero outside the bands (as eval)."""
    spectrum = values.reshape(-1, values.shape[-1]).mean(axis=0, dtype=np.float64)
    return _mean_of(wavelengths, spectrum)


def _mean_of(wavelengths: np.ndarray, spectrum: np.ndarray) -> float:
    """A spectrum's mean over Mitsuba's wavelength range, zero outside the bands (as eval)."""
    lam = np.arange(mi.MI_CIE_MIN, mi.MI_CIE_MAX + 0.5, 1.0)
    return float(np.interp(lam, wavelengths, spectrum, left=0.0, right=0.0).mean())
