"""Compact textures decoded in numpy from their header text alone (docs/compact.md).

A compact texel is (X, Y, Z, u0, u1, u2); its spectrum is

    r = clip(sum_i w_i(xy) * (T_i c + l_dark o_i) + B u, 0, 1)

with the tree's blend weights w_i of the colour's chromaticity, the leaves' affine maps
(T_i, o_i), l_dark = min((X+Y+Z)/DARK, 1), B the output's XYZ weights by band, and no clip when
the header says ``clip 0``. This module reads the text a compact file's ``specconvCompact``
attribute holds (or ``encode`` returns) and evaluates that rule with numpy only: a second,
independent reading of the format, not a call of the library that wrote it. It is Python's
one decoder: Mitsuba's scalar variants call it per lookup; only Dr.Jit's, which must be
traced, is a second (specconv.mitsuba).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np
import numpy.typing as npt

__all__ = ["Header", "parse", "decode"]

# The largest float32: the reference's spectra are float32, so bands beyond it saturate there.
F32_MAX = float(np.finfo(np.float32).max)


@dataclass
class Header:
    """The model's part of a compact texture."""

    model: str = ""
    hash: str = ""
    wavelengths: np.ndarray = field(default_factory=lambda: np.zeros(0))
    white: tuple[float, float] = (1 / 3, 1 / 3)
    dark: float = 0.01
    blend: float = 0.0
    clip: bool = True
    # node index -> ("split", axis 0/1, value, below, above, width) or ("leaf", k)
    nodes: list = field(default_factory=list)
    # (leaves, 4, bands): T x, T y, T z, o
    maps: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 0)))
    # (3, bands): the rows of A, B's columns
    b: np.ndarray = field(default_factory=lambda: np.zeros((3, 0)))


def parse(text: str) -> Header:
    """The header text's content; raises ValueError on a text of another version."""
    lines = text.splitlines()
    if not lines or lines[0].strip() != "specconv compact 1":
        raise ValueError("not a text of `specconv compact 1`")
    h = Header()
    nodes: dict[int, tuple] = {}
    maps: dict[int, np.ndarray] = {}
    rows: dict[str, np.ndarray] = {}
    for line in lines[1:]:
        word, _, rest = line.partition(" ")
        if word == "model":
            h.model = rest
        elif word == "hash":
            h.hash = rest
        elif word == "wavelengths":
            h.wavelengths = np.array(rest.split(), dtype=np.float64)
        elif word == "white":
            x, y = rest.split()
            h.white = (float(x), float(y))
        elif word == "dark":
            h.dark = float(rest)
        elif word == "blend":
            h.blend = float(rest)
        elif word == "clip":
            h.clip = rest.strip() == "1"
        elif word == "node":
            w = rest.split()
            if w[1] == "leaf":
                nodes[int(w[0])] = ("leaf", int(w[2]))
            else:
                axis = {"x": 0, "y": 1}[w[2]]
                nodes[int(w[0])] = ("split", axis, float(w[3]), int(w[4]), int(w[5]), float(w[6]))
        elif word == "map":
            k, _, values = rest.partition(" ")
            maps[int(k)] = np.array(values.split(), dtype=np.float64)
        elif word == "b":
            name, _, values = rest.partition(" ")
            rows[name] = np.array(values.split(), dtype=np.float64)
    n = len(h.wavelengths)
    h.nodes = [nodes[i] for i in range(len(nodes))]
    h.maps = np.stack([maps[k] for k in range(len(maps))]).reshape(len(maps), 4, n)
    h.b = np.stack([rows["X"], rows["Y"], rows["Z"]])
    return h


