"""Python parity (issue 31, item 4): nibabel and SimpleITK images taken as they are, the peel
and the endoscope's look as the CLI draws them, and every option documented in help()."""

import nibabel as nib
import numpy as np
import pytest

import endocast
from reference import read_png_rgb



def sitk():
    """SimpleITK (installed by .ci/run); a visible skip elsewhere when it is absent."""
    from conftest import missing

    try:
        import SimpleITK
    except ImportError:
        missing("SimpleITK (pip install SimpleITK)")
    return SimpleITK


def same_view(a, b):
    """Both volumes give the same default camera and the same image."""
    for x, y in zip(endocast.default_view(a, preset="colonoscopy"),
                    endocast.default_view(b, preset="colonoscopy")):
        np.testing.assert_allclose(x, y, atol=1e-6)
    rgba_a, _ = endocast.render(a, preset="colonoscopy", size=(48, 48))
    rgba_b, _ = endocast.render(b, preset="colonoscopy", size=(48, 48))
    np.testing.assert_array_equal(rgba_a, rgba_b)


def test_a_nibabel_image_is_a_volume(colon):
    ours = endocast.open(colon)
    image = nib.load(colon)
    volume = endocast.as_volume(image)
    np.testing.assert_allclose(volume.affine, ours.affine, atol=1e-9)
    np.testing.assert_array_equal(volume.voxels, ours.voxels)
    same_view(image, ours)
    points, _ = endocast.path(image, preset="colonoscopy")
    assert len(points) > 10


def test_a_simpleitk_image_is_a_volume(colon):
    sitk_module = sitk()
    ours = endocast.open(colon)
    image = sitk_module.ReadImage(str(colon))
    volume = endocast.as_volume(image)
    np.testing.assert_allclose(volume.affine, ours.affine, atol=1e-6)
    np.testing.assert_array_equal(volume.voxels, ours.voxels)
    same_view(image, ours)


def test_other_objects_are_refused_by_name():
    with pytest.raises(TypeError, match="nibabel image or a SimpleITK Image"):
        endocast.render([1, 2, 3])
    flat = nib.Nifti1Image(np.zeros((4, 4, 4, 2), np.int16), np.eye(4))
    with pytest.raises(ValueError, match="one 3-D volume"):
        endocast.as_volume(flat)


def cli_image(cli, tmp_path, scan, *options):
    out = tmp_path / "cli.png"
    cli("render", scan, "-o", out, "--size", "40x32", *options)
    return read_png_rgb(out)


def test_the_peel_is_the_clis(cli, tmp_path):
    joint = tmp_path / "joint.nii.gz"
    cli("phantom", "joint", "--size", "64", "-o", joint)
    volume = endocast.open(joint)
    options = dict(mode="peel", peel="last", peel_keep=0.3, unpeeled="context")
    rgba, _ = endocast.render(volume, preset="arthroscopy", size=(40, 32), **options)
    theirs = cli_image(cli, tmp_path, joint, "--preset", "arthroscopy", "--mode", "peel",
                       "--peel", "last", "--peel-keep", "0.3", "--unpeeled", "context")
    np.testing.assert_array_equal(rgba[..., :3], theirs)


def test_the_realistic_look_is_the_clis(cli, tmp_path):
    layered = tmp_path / "layered.nii.gz"
    cli("phantom", "layered", "-o", layered)
    volume = endocast.open(layered)
    options = dict(look="realistic", secretion="accumulate", wetness=0.5, texture="grid")
    rgba, _ = endocast.render(volume, size=(40, 32), **options)
    theirs = cli_image(cli, tmp_path, layered, "--look", "realistic", "--secretion",
                       "accumulate", "--wetness", "0.5", "--texture", "grid")
    np.testing.assert_array_equal(rgba[..., :3], theirs)
    plain, _ = endocast.render(volume, size=(40, 32))
    assert np.abs(plain.astype(int) - rgba.astype(int)).max() > 20


def test_the_realistic_looks_endoscope_lens_and_lighting_are_the_clis(cli, tmp_path):
    layered = tmp_path / "layered.nii.gz"
    cli("phantom", "layered", "-o", layered)
    volume = endocast.open(layered)
    # (The sinus preset: without one the layered phantom's start sees no wall.)
    # The default lens of the look (a rigid endoscope's) on both sides, and it is the one
    # given explicitly; the ideal lens differs.
    rgba, _ = endocast.render(volume, size=(40, 32), preset="sinus", look="realistic")
    np.testing.assert_array_equal(rgba[..., :3], cli_image(cli, tmp_path, layered, "--preset", "sinus", "--look",
                                                           "realistic"))
    explicit, _ = endocast.render(volume, size=(40, 32), preset="sinus", look="realistic",
                                  distortion=(-0.166, 0.0246), vignetting=0.6)
    np.testing.assert_array_equal(rgba, explicit)
    ideal, _ = endocast.render(volume, size=(40, 32), preset="sinus", look="realistic", distortion=(0, 0),
                               vignetting=0)
    assert np.abs(ideal.astype(int) - rgba.astype(int)).max() > 20
    lit, _ = endocast.render(volume, size=(40, 32), preset="sinus", look="realistic", lighting="ibl")
    np.testing.assert_array_equal(lit[..., :3], cli_image(cli, tmp_path, layered, "--preset", "sinus", "--look",
                                                          "realistic", "--lighting", "ibl"))
    assert np.abs(lit.astype(int) - rgba.astype(int)).max() > 5


