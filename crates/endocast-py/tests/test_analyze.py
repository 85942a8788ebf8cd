"""Analyze 7.5 pairs (issue 32, item 5): `.hdr` + `.img` written by nibabel's AnalyzeImage,
Spm99AnalyzeImage and Spm2AnalyzeImage, each read by endocast with the values and the affine
that `nibabel.load` gives (it reads every magic-less `.hdr` as an Spm2AnalyzeImage)."""

import numpy as np
import pytest

import endocast

nib = pytest.importorskip("nibabel")

ZOOMS = (0.7, 0.9, 1.3)


def data(dtype, shape=(5, 6, 7)):
    """A ramp of `dtype` values that a 16-bit store holds exactly, negative where it can be."""
    ramp = np.arange(np.prod(shape)).reshape(shape)
    if np.issubdtype(dtype, np.signedinteger) or np.issubdtype(dtype, np.floating):
        ramp = ramp - ramp.size // 3
    return ramp.astype(dtype)


def assert_reads_like_nibabel(path):
    """endocast's volume of `path` has nibabel's scaled values and RAS affine."""
    image = nib.load(path)
    assert type(image).__name__ == "Spm2AnalyzeImage"
    theirs = np.asanyarray(image.dataobj).astype(np.float64)
    volume = endocast.open(path)
    assert volume.source == "Analyze 7.5"
    assert volume.shape == theirs.shape
    np.testing.assert_allclose(volume.affine_ras, image.affine, rtol=0, atol=1e-5)
    scale = max(1.0, float(np.max(np.abs(theirs))))
    np.testing.assert_allclose(volume.voxels, theirs, rtol=0, atol=1e-6 * scale)
    return volume


def write_pair(path, header, stored):
    """`path` (.hdr) and its .img: `header` as it is, `stored` in its byte order."""
    with open(path, "wb") as f:
        header.write_to(f)
    with open(path.with_suffix(".img"), "wb") as f:
        header.data_to_fileobj(stored, f, rescale=False)


@pytest.mark.parametrize("dtype", [np.uint8, np.int16, np.int32, np.float32, np.float64])
@pytest.mark.parametrize("endianness", ["<", ">"])
def test_analyze_image_reads_through_the_centre(tmp_path, dtype, endianness):
    path = tmp_path / "plain.hdr"
    header = nib.AnalyzeHeader(endianness=endianness)
    header.set_data_dtype(dtype)
    header.set_data_shape((5, 6, 7))
    header.set_zooms(ZOOMS)
    write_pair(path, header, data(dtype))
    volume = assert_reads_like_nibabel(path)
    assert any("Analyze 7.5" in w and "LAS" in w for w in volume.warnings), volume.warnings


@pytest.mark.parametrize("spm2", [False, True])
@pytest.mark.parametrize("origin", [(0, 0, 0), (3, 2, 5), (-2, 9, 13), (40, 1, 1)])
def test_spm_origin_and_scale_factor(tmp_path, spm2, origin):
    """SPM's origin (the centre when it is unset or out of reach), funused1 scaling int16 and
    the funused2 intercept SPM2 reads (nibabel reads SPM99 headers as SPM2 ones too)."""
    path = tmp_path / "spm.hdr"
    header = nib.Spm2AnalyzeHeader() if spm2 else nib.Spm99AnalyzeHeader()
    header.set_data_dtype(np.int16)
    header.set_data_shape((5, 6, 7))
    header.set_zooms(ZOOMS)
    header["origin"][:3] = origin
    header["scl_slope"] = 0.25
    header["scl_inter" if spm2 else "funused2"] = -3.5
    write_pair(path, header, data(np.int16))
    assert_reads_like_nibabel(path)


def test_spm2_calibration_scales_without_a_scale_factor(tmp_path):
    path = tmp_path / "cal.hdr"
    header = nib.Spm2AnalyzeHeader()
    header.set_data_dtype(np.uint8)
    header.set_data_shape((5, 6, 7))
    header["scl_slope"] = 0
    header["glmin"], header["glmax"] = 10, 110
    header["cal_min"], header["cal_max"] = -1.0, 4.0
    write_pair(path, header, data(np.uint8))
    volume = assert_reads_like_nibabel(path)
    assert any("cal_min" in w for w in volume.warnings), volume.warnings


def scipy():
    """scipy, which nibabel needs to write and read the .mat of an SPM image (installed by
    .ci/run); a visible skip elsewhere when it is absent."""
    from conftest import missing

    try:
        import scipy
    except ImportError:
        missing("scipy (pip install scipy), nibabel's .mat reader and writer")
    return scipy


@pytest.mark.parametrize("klass", ["AnalyzeImage", "Spm99AnalyzeImage", "Spm2AnalyzeImage"])
@pytest.mark.parametrize("suffix", [".hdr", ".hdr.gz"])
def test_images_saved_by_nibabel(tmp_path, klass, suffix):
    """Whole images saved by nibabel: the SPM ones keep their affine in a .mat beside them
    (MATLAB 4 format), which nibabel and endocast read back."""
    if klass != "AnalyzeImage":
        scipy()
    affine = np.array(
        [[-0.7, 0, 0, 10.3], [0, 0.9, 0, -20.1], [0, 0, 1.3, 5.55], [0, 0, 0, 1.0]]
    )
    path = tmp_path / f"saved{suffix}"
    getattr(nib, klass)(data(np.float32), affine).to_filename(path)
    assert (tmp_path / f"saved.mat{suffix[4:]}").exists() == (klass != "AnalyzeImage")
    assert_reads_like_nibabel(path)


def test_rgb_and_complex_are_refused_naming_the_type(tmp_path):
    for code in [32, 128]:
        path = tmp_path / f"{code}.hdr"
        header = nib.AnalyzeHeader()
        header.set_data_dtype(code)
        header.set_data_shape((2, 3, 4))
        with open(path, "wb") as f:
            header.write_to(f)
        path.with_suffix(".img").write_bytes(bytes(24 * header.get_data_dtype().itemsize))
        with pytest.raises(endocast.EndocastError, match=f"Analyze 7.5 datatype {code}"):
            endocast.open(path)
