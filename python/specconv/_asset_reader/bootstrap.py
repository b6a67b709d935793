"""The command line's carrier (crates/asset/src/reader.rs), never imported by the package: run
as `python -I -c BOOTSTRAP NAME SOURCE …` with this package's modules as arguments, it imports
them from those strings as the package `_specconv_asset_reader` (nothing is written to disk),
then answers the request on standard input.

`-I` keeps the working directory, the user's site-packages and every PYTHON* variable off the
import path, so that a stray json.py or pxr.py where specconv runs is never imported.
PYTHONPATH is how studios reach their own USD build, so its absolute folders are put back
where Python puts them, first; an empty or relative entry (the working directory by another
name) is not.
"""
import importlib.abc
import importlib.util
import os
import sys

PACKAGE = "_specconv_asset_reader"


class Embedded(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """PACKAGE and its modules, from their sources."""

    def __init__(self, sources):
        self.sources = sources

    def find_spec(self, name, path=None, target=None):
        if name not in self.sources:
            return None
        return importlib.util.spec_from_loader(name, self, is_package=name == PACKAGE)

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        name = module.__name__
        code = compile(self.sources[name], "<specconv asset reader>/%s.py" % name, "exec")
        exec(code, module.__dict__)


sys.path[0:0] = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                 if os.path.isabs(p)]
args = sys.argv[1:]
sources = {PACKAGE + ("" if n == "__init__" else "." + n): s
           for n, s in zip(args[0::2], args[1::2])}
sys.meta_path.insert(0, Embedded(sources))
reader = importlib.import_module(PACKAGE)
sys.exit(reader.main())
