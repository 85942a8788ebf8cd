"""`endocast.polyps` lists the polyp candidates `endocast polyps --json` prints (issue 36):
the same records from the same core."""

import json

import numpy as np
import pytest

import endocast


@pytest.fixture(scope="module")
def polyp_colon(cli, tmp_path_factory):
    """A 160³ colon phantom with nine drawn polyps, written by `endocast phantom`."""
    path = tmp_path_factory.mktemp("polyps") / "colon.nii.gz"
    cli("phantom", "colon", "--size", "160", "--polyps", "9", "--seed", "2", "-o", path)
    return path


def test_polyps_are_the_clis(polyp_colon, cli):
    volume = endocast.open(polyp_colon)
    ours = endocast.polyps(volume, preset="colonoscopy", min_size=3.0)
    args = ["polyps", polyp_colon, "--preset", "colonoscopy", "--min-size", "3", "--json"]
    theirs = json.loads(cli(*args))
    assert ours["candidates"], ours
    assert len(ours["candidates"]) == len(theirs["candidates"])
    for a, b in zip(ours["candidates"], theirs["candidates"]):
        assert set(a) == set(b) == {"centre", "size_mm", "score"}
        np.testing.assert_allclose(a["centre"], b["centre"], atol=1e-9)
        assert a["size_mm"] == pytest.approx(b["size_mm"], abs=1e-9)
        assert a["score"] == pytest.approx(b["score"], abs=1e-9)


def test_bad_options_are_named(polyp_colon):
    volume = endocast.open(polyp_colon)
    with pytest.raises(endocast.EndocastError, match="sigma"):
        endocast.polyps(volume, preset="colonoscopy", sigma=float("nan"))
    with pytest.raises(endocast.EndocastError, match="min_size"):
        endocast.polyps(volume, preset="colonoscopy", min_size=-1.0)
