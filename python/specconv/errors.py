"""The exceptions of specconv, by kind.

Every error the library reports is a :class:`specconv.Error`; each kind is also the built-in
exception a Python caller already catches for it (``ValueError`` for what is wrong with a
setting or an input, ``OSError`` for files), and carries the library's message with the keyword
that would fix it.
"""


class Error(Exception):
    """Any error specconv reports."""


class OptionError(Error, ValueError):
    """A setting is wrong: an unknown colour space, model, grid, compression, a bad shape."""


class InputError(Error, ValueError):
    """An input cannot be converted as asked: NaN pixels, a data texture, channels to choose."""


class FileError(Error, OSError):
    """A file cannot be read or written, or may not be (an output that is an input)."""


class OutputExistsError(FileError, FileExistsError):
    """An output exists and replacing it was not asked for (``overwrite=True``)."""


__all__ = ["Error", "OptionError", "InputError", "FileError", "OutputExistsError"]
