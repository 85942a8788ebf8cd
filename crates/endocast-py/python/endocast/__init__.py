"""endocast: virtual endoscopy of CT and MRI scans from Python.

Read a scan (``open``), wrap a numpy array (``Volume.from_array``) or pass a nibabel or
SimpleITK image as it is (``as_volume`` converts it), render the endoscope's
view (``render``), plan a centred path through a lumen (``path``), fly along it (``fly``) and review the
wall a flight missed (``coverage``), find polyp candidates on a colon's wall (``polyps``),
lay the wall open along the path (``dissect``); run a cohort's manifest, or a long flight in
parts, on a Dask cluster (``batch``, ``fly_split``).
The options are those of the ``endocast`` command (``--look-at`` is ``look_at=``), with the
same defaults and presets; positions are in the patient frame, LPS millimetres, as DICOM has
them (``Volume.affine_ras`` converts to nibabel's RAS).

    >>> import endocast
    >>> vol = endocast.open("colon.nii.gz")
    >>> rgba, depth = endocast.render(vol, preset="colonoscopy", size=(256, 256))
"""

from . import _endocast
from ._batch import batch, fly_split
from ._endocast import EndocastError, Volume, open, presets, save_png
from ._images import accepting_images, as_volume

render = accepting_images(_endocast.render)
default_view = accepting_images(_endocast.default_view)
path = accepting_images(_endocast.path)
fly = accepting_images(_endocast.fly)
coverage = accepting_images(_endocast.coverage)
match = _endocast.match
polyps = accepting_images(_endocast.polyps)
dissect = accepting_images(_endocast.dissect)

__all__ = [
    "EndocastError",
    "Volume",
    "as_volume",
    "batch",
    "coverage",
    "default_view",
    "dissect",
    "fly",
    "fly_split",
    "match",
    "open",
    "path",
    "polyps",
    "presets",
    "render",
    "save_png",
]
