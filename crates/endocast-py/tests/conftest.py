"""Fixtures: the shared scans, the `endocast` command, and a colon phantom it made."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(Path(__file__).parent))


def missing(what):
    """Skip with a visible reason outside CI; under CI=true a missing input is a failure."""
    if os.environ.get("CI") == "true":
        pytest.fail(f"{what} is missing under CI")
    print(f"SKIPPED: {what} is missing", file=sys.stderr)
    pytest.skip(f"{what} is missing")


@pytest.fixture(scope="session")
def shared_data():
    root = REPO.parent / "shared" / "data"
    if not root.is_dir():
        missing(f"the shared scans ({root})")
    return root


@pytest.fixture(scope="session")
def endocast_bin():
    """The `endocast` command the Python results are compared with (ENDOCAST_BIN, else the
    debug build `cargo test` makes)."""
    path = Path(os.environ.get("ENDOCAST_BIN", REPO / "target" / "debug" / "endocast"))
    if not path.is_file():
        missing(f"the endocast command ({path}; build it with cargo build -p endocast-cli)")
    return path


@pytest.fixture(scope="session")
def cli(endocast_bin):
    """Runs `endocast ARGS...` and returns its standard output; fails with its error."""

    def run(*args):
        result = subprocess.run(
            [str(endocast_bin), *map(str, args)], capture_output=True, text=True
        )
        assert result.returncode == 0, result.stderr
        return result.stdout

    return run


@pytest.fixture(scope="session")
def colon(cli, tmp_path_factory):
    """A 64³ colon phantom written by `endocast phantom`."""
    path = tmp_path_factory.mktemp("phantom") / "colon.nii.gz"
    cli("phantom", "colon", "--size", "64", "-o", path)
    return path
