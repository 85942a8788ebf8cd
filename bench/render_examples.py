#!/usr/bin/env python3
"""Renders the example images in docs/examples/ from the poses in bench/scenes.json (inside the
trachea, the aorta, the nasal cavity and a lateral ventricle) with each scene's preset, plus an
iso view of each, with the `endocast` bench/cargo_bin.py finds ($ENDOCAST, else the release
build). Run from the repository root with ../shared/data beside it: python3 bench/render_examples.py"""
import json
import subprocess

import cargo_bin

exe = cargo_bin.endocast()
scenes = json.load(open("bench/scenes.json"))["scenes"]
for scene in scenes:
    triple = lambda key: ",".join(str(v) for v in scene[key])
    base = [exe, "render", scene["volume"], "--size", "384x384",
            "--eye", triple("eye"), "--look-at", triple("look_at"), "--up", triple("up"),
            "--iso", str(scene["iso"])]
    for key, value in scene.get("open_options", {}).items():
        base += ["--" + key, str(value)]
    name = scene["name"]
    subprocess.run(base + ["--mode", "iso", "-o", f"docs/examples/{name}-iso.png"], check=True)
    subprocess.run(base + ["--preset", scene["preset"], "-o", f"docs/examples/{name}-{scene['preset']}.png"],
                   check=True)
