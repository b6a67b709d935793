"""Compact textures decoded in numpy from their header text alone (docs/compact.md).

A compact texel is (X, Y, Z, u0, u1, u2); its spectrum is

    r = clip(sum_i w_i(xy) * (T_i c + l_dark o_i) + B u, 0, 1)

with the tree's blend weights w_i of the colour's chromaticity, the leaves' affine maps
(T_i, o_i), l_dark = min((X+Y+Z)/DARK, 1), B the output's XYZ weights by band, and no clip when
the header says ``clip 0``. This module reads the text a compact file's ``specconvCompact``
attribute holds (or ``encode`` returns) and evaluates that rule with numpy only: a second,
independent reading of the format, not a call of the library that wrote it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np
import numpy.typing as npt

__all__ = ["Header", "parse", "decode"]


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
    above, when the width is 0)."""
    out = np.zeros((len(xy), h.maps.shape[0]))

    def add(i: int, weight: np.ndarray) -> None:
        node = h.nodes[i]
        if node[0] == "leaf":
            out[:, node[1]] += weight
            return
        _, axis, v, below, above, width = node
        u = xy[:, axis]
        if h.blend > 0 and width > 0:
            t = np.clip((u - v + width) / (2 * width), 0.0, 1.0)
            s = t * t * (3 - 2 * t)
        else:
            s = (u >= v).astype(np.float64)
        if np.any(weight * s > 0):
            add(above, weight * s)
        if np.any(weight * (1 - s) > 0):
            add(below, weight * (1 - s))

    add(0, np.ones(len(xy)))
    return out


def decode(
    header_text: str | Header,
    texels: npt.ArrayLike,
    wavelengths: Optional[npt.ArrayLike] = None,
) -> np.ndarray:
    """Spectra of texels (..., 6) in float64: (..., bands) at the header's wavelengths, or at
    ``wavelengths`` (nm) by linear interpolation of those, ends held flat, as a reader of the
    spectral file interpolates its bands. NaN or infinite colours give NaN in every band."""
    h = header_text if isinstance(header_text, Header) else parse(header_text)
    t = np.asarray(texels, dtype=np.float64)
    lead = t.shape[:-1]
    t = t.reshape(-1, 6)
    c, u = t[:, :3], t[:, 3:]
    # A texel with a value that is not finite (u too, where the rule adds it) is NaN
    # throughout: an infinite u would leave NaN only where a `b` row is 0 (∞·0).
    finite = np.all(np.isfinite(c), axis=1)
    if h.clip:
        finite &= np.all(np.isfinite(u), axis=1)
    c = np.where(finite[:, None], c, 0.0)
    s = c.sum(axis=1)
    # X+Y+Z <= 0 has no chromaticity: the white point's leaves, without the offset.
    lit = s > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        xy = np.where(lit[:, None], c[:, :2] / np.where(lit, s, 1.0)[:, None], h.white)
    dark = np.where(lit, np.minimum(s / h.dark, 1.0), 0.0)
    w = _weights(h, xy)
    # sum_i w_i (T_i c + l o_i): the blended map, then the colour.
    m = np.einsum("pl,lkn->pkn", w, h.maps)
    r = np.einsum("pk,pkn->pn", c, m[:, :3, :]) + dark[:, None] * m[:, 3, :]
    if h.clip:
        r = np.clip(r + np.where(finite[:, None], u, 0.0) @ h.b, 0.0, 1.0)
    r[~finite] = np.nan
    if wavelengths is not None:
        at = np.asarray(wavelengths, dtype=np.float64)
        r = np.stack([np.interp(at, h.wavelengths, row) for row in r]) if len(r) else r
        return r.reshape(lead + at.shape)
    return r.reshape(lead + (r.shape[-1],))