def test_bad_look_values_name_the_keyword(colon):
    volume = endocast.open(colon)
    for options, needle in [
        (dict(look="photo"), "look"),
        (dict(look="realistic", wetness=2.0), "wetness must be between 0 and 1"),
        (dict(secretion="on"), "secretion only applies to the clinical or realistic look"),
        (dict(mode="peel", peel="first"), "peel"),
        (dict(still=0), "still must be between 1"),
        (dict(distortion=(float("nan"), 0.0)), "distortion must be two finite numbers"),
        (dict(look="realistic", lighting="ibl:missing.png"), "missing.png"),
        (dict(lighting="ibl"), "lighting only applies to the clinical or realistic look"),
        (dict(still=2, still_filter="cubic"), "still_filter must be trilinear or bspline"),
    ]:
        with pytest.raises(endocast.EndocastError, match=needle):
            endocast.render(volume, size=(8, 8), **options)


def test_help_documents_every_option():
    render_doc = endocast.render.__doc__
    for option in ["preset", "eye", "look_at", "lens", "stereo", "peel_threshold", "tf_after",
                   "look", "secretion", "wetness", "texture", "lighting", "still", "still_filter",
                   "lumen_threshold",
                   "meshes", "overlays"]:
        assert option in render_doc, option
    assert "nibabel" in endocast.as_volume.__doc__
    for function in [endocast.fly, endocast.path, endocast.default_view]:
        assert "preset" in function.__doc__, function.__name__


def test_open_takes_the_readers_options(colon):
    plain = endocast.open(colon)
    lenient = endocast.open(colon, fill_missing_slices=True, allow_outside_data=True)
    np.testing.assert_array_equal(plain.voxels, lenient.voxels)
    assert "fill_missing_slices" in endocast.open.__doc__


def test_save_png_takes_a_view_of_the_image(colon, tmp_path):
    rgba, _ = endocast.render(endocast.open(colon), size=(24, 16))
    out = tmp_path / "view.png"
    endocast.save_png(out, rgba[..., :3])
    np.testing.assert_array_equal(read_png_rgb(out), rgba[..., :3])
    endocast.save_png(out, rgba[::-1, :, :3])
    np.testing.assert_array_equal(read_png_rgb(out), rgba[::-1, :, :3])


def test_meshes_and_overlays_are_the_clis(cli, colon, tmp_path):
    volume = endocast.open(colon)
    eye, look_at, up = (np.asarray(v) for v in endocast.default_view(volume, preset="colonoscopy"))
    forward = (look_at - eye) / np.linalg.norm(look_at - eye)
    right = np.cross(forward, up)
    ahead = eye + 3.0 * forward
    corners = [ahead - right - up, ahead + right - up, ahead + up]
    stl = tmp_path / "triangle.stl"
    facet = "\n".join(f"vertex {x} {y} {z}" for x, y, z in corners)
    stl.write_text(f"solid t\nfacet normal 0 0 0\nouter loop\n{facet}\nendloop\nendfacet\n"
                   "endsolid t\n")
    rgba, _ = endocast.render(volume, preset="colonoscopy", size=(40, 32), meshes=[stl])
    theirs = cli_image(cli, tmp_path, colon, "--preset", "colonoscopy", "--mesh", stl)
    np.testing.assert_array_equal(rgba[..., :3], theirs)
    bare, _ = endocast.render(volume, preset="colonoscopy", size=(40, 32))
    assert (rgba != bare).any(), "the mesh is not in view"
    looked, _ = endocast.render(volume, preset="colonoscopy", size=(40, 32), look="clinical",
                                meshes=[stl])
    theirs = cli_image(cli, tmp_path, colon, "--preset", "colonoscopy", "--look", "clinical",
                       "--mesh", stl)
    np.testing.assert_array_equal(looked[..., :3], theirs)
    with pytest.raises(endocast.EndocastError, match="gone.dcm"):
        endocast.render(volume, size=(8, 8), overlays=[tmp_path / "gone.dcm"])
