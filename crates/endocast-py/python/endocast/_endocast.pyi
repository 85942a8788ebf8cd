"""Type stubs of the native module (re-exported by ``endocast``)."""

import os
import pathlib
from typing import Any, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

_Vec3 = Tuple[float, float, float]
_Point = Union[_Vec3, Sequence[float], npt.NDArray[np.floating]]
_Path = Union[str, "os.PathLike[str]"]
_Mode = Literal["iso", "dvr", "hybrid", "two-iso", "mip", "minip", "peel"]
_Lens = Literal["pinhole", "equidistant", "equisolid", "orthographic"]
_Stereo = Literal["anaglyph", "red-cyan", "dubois", "side-by-side", "top-bottom", "pair"]
_Look = Literal["plain", "clinical", "realistic"]
_Secretion = Literal["off", "on", "accumulate"]
_Unpeeled = Literal["discard", "context"]
# A volume: endocast's own, or a nibabel image or SimpleITK Image (``as_volume`` converts them).
_VolumeLike = Union["Volume", Any]

class EndocastError(ValueError):
    """An error from endocast; the message is the library's, naming the file and the problem."""

class Volume:
    """A scan: voxels, their geometry in the patient (LPS mm) and their physical values."""

    @staticmethod
    def from_array(
        array: npt.ArrayLike,
        affine: npt.ArrayLike,
        space: Literal["RAS", "LPS"] = "RAS",
        modality: Optional[str] = None,
    ) -> Volume:
        """A volume from a 3-D array indexed [i, j, k] and its 4x4 voxel-to-world affine.

        ``space="RAS"`` for nibabel (``img.get_fdata(), img.affine``); ``"LPS"`` for DICOM
        and SimpleITK (``sitk.GetArrayFromImage(img).T`` with the affine built from
        ``GetDirection``, ``GetSpacing`` and ``GetOrigin``). Integer arrays of 8 and 16 bits
        are kept exactly; wider and float arrays exactly when they hold at most 65 536
        integer values, otherwise quantised to 16 bits (a warning says so)."""

    @property
    def voxels(self) -> npt.NDArray[np.float32]:
        """Physical values (HU for CT), read-only float32 (i, j, k), Fortran order; made once."""
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    @property
    def affine(self) -> npt.NDArray[np.float64]:
        """4x4 affine from voxel index to LPS mm."""
    @property
    def affine_ras(self) -> npt.NDArray[np.float64]:
        """4x4 affine from voxel index to RAS mm (nibabel's world)."""
    @property
    def spacing(self) -> npt.NDArray[np.float64]:
        """Voxel spacing along i, j, k, mm."""
    @property
    def origin(self) -> npt.NDArray[np.float64]:
        """LPS position of the centre of voxel (0, 0, 0), mm."""
    @property
    def modality(self) -> str:
        """"CT", "MR", another DICOM code, or "unknown"."""
    @property
    def warnings(self) -> list[str]:
        """What the reader noted without stopping."""
    @property
    def source(self) -> str:
        """The format read ("NIfTI", "DICOM", ...), or "array"."""
    @property
    def value_range(self) -> Tuple[float, float]: ...

def open(
    path: _Path,
    series: Optional[str] = None,
    *,
    max_voxels: Optional[int] = None,
    orientation: Optional[str] = None,
    fill_missing_slices: bool = False,
    allow_outside_data: bool = False,
) -> Volume:
    """Read a DICOM directory or file, NIfTI, NRRD or MetaImage scan."""

