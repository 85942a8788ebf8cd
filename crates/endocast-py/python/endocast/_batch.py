"""Cohorts and long flights on a Dask cluster, through the ``endocast`` command.

``batch`` runs a manifest's studies. Each study is run by ``endocast batch MANIFEST -o OUT
--study K`` -- the very function a whole ``endocast batch`` run calls for it -- on a worker of a
``dask.distributed.Client`` (or, without one, the whole run by ``endocast batch`` here), and
the summary is written by ``endocast batch --from-records``: the records and files are those of
the command. ``fly_split`` flies a long flight in parts (``fly --frames K/N``) on the workers
and joins their frames into the film (``endocast film``), the film of the whole flight.

The workers need the ``endocast`` command and the scans and output folder at the same paths
(a shared filesystem; docs/batch.md shows a SLURM and a Kubernetes launch). The command is
``program=`` when given, else ``ENDOCAST_BIN``, else ``endocast`` on ``PATH``. Waiting for it
holds no lock: the workers' other threads and the caller's go on.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from ._endocast import EndocastError


def find_program(program=None):
    """The ``endocast`` command: ``program`` when given, else the ``ENDOCAST_BIN``
    environment variable, else ``endocast`` on ``PATH``; an ``EndocastError`` when none is."""
    if program is None:
        program = os.environ.get("ENDOCAST_BIN") or shutil.which("endocast")
        if program is None:
            raise EndocastError(
                "the endocast command is needed: pass program=, set ENDOCAST_BIN or put "
                "endocast on PATH"
            )
    path = Path(program)
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise EndocastError(f"the endocast command {path} is not an executable file")
    return path


def _run(program, args, stdin=None):
    """Runs ``program args...``; the finished process, or an ``EndocastError`` with its
    error line."""
    done = subprocess.run(
        [str(program), *map(str, args)], capture_output=True, text=True, input=stdin
    )
    if done.returncode != 0:
        raise EndocastError(_said(done.stderr) or f"endocast {args[0]} failed ({done.returncode})")
    return done


def _said(stderr):
    """The ``error:`` line of the command's standard error (its last line else)."""
    lines = [line for line in stderr.splitlines() if line.strip()]
    for line in reversed(lines):
        if line.startswith("error: "):
            return line[len("error: "):]
    return lines[-1] if lines else ""


def batch(
    manifest,
    out,
    client=None,
    workers=None,
    program=None,
    timeout=None,
    fail_on_error=False,
    progress=True,
):
    """Runs every study of ``manifest`` (CSV or JSON lines, as ``endocast batch`` takes it)
    into ``out`` and returns the records of ``out/summary.json`` (scan, status ok | failed |
    skipped, message, seconds, output, outputs), in the manifest's order.

    With a ``dask.distributed.Client`` each study is a task on its workers, the records
    gathered as they end; a study that fails, or whose worker is lost, is a failed record with
    its message. ``workers`` is the number of studies run at once on one machine, which share
    its cores and memory (default: 1 without a client; with one, the most worker threads on
    one host). ``timeout`` is the most seconds a study may take. With ``fail_on_error`` an
    ``EndocastError`` is raised when a study failed, once the summary is written. A bad
    manifest raises ``EndocastError`` before anything runs.
    """
    program = find_program(program)
    common = [Path(manifest), "-o", Path(out)]
    if timeout is not None:
        common += ["--timeout", timeout]
    if fail_on_error:
        common.append("--fail-on-error")
    if client is None:
        done = _run(program, ["batch", *common, "--workers", workers or 1, "--json"])
        return json.loads(done.stdout)["studies"]
    plan = json.loads(_run(program, ["batch", *common, "--plan"]).stdout)["studies"]
    workers = workers or _threads_per_host(client)
    records = _gather(client, plan, [program, *common, "--workers", workers], progress)
    records = json.dumps({"studies": records})
    done = _run(program, ["batch", *common, "--from-records", "-", "--json"], stdin=records)
    return json.loads(done.stdout)["studies"]


def _threads_per_host(client):
    """The most worker threads the client's cluster has on one host."""
    per_host = {}
    for worker in client.scheduler_info()["workers"].values():
        host = worker.get("host", "")
        per_host[host] = per_host.get(host, 0) + worker.get("nthreads", 1)
    return max(per_host.values(), default=1)


