"""`endocast.fly(..., dataset=FOLDER)` writes the training data `endocast fly --dataset` writes."""

import json

import pytest

import endocast


def test_fly_dataset_is_the_clis(colon, cli, tmp_path):
    volume = endocast.open(colon)
    eye, _, _ = endocast.default_view(volume, preset="colonoscopy")
    start = ",".join(f"{c:.6f}" for c in eye)
    route = tmp_path / "path.json"
    cli("path", colon, "--preset", "colonoscopy", f"--from={start}", "-o", route)
    mine, theirs = tmp_path / "py", tmp_path / "cli"
    options = dict(preset="colonoscopy", size=(32, 24), frame_step=4.0)
    frames = endocast.fly(volume, route, dataset=mine, **options)
    cli("fly", colon, "--path", route, "--preset", "colonoscopy", "--size", "32x24",
        "--frame-step", "4", "-o", tmp_path / "film", "--dataset", theirs)
    transforms = json.loads((mine / "transforms.json").read_text())
    assert transforms == json.loads((theirs / "transforms.json").read_text())
    assert len(transforms["frames"]) == frames.shape[0] >= 2
    written = sorted(p.relative_to(theirs) for p in theirs.rglob("*") if p.is_file())
    assert written == sorted(p.relative_to(mine) for p in mine.rglob("*") if p.is_file())
    for name in written:
        assert (mine / name).read_bytes() == (theirs / name).read_bytes(), name
    with pytest.raises(endocast.EndocastError, match="files in it"):
        endocast.fly(volume, route, dataset=mine, **options)
