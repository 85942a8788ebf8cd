"""endocast: virtual endoscopy of CT and MRI scans from Python.

Read a scan (``open``) or wrap a numpy array (``Volume.from_array``), render the endoscope's
view (``render``), plan a centred path through a lumen (``path``) and fly along it (``fly``).
The options are those of the ``endocast`` command (``--look-at`` is ``look_at=``), with the
same defaults and presets; positions are in the patient frame, LPS millimetres, as DICOM has
them (``Volume.affine_ras`` converts to nibabel's RAS).

    >>> import endocast
    >>> vol = endocast.open("colon.nii.gz")
    >>> rgba, depth = endocast.render(vol, preset="colonoscopy", size=(256, 256))
"""

from ._endocast import (
    EndocastError,
    Volume,
    default_view,
    fly,
    open,
    path,
    presets,
    render,
    save_png,
)

__all__ = [
    "EndocastError",
    "Volume",
    "default_view",
    "fly",
    "open",
    "path",
    "presets",
    "render",
    "save_png",
]
