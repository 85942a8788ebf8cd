"""Issue 37, item 2: a cohort from Python on a Dask LocalCluster of two worker processes gives
the records and the films of the CLI's `endocast batch` (one corrupt scan among small
phantoms), without a client too; a worker lost mid-study is a failed record; a flight split
into parts on the workers joins into the whole flight's film, byte for byte."""

import json
import stat

import pytest

import endocast
from conftest import missing


@pytest.fixture(scope="module")
def distributed():
    try:
        import dask.distributed
    except ImportError:
        missing("dask.distributed (pip install 'dask[distributed]')")
    return dask.distributed


@pytest.fixture(scope="module")
def cluster(distributed):
    """Two worker processes of one thread, as the issue's acceptance has it."""
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster, distributed.Client(cluster) as client:
        yield client


@pytest.fixture(scope="module")
def cohort(cli, tmp_path_factory):
    """A manifest of small colon phantoms and a corrupt scan."""
    folder = tmp_path_factory.mktemp("cohort")
    cli("phantom", "colon", "--size", "48", "-o", folder / "colon.nii.gz")
    whole = (folder / "colon.nii.gz").read_bytes()
    (folder / "corrupt.nii.gz").write_bytes(whole[: len(whole) // 2])
    manifest = folder / "studies.csv"
    manifest.write_text(
        "scan,preset,size,output\n"
        "colon.nii.gz,colonoscopy,48x48,\n"
        "corrupt.nii.gz,colonoscopy,,\n"
        "colon.nii.gz,colonoscopy,32x32,colon-small\n"
    )
    return manifest


def same_run(records, expected, out, expected_out):
    """Records equal but for the time and the output folder's place."""

    def strip(record, folder):
        text = json.dumps({k: v for k, v in record.items() if k != "seconds"})
        return json.loads(text.replace(str(folder), "OUT"))

    assert [strip(r, out) for r in records] == [strip(r, expected_out) for r in expected]


def test_batch_on_dask_gives_the_cli_records_and_films(
    cli, endocast_bin, cohort, cluster, tmp_path
):
    cli_out = tmp_path / "cli"
    cli("batch", cohort, "-o", cli_out)
    expected = json.loads((cli_out / "summary.json").read_text())["studies"]
    assert [r["status"] for r in expected] == ["ok", "failed", "ok"]

    out = tmp_path / "dask"
    records = endocast.batch(cohort, out, client=cluster, program=endocast_bin)
    same_run(records, expected, out, cli_out)
    assert json.loads((out / "summary.json").read_text())["studies"] == records
    assert "corrupt.nii.gz" in records[1]["message"]
    for study in ("colon", "colon-small"):
        for name in ("film.mp4", "start.png", "flat.png"):
            made, wanted = out / study / name, cli_out / study / name
            assert made.read_bytes() == wanted.read_bytes(), f"{study}/{name}"

    again = endocast.batch(cohort, out, client=cluster, program=endocast_bin)
    assert [r["status"] for r in again] == ["skipped", "failed", "skipped"]

    here = tmp_path / "here"
    records = endocast.batch(cohort, here, program=endocast_bin, workers=2)
    same_run(records, expected, here, cli_out)
    film = "colon/film.mp4"
    assert (here / film).read_bytes() == (cli_out / film).read_bytes()


def test_a_worker_lost_mid_study_is_a_failed_record(endocast_bin, cohort, distributed, tmp_path):
    """A program that kills its worker on study 3; the scheduler gives up on the first loss."""
    killer = tmp_path / "endocast-killer"
    killer.write_text(
        "#!/bin/sh\n"
        'case " $* " in *" --study 3 "*) kill -9 "$PPID"; exit 1 ;; esac\n'
        f'exec "{endocast_bin}" "$@"\n'
    )
    killer.chmod(killer.stat().st_mode | stat.S_IXUSR)
    import dask

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster, distributed.Client(cluster) as client:
            records = endocast.batch(cohort, tmp_path / "out", client=client, program=killer)
    assert [r["status"] for r in records] == ["ok", "failed", "failed"]
    assert "worker was lost" in records[2]["message"], records[2]


def test_a_bad_manifest_or_no_program_is_an_error(cohort, tmp_path, monkeypatch):
    with pytest.raises(endocast.EndocastError, match="not an executable"):
        endocast.batch(cohort, tmp_path, program=tmp_path / "nowhere")
    monkeypatch.delenv("ENDOCAST_BIN", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(endocast.EndocastError, match="ENDOCAST_BIN"):
        endocast.batch(cohort, tmp_path)


def test_a_bad_manifest_raises_before_anything_runs(endocast_bin, tmp_path):
    manifest = tmp_path / "m.csv"
    manifest.write_text("scan,colour\na.nii,red\n")
    with pytest.raises(endocast.EndocastError, match='"colour" is not a column'):
        endocast.batch(manifest, tmp_path / "out", program=endocast_bin)
    assert not (tmp_path / "out").exists()


def test_a_flight_split_on_the_workers_is_the_whole_flights_film(
    cli, endocast_bin, cluster, colon, tmp_path
):
    path = tmp_path / "path.json"
    cli("path", colon, "--preset", "colonoscopy", "-o", path)
    options = {"preset": "colonoscopy", "size": (48, 40), "frame_step": 2.0}
    whole = tmp_path / "whole.mp4"
    cli("fly", colon, "--path", path, "--preset", "colonoscopy", "--size", "48x40",
        "--frame-step", "2", "-o", whole)  # fmt: skip
    split = tmp_path / "split.mp4"
    made = endocast.fly_split(
        colon, path, split, client=cluster, parts=3, program=endocast_bin, **options
    )
    assert made == split
    assert split.read_bytes() == whole.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["path.json", "split.mp4", "whole.mp4"]
