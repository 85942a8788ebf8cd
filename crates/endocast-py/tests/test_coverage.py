"""`endocast.coverage` reviews the wall a flight missed with the numbers `endocast coverage
--json` prints (issue 36): the same patches, poses and coverage from the same core."""

import json

import numpy as np
import pytest

import endocast

OPTIONS = {"size": (48, 48), "frame_step": 4.0, "min_area": 1.0, "forward_only": True}


def cli_args(options):
    """`endocast coverage` flags for the keyword options."""
    args = ["--size", "{}x{}".format(*options["size"])]
    args += ["--frame-step", str(options["frame_step"]), "--min-area", str(options["min_area"])]
    return args + (["--forward-only"] if options["forward_only"] else [])


def test_coverage_is_the_clis_review(colon, cli, tmp_path):
    volume = endocast.open(colon)
    ours = endocast.coverage(volume, preset="colonoscopy", views=tmp_path / "py", **OPTIONS)
    args = ["coverage", colon, "--preset", "colonoscopy", "--json", "--views", tmp_path / "cli"]
    theirs = json.loads(cli(*args, *cli_args(OPTIONS)))
    assert ours["patches"], ours
    assert len(ours["patches"]) == len(theirs["patches"])
    for key in ("patches_total", "wall_voxels", "both_ways", "patches_at_least_300_mm2"):
        assert ours[key] == theirs[key], key
    for key in ("coverage_forward", "coverage_before", "coverage_after", "reach_mm"):
        assert ours[key] == pytest.approx(theirs[key], abs=1e-9), key
    for a, b in zip(ours["patches"], theirs["patches"]):
        assert a["area_mm2"] == pytest.approx(b["area_mm2"], rel=1e-9)
        for key in ("centroid", "eye", "look_at", "up"):
            np.testing.assert_allclose(a[key], b[key], atol=1e-9, err_msg=key)
        assert a["voxels_seen_by_view"] == b["voxels_seen_by_view"]
        assert a["view"].name == b["view"].split("/")[-1]
        assert a["view"].is_file()
    assert ours["coverage_after"] > ours["coverage_before"]


def test_bad_options_are_named(colon):
    volume = endocast.open(colon)
    with pytest.raises(endocast.EndocastError, match="min_area"):
        endocast.coverage(volume, preset="colonoscopy", min_area=float("nan"))
    with pytest.raises(endocast.EndocastError, match="frame_step"):
        endocast.coverage(volume, preset="colonoscopy", frame_step=0.0)
