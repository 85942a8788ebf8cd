"""Every shared scan opened by endocast and by an independent reader: same shape, geometry and
values (nibabel for NIfTI, pydicom for DICOM, small readers for NRRD and MetaImage)."""

from pathlib import Path

import numpy as np
import pytest

import endocast
from reference import read_metaimage, read_nrrd

RAS_FROM_LPS = np.diag([-1.0, -1.0, 1.0, 1.0])


def test_nifti_matches_nibabel(shared_data):
    nibabel = pytest.importorskip("nibabel")
    for name in ["brain-mri-t1/chris_t1.nii.gz", "classic-engine-ct/engine.nii.gz"]:
        image = nibabel.load(shared_data / name)
        volume = endocast.open(shared_data / name)
        assert volume.shape == image.shape[:3], name
        np.testing.assert_allclose(volume.affine_ras, image.affine, atol=1e-4, err_msg=name)
        np.testing.assert_allclose(RAS_FROM_LPS @ volume.affine, image.affine, atol=1e-4)
        np.testing.assert_array_equal(volume.voxels, image.get_fdata(dtype=np.float32))
        assert not volume.voxels.flags.writeable


def dicom_files(folder):
    pydicom = pytest.importorskip("pydicom")
    files = [pydicom.dcmread(p) for p in sorted(Path(folder).rglob("*.dcm"))]
    if not files:
        files = [
            pydicom.dcmread(p)
            for p in sorted(Path(folder).rglob("*"))
            if p.is_file() and p.suffix not in {".md", ".txt", ".png"} and p.name != "LICENSE"
        ]
    return files


def physical(ds, padding_value=None):
    """A slice's values as (columns, rows): the volume's [i, j] order. PixelPaddingValue
    voxels become `padding_value` (endocast gives them the lowest real value of the series)."""
    slope = float(getattr(ds, "RescaleSlope", 1.0))
    intercept = float(getattr(ds, "RescaleIntercept", 0.0))
    raw = ds.pixel_array
    values = raw.astype(np.float64) * slope + intercept
    if padding_value is not None and "PixelPaddingValue" in ds:
        values[raw == ds.PixelPaddingValue] = padding_value
    return values.T


@pytest.mark.parametrize(
    "folder",
    ["abdomen-ct-pancreas-dicom", "chest-ct-airways-dicom", "head-ct-ge-gantry-tilt"],
)
def test_dicom_series_matches_pydicom(shared_data, folder):
    """Each slice that lies on the volume's grid (all of them, but for the resampled uneven
    gaps of the GE series, where the first and last stay in place) equals pydicom's."""
    files = dicom_files(shared_data / folder)
    volume = endocast.open(shared_data / folder)
    first = files[0]
    assert volume.shape[:2] == (first.Columns, first.Rows)
    row, column = np.array(first.ImageOrientationPatient, float).reshape(2, 3)
    dy, dx = (float(s) for s in first.PixelSpacing)
    np.testing.assert_allclose(volume.affine[:3, 0], row * dx, atol=1e-4)
    np.testing.assert_allclose(volume.affine[:3, 1], column * dy, atol=1e-4)
    voxel_from_world = np.linalg.inv(volume.affine)
    compared = 0
    for ds in files:
        i, j, k, _ = voxel_from_world @ np.append(np.array(ds.ImagePositionPatient, float), 1)
        assert abs(i) < 1e-3 and abs(j) < 1e-3, (folder, i, j)
        if abs(k - round(k)) > 1e-3:
            continue
        lowest = volume.value_range[0]
        np.testing.assert_array_equal(volume.voxels[:, :, round(k)], physical(ds, lowest))
        compared += 1
    assert compared >= (2 if folder == "head-ct-ge-gantry-tilt" else len(files)), compared
    assert volume.modality == "CT"


def test_every_transfer_syntax_gives_the_same_slices(shared_data):
    folder = shared_data / "dicom-transfer-syntaxes"
    pydicom = pytest.importorskip("pydicom")
    reference = physical(pydicom.dcmread(folder / "1.dcm"))
    for n in range(1, 10):
        volume = endocast.open(folder / f"{n}.dcm")
        # Siemens mosaics: 35 slices of 64 × 64, tiled 6 a side row by row.
        assert volume.shape == (64, 64, 35)
        for k in range(35):
            column, row = 64 * (k % 6), 64 * (k // 6)  # reference is [column, row]
            tile = reference[column : column + 64, row : row + 64]
            np.testing.assert_array_equal(volume.voxels[:, :, k], tile, err_msg=f"{n}.dcm {k}")
        if n <= 4:  # uncompressed and RLE: pydicom decodes them without plugins
            np.testing.assert_array_equal(physical(pydicom.dcmread(folder / f"{n}.dcm")), reference)


@pytest.mark.parametrize(
    "name, declared",
    [
        ("aorta-stent-cta/stent.nrrd", True),
        ("brain-mri-flair-nrrd/FLAIR.nrrd", True),
        ("head-ct-stanford-cthead/CThead.nhdr", False),
        ("classic-vtk-headsq/quarter_nospace.nhdr", False),
        ("classic-vtk-headsq/quarter.nhdr", False),
    ],
)
def test_nrrd_matches_its_bytes(shared_data, name, declared):
    array, affine = read_nrrd(shared_data / name)
    volume = endocast.open(shared_data / name)
    assert volume.shape == array.shape
    np.testing.assert_array_equal(volume.voxels, array.astype(np.float32))
    spacing = np.linalg.norm(affine[:3, :3], axis=0)
    np.testing.assert_allclose(volume.spacing, spacing, rtol=1e-6)
    if declared:
        np.testing.assert_allclose(volume.affine, affine, atol=1e-4)
    else:
        assert any("axis-aligned" in w for w in volume.warnings), volume.warnings


def test_metaimage_matches_its_bytes(shared_data):
    for name in ["knee-mri/knee3D_dataR.mha", "knee-mri/knee3D_dataT.mha"]:
        array, spacing = read_metaimage(shared_data / name)
        volume = endocast.open(shared_data / name)
        assert volume.shape == array.shape
        np.testing.assert_array_equal(volume.voxels, array.astype(np.float32))
        np.testing.assert_allclose(volume.spacing, spacing)


def test_stent_nrrd_equals_the_original_npz(shared_data):
    original = np.load(shared_data / "aorta-stent-cta" / "stent.npz")
    (array,) = [original[k] for k in original.files]
    volume = endocast.open(shared_data / "aorta-stent-cta" / "stent.nrrd")
    # The npz is indexed [k, j, i] (numpy's C order of the same bytes).
    np.testing.assert_array_equal(volume.voxels, array.T.astype(np.float32))