def render(
    volume: _VolumeLike,
    *,
    preset: Optional[str] = None,
    mode: Optional[_Mode] = None,
    iso: Optional[float] = None,
    iso2: Optional[float] = None,
    iso_opacity: Optional[float] = None,
    tf: Optional[str] = None,
    step: Optional[float] = None,
    jitter: Optional[bool] = None,
    skip_empty: Optional[bool] = None,
    shade_dvr: Optional[bool] = None,
    background: Optional[_Vec3] = None,
    eye: Optional[_Point] = None,
    look_at: Optional[_Point] = None,
    up: Optional[_Point] = None,
    fov: Optional[float] = None,
    near: float = 0.0,
    size: Tuple[int, int] = (512, 512),
    lens: Optional[_Lens] = None,
    distortion: Optional[Tuple[float, float]] = None,
    vignetting: Optional[float] = None,
    stereo: Optional[_Stereo] = None,
    eye_separation: Optional[float] = None,
    focus: Optional[float] = None,
    peel: Optional[Union[int, Literal["last"]]] = None,
    peel_threshold: Optional[float] = None,
    peel_falling: Optional[bool] = None,
    peel_keep: Optional[float] = None,
    unpeeled: Optional[_Unpeeled] = None,
    tf_after: Optional[str] = None,
    look: Optional[_Look] = None,
    secretion: Optional[_Secretion] = None,
    secretion_iso: Optional[float] = None,
    wetness: Optional[float] = None,
    texture: Optional[str] = None,
    texture_scale: Optional[float] = None,
    specular_map: Optional[str] = None,
    attenuation: Optional[float] = None,
    lighting: Optional[str] = None,
    still: int = 1,
    still_filter: Optional[Literal["trilinear", "bspline"]] = None,
    lumen_threshold: Optional[float] = None,
    bright_lumen: bool = False,
    threads: Optional[int] = None,
    meshes: Sequence[_Path] = (),
    overlays: Sequence[_Path] = (),
    target: Optional[_Point] = None,
) -> Tuple[npt.NDArray[np.uint8], npt.NDArray[np.float32]]:
    """Render one view as ``endocast render`` does: (rgba, depth).

    rgba is uint8 (height, width, 4), the colour over the background with alpha 255; depth is
    float32 (height, width), mm from the eye to the first isosurface hit, NaN where none.
    ``size`` is (width, height). ``stereo="pair"`` gives (2, height, width, 4) and
    (2, height, width). Without ``eye``/``look_at`` the camera is ``default_view``'s.
    ``mode="peel"`` with the ``peel*`` options peels (Borland et al.); ``look`` "clinical" or
    "realistic" draws the endoscope's look (Krüger et al.) with ``secretion``, ``wetness``,
    ``texture``, ``attenuation``, ``lighting`` ("phong", "ibl" or "ibl:FILE.png"), through a
    rigid endoscope's lens unless ``distortion``/``vignetting`` say otherwise; ``still``
    averages that many jittered frames, reconstructed by ``still_filter`` ("trilinear", the
    default, or "bspline": tricubic B-splines, about ten times slower a frame). ``meshes``
    (STL, OBJ, PLY) and ``overlays`` (DICOM SEG; RTDOSE as ``FILE`` or ``FILE:LEVEL,...``)
    are drawn with the scan as ``--mesh`` and ``--overlay`` draw them. ``target`` (LPS mm,
    e.g. a nodule ``endocast path --target`` routes to) is ringed in the view: solid where
    the view sees it, dashed and dimmer where it lies behind the wall, with its distance."""

def default_view(
    volume: _VolumeLike,
    *,
    preset: Optional[str] = None,
    iso: Optional[float] = None,
    fov: Optional[float] = None,
    lumen_threshold: Optional[float] = None,
    bright_lumen: bool = False,
    **look: object,
) -> Tuple[_Vec3, _Vec3, _Vec3]:
    """The camera ``render`` uses without ``eye``, the same as ``endocast render``'s:
    (eye, look_at, up), LPS mm. With an endoscopic ``preset`` (carried into the scan's units:
    HU, HU + 1024, MR) inside the structure it names, looking along the automatic path;
    without one, the whole object framed from the front. Takes ``render``'s look options."""

