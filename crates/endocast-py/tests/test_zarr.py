"""OME-Zarr written by the Python `zarr` package (issue 37, item 3): v0.4 (Zarr v2, blosc) and
v0.5 (Zarr v3, zstd) images read with the right spacing and origin, and the same voxels, as
their NIfTI twin written by nibabel. OME-Zarr declares no patient orientation: its x, y, z
are read as L, P, S (docs/formats.md), so the twin's RAS affine flips x and y."""

import numpy as np
import pytest

import endocast

RAS_FROM_LPS = np.diag([-1.0, -1.0, 1.0, 1.0])
SCALE_ZYX_MM = (2.5, 0.75, 0.5)
ORIGIN_ZYX_MM = (-30.0, 12.5, 4.25)


def samples():
    """A (z, y, x) int16 block with a pattern no axis mix-up leaves unchanged."""
    z, y, x = np.meshgrid(np.arange(6), np.arange(7), np.arange(9), indexing="ij")
    return (z * 300 + y * 17 - x * 5 - 1000).astype(np.int16)


def ome_metadata(version, unit, per_mm):
    axes = [{"name": n, "type": "space", "unit": unit} for n in "zyx"]
    level = {
        "path": "0",
        "coordinateTransformations": [
            {"type": "scale", "scale": [s * per_mm for s in SCALE_ZYX_MM]},
            {"type": "translation", "translation": [t * per_mm for t in ORIGIN_ZYX_MM]},
        ],
    }
    return {"version": version, "axes": axes, "datasets": [level]}


def write_v05(path, zarr):
    group = zarr.open_group(str(path), mode="w", zarr_format=3)
    group.create_array("0", data=samples(), chunks=(4, 4, 4))
    group.attrs["ome"] = {"version": "0.5", "multiscales": [ome_metadata("0.5", "millimeter", 1)]}


def write_v04(path, zarr):
    numcodecs = pytest.importorskip("numcodecs")
    group = zarr.open_group(str(path), mode="w", zarr_format=2)
    blosc = numcodecs.Blosc(cname="lz4", clevel=5, shuffle=numcodecs.Blosc.SHUFFLE)
    group.create_array("0", data=samples(), chunks=(4, 4, 4), compressors=blosc)
    group.attrs["multiscales"] = [ome_metadata("0.4", "micrometer", 1000)]


def nifti_twin(path, nibabel):
    """The same grid as NIfTI: voxels indexed [x, y, z], the RAS affine of LPS x, y, z."""
    lps = np.eye(4)
    lps[:3, :3] = np.diag(SCALE_ZYX_MM[::-1])
    lps[:3, 3] = ORIGIN_ZYX_MM[::-1]
    nibabel.save(nibabel.Nifti1Image(samples().transpose(2, 1, 0), RAS_FROM_LPS @ lps), path)


@pytest.mark.parametrize("writer", [write_v05, write_v04])
def test_python_written_ome_zarr_matches_its_nifti_twin(tmp_path, writer):
    zarr = pytest.importorskip("zarr")
    nibabel = pytest.importorskip("nibabel")
    store = tmp_path / "image.zarr"
    writer(store, zarr)
    nifti_twin(tmp_path / "twin.nii", nibabel)
    volume = endocast.open(store)
    twin = endocast.open(tmp_path / "twin.nii")
    assert volume.shape == (9, 7, 6) == twin.shape
    np.testing.assert_allclose(volume.affine, twin.affine, atol=1e-9)
    np.testing.assert_allclose(np.diag(volume.affine)[:3], SCALE_ZYX_MM[::-1], atol=1e-9)
    np.testing.assert_allclose(volume.affine[:3, 3], ORIGIN_ZYX_MM[::-1], atol=1e-9)
    np.testing.assert_array_equal(volume.voxels, twin.voxels)
    np.testing.assert_array_equal(volume.voxels, samples().transpose(2, 1, 0))
    assert any("no patient orientation" in w for w in volume.warnings)
