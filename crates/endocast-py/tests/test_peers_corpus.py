"""Read what the peers read (issue 32): every test file that ships with pydicom, pydicom-data
and nibabel, opened by endocast and by its peer (pydicom for DICOM, nibabel for NIfTI and
Analyze), each file put in one class:

- agree: same values (float32 rounding; one stored unit for lossy JPEG, whose decoders may
  round differently) and geometry within 1e-3 mm;
- both refuse: the peer cannot decode it either (not DICOM without `force`, no pixel data, no
  decoder), and endocast refuses;
- refused, stated limit: the peer reads it but it is not a grey-scale volume (colour, palette,
  1-bit segmentation, RT dose, several volumes), and endocast's refusal names that limit;
- refused otherwise, not grey-scale: the peer reads a colour or other non-grey-scale image
  that endocast refuses for another reason (a header it cannot parse);
- endocast only: endocast reads a file its peer cannot decode;
- differs with a warning: values or geometry differ and endocast said why, or endocast reads
  the file by a stated convention and said so (MONOCHROME1 inverted so that bright is high; the
  first of several NIfTI volumes); a Siemens mosaic is compared unpacked, as nibabel's
  MosaicWrapper unpacks it;
- and the two that must stay empty: refused although the peer reads a grey-scale image, and
  differs without a warning.

The table is printed (and kept in BENCHMARKS.md, "Read what the peers read").
"""

import gzip
import os
import time
import warnings
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np
import pytest

import endocast

AGREE = "agree"
BOTH_REFUSE = "both refuse"
LIMIT = "refused, stated limit"
OTHER_REFUSAL = "refused otherwise, not grey-scale"
ONLY_US = "endocast only"
DIFFER_WARNED = "differs with a warning"
BAD_REFUSED = "BAD: refused, peer reads grey-scale"
BAD_DIFFER = "BAD: differs without a warning"
CLASSES = [AGREE, BOTH_REFUSE, LIMIT, OTHER_REFUSAL, ONLY_US, DIFFER_WARNED, BAD_REFUSED, BAD_DIFFER]

# Files that are not images of any format: the packages' code, notes and text dumps.
NOT_IMAGES = {".py", ".pyc", ".txt", ".json", ".dump", ".rst", ".md", ".m", ".gitignore"}
NIFTI_NAMES = (".nii", ".nii.gz", ".hdr")
GEOMETRY_MM = 1e-3
LOSSY_JPEG = {"1.2.840.10008.1.2.4.50", "1.2.840.10008.1.2.4.51"}


class NotGreyscale(Exception):
    """The peer reads the file, but it is not a grey-scale volume (a stated limit of ours)."""


class PeerCannot(Exception):
    """The peer cannot decode the file."""


def corpus():
    """(source, path) of every candidate file, sorted; empty sources are missing packages."""
    files = []
    pydicom = pytest.importorskip("pydicom")
    root = Path(pydicom.__file__).parent / "data" / "test_files"
    files += [("pydicom", p) for p in sorted(root.rglob("*")) if p.is_file()]
    try:
        import data_store  # pydicom-data's package

        root = Path(data_store.__file__).parent / "data"
        files += [("pydicom-data", p) for p in sorted(root.rglob("*")) if p.is_file()]
    except ImportError:
        files.append(("pydicom-data", None))
    nibabel = pytest.importorskip("nibabel")
    root = Path(nibabel.__file__).parent
    for folder in [root / "tests" / "data", root / "nicom" / "tests" / "data"]:
        for p in sorted(folder.rglob("*")):
            if p.is_file() and (p.name.endswith(NIFTI_NAMES) or ".dcm" in p.name):
                files.append(("nibabel", p))
    return [(s, p) for s, p in files if p is None or "".join(p.suffixes[-1:]) not in NOT_IMAGES]


# ---- the peers ---------------------------------------------------------------------------


def frame_attribute(ds, frame, sequence, keyword):
    """An attribute of frame `frame`: per-frame functional group, shared group, top level."""
    for groups in ["PerFrameFunctionalGroupsSequence", "SharedFunctionalGroupsSequence"]:
        items = ds.get(groups)
        if not items:
            continue
        item = items[min(frame, len(items) - 1)] if groups.startswith("Per") else items[0]
        inner = item.get(sequence)
        if inner and keyword in inner[0]:
            return inner[0][keyword].value
    return ds.get(keyword)


