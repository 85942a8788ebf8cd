"""`endocast.match` gives the counterpart `endocast match --json` prints (issue 36, supine/prone
correspondence): the same point, arc and pose from the same core, on the phantom pair."""

import json

import numpy as np
import pytest

import endocast


@pytest.fixture(scope="module")
def prone(cli, tmp_path_factory):
    """The prone twin of the `colon` fixture (same size and seed)."""
    path = tmp_path_factory.mktemp("phantom") / "colon-prone.nii.gz"
    cli("phantom", "colon-prone", "--size", "64", "-o", path)
    return path


def test_match_is_the_clis(colon, prone, cli, tmp_path):
    supine = endocast.open(colon)
    points, _ = endocast.path(supine, preset="colonoscopy")
    at = [float(c) for c in points[len(points) // 3]]
    ours = endocast.match(supine, endocast.open(prone), at, output=tmp_path / "py.png", size=(64, 64))
    where = ",".join(str(c) for c in at)
    theirs = json.loads(cli("match", colon, prone, "--at", where, "--json"))
    for key in ("point", "eye", "look_at", "up"):
        np.testing.assert_allclose(ours[key], theirs[key], atol=1e-9, err_msg=key)
    for key in ("arc_mm", "path_mm", "turn_deg", "match_cost"):
        assert ours[key] == pytest.approx(theirs[key], abs=1e-9), key
    np.testing.assert_allclose(ours["first"]["eye"], theirs["first"]["eye"], atol=1e-9)
    assert abs(abs(ours["turn_deg"]) - 180.0) < 10.0
    assert (tmp_path / "py.png").is_file()


def test_bad_input_is_named(colon):
    supine = endocast.open(colon)
    with pytest.raises(endocast.EndocastError, match="point"):
        endocast.match(supine, supine, (float("nan"), 0.0, 0.0))
    with pytest.raises(endocast.EndocastError, match="preset"):
        endocast.match(supine, supine, (0.0, 0.0, 0.0), preset="nonsense")