def _weights(h: Header, xy: np.ndarray) -> np.ndarray:
    """Per colour, the weight of each leaf: the tree with each split's switch softened to a
    smoothstep over [v - w, v + w] of the coordinate (a hard switch, coordinate >= v going
    above, when the width is 0). A leaf's weight is the product of its path's factors: every
    split at once, no walk per call (the scalar Mitsuba lookup calls this per texel)."""
    tree = _tree(h)
    p = xy[:, tree.axis]
    if tree.smooth is None:
        s = p >= tree.value
    else:
        t = np.minimum(np.maximum((p - tree.value + tree.width) / tree.span, 0.0), 1.0)
        s = t * t * (3 - 2 * t)
        if tree.smooth is not True:
            s = np.where(tree.smooth, s, p >= tree.value)
    factors = np.concatenate((s, 1 - s, np.ones((len(p), 1))), axis=1)
    w = factors[:, tree.paths].prod(axis=2)
    return w if tree.leaf_map is None else w @ tree.leaf_map


@dataclass
class _Tree:
    """The tree as arrays: each split's axis, value, width and 2·width (1 where hard); which
    splits blend (True: all, None: none); each leaf's path as columns of [s, 1 - s, 1] (s of
    every split, 1 - s, then a 1 to pad), rows in map order; leaf_map when the leaves are not
    one per map (rows to maps)."""

    axis: np.ndarray
    value: np.ndarray
    width: np.ndarray
    span: np.ndarray
    smooth: object
    paths: np.ndarray
    leaf_map: Optional[np.ndarray]


def _tree(h: Header) -> _Tree:
    """The header's _Tree, cached on it while its nodes, blend and maps stay."""
    key = (tuple(h.nodes), h.blend, h.maps.shape[0])
    cached = getattr(h, "_tree_cache", None)
    if cached is not None and cached[0] == key:
        return cached[1]
    split = [i for i, node in enumerate(h.nodes) if node[0] == "split"]
    column = {node: k for k, node in enumerate(split)}
    nodes = [h.nodes[i] for i in split]
    smooth = np.array([h.blend > 0 and n[5] > 0 for n in nodes], dtype=bool)
    width = np.array([n[5] for n in nodes], dtype=np.float64)
    leaves, stack = [], [(0, [])]
    while stack:
        i, path = stack.pop()
        node = h.nodes[i]
        if node[0] == "leaf":
            leaves.append((node[1], path))
        else:
            k = column[i]
            stack += [(node[4], path + [k]), (node[3], path + [len(split) + k])]
    leaves.sort(key=lambda leaf: leaf[0])
    depth = max(len(path) for _, path in leaves)
    paths = np.full((len(leaves), max(depth, 1)), 2 * len(split), dtype=np.intp)
    leaf_map = np.zeros((len(leaves), h.maps.shape[0]))
    for row, (k, path) in enumerate(leaves):
        paths[row, : len(path)] = path
        leaf_map[row, k] = 1.0
    one_each = [k for k, _ in leaves] == list(range(h.maps.shape[0]))
    tree = _Tree(
        axis=np.array([n[1] for n in nodes], dtype=np.intp),
        value=np.array([n[2] for n in nodes], dtype=np.float64),
        width=width,
        span=np.where(smooth, 2 * width, 1.0),
        smooth=True if smooth.all() and len(nodes) else smooth if smooth.any() else None,
        paths=paths,
        leaf_map=None if one_each else leaf_map,
    )
    h._tree_cache = (key, tree)
    return tree


def decode(
    header_text: str | Header,
    texels: npt.ArrayLike,
    wavelengths: Optional[npt.ArrayLike] = None,
) -> np.ndarray:
    """Spectra of texels (..., 6) in float64: (..., bands) at the header's wavelengths, or at
    ``wavelengths`` (nm) by linear interpolation of those, ends held flat, as a reader of the
    spectral file interpolates its bands. NaN or infinite colours give NaN in every band.
    Bands beyond the largest float32 (``clip 0``) are that float, as in the file ``expand``
    writes and in every decoder."""
    h = header_text if isinstance(header_text, Header) else parse(header_text)
    t = np.asarray(texels, dtype=np.float64)
    lead = t.shape[:-1]
    r = _bands(h, t.reshape(-1, 6))
    if wavelengths is None:
        return r.reshape(lead + (r.shape[-1],))
    at = np.asarray(wavelengths, dtype=np.float64)
    r = _interpolate(h.wavelengths, r, at.ravel())
    # Within the bands' range again (a rounding can step past it), as the C header
    # saturates where it rounds to float.
    lo, hi = (0.0, 1.0) if h.clip else (-F32_MAX, F32_MAX)
    return np.minimum(np.maximum(r, lo), hi).reshape(lead + at.shape)


