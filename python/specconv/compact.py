"""Compact textures decoded in numpy from their header text alone (docs/compact.md).

A compact texel is (X, Y, Z, u0, u1, u2); its spectrum is

    r = clip(sum_i w_i(xy) * (T_i c + l_dark o_i) + B u, 0, 1)

with the tree's blend weights w_i of the colour's chromaticity, the leaves' affine maps
(T_i, o_i), l_dark = min((X+Y+Z)/DARK, 1), B the output's XYZ weights by band, and no clip when
the header says ``clip 0``. A file stores nine values a texel (R G B U.0 U.1 U.2 UF.0 UF.1
UF.2: the colour in the working space whose matrix to XYZ the text's ``rgb`` line gives, u as
half, u as float32), which ``unstore`` turns into the six. This module reads the text a compact file's ``specconvCompact``
attribute holds (or ``encode`` returns) and evaluates that rule with numpy only: a second,
independent reading of the format, not a call of the library that wrote it. It is Python's
one decoder: Mitsuba's scalar variants call it per lookup; only Dr.Jit's, which must be
traced, is a second (specconv.mitsuba).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Optional

import numpy as np
import numpy.typing as npt

from specconv._specconv import compact_limits

_limits = compact_limits()

__all__ = ["Header", "parse", "decode", "unstore", "VERSION"]

# The first line of the texts this module reads.
VERSION = "specconv compact 2"

# The largest float32: the reference's spectra are float32, so bands beyond it saturate there.
F32_MAX = float(np.finfo(np.float32).max)

# The grammar's limits, the library's own (docs/compact.md): the deepest tree, the most bands,
# the dark level, the widest blend.
MAX_DEPTH, MAX_BANDS, DARK, MAX_WIDTH = (
    _limits["max_depth"],
    _limits["max_bands"],
    _limits["dark"],
    _limits["max_width"],
)


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
    # the working space's matrix to XYZ (3, 3): XYZ = rgb @ RGB
    rgb: np.ndarray = field(default_factory=lambda: np.eye(3))
    # node index -> ("split", axis 0/1, value, below, above, width) or ("leaf", k)
    nodes: list = field(default_factory=list)
    # (leaves, 4, bands): T x, T y, T z, o
    maps: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 0)))
    # (3, bands): the rows of A, B's columns
    b: np.ndarray = field(default_factory=lambda: np.zeros((3, 0)))


_NUMBER = re.compile(r"[+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?\Z")
_KEYWORD = re.compile(r"[a-z][a-z0-9_]*\Z")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
_ONCE = ("model", "hash", "grid", "wavelengths", "white", "dark", "blend", "clip", "rgb")
_KNOWN = _ONCE + ("node", "map", "b")


def _number(w: str) -> float:
    """A number of the grammar (ASCII decimal; no inf, nan, ``_`` or spaces, which float takes)."""
    if not _NUMBER.match(w):
        raise ValueError(f"'{w}' is not a finite decimal number")
    v = float(w)
    if not math.isfinite(v):
        raise ValueError(f"'{w}' is not a finite decimal number")
    return v


def _index(w: str, count: int, what: str) -> int:
    """An index of the grammar: ASCII digits, below count."""
    if not w.isascii() or not w.isdigit():
        raise ValueError(f"'{w}' is not an index")
    # Long digit strings are out of range whatever their value (and int() would refuse them).
    if len(w) > 18 or int(w) >= count:
        raise ValueError(f"{what} {w} is out of range (0 to {max(count, 1) - 1})")
    return int(w)


def parse(text: str) -> Header:
    """The header text's content, read by the grammar of docs/compact.md ("The header text"),
    the library's: anything else raises ValueError with the line and why."""
    h = Header()
    nodes: list = []
    maps: list = []
    rows: dict[str, np.ndarray] = {}
    seen: set = set()
    grid = None
    for i, raw in enumerate(text.split("\n")):
        line = raw[:-1] if raw.endswith("\r") else raw
        try:
            if i == 0:
                if line != VERSION:
                    raise ValueError(_version_error(line))
                continue
            if not line:
                continue
            grid = _line(h, line, seen, nodes, maps, rows, grid)
        except ValueError as e:
            raise ValueError(f"line {i + 1}: {e}: {line[:60]!r}") from None
    return _build(h, seen, nodes, maps, rows, grid)


