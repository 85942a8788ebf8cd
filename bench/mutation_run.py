#!/usr/bin/env python3
"""The mutation run of issue 32 as a benchmark: damaged copies of valid scans, each read by the
real CLI (`endocast info FILE`) in its own process under a wall-time and an address-space
limit, tallied as tried / refused / accepted / panics / timeouts / killed, with the largest
peak memory and wall time of the refusals.

The seeds are the fuzz seeds of the volume readers (fuzz/seeds/{dicom,nrrd,metaimage,nifti})
and, when present, the shared DICOM files in every transfer syntax. Each mutant is one seed
with one damage chosen by a seeded generator: a truncation, flipped bytes (mostly in the
header), a 16- or 32-bit field overwritten with a hostile number (0, -1, 0xFFFF, 0x7FFFFFFF,
0xFFFFFFFF, ...: lying lengths and sizes), a number in a text header replaced (0, -1, huge,
nan, inf, 1e308), a block of the file duplicated or cut out. The same --seed gives the same
files.

    cargo build -p endocast-cli
    python3 bench/mutation_run.py --count 4000 --seed 32 --endocast target/debug/endocast OUT

Writes OUT/results.tsv (one line per mutant) and prints the table. A mutant that panics, times
out or is killed stays in OUT/mutants with its stderr (.err), listed at the end: make it a fuzz
seed. The others are deleted once read (30 000 take 2.5 GB), unless --keep.
"""

import argparse
import os
import random
import re
import resource
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = Path(os.environ.get("ENDOCAST_SHARED_DATA", "/work/shared/data"))
HOSTILE_INTS = [0, 1, 0xFF, 0x7FFF, 0x8000, 0xFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF,
                0xFFFFFFF0, 0x10000, 0x1000000]
HOSTILE_TEXT = [b"0", b"-1", b"-2147483649", b"99999999999999999999", b"nan", b"inf",
                b"1e308", b"4294967296", b""]


def seeds():
    """(name, extension, bytes) of every valid seed."""
    found = []
    for target in ["dicom", "nrrd", "metaimage", "nifti"]:
        for path in sorted((ROOT / "fuzz" / "seeds" / target).glob("*")):
            if path.name == "dev-zero.nhdr":
                continue  # names /dev/zero: refused before any mutation matters
            ext = ".nii.gz" if path.name.endswith(".nii.gz") else path.suffix
            found.append((f"{target}/{path.name}", ext, path.read_bytes()))
    shared = SHARED / "dicom-transfer-syntaxes"
    for path in sorted(shared.glob("*.dcm")) if shared.is_dir() else []:
        found.append((f"shared/{path.name}", ".dcm", path.read_bytes()))
    return found


def header_end(data):
    """Bytes worth aiming at: a text header up to its blank line, else the first 1 KiB."""
    blank = data.find(b"\n\n")
    return max(16, min(len(data), blank if blank > 0 else 1024))


