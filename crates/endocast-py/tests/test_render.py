"""render, path and fly give what the `endocast` command gives; errors raise; the GIL is
released while rendering."""

import json
import threading
import time

import numpy as np
import pytest

import endocast
from reference import read_png_rgb


@pytest.fixture(scope="module")
def volume(colon):
    return endocast.open(colon)


@pytest.mark.parametrize(
    "options, flags",
    [
        ({"preset": "colonoscopy"}, ["--preset", "colonoscopy"]),
        (
            {"mode": "iso", "iso": -480, "eye": (0, 0, 0), "look_at": (0, 10, 0), "up": (0, 0, 1),
             "lens": "equidistant", "fov": 170},
            ["--mode", "iso", "--iso=-480", "--eye=0,0,0", "--look-at=0,10,0", "--up=0,0,1",
             "--lens", "equidistant", "--fov", "170"],
        ),
        (
            {"preset": "colonoscopy", "stereo": "red-cyan", "vignetting": 0.5,
             "distortion": (-0.2, 0.05)},
            ["--preset", "colonoscopy", "--stereo", "red-cyan", "--vignetting", "0.5",
             "--distortion=-0.2,0.05"],
        ),
    ],
)
def test_render_equals_the_cli(volume, colon, cli, tmp_path, options, flags):
    png, npy = tmp_path / "cli.png", tmp_path / "depth.npy"
    cli("render", colon, "--size", "96x80", "-o", png, "--depth-out", npy, *flags)
    rgba, depth = endocast.render(volume, size=(96, 80), **options)
    assert rgba.shape == (80, 96, 4) and rgba.dtype == np.uint8
    assert depth.shape == (80, 96) and depth.dtype == np.float32
    np.testing.assert_array_equal(rgba[..., :3], read_png_rgb(png))
    assert (rgba[..., 3] == 255).all()
    np.testing.assert_array_equal(depth, np.load(npy).reshape(80, 96))
    assert np.isfinite(depth).any()


@pytest.mark.parametrize("lens, size", [
    ("cube", (96, 72)),
    ("panorama", (96, 48)),
])
def test_the_cube_and_the_panorama_equal_the_cli(volume, colon, cli, tmp_path, lens, size):
    (w, h), png, npy = size, tmp_path / "cli.png", tmp_path / "depth.npy"
    cli("render", colon, "--preset", "colonoscopy", "--lens", lens, "--size", f"{w}x{h}",
        "-o", png, "--depth-out", npy)
    rgba, depth = endocast.render(volume, preset="colonoscopy", lens=lens, size=size)
    np.testing.assert_array_equal(rgba[..., :3], read_png_rgb(png))
    np.testing.assert_array_equal(depth, np.load(npy).reshape(h, w))
    if lens == "cube":
        # The cross's top-left cell is empty: no ray, transparent; the front face sees the wall.
        assert np.isnan(depth[:24, :24]).all() and (rgba[:24, :24, 3] == 0).all()
        assert np.isfinite(depth[24:48, 24:48]).all()
    else:
        assert np.isfinite(depth).all(), "from inside the gas every direction meets the wall"
    with pytest.raises(endocast.EndocastError, match="stereo"):
        endocast.render(volume, preset="colonoscopy", lens=lens, stereo="anaglyph", size=size)


def test_a_target_is_ringed_as_the_cli_rings_it(volume, colon, cli, tmp_path):
    eye, look_at, _ = endocast.default_view(volume, preset="colonoscopy")
    ahead = np.asarray(look_at) - np.asarray(eye)
    target = tuple(np.asarray(eye) + 3.0 * ahead / np.linalg.norm(ahead))
    png = tmp_path / "cli.png"
    cli("render", colon, "--preset", "colonoscopy", "--size", "96x80", "-o", png,
        "--target=" + ",".join(map(str, target)))
    rgba, _ = endocast.render(volume, preset="colonoscopy", size=(96, 80), target=target)
    np.testing.assert_array_equal(rgba[..., :3], read_png_rgb(png))
    plain, _ = endocast.render(volume, preset="colonoscopy", size=(96, 80))
    assert (rgba != plain).any(), "the target is drawn"
    with pytest.raises(endocast.EndocastError, match="target"):
        endocast.render(volume, preset="colonoscopy", target=(0, float("nan"), 0))


