"""The `endocast` binary for the bench scripts (issue 31), found through cargo as
bench/cargo_bin.sh finds it: $ENDOCAST when set, else the release build, built first, in the
target directory `cargo metadata` reports — never a fixed target/release."""
import json
import os
import subprocess


def endocast():
    """The path of the endocast binary to run."""
    if os.environ.get("ENDOCAST"):
        return os.environ["ENDOCAST"]
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "endocast-cli"], check=True)
    meta = subprocess.run(["cargo", "metadata", "--format-version", "1", "--no-deps"],
                          check=True, capture_output=True, text=True).stdout
    return os.path.join(json.loads(meta)["target_directory"], "release", "endocast")