def mutate(rng, data):
    """One damaged copy of `data` and the damage, in words."""
    kind = rng.choice(["truncate", "flip", "field16", "field32", "text", "dup", "cut"])
    end = header_end(data)
    if kind == "truncate":
        at = rng.randrange(len(data)) if rng.random() < 0.5 else rng.randrange(end)
        return data[:at], f"truncated at {at}"
    if kind == "flip":
        out = bytearray(data)
        spots = [rng.randrange(end) if rng.random() < 0.7 else rng.randrange(len(data))
                 for _ in range(rng.randint(1, 8))]
        for at in spots:
            out[at] ^= rng.randint(1, 255)
        return bytes(out), f"bytes {spots} flipped"
    if kind in ("field16", "field32"):
        width = 2 if kind == "field16" else 4
        at = rng.randrange(max(1, end - width))
        value = rng.choice(HOSTILE_INTS) & ((1 << (8 * width)) - 1)
        order = rng.choice(["little", "big"])
        out = data[:at] + value.to_bytes(width, order) + data[at + width:]
        return out, f"{8 * width}-bit {value:#x} ({order}) at {at}"
    if kind == "text":
        numbers = list(re.finditer(rb"-?[0-9][0-9.eE+-]*", data[:end]))
        if numbers:
            m = rng.choice(numbers)
            value = rng.choice(HOSTILE_TEXT)
            return data[:m.start()] + value + data[m.end():], f"number at {m.start()} -> {value!r}"
        return data[: len(data) // 2], "halved"
    a = rng.randrange(len(data))
    b = min(len(data), a + rng.randint(1, 4096))
    if kind == "dup":
        return data[:b] + data[a:b] + data[b:], f"bytes {a}..{b} doubled"
    return data[:a] + data[b:], f"bytes {a}..{b} cut out"


def limit_address_space(limit):
    def apply():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return apply


def run_one(endocast, path, timeout, as_limit, log_dir):
    """(outcome, peak RSS KiB, wall s, exit): refused, accepted, panic, timeout or killed."""
    err_path = log_dir / (path.name + ".err")
    with open(os.devnull, "wb") as out, open(err_path, "wb") as err:
        start = time.monotonic()
        proc = subprocess.Popen([endocast, "info", str(path)], stdout=out, stderr=err,
                                preexec_fn=limit_address_space(as_limit))
        fired = threading.Event()

        def kill():
            fired.set()
            proc.kill()
        timer = threading.Timer(timeout, kill)
        timer.start()
        _, status, usage = os.wait4(proc.pid, 0)
        timer.cancel()
        wall = time.monotonic() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
    stderr = err_path.read_bytes()
    code = proc.returncode
    if fired.is_set():
        outcome = "timeout"
    elif code == 101 or b"panicked" in stderr:
        outcome = "panic"
    elif code < 0:
        outcome = "killed"
    elif code == 0:
        outcome = "accepted"
    else:
        outcome = "refused"
    if outcome in ("refused", "accepted"):
        err_path.unlink()
    return outcome, usage.ru_maxrss, wall, code


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=32)
    parser.add_argument("--endocast", default=str(ROOT / "target" / "debug" / "endocast"))
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds per read")
    parser.add_argument("--as-limit", type=int, default=4 << 30, help="address space, bytes")
    parser.add_argument("--keep", action="store_true", help="keep every mutant, not only the bad")
    args = parser.parse_args()

    mutants = args.out / "mutants"
    mutants.mkdir(parents=True, exist_ok=True)
    rng = random.Random(args.seed)
    pool = seeds()
    counts = dict.fromkeys(["tried", "refused", "accepted", "panic", "timeout", "killed"], 0)
    worst_rss, worst_wall, bad = (0, ""), (0.0, ""), []
    started = time.monotonic()
    with open(args.out / "results.tsv", "w") as results:
        results.write("file\tseed\tdamage\toutcome\texit\tpeak_rss_kib\twall_s\n")
        for n in range(args.count):
            name, ext, data = rng.choice(pool)
            mutant, damage = mutate(rng, data)
            path = mutants / f"{n:05d}{ext}"
            path.write_bytes(mutant)
            outcome, rss, wall, code = run_one(args.endocast, path, args.timeout,
                                               args.as_limit, mutants)
            counts["tried"] += 1
            counts[outcome] += 1
            if outcome == "refused":
                worst_rss = max(worst_rss, (rss, path.name))
                worst_wall = max(worst_wall, (wall, path.name))
            if outcome in ("panic", "timeout", "killed"):
                bad.append(f"{path} ({name}, {damage}): {outcome}, exit {code}")
            elif not args.keep:
                path.unlink()
            results.write(f"{path.name}\t{name}\t{damage}\t{outcome}\t{code}\t{rss}\t{wall:.3f}\n")
    elapsed = time.monotonic() - started
    print(f"seeds: {len(pool)}; mutants: {args.count} (seed {args.seed}); {elapsed:.0f} s")
    print("| tried | refused | accepted | panics | timeouts | killed |")
    print("|---:|---:|---:|---:|---:|---:|")
    print("| {tried} | {refused} | {accepted} | {panic} | {timeout} | {killed} |".format(**counts))
    print(f"refusals: peak RSS at most {worst_rss[0] / 1024:.1f} MiB ({worst_rss[1]}), "
          f"wall time at most {worst_wall[0]:.2f} s ({worst_wall[1]})")
    for line in bad:
        print(line)
    return 1 if bad else 0


if __name__ == "__main__":
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.exit(main())