def test_default_view_is_inside_the_colon(volume):
    eye, look_at, up = endocast.default_view(volume, preset="colonoscopy")
    rgba, depth = endocast.render(volume, preset="colonoscopy", eye=eye, look_at=look_at, up=up,
                                  size=(32, 32))
    auto, auto_depth = endocast.render(volume, preset="colonoscopy", size=(32, 32))
    np.testing.assert_array_equal(rgba, auto)
    assert np.isfinite(auto_depth).all(), "every ray from inside the gas meets the wall"


def test_a_stereo_pair_is_two_images(volume):
    rgba, depth = endocast.render(volume, preset="colonoscopy", stereo="pair", size=(24, 16))
    assert rgba.shape == (2, 16, 24, 4) and depth.shape == (2, 16, 24)
    assert not np.array_equal(rgba[0], rgba[1])


def octahedron_obj(centre, r):
    """A closed octahedron of half-diagonal `r` mm around `centre`, as OBJ text."""
    corners = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    lines = [f"v {centre[0] + r * x} {centre[1] + r * y} {centre[2] + r * z}"
             for x, y, z in corners]
    for a, b in [(1, 3), (3, 2), (2, 4), (4, 1)]:
        lines += [f"f {a} {b} 5", f"f {b} {a} 6"]
    return "\n".join(lines) + "\n"


def test_a_realistic_stereo_pair_with_a_mesh_equals_the_cli(volume, colon, cli, tmp_path):
    eye, look_at, _ = endocast.default_view(volume, preset="colonoscopy")
    eye, look_at = np.array(eye), np.array(look_at)
    ahead = (look_at - eye) / np.linalg.norm(look_at - eye)
    mesh = tmp_path / "marker.obj"
    mesh.write_text(octahedron_obj(eye + 6 * ahead, 1.5))
    png = tmp_path / "cli.png"
    cli("render", colon, "--size", "48x40", "-o", png, "--preset", "colonoscopy", "--look",
        "realistic", "--stereo", "side-by-side", "--mesh", mesh)
    rgba, depth = endocast.render(volume, size=(48, 40), preset="colonoscopy", look="realistic",
                                  stereo="side-by-side", meshes=[str(mesh)])
    assert rgba.shape == (40, 96, 4) and depth.shape == (40, 48)
    np.testing.assert_array_equal(rgba[..., :3], read_png_rgb(png))
    assert not np.array_equal(rgba[:, :48], rgba[:, 48:])


def test_path_equals_the_cli(volume, colon, cli, tmp_path):
    out = tmp_path / "path.json"
    eye, _, _ = endocast.default_view(volume, preset="colonoscopy")
    start = ",".join(f"{c:.6f}" for c in eye)
    cli("path", colon, "--preset", "colonoscopy", f"--from={start}", "-o", out)
    points, radii = endocast.path(volume, [float(c) for c in start.split(",")],
                                  preset="colonoscopy")
    written = json.loads(out.read_text())
    expected = np.array([[p["x"], p["y"], p["z"]] if isinstance(p, dict) else p
                         for p in written["points"]], dtype=float)
    assert points.shape == expected.shape and points.shape[0] > 10
    np.testing.assert_array_equal(points, expected)
    assert radii.shape == (points.shape[0],) and (radii > 0).all()


def inside(volume):
    """A voxel index inside the colon's gas: the default view's eye."""
    eye, _, _ = endocast.default_view(volume, preset="colonoscopy")
    return (np.linalg.inv(volume.affine) @ np.append(eye, 1))[:3]