def _bands(h: Header, t: np.ndarray) -> np.ndarray:
    """The rule's spectra (p, bands) of texels t (p, 6), float64. Few numpy calls, fewer for
    ordinary texels: Mitsuba's scalar variants call this per lookup."""
    c, u = t[:, :3], t[:, 3:]
    # A texel with a value that is not finite (u too, where the rule adds it) is NaN
    # throughout: an infinite u would leave NaN only where a `b` row is 0 (∞·0).
    finite = None
    if not np.isfinite(t if h.clip else c).all():
        finite = np.isfinite(t if h.clip else c).all(axis=1)
        c, u = np.where(finite[:, None], c, 0.0), np.where(finite[:, None], u, 0.0)
    # The reference's overflow guard, exact in powers of two: c is summed scaled by 2^-k
    # and the sums scaled back. Float32 texels never need it in double; wider input might.
    k = None
    if np.abs(c).max(initial=0.0) >= 2.0**900:
        k = np.maximum(np.frexp(np.abs(c).max(axis=1))[1] - 900, 0)
        c = np.ldexp(c, -k[:, None])
    s = c.sum(axis=1)
    # X+Y+Z <= 0 has no chromaticity: the white point's leaves, without the offset.
    lit = s > 0
    if lit.all():
        xy = c[:, :2] / s[:, None]
    else:
        xy = np.where(lit[:, None], c[:, :2] / np.where(lit, s, 1.0)[:, None], h.white)
    if k is None:
        dark = np.minimum(s / h.dark, 1.0)
        if not lit.all():
            dark = np.where(lit, dark, 0.0)
    else:
        with np.errstate(over="ignore"):
            dark = np.ldexp(np.where(lit, np.minimum(np.ldexp(s, k) / h.dark, 1.0), 0.0), -k)
    # sum_i w_i (T_i c + l o_i): the blended map, then the colour.
    leaves, _, n = h.maps.shape
    maps = (_weights(h, xy) @ h.maps.reshape(leaves, -1)).reshape(len(t), 4, n)
    r = np.einsum("pk,pkn->pn", c, maps[:, :3]) + dark[:, None] * maps[:, 3]
    if k is not None:
        with np.errstate(over="ignore"):
            r = np.ldexp(r, k[:, None])
    if h.clip:
        r = np.minimum(np.maximum(r + u @ h.b, 0.0), 1.0)
    else:
        # As the reference's float32 spectra: a band beyond the largest float32 is that float.
        r = np.minimum(np.maximum(r, -F32_MAX), F32_MAX)
    if finite is not None:
        r[~finite] = np.nan
    return r


def _interpolate(wl: np.ndarray, r: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Bands r (p, n) at wavelengths wl, linearly at ``at`` (ends held flat), as np.interp
    (a band's own value at its wavelength and between two equal bands), vectorised."""
    if len(wl) < 2:
        return np.repeat(r[:, :1], len(at), axis=1)
    j = np.minimum(np.maximum(wl.searchsorted(at, side="right") - 1, 0), len(wl) - 2)
    x0 = wl[j]
    f = np.minimum(np.maximum((at - x0) / (wl[j + 1] - x0), 0.0), 1.0)
    r0, r1 = r[:, j], r[:, j + 1]
    return np.where(f == 1.0, r1, r0 + f * (r1 - r0))
