"""Type stubs of the compiled module (python/src)."""
from os import PathLike
from pathlib import Path
from typing import Any, Callable, Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, bytes, PathLike[str], PathLike[bytes]]
_Array = npt.ArrayLike

__version__: str

class Model:
    @staticmethod
    def builtin(name: Optional[str] = None) -> Model: ...
    @staticmethod
    def builtin_names() -> list[str]: ...
    @staticmethod
    def load(path: _Path) -> Model: ...
    @staticmethod
    def train(
        spectra: _Array,
        wavelengths: _Array,
        *,
        clusters: Optional[int] = None,
        min_cluster_size: Optional[int] = None,
        max_condition: Optional[float] = None,
        weights: Optional[_Array] = None,
        bands: str = "380:730:10",
        observer: str = "cie1931",
        illuminant: str = "D65",
        source: str = "numpy",
        licence: Optional[str] = None,
        commercial: Optional[str] = None,
        with_model: Optional[_Path] = None,
        with_data: Optional[_Path] = None,
        weight: float = 1.0,
    ) -> Model: ...
    def save(self, path: _Path, *, overwrite: bool = False) -> None: ...
    @property
    def wavelengths(self) -> npt.NDArray[np.float64]: ...
    @property
    def clusters(self) -> int: ...
    @property
    def observer(self) -> str: ...
    @property
    def illuminant(self) -> str: ...
    @property
    def sources(self) -> str: ...
    @property
    def commercial(self) -> str: ...
    @property
    def attribution(self) -> Optional[str]: ...
    @property
    def description(self) -> str: ...
    @property
    def path(self) -> Optional[str]: ...

class SpectralImage:
    wavelengths: npt.NDArray[np.float64]
    values: npt.NDArray[np.float32]
    alpha: Optional[npt.NDArray[np.float32]]
    kind: Literal["reflectance", "emission"]
    units: Optional[str]
    levels: int
    level: int
    attributes: dict[str, str]

class CompactImage:
    text: str
    texels: npt.NDArray[np.float32]
    alpha: Optional[npt.NDArray[np.float32]]
    levels: int
    level: int

def uplift(
    xyz: _Array,
    model: Optional[Model] = None,
    *,
    bounded: bool = True,
    blend: float = 0.02,
    method: str = "otsu2018",
    bands: Optional[str] = None,
    emission: Optional[str] = None,
) -> npt.NDArray[Any]: ...
def encode(
    xyz: _Array,
    model: Optional[Model] = None,
    *,
    bounded: bool = True,
    blend: float = 0.02,
    method: str = "otsu2018",
    bands: Optional[str] = None,
) -> tuple[str, npt.NDArray[np.float32]]: ...
def spectra_to_xyz(
    spectra: _Array,
    wavelengths: _Array,
    *,
    illuminant: str = "D65",
    observer: str = "cie1931",
    emission: Optional[str] = None,
) -> npt.NDArray[np.float64]: ...
def evaluate(
    spectra: _Array,
    wavelengths: _Array,
    model: Optional[Model] = None,
    *,
    under: Optional[Sequence[str]] = None,
    bounded: bool = True,
    blend: float = 0.02,
) -> dict[str, Any]: ...
def rgb_to_xyz(rgb: _Array, colorspace: str, config: Optional[str] = "aces") -> npt.NDArray[Any]: ...
# BEGIN GENERATED: convert's keywords (by `cargo run -p specconv-dev -- generate`, from the options' definitions)
def convert(
    inputs: Union[_Path, Sequence[_Path]],
    outputs: Union[None, _Path, Sequence[_Path]] = None,
    *,
    output_template: Optional[str] = None,
    update: bool = False,
    errors: Literal["raise", "record"] = "raise",
    progress: Optional[Callable[[int, Path, int, int], Any]] = None,
    ocio: Optional[str] = None,
    colorspace: Optional[str] = None,
    alpha: Literal["auto", "straight", "premultiplied", "unassociated", "associated"] = "auto",
    subimage: Optional[str] = None,
    channels: Optional[str] = None,
    method: Literal["otsu2018", "pca", "smits1999", "meng2015", "meng2015-bounded", "jakob2019"] = "otsu2018",
    model: Optional[Union[_Path, Model]] = None,
    blend: float = 0.02,
    bounded: bool = True,
    bands: Optional[str] = None,
    emission: Optional[Literal["reference", "normalised", "photometric", "normalized"]] = None,
    layout: Literal["spectral", "compact", "fichet"] = "spectral",
    sample: Literal["half", "float"] = "half",
    rounding: Optional[Literal["nearest", "colour", "color"]] = None,
    compression: Literal["none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"] = "zip",
    zip_level: Optional[int] = None,
    tile: Union[tuple[int, int], Literal["scanline"]] = (64, 64),
    mip: Union[Literal["all", "0", "true", "false"], bool] = "all",
    filter: Literal["box", "triangle", "gaussian", "sharp-gaussian", "catmull-rom", "blackman-harris", "sinc", "lanczos3", "radial-lanczos3", "nuke-lanczos6", "mitchell", "bspline", "disk", "cubic", "keys", "simon", "rifman"] = "box",
    resize: bool = False,
    wrap: Optional[str] = None,
    non_finite: Literal["refuse", "black", "box3", "keep", "check", "none"] = "refuse",
    constant_detect: bool = True,
    opaque_detect: bool = True,
    threads: Optional[int] = None,
    overwrite: bool = False,
    table_dir: Optional[_Path] = None,
    data: Literal["skip", "copy", "fail"] = "skip",
    strip_metadata: bool = False,
    strict: bool = False,
) -> list[dict[str, Any]]: ...
# END GENERATED: convert's keywords
def convert_asset(
    stage: _Path,
    output: _Path,
    *,
    update: bool = False,
    errors: Literal["raise", "record"] = "raise",
    dry_run: bool = False,
    progress: Optional[Callable[[int, Path, int, int], Any]] = None,
    **options: Any,
) -> list[dict[str, Any]]: ...
def options() -> list[dict[str, Any]]: ...
def read_spectral(path: _Path, *, level: int = 0) -> SpectralImage: ...
def read_compact(path: _Path, *, level: int = 0) -> CompactImage: ...
def check_readable(path: _Path) -> None: ...
def compact_limits() -> dict[str, float]: ...
def compact_texels(
    pixels: _Array,
    path: _Path,
    *,
    straight_alpha: bool = False,
    moved: bool = False,
    palette: bool = False,
    **options: Any,
) -> tuple[str, _Array | tuple[_Array, _Array], str]: ...
def palette(text: str, texels: _Array) -> tuple[_Array, _Array] | None: ...
def check_compact_header(
    path: _Path, attributes: dict[str, str], channels: list[str]
) -> tuple[str, list[int]]: ...
def write_spectral(
    path: _Path,
    wavelengths: _Array,
    values: _Array,
    *,
    alpha: Optional[_Array] = None,
    emission: Optional[Literal["reference", "normalised", "photometric"]] = None,
    sample: Literal["half", "float"] = "half",
    compression: str = "zip",
    tile: Optional[tuple[int, int]] = (64, 64),
    attributes: Optional[dict[str, str]] = None,
    overwrite: bool = False,
    emission_units: Optional[Literal["reference", "normalised", "photometric"]] = None,
) -> None: ...
