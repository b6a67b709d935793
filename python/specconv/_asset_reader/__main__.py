"""`python -I -m specconv._asset_reader`: one request on standard input (protocol.py)."""
import sys

from . import main

sys.exit(main())
