"""One study in every front end (issue 31): Python resolves a scan as `endocast render` does —
the preset in the scan's units, the same start pose — and plans a path from a preset alone."""

import json

import numpy as np
import pytest

import endocast

# Every shared scan that holds a volume, with the presets that apply to it.
TABLE = [
    ("abdomen-ct-pancreas-dicom", ["colonoscopy"]),
    ("aorta-stent-cta/stent.nrrd", ["angioscopy"]),
    ("brain-mri-flair-nrrd/FLAIR.nrrd", ["ventricles"]),
    ("brain-mri-t1/chris_t1.nii.gz", ["ventricles"]),
    ("chest-ct-airways-dicom", ["bronchoscopy"]),
    ("classic-engine-ct/engine.nii.gz", []),
    ("classic-vtk-headsq/quarter.nhdr", ["sinus"]),
    ("head-ct-ge-gantry-tilt/GE", ["sinus"]),
    ("head-ct-stanford-cthead/CThead.nhdr", ["sinus"]),
    ("knee-mri/knee3D_dataR.mha", ["arthroscopy"]),
    ("knee-mri/knee3D_dataT.mha", ["arthroscopy"]),
]


def cli_start(cli, scan, preset, tmp_path):
    """The start `endocast render --json` reports: (eye, look_at, up)."""
    args = ["render", scan, "-o", tmp_path / "v.png", "--size", "16x16", "--json"]
    if preset:
        args += ["--preset", preset]
    start = json.loads(cli(*args))["study"]["start"]
    return [np.array(start[k]) for k in ("eye", "look_at", "up")]


@pytest.mark.parametrize("name, presets", TABLE, ids=[t[0] for t in TABLE])
def test_default_view_is_the_clis_start(shared_data, cli, tmp_path, name, presets):
    scan = shared_data / name
    volume = endocast.open(scan)
    for preset in [None, *presets]:
        options = {"preset": preset} if preset else {}
        ours = [np.array(v) for v in endocast.default_view(volume, **options)]
        theirs = cli_start(cli, scan, preset, tmp_path)
        for a, b in zip(ours, theirs):
            np.testing.assert_allclose(a, b, atol=1e-6, err_msg=f"{name} {preset}")


def test_a_scan_stored_as_hu_plus_1024_renders_its_preset(shared_data):
    """CThead stores HU + 1024: the sinus preset is carried into its units, not used as HU."""
    volume = endocast.open(shared_data / "head-ct-stanford-cthead" / "CThead.nhdr")
    rgba, depth = endocast.render(volume, preset="sinus", size=(32, 32))
    assert np.isfinite(depth).mean() > 0.5
    assert rgba[..., :3].max() > 50


def test_path_from_a_preset_alone_starts_at_the_default_view(colon):
    volume = endocast.open(colon)
    points, radii = endocast.path(volume, preset="colonoscopy")
    eye, _, _ = endocast.default_view(volume, preset="colonoscopy")
    assert np.linalg.norm(points[0] - np.array(eye)) < 1e-6
    assert points.shape[0] > 10 and (radii > 0).all()


def test_a_path_without_a_start_or_preset_says_what_to_give(colon):
    volume = endocast.open(colon)
    with pytest.raises(endocast.EndocastError, match="start=") as error:
        endocast.path(volume, iso=-500)
    assert "--from" not in str(error.value)