def pydicom_frames(path):
    """(frames as float64 [frame, row, column], [per frame: position or None], row cosine,
    column cosine, (row spacing, column spacing) or None, pixel padding mask or None, the word
    endocast's warning must contain (MONOCHROME1 inverted) or None, the tolerance of a lossy
    JPEG decoder). A Siemens mosaic gives its slices, as nibabel unpacks them."""
    import pydicom
    from pydicom.pixels import apply_modality_lut

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = pydicom.dcmread(path)
            if "PixelData" not in ds or "Rows" not in ds or "Columns" not in ds:
                raise PeerCannot("no image (PixelData, Rows, Columns)")
            kind = (ds.get("Modality", ""), ds.get("PhotometricInterpretation", ""))
            bits = ds.get("BitsAllocated", 0)
            if kind[0] in ("SEG", "RTDOSE") or not kind[1].startswith("MONOCHROME"):
                raise NotGreyscale(f"{kind[0]} {kind[1]}, {bits} bits")
            if ds.get("SamplesPerPixel", 1) != 1 or bits == 1:
                raise NotGreyscale(f"{ds.get('SamplesPerPixel')} samples, {bits} bits")
            raw = ds.pixel_array
            said = None
            mosaic_positions = None
            if "MOSAIC" in ds.get("ImageType", []):
                raw, mosaic_positions = unpack_mosaic(ds, raw)
            inverted = kind[1] == "MONOCHROME1" and kind[0] != "CT"
            if inverted:
                said = "MONOCHROME1"
                # endocast's stated convention: bright is high (inverted within BitsStored).
                raw = invert_monochrome1(raw, ds)
    except (NotGreyscale, PeerCannot):
        raise
    except Exception as e:  # noqa: BLE001 - any peer failure means "the peer cannot"
        raise PeerCannot(f"{type(e).__name__}: {e}") from e
    frames = raw.reshape((-1, *raw.shape[-2:]))
    values = np.empty(frames.shape, np.float64)
    for f, frame in enumerate(frames):
        slope = frame_attribute(ds, f, "PixelValueTransformationSequence", "RescaleSlope")
        intercept = frame_attribute(ds, f, "PixelValueTransformationSequence", "RescaleIntercept")
        if "ModalityLUTSequence" in ds or slope is None:
            values[f] = apply_modality_lut(frame, ds)
        else:
            values[f] = frame * float(slope) + float(intercept or 0.0)
    positions = mosaic_positions or []
    for f in range(len(positions), len(frames)):
        ipp = frame_attribute(ds, f, "PlanePositionSequence", "ImagePositionPatient")
        positions.append(None if not ipp else np.array([float(v) for v in ipp]))
    iop = frame_attribute(ds, 0, "PlaneOrientationSequence", "ImageOrientationPatient")
    spacing = frame_attribute(ds, 0, "PixelMeasuresSequence", "PixelSpacing")
    spacing = [float(v) for v in spacing] if spacing else None
    if spacing == [0.0, 0.0]:
        spacing = None
    padding = None
    if "PixelPaddingValue" in ds:
        padding = frames == ds.PixelPaddingValue
    cosines = None
    if iop and len(iop) == 6:
        cosines = np.array([float(v) for v in iop]).reshape(2, 3)
        cosines /= np.linalg.norm(cosines, axis=1)[:, None]
    unit = 0.0
    if ds.file_meta.get("TransferSyntaxUID") in LOSSY_JPEG:
        unit = abs(float(frame_attribute(ds, 0, "PixelValueTransformationSequence", "RescaleSlope") or 1))
    return values, positions, cosines, spacing, padding, said, unit


