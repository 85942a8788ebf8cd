"""`endocast.path(..., target=...)` plans the bronchoscope's route that `endocast path --target
--json` prints (issue 36): the same points, branches and remaining distance from the same core."""

import json

import numpy as np
import pytest

import endocast

# In the lung beside the chest CT's left lower lobe bronchus (see the CLI's bronchoscopy tests).
NODULE = (52.0, 79.2, -50.5)


def test_route_to_a_target_is_the_clis(shared_data, cli, tmp_path):
    chest = shared_data / "chest-ct-airways-dicom"
    volume = endocast.open(chest)
    points, radii, route = endocast.path(
        volume, preset="bronchoscopy", target=NODULE, scope_diameter=4.9
    )
    out = tmp_path / "route.json"
    target = ",".join(map(str, NODULE))
    args = ["path", chest, "--preset", "bronchoscopy", "--target", target]
    theirs = json.loads(cli(*args, "--scope-diameter", "4.9", "-o", out, "--json"))
    assert route["branches"] == theirs["branches"]
    np.testing.assert_allclose(route["carina"], theirs["carina"], atol=1e-9)
    assert route["remaining_mm"] == pytest.approx(theirs["remaining_mm"], abs=1e-9)
    np.testing.assert_allclose(route["end"], theirs["end"], atol=1e-9)
    assert len(points) == theirs["points"] and len(radii) == len(points)
    cli_points = np.array(json.loads(out.read_text())["points"])
    np.testing.assert_allclose(points, cli_points, atol=1e-6)
    with pytest.raises(Exception, match="scope diameter"):
        endocast.path(volume, preset="bronchoscopy", target=NODULE, scope_diameter=float("nan"))