def _gather(client, plan, command, progress):
    """Runs each study of ``plan`` as a task and returns their records in plan order."""
    from dask.distributed import as_completed

    futures = client.map(_study, plan, command=command, pure=False)
    order = {future.key: n for n, future in enumerate(futures)}
    records = [None] * len(plan)
    for ended, future in enumerate(as_completed(futures), start=1):
        n = order[future.key]
        try:
            records[n] = future.result()
        except Exception as lost:  # the worker died or the task could not run
            records[n] = _failed(plan[n], f"the study's worker was lost: {lost!r}")
        if progress:
            record = records[n]
            print(
                f"[{ended}/{len(plan)}] {record['scan']} in {record['seconds']:.1f} s: "
                f"{record['status']} {record['message']}".rstrip(),
                file=sys.stderr,
            )
    return records


def _failed(study, message):
    """The record of a study that ended without one of its own."""
    return {
        "scan": study["scan"],
        "status": "failed",
        "message": message,
        "seconds": 0.0,
        "output": study["output"],
        "outputs": {},
    }


def _study(study, command):
    """Task: runs ``endocast batch ... --study K --json`` on this worker; its record."""
    program, *args = command
    args = ["batch", *map(str, args), "--study", str(study["study"]), "--json"]
    done = subprocess.run(
        [str(_here(program)), *args],
        capture_output=True,
        text=True,
    )
    if done.returncode != 0 and not done.stdout.strip():
        return _failed(study, _said(done.stderr) or f"endocast failed ({done.returncode})")
    return json.loads(done.stdout)


def fly_split(scan, path, output, client=None, parts=None, program=None, **options):
    """Flies ``scan`` along ``path`` (files the workers read at the same paths) into
    ``output`` (.mp4, .gif or a folder of PNGs) in ``parts`` parts, each ``endocast fly
    --frames K/N`` as a task on the client's workers (one after another without a client), and
    joins their frames into ``output`` with ``endocast film``: the film ``endocast fly`` makes
    of the whole flight, byte for byte. ``options`` are ``fly``'s (``preset="colonoscopy"``,
    ``size=(256, 256)``, ``look="realistic"``, ``fps=30``; a flag is ``True``); ``coverage``
    and ``dataset`` need the whole flight. ``parts`` defaults to the client's worker threads
    and must not exceed the flight's frames. Returns the output's path.
    """
    program = find_program(program)
    output = Path(output)
    if parts is None:
        parts = sum(client.nthreads().values()) if client is not None else 1
    args = ["fly", Path(scan), "--path", Path(path), *_options(options)]
    film = []  # the film's options, as the whole flight's
    for key in ("fps", "ffmpeg"):
        if options.get(key) is not None:
            film += [f"--{key}", options[key]]
    output.parent.mkdir(parents=True, exist_ok=True)
    folder = Path(tempfile.mkdtemp(prefix=f".{output.name}.parts.", dir=output.parent))
    try:
        folders = [folder / f"part{k:04}" for k in range(1, parts + 1)]
        commands = [
            [program, *args, "--frames", f"{k}/{parts}", "-o", part]
            for k, part in enumerate(folders, start=1)
        ]
        if client is None:
            for command in commands:
                _fly_part(command)
        else:
            client.gather(client.map(_fly_part, commands, pure=False))
        _run(program, ["film", *folders, "-o", output, *film])
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return output


def _fly_part(command):
    """Task: flies one part (``endocast fly ... --frames K/N``); an ``EndocastError`` when it
    fails."""
    program, *args = command
    _run(_here(program), args)


def _here(program):
    """The command on this worker: the client's when this machine has it at the same path,
    else this machine's own (``ENDOCAST_BIN``, ``PATH``)."""
    return program if Path(program).is_file() else find_program()


def _options(options):
    """Keyword options as ``endocast`` options: ``look_at=(x, y, z)`` is ``--look-at x,y,z``,
    ``size=(w, h)`` is ``--size WxH``, ``True`` a flag, ``False`` or ``None`` left out."""
    args = []
    for key, value in options.items():
        name = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            args.append(name)
        elif key == "size" and isinstance(value, (tuple, list)):
            args += [name, "x".join(map(str, value))]
        elif isinstance(value, (tuple, list)):
            args += [name, ",".join(map(str, value))]
        else:
            args += [name, str(value)]
    return args