def unpack_mosaic(ds, raw):
    """The slices of a Siemens mosaic [slice, row, column] and their positions, as nibabel's
    MosaicWrapper gives them (its count, first position, normal and spacing)."""
    from nibabel.nicom.dicomwrappers import MosaicWrapper

    wrapper = MosaicWrapper(ds)
    count = wrapper.n_mosaic
    side = int(np.ceil(np.sqrt(count)))
    rows, columns = ds.Rows // side, ds.Columns // side
    tiles = raw.reshape(side, rows, side, columns).transpose(0, 2, 1, 3)
    affine = wrapper.affine  # DICOM patient (LPS) mm; column 2 is the step between slices
    positions = [affine[:3, 3] + k * affine[:3, 2] for k in range(count)]
    return tiles.reshape(-1, rows, columns)[:count], positions


def invert_monochrome1(raw, ds):
    """MONOCHROME1 samples inverted within BitsStored, as endocast stores them."""
    if ds.get("PixelRepresentation", 0) == 1:
        return -1 - raw.astype(np.int64)
    return (1 << ds.BitsStored) - 1 - raw.astype(np.int64)


def nibabel_volume(path):
    """(values [i, j, k], RAS affine) by nibabel, or the reason it is not a grey-scale volume."""
    import nibabel

    try:
        image = nibabel.load(path)
        if getattr(image, "affine", None) is None:
            raise NotGreyscale(f"a {type(image).__name__}, not a volume")
        dtype = image.get_data_dtype()
        if dtype.names or np.issubdtype(dtype, np.complexfloating):
            raise NotGreyscale(f"samples of type {dtype}")
        data = np.asanyarray(image.dataobj).astype(np.float64)
    except NotGreyscale:
        raise
    except Exception as e:  # noqa: BLE001
        raise PeerCannot(f"{type(e).__name__}: {e}") from e
    while data.ndim < 3:
        data = data[..., None]
    return data, image.affine


# ---- comparison --------------------------------------------------------------------------


def close(ours, theirs, unit=0.0):
    """Equal up to float32 rounding of the physical values, and `unit` (one stored unit for
    lossy JPEG, whose decoders may round a value half-way either side: ISO 10918-2)."""
    scale = max(1.0, float(np.max(np.abs(theirs))) if theirs.size else 1.0)
    atol = 1e-5 * scale + unit
    return ours.shape == theirs.shape and np.allclose(ours, theirs, rtol=0, atol=atol)


def compare_dicom(volume, peer):
    """None when endocast's volume is the peer's frames, else what differs."""
    values, positions, cosines, spacing, padding, _, unit = peer
    nframes, rows, columns = values.shape
    if volume.shape != (columns, rows, nframes):
        return f"shape {volume.shape} against {(columns, rows, nframes)}"
    affine = volume.affine
    if cosines is not None and spacing is not None:
        expected = np.stack([cosines[0] * spacing[1], cosines[1] * spacing[0]], axis=1)
        extent = max(rows, columns)
        if np.max(np.abs(affine[:3, :2] - expected)) * extent > GEOMETRY_MM:
            return f"in-plane axes {affine[:3, :2].T.tolist()} against {expected.T.tolist()}"
    from_world = np.linalg.inv(affine)
    ks = list(range(nframes))
    if all(p is not None for p in positions) and cosines is not None:
        for f, position in enumerate(positions):
            k = round(float((from_world @ np.append(position, 1))[2]))
            if np.linalg.norm((affine @ [0, 0, k, 1])[:3] - position) > GEOMETRY_MM:
                return f"frame {f} at {position.tolist()}, not on the volume's grid"
            ks[f] = k
    if sorted(ks) != list(range(nframes)):
        return f"frames land on slices {ks}"
    for f, k in enumerate(ks):
        ours = volume.voxels[:, :, k]
        theirs = values[f].T
        if padding is not None:  # endocast gives padding the lowest real value (warned)
            keep = ~padding[f].T
            ours, theirs = ours[keep], theirs[keep]
        if not close(ours, theirs, unit):
            diff = np.max(np.abs(ours - theirs))
            return f"frame {f}: values differ by up to {diff:g}"
    return None


