"""The asset reader's protocol (docs/assets.md, "The reader"): one request in, one answer out,
each a JSON object carrying PROTOCOL, whichever way it is carried (a child `python -I` for the
command line, an import for the Python package).

A request is {"protocol", "command": "read", "stage", "extract": null | {"dir", "replaceable"}}
or {"protocol", "command": "layer", "plan"}. An answer is the result, or {"error", "detail"},
with a status: OK, FAILED, NO_USD (usd-core, the pxr module, is missing) or NO_MATERIALX.
"""
import json

# Raised whenever a request or an answer changes shape; crates/asset/src/reader.rs checks it.
PROTOCOL = 1
OK, FAILED, NO_USD, NO_MATERIALX = 0, 2, 3, 4


class Failure(Exception):
    """The answer to a request that failed: its status and its JSON object."""

    def __init__(self, status, answer):
        super().__init__(answer.get("detail"))
        self.status, self.answer = status, answer


def fail(kind, detail, status=FAILED, **more):
    raise Failure(status, dict(error=kind, detail=detail, **more))


def text(answer):
    """The answer as the JSON text both carriers give back."""
    return json.dumps(dict(answer, protocol=PROTOCOL))