def test_path_in_voxels_and_to_an_end(volume):
    points, radii = endocast.path(volume, preset="colonoscopy", start_voxel=inside(volume))
    far, _ = endocast.path(volume, points[0], points[len(points) // 2], preset="colonoscopy")
    # The end snaps to the nearest voxel centre of the lumen.
    assert np.linalg.norm(far[-1] - points[len(points) // 2]) <= np.linalg.norm(volume.spacing)


def test_fly_frames_and_video(volume, tmp_path):
    points, _ = endocast.path(volume, preset="colonoscopy", start_voxel=inside(volume), step=4.0)
    route = points[:4]
    frames = endocast.fly(volume, route, preset="colonoscopy", size=(32, 24), frame_step=2.0)
    assert frames.ndim == 4 and frames.shape[1:] == (24, 32, 3) and frames.shape[0] >= 4
    assert frames.std() > 0
    gif = endocast.fly(volume, route, tmp_path / "fly.gif", size=(32, 24), frame_step=2.0)
    assert (tmp_path / "fly.gif").stat().st_size > 0 and gif.name == "fly.gif"


def test_from_array_takes_nibabel_and_itk_conventions(volume):
    again = endocast.Volume.from_array(volume.voxels, volume.affine_ras, space="RAS")
    np.testing.assert_array_equal(again.voxels, volume.voxels)
    np.testing.assert_allclose(again.affine, volume.affine)
    lps = endocast.Volume.from_array(np.ascontiguousarray(volume.voxels), volume.affine,
                                     space="LPS", modality="CT")
    np.testing.assert_allclose(lps.affine, volume.affine)
    assert lps.modality == "CT"
    a, _ = endocast.render(volume, preset="colonoscopy", size=(24, 24))
    b, _ = endocast.render(lps, preset="colonoscopy", size=(24, 24))
    np.testing.assert_array_equal(a, b)
    floats = endocast.Volume.from_array(np.linspace(0, 1, 24).reshape(2, 3, 4), np.eye(4))
    assert floats.warnings and "quantised" in floats.warnings[0]
    np.testing.assert_allclose(floats.voxels, np.linspace(0, 1, 24).reshape(2, 3, 4), atol=1e-4)


def test_errors_raise_with_the_library_message(volume, tmp_path):
    missing = tmp_path / "nothing.nii.gz"
    with pytest.raises(endocast.EndocastError, match="nothing.nii.gz"):
        endocast.open(missing)
    with pytest.raises(endocast.EndocastError, match="unknown preset"):
        endocast.render(volume, preset="gastroscopy")
    with pytest.raises(endocast.EndocastError, match="iso_opacity"):
        endocast.render(volume, iso_opacity=2.0)
    with pytest.raises(endocast.EndocastError, match="eye and look_at"):
        endocast.render(volume, eye=(0, 0, 0))
    with pytest.raises(TypeError, match="colour"):
        endocast.render(volume, colour="red")
    with pytest.raises(endocast.EndocastError, match="3"):
        endocast.Volume.from_array(np.zeros((4, 4)), np.eye(4))
    with pytest.raises(endocast.EndocastError, match="space"):
        endocast.Volume.from_array(np.zeros((2, 2, 2)), np.eye(4), space="XYZ")
    with pytest.raises(endocast.EndocastError, match="outside"):
        endocast.path(volume, (0, 0, 500), preset="colonoscopy")
    with pytest.raises(endocast.EndocastError):
        endocast.fly(volume, tmp_path / "no-route.json")
    bad = tmp_path / "bad.nii"
    bad.write_bytes(b"\0" * 400)
    with pytest.raises(endocast.EndocastError, match="bad.nii"):
        endocast.open(bad)


def test_two_threads_render_at_once(volume):
    """With the GIL released, two single-threaded renders in two Python threads overlap in
    time (holding the GIL, the second could only start after the first ended)."""
    options = dict(preset="colonoscopy", size=(160, 160), threads=1)
    endocast.render(volume, **options)
    start = time.perf_counter()
    endocast.render(volume, **options)
    alone = time.perf_counter() - start
    barrier, spans = threading.Barrier(2), []

    def work():
        barrier.wait()
        begin = time.perf_counter()
        endocast.render(volume, **options)
        spans.append((begin, time.perf_counter()))

    threads = [threading.Thread(target=work) for _ in range(2)]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    both = time.perf_counter() - start
    (a0, a1), (b0, b1) = spans
    overlap = min(a1, b1) - max(a0, b0)
    print(f"one render {alone * 1e3:.0f} ms, two threads {both * 1e3:.0f} ms "
          f"({both / alone:.2f}x), overlap {overlap * 1e3:.0f} ms")
    assert overlap > 0.5 * min(a1 - a0, b1 - b0)


def test_save_png_writes_what_it_is_given(tmp_path):
    image = np.arange(4 * 5 * 3, dtype=np.uint8).reshape(4, 5, 3)
    endocast.save_png(tmp_path / "x.png", image)
    np.testing.assert_array_equal(read_png_rgb(tmp_path / "x.png"), image)
    with pytest.raises(endocast.EndocastError, match="channels"):
        endocast.save_png(tmp_path / "y.png", np.zeros((2, 2, 2), np.uint8))