def compare_nifti(volume, peer):
    data, affine = peer
    if data.ndim > 3:
        if data.shape[3:] != (1,) * (data.ndim - 3) and volume.shape == data.shape[:3]:
            data = data.reshape(data.shape[:3] + (-1,))[..., 0]
        else:
            data = data.reshape(data.shape[:3])
    if volume.shape != data.shape:
        return f"shape {volume.shape} against {data.shape}"
    extent = max(volume.shape)
    if np.max(np.abs(volume.affine_ras - affine)) * extent > GEOMETRY_MM:
        return f"affine {volume.affine_ras.tolist()} against {affine.tolist()}"
    if not close(volume.voxels, data):
        return f"values differ by up to {np.max(np.abs(volume.voxels - data)):g}"
    return None


def classify(path):
    """(class, detail) of one file."""
    is_nifti = path.name.endswith(NIFTI_NAMES)
    try:
        peer = nibabel_volume(path) if is_nifti else pydicom_frames(path)
        peer_state = None
    except NotGreyscale as e:
        peer, peer_state = None, f"peer: not grey-scale ({e})"
    except PeerCannot as e:
        peer, peer_state = None, f"peer cannot: {e}"
    try:
        volume = endocast.open(path)
    except endocast.EndocastError as e:
        message = str(e)
        if peer is not None:
            return BAD_REFUSED, message
        if peer_state.startswith("peer cannot"):
            return BOTH_REFUSE, f"{peer_state} | {message}"
        return (LIMIT if "unsupported" in message else OTHER_REFUSAL), f"{peer_state} | {message}"
    if peer is None:
        return ONLY_US, peer_state
    difference = (compare_nifti if is_nifti else compare_dicom)(volume, peer)
    said = expected_warning(peer, is_nifti)
    if difference is None and not said:
        return AGREE, ""
    if said and any(said in w for w in volume.warnings):
        return DIFFER_WARNED, f"{said}: {difference or 'otherwise equal'}"
    if difference is not None and volume.warnings:
        return DIFFER_WARNED, f"{difference} | {' / '.join(volume.warnings)}"
    return BAD_DIFFER, difference or f"no warning saying {said!r}"


def expected_warning(peer, is_nifti):
    """What endocast must say about a file it reads differently by convention: the first of
    several NIfTI volumes, MONOCHROME1 inverted."""
    if is_nifti:
        return "volume" if peer[0].ndim > 3 and np.prod(peer[0].shape[3:]) > 1 else None
    return peer[5]


def table(results):
    """The Markdown table: one row per source, one column per class."""
    counts = defaultdict(Counter)
    for source, kind, _, _ in results:
        counts[source][kind] += 1
    lines = ["| source | files | " + " | ".join(CLASSES) + " |"]
    lines.append("|---" * (len(CLASSES) + 2) + "|")
    for source in ["pydicom", "pydicom-data", "nibabel"]:
        row = counts[source]
        cells = [str(row[c]) for c in CLASSES]
        lines.append(f"| {source} | {sum(row.values())} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def test_peers_corpus(capsys, tmp_path):
    files = corpus()
    if any(p is None for _, p in files):
        if os.environ.get("CI") == "true":
            pytest.fail("pydicom-data is not installed under CI")
        print("SKIPPED: pydicom-data's files (pip install pydicom-data)")
        files = [(s, p) for s, p in files if p is not None]
    results = []
    start = time.monotonic()
    for source, path in files:
        if path.name.endswith(".gz") and ".dcm" in path.name:  # nibabel's gzipped DICOM
            plain = tmp_path / path.name.removesuffix(".gz")
            plain.write_bytes(gzip.decompress(path.read_bytes()))
            path = plain
        kind, detail = classify(path)
        results.append((source, kind, path.name, detail))
    elapsed = time.monotonic() - start
    with capsys.disabled():
        print(f"\npeers corpus: {len(results)} files in {elapsed:.1f} s")
        print(table(results))
        for source, kind, name, detail in results:
            if os.environ.get("PEERS_VERBOSE") or kind not in (AGREE, BOTH_REFUSE):
                print(f"  {kind:<36} {source:<13} {name}: {detail[:300]}")
    bad = [r for r in results if r[1] in (BAD_REFUSED, BAD_DIFFER)]
    assert not bad, "\n".join(f"{k}: {s} {n}: {d}" for s, k, n, d in bad)