def path(
    volume: _VolumeLike,
    start: Optional[_Point] = None,
    end: Optional[_Point] = None,
    *,
    start_voxel: Optional[_Point] = None,
    end_voxel: Optional[_Point] = None,
    preset: Optional[str] = None,
    iso: Optional[float] = None,
    lumen_threshold: Optional[float] = None,
    bright_lumen: bool = False,
    smoothing: float = 5.0,
    step: float = 2.0,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The centred path through the lumen as ``endocast path`` writes it: (points, radii).

    points is (N, 3) LPS mm, every ``step`` mm and the end; radii (N,) the distance to the
    wall, mm. Without ``start`` the ``preset``'s structure is found and the path starts where
    ``default_view`` puts the camera; without ``end`` it runs to the structure's known end
    (the aorta's lowest section), else to the farthest point of the lumen."""

@overload
def fly(
    volume: _VolumeLike,
    route: Union[_Path, npt.ArrayLike],
    out: None = None,
    *,
    preset: Optional[str] = None,
    mode: Optional[_Mode] = None,
    iso: Optional[float] = None,
    iso2: Optional[float] = None,
    iso_opacity: Optional[float] = None,
    tf: Optional[str] = None,
    step: Optional[float] = None,
    jitter: Optional[bool] = None,
    skip_empty: Optional[bool] = None,
    shade_dvr: Optional[bool] = None,
    background: Optional[_Vec3] = None,
    fov: Optional[float] = None,
    near: float = 0.0,
    lens: Optional[_Lens] = None,
    distortion: Optional[Tuple[float, float]] = None,
    vignetting: Optional[float] = None,
    peel: Optional[Union[int, Literal["last"]]] = None,
    peel_threshold: Optional[float] = None,
    peel_falling: Optional[bool] = None,
    peel_keep: Optional[float] = None,
    unpeeled: Optional[_Unpeeled] = None,
    tf_after: Optional[str] = None,
    look: Optional[_Look] = None,
    secretion: Optional[_Secretion] = None,
    secretion_iso: Optional[float] = None,
    wetness: Optional[float] = None,
    texture: Optional[str] = None,
    texture_scale: Optional[float] = None,
    specular_map: Optional[str] = None,
    attenuation: Optional[float] = None,
    lighting: Optional[str] = None,
    size: Tuple[int, int] = (384, 384),
    frame_step: float = 1.0,
    look_ahead: float = 10.0,
    fps: float = 25.0,
    threads: Optional[int] = None,
    meshes: Sequence[_Path] = (),
    overlays: Sequence[_Path] = (),
    target: Optional[_Point] = None,
    dataset: Optional[_Path] = None,
) -> npt.NDArray[np.uint8]:
    """Fly along ``route`` (an (N, 3) array of LPS points or a path file) as ``endocast fly``
    films the endoscopic view: without ``out`` the frames, RGB uint8 (frames, height, width, 3).
    With ``dataset`` (a new or empty folder) also writes the training data of
    ``endocast fly --dataset`` (docs/dataset-format.md)."""
@overload
def fly(
    volume: _VolumeLike,
    route: Union[_Path, npt.ArrayLike],
    out: _Path,
    **options: object,
) -> pathlib.Path:
    """The same flight written to ``out`` (.gif, .mp4 or a folder of PNGs); returns its path."""
def coverage(
    volume: _VolumeLike,
    path: Optional[Union[_Path, npt.ArrayLike]] = None,
    *,
    preset: Optional[str] = None,
    iso: Optional[float] = None,
    look: Optional[_Look] = None,
    fov: Optional[float] = None,
    lens: Optional[_Lens] = None,
    size: Tuple[int, int] = (256, 256),
    frame_step: float = 1.0,
    look_ahead: float = 10.0,
    min_area: float = 10.0,
    forward_only: bool = False,
    views: Optional[_Path] = None,
    lumen_threshold: Optional[float] = None,
    bright_lumen: bool = False,
    threads: Optional[int] = None,
    **options: object,
) -> dict[str, Any]:
    """Fly ``path`` (or the ``preset``'s automatic path) and review the wall it missed, as
    ``endocast coverage --json`` reports it: ``patches`` (largest first: ``area_mm2``,
    ``centroid``, ``eye``, ``look_at``, ...) and the coverage before and after the review."""
def match(
    first: Volume,
    second: Volume,
    at: Tuple[float, float, float],
    preset: str = "colonoscopy",
    output: Optional[_Path] = None,
    size: Tuple[int, int] = (384, 384),
    fov: Optional[float] = None,
) -> dict[str, Any]:
    """The counterpart in ``second`` (prone) of the point ``at`` (LPS mm) of ``first``
    (supine), as ``endocast match --json`` reports it: ``point``, ``arc_mm``, ``eye``,
    ``look_at`` and the match (``turn_deg``, ``reversed``, ...); with ``output``, the two views
    side by side as a PNG."""
def polyps(
    volume: _VolumeLike,
    path: Optional[Union[_Path, npt.ArrayLike]] = None,
    *,
    preset: Optional[str] = None,
    iso: Optional[float] = None,
    sigma: float = 1.0,
    min_size: float = 4.0,
    lumen_threshold: Optional[float] = None,
    bright_lumen: bool = False,
    threads: Optional[int] = None,
    **options: object,
) -> dict[str, Any]:
    """Polyp candidates on the wall of the lumen ``path`` starts in (or of the ``preset``'s
    structure), as ``endocast polyps --json`` lists them: ``candidates`` (best first:
    ``centre`` on the wall, LPS mm, ``size_mm``, ``score``)."""
def dissect(
    volume: _VolumeLike,
    path: Optional[Union[_Path, npt.ArrayLike]] = None,
    *,
    preset: Optional[str] = None,
    iso: Optional[float] = None,
    along_step: float = 0.5,
    rows: int = 360,
    reach: float = 60.0,
    lumen_threshold: Optional[float] = None,
    bright_lumen: bool = False,
    threads: Optional[int] = None,
    **options: object,
) -> dict[str, Any]:
    """The wall along ``path`` (or the ``preset``'s automatic path) cut open and laid flat, as
    ``endocast dissect`` writes it: ``image`` (height, width, 3 uint8), ``map`` (height, width,
    3 float32: the LPS mm wall point of each pixel, NaN where none), ``plot`` (where the wall
    pixels lie), ``along_mm_per_px``, ``around_deg_per_px``, ``wall_fraction``, ..."""
def presets() -> list[str]:
    """The preset names."""
def save_png(path: _Path, image: npt.NDArray[np.uint8]) -> None:
    """Write an RGB or RGBA uint8 image (height, width, 3 or 4) as an 8-bit PNG."""
