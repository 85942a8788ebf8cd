"""`endocast.dissect` lays the wall flat as `endocast dissect` does (issue 36): the same image,
the same map back to 3D, the same figures, from the same core."""

import json

import numpy as np
import pytest

import endocast
from reference import read_png_rgb


def test_dissect_is_the_clis(colon, cli, tmp_path):
    volume = endocast.open(colon)
    ours = endocast.dissect(volume, preset="colonoscopy", rows=90)
    png = tmp_path / "flat.png"
    report = json.loads(
        cli("dissect", colon, "--preset", "colonoscopy", "--rows", "90", "-o", png, "--json")
    )
    theirs_map = np.load(tmp_path / "flat.map.npy")
    assert ours["image"].shape == (report["height"], report["width"], 3)
    assert ours["image"].dtype == np.uint8
    np.testing.assert_array_equal(ours["map"], theirs_map)
    np.testing.assert_array_equal(ours["image"], read_png_rgb(png))
    for key in ("plot", "along_mm_per_px", "around_deg_per_px", "wall_fraction"):
        assert ours[key] == pytest.approx(report[key]), key
    assert ours["path_length_mm"] == pytest.approx(report["path_length_mm"])


def test_the_map_points_lie_on_the_wall_of_the_path(colon):
    volume = endocast.open(colon)
    flat = endocast.dissect(volume, preset="colonoscopy", rows=90)
    plot = flat["plot"]
    wall = flat["map"][plot["y"] : plot["y"] + plot["rows"], plot["x"] : plot["x"] + plot["columns"]]
    hit = ~np.isnan(wall[..., 0])
    assert hit.mean() == pytest.approx(flat["wall_fraction"], abs=1e-6)
    assert hit.mean() > 0.9
    # Outside the plot (the axis and its labels) no pixel maps to the wall.
    outside = np.ones(flat["map"].shape[:2], bool)
    outside[plot["y"] : plot["y"] + plot["rows"], plot["x"] : plot["x"] + plot["columns"]] = False
    assert np.isnan(flat["map"][outside]).all()


def test_bad_options_are_named(colon):
    volume = endocast.open(colon)
    with pytest.raises(endocast.EndocastError, match="step"):
        endocast.dissect(volume, preset="colonoscopy", along_step=float("nan"))
    with pytest.raises(endocast.EndocastError, match="rows"):
        endocast.dissect(volume, preset="colonoscopy", rows=2)
