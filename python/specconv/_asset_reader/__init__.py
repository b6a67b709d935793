"""specconv's asset reader (docs/assets.md, "The reader"): what usd-core and MaterialX say of a
USD stage or a MaterialX document, for the library (crates/asset) to decide. One protocol
(protocol.py), two carriers: `specconv asset` runs this package in a child `python -I` (the
interpreter $SPECCONV_USD_PYTHON names, else python3) from the copy built into the program;
the Python package imports it and calls `answer`. It needs only the standard library, usd-core
(pxr) and MaterialX: never the compiled `specconv._specconv`, which that child may not have.

    python -I -m specconv._asset_reader < request.json
"""
import json
import sys

from . import mtlx
from .protocol import FAILED, OK, PROTOCOL, Failure, fail, text

__all__ = ["PROTOCOL", "answer", "main"]


def respond(request):
    """The answer (a JSON object) to `request`, or Failure."""
    if not isinstance(request, dict) or request.get("protocol") != PROTOCOL:
        got = request.get("protocol") if isinstance(request, dict) else None
        fail("protocol", "the request is in protocol %s and this reader speaks %d: specconv's "
             "program and its reader come from different versions; reinstall specconv"
             % (got, PROTOCOL))
    # The files one request loaded, not those of the ones before it in this interpreter.
    del mtlx.LOADED[:]
    from . import stage
    command = request.get("command")
    if command == "read":
        extract = request.get("extract") or {}
        return stage.read_any(request["stage"], extract.get("dir"),
                              extract.get("replaceable", []))
    if command == "layer":
        return stage.layer(request["plan"])
    fail("usage", "no command %r: read or layer" % (command,))


def answer(request):
    """The answer to `request` (JSON text) as (status, JSON text): protocol.OK, FAILED,
    NO_USD or NO_MATERIALX. Whatever usd-core, MaterialX or Python raise is said in one line,
    never a traceback."""
    try:
        return OK, text(respond(json.loads(request)))
    except Failure as f:
        return f.status, text(f.answer)
    except RecursionError:
        detail = ("a chain of connections, interfacenames or includes that loops or is deeper "
                  "than Python's limit")
        return FAILED, text(dict(error="loop", detail=detail))
    except UnicodeError as e:
        # The bytes around the one that is not text, so that the path can be found.
        around, start = getattr(e, "object", None), getattr(e, "start", 0)
        where = " in %r" % bytes(around[max(0, start - 40):start + 40]) \
            if isinstance(around, (bytes, bytearray)) else ""
        detail = "a path or a name that is not text in its encoding (%s%s)" % (e.reason, where)
        return FAILED, text(dict(error="encoding", detail=detail))
    except Exception as e:
        return FAILED, text(dict(error=type(e).__name__,
                                 detail=" ".join(str(e).split()) or "no message"))


def main():
    """The child's side: the request on standard input, the answer on standard output, the
    status as the exit status."""
    status, out = answer(sys.stdin.buffer.read())
    sys.stdout.write(out + "\n")
    return status