def _version_error(line: str) -> str:
    """Why a first line is not this version's, naming the version it has when it names one."""
    if line.startswith("specconv compact "):
        return (
            f"compact version '{line[17:]}', which this specconv does not read (it reads "
            f"`{VERSION}`): convert the texture again, or decode it with the specconv that wrote it"
        )
    return f"not a text of `{VERSION}`"


def _line(h: Header, line: str, seen: set, nodes: list, maps: list, rows: dict, grid):
    """One line read into h (nodes, maps and rows as they come); returns the grid."""
    if _CONTROL.search(line):
        raise ValueError("a control character (a tab, a CR, ...): words are separated by single spaces")
    word, space, rest = line.partition(" ")
    if not _KEYWORD.match(word):
        raise ValueError(f"'{word}' is no keyword (a-z, then a-z, 0-9 or _)")
    if word in _ONCE:
        if word in seen:
            raise ValueError(f"a second '{word}' line")
        seen.add(word)
    if word == "model":
        h.model = rest
        return grid
    if word not in _KNOWN:
        return grid  # decoders skip what they do not know, whatever its fields
    w = rest.split(" ") if space else []
    if "" in w:
        raise ValueError("an empty field (two spaces, or a space at the end)")
    if word == "hash":
        if len(w) != 1 or not re.fullmatch(r"[0-9a-f]{16}", w[0]):
            raise ValueError("a hash is 16 hex digits (0-9, a-f)")
        h.hash = w[0]
    elif word == "grid":
        if len(w) != 3:
            raise ValueError("a grid is START END STEP")
        grid = tuple(_number(v) for v in w)
    elif word == "wavelengths":
        if not 1 <= len(w) <= MAX_BANDS:
            raise ValueError(f"{len(w)} wavelengths (1 to {MAX_BANDS})")
        h.wavelengths = np.array([_number(v) for v in w])
    elif word == "white":
        if len(w) != 2:
            raise ValueError("white is x y")
        h.white = (_number(w[0]), _number(w[1]))
    elif word == "dark":
        if len(w) != 1 or _number(w[0]) != DARK:
            raise ValueError(f"the dark level is {DARK}, one number")
        h.dark = DARK
    elif word == "blend":
        if len(w) != 1 or not 0 <= _number(w[0]) <= MAX_WIDTH:
            raise ValueError(f"blend is one width from 0 to {MAX_WIDTH}")
        h.blend = _number(w[0])
    elif word == "clip":
        if w not in (["0"], ["1"]):
            raise ValueError("clip is 0 or 1, one field")
        h.clip = w == ["1"]
    elif word == "rgb":
        if len(w) != 9:
            raise ValueError("rgb is the working space's matrix to XYZ, 9 numbers")
        h.rgb = np.array([_number(v) for v in w]).reshape(3, 3)
    elif word == "node":
        if len(w) == 3 and w[1] == "leaf":
            nodes.append((w[0], ("leaf", _index(w[2], 1 << 62, "leaf"))))
        elif len(w) == 7 and w[1] == "split" and w[2] in ("x", "y"):
            b, a = _index(w[4], 1 << 62, "node"), _index(w[5], 1 << 62, "node")
            nodes.append((w[0], ("split", "xy".index(w[2]), _number(w[3]), b, a, _number(w[6]))))
        else:
            raise ValueError("a node is `I leaf K` or `I split AXIS VALUE BELOW ABOVE WIDTH`")
    elif word == "map":
        if not w:
            raise ValueError("a map is K VALUES")
        maps.append((w[0], np.array([_number(v) for v in w[1:]])))
    elif word == "b":
        if not w or w[0] not in ("X", "Y", "Z"):
            raise ValueError(f"a b row is X, Y or Z, not {w[:1]}")
        if w[0] in rows:
            raise ValueError(f"a second 'b {w[0]}' line")
        rows[w[0]] = np.array([_number(v) for v in w[1:]])
    # Decoders skip what they do not know.
    return grid


def _numbered(items: list, what: str) -> list:
    """The items in the order of their indices, which must be 0 ... count - 1, each once."""
    out: list = [None] * len(items)
    for i, item in items:
        k = _index(i, len(items), what)
        if out[k] is not None:
            raise ValueError(f"a second {what} {k}")
        out[k] = item
    return out


