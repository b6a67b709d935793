"""The installed package carries the licences of what it is built from and trained on:
THIRD-PARTY.md (scripts/third_party.py writes it) in its .dist-info/licenses/, named by the
metadata's License-File (PEP 639; python/pyproject.toml's `license-files`). maturin writes the
dist-info of `maturin develop` as of a wheel (it builds one and pip installs it), so the
package this suite runs against has it too."""
import importlib.metadata
import pathlib

import pytest

from conftest import ROOT

NAME = "THIRD-PARTY.md"


@pytest.fixture(scope="module")
def dist():
    try:
        return importlib.metadata.distribution("specconv")
    except importlib.metadata.PackageNotFoundError:
        pytest.fail("specconv is not installed: maturin develop -m python/Cargo.toml, or "
                    "pip install ./python (docs/python.md)")


def test_metadata_names_the_licence_files(dist):
    assert dist.metadata.get_all("License-File") == ["LICENSE-MIT", "LICENSE-APACHE", NAME]
    assert dist.metadata["License-Expression"] == "MIT OR Apache-2.0"


def test_dist_info_holds_third_party_md(dist):
    # Listed in RECORD at <name>.dist-info/licenses/THIRD-PARTY.md...
    recorded = [f for f in dist.files or []
                if f.parts[-2:] == ("licenses", NAME) and f.parts[-3].endswith(".dist-info")]
    assert len(recorded) == 1, f"no licenses/{NAME} in the dist-info's RECORD: {dist.files}"
    path = pathlib.Path(dist.locate_file(recorded[0]))
    assert path.is_file(), path
    # ...and there on disk, the same file the dist-info reader finds.
    text = dist.read_text(f"licenses/{NAME}")
    assert text is not None and text == path.read_text(encoding="utf-8")

    # The crates' licences and the training data's terms.
    assert "| serde | " in text and "| pyo3 | " in text
    assert "Apache License" in text and "Permission is hereby granted" in text
    assert "hyppigments_405-780_5nm.csv" in text and "CC BY 4.0" in text
    assert "Copyright 2013 Colour Developers" in text  # crates/spectral/notices/
    assert "Copyright (c) 2022 Beth McDonald" in text

    # The copy this checkout would ship: an install older than it is stale.
    assert text == (ROOT / "python" / NAME).read_text(encoding="utf-8"), (
        f"the installed {NAME} is not python/{NAME}: reinstall (maturin develop)")
