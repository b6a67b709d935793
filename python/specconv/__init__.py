"""specconv: spectral reflectance textures from colour textures, from Python.

The same library as the ``specconv`` command, numpy in and out::

    import numpy as np, specconv
    xyz = specconv.rgb_to_xyz(srgb, "sRGB - Texture")      # (..., 3) through OpenColorIO
    spectra = specconv.uplift(xyz)                          # (..., 36), 380-730 nm
    specconv.convert("albedo.png", "albedo_spectral.exr")   # the CLI's bytes

See docs/python.md in the repository.
"""

from specconv._specconv import (
    CompactImage,
    Model,
    SpectralImage,
    __version__,
    convert,
    convert_asset,
    encode,
    evaluate,
    options,
    read_compact,
    read_spectral,
    rgb_to_xyz,
    spectra_to_xyz,
    uplift,
    write_spectral,
)
from specconv.compact import decode
from specconv.errors import Error, FileError, InputError, OptionError, OutputExistsError

__all__ = [
    "CompactImage",
    "Model",
    "SpectralImage",
    "__version__",
    "convert",
    "convert_asset",
    "decode",
    "encode",
    "evaluate",
    "options",
    "read_compact",
    "read_spectral",
    "rgb_to_xyz",
    "spectra_to_xyz",
    "uplift",
    "write_spectral",
    "Error",
    "FileError",
    "InputError",
    "OptionError",
    "OutputExistsError",
]
