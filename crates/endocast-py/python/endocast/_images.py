"""Volumes from the images of the other Python imaging libraries: nibabel and SimpleITK.

Every function of endocast that takes a ``Volume`` also takes these images as they are; they
are converted once by ``as_volume`` (the voxels copied into endocast's 16-bit store, the
geometry kept exactly).
"""

import functools

import numpy as np

from ._endocast import Volume


def as_volume(image):
    """The ``Volume`` of ``image``: an endocast ``Volume`` (returned as it is), a nibabel image
    (``Nifti1Image``, ``Nifti2Image``, ``AnalyzeImage``, ... : its scaled data and RAS affine)
    or a SimpleITK ``Image`` (its voxels and LPS origin, spacing and direction).

    A 4-D image with one volume is taken as 3-D; more volumes, vector pixels and 2-D images
    raise ``ValueError``."""
    if isinstance(image, Volume):
        return image
    if _is_simpleitk(image):
        return _from_simpleitk(image)
    if hasattr(image, "affine") and hasattr(image, "dataobj"):
        return _from_nibabel(image)
    raise TypeError(
        f"expected an endocast.Volume, a nibabel image or a SimpleITK Image, not "
        f"{type(image).__module__}.{type(image).__qualname__}"
    )


def _three_d(array, what):
    """``array`` as 3-D: a trailing axis of length one dropped."""
    while array.ndim > 3 and array.shape[-1] == 1:
        array = array[..., 0]
    if array.ndim != 3:
        raise ValueError(f"{what} has shape {array.shape}: endocast takes one 3-D volume")
    return array


def _from_nibabel(image):
    """A nibabel image: the data with its scaling applied, the affine in RAS."""
    if image.affine is None:
        raise ValueError("the nibabel image has no affine: give one to Volume.from_array")
    array = _three_d(np.asanyarray(image.dataobj), "the nibabel image")
    return Volume.from_array(array, np.asarray(image.affine, dtype=np.float64), space="RAS")


def _is_simpleitk(image):
    return type(image).__module__.split(".")[0] == "SimpleITK" and hasattr(image, "GetDirection")


def _from_simpleitk(image):
    """A SimpleITK image: its array (SimpleITK indexes it [k, j, i]) transposed to [i, j, k],
    and the affine from its direction, spacing and origin, which are LPS."""
    import SimpleITK as sitk

    if image.GetDimension() != 3:
        raise ValueError(f"the SimpleITK image has {image.GetDimension()} dimensions, not 3")
    if image.GetNumberOfComponentsPerPixel() != 1:
        raise ValueError("the SimpleITK image has vector pixels: endocast takes a scalar volume")
    array = sitk.GetArrayViewFromImage(image).T
    direction = np.asarray(image.GetDirection(), dtype=np.float64).reshape(3, 3)
    affine = np.eye(4)
    affine[:3, :3] = direction @ np.diag(image.GetSpacing())
    affine[:3, 3] = image.GetOrigin()
    return Volume.from_array(array, affine, space="LPS")


def accepting_images(function):
    """``function`` with its first argument, a volume, converted by ``as_volume``."""

    @functools.wraps(function)
    def wrapper(volume, *args, **kwargs):
        return function(as_volume(volume), *args, **kwargs)

    return wrapper