def _grid_bands(start: float, end: float, step: float) -> Optional[np.ndarray]:
    """The library's grid START END STEP (0 < START <= END, STEP > 0, END - START a whole
    number of steps to 1e-9 relative, at most MAX_BANDS bands): START + i * STEP; None if not."""
    if not (start > 0 and step > 0 and end >= start):
        return None
    intervals = (end - start) / step
    whole = math.floor(intervals + 0.5)
    if abs(intervals - whole) > 1e-9 * max(intervals, 1.0) or whole + 1 > MAX_BANDS:
        return None
    return np.array([start + step * float(i) for i in range(whole + 1)])


def _build(h: Header, seen: set, nodes: list, maps: list, rows: dict, grid) -> Header:
    """The header once every line is read: what holds between lines (docs/compact.md)."""
    missing = [w for w in _ONCE if w not in seen]
    if missing:
        raise ValueError(f"no {', '.join(missing)} line")
    if set(rows) != {"X", "Y", "Z"}:
        raise ValueError("three b rows (X, Y, Z) are required")
    bands = _grid_bands(*grid)
    wl = h.wavelengths
    if bands is None or len(bands) != len(wl) or (bands != wl).any() or (np.diff(wl) <= 0).any():
        raise ValueError(f"the wavelengths line is not the grid's ({grid}: START + i * STEP)")
    n = len(wl)
    if any(len(r) != n for r in rows.values()):
        raise ValueError(f"a b row needs {n} numbers, one a band")
    h.nodes = _numbered(nodes, "node")
    map_list = _numbered(maps, "map")
    if not map_list or any(len(m) != 4 * n for m in map_list):
        raise ValueError(f"every map needs 4 x {n} numbers, and there is one at least")
    for i, node in enumerate(h.nodes):
        if node[0] == "split" and (
            not h.blend <= node[5] <= MAX_WIDTH if h.blend > 0 else node[5] != 0
        ):
            raise ValueError(f"node {i}'s width is outside [blend, {MAX_WIDTH}] (0 with blend 0)")
    _check_tree(h.nodes, len(map_list))
    h.maps = np.stack(map_list).reshape(len(map_list), 4, n)
    h.b = np.stack([rows["X"], rows["Y"], rows["Z"]])
    return h


def _check_tree(nodes: list, maps: int) -> None:
    """From node 0 every node reached once, at most MAX_DEPTH splits to a leaf, each map the
    map of one leaf: without recursion, in time linear in the nodes."""
    if not nodes:
        raise ValueError("the tree has no nodes")
    reached, used, stack = [False] * len(nodes), [False] * maps, [(0, 0)]
    while stack:
        i, depth = stack.pop()
        if i >= len(nodes):
            raise ValueError(f"the tree refers to node {i}, which does not exist")
        if depth > MAX_DEPTH:
            raise ValueError(f"the tree is deeper than {MAX_DEPTH} splits (node {i})")
        if reached[i]:
            raise ValueError(f"node {i} is reached twice: the tree has a cycle or shared child")
        reached[i] = True
        node = nodes[i]
        if node[0] == "leaf":
            if node[1] >= maps or used[node[1]]:
                raise ValueError(f"node {i}'s map {node[1]} does not exist or has a leaf already")
            used[node[1]] = True
        else:
            stack += [(node[3], depth + 1), (node[4], depth + 1)]
    if not all(reached) or not all(used):
        raise ValueError("a node is not reached from the root, or a map has no leaf")


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


def unstore(header_text: str | Header, stored: npt.ArrayLike) -> np.ndarray:
    """The six values (..., 6) the rule decodes, float32, from the nine (..., 9) a file stores:
    the colour's XYZ, the rgb matrix times (R, G, B) summed in double in that order and
    rounded to float32 once, as every decoder computes it; u = U + UF."""
    h = header_text if isinstance(header_text, Header) else parse(header_text)
    s = np.asarray(stored, dtype=np.float32)
    rgb = s[..., :3].astype(np.float64)
    m = h.rgb
    out = np.empty(s.shape[:-1] + (6,), dtype=np.float32)
    with np.errstate(invalid="ignore", over="ignore"):
        for i in range(3):
            out[..., i] = (m[i, 0] * rgb[..., 0] + m[i, 1] * rgb[..., 1] + m[i, 2] * rgb[..., 2]).astype(
                np.float32
            )
        out[..., 3:] = s[..., 3:6] + s[..., 6:9]
    return out


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
