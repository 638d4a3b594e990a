#!/usr/bin/env python3
"""Whole-process time of short `lookdev render`s, where start-up is most of the time.

Two cases, each run --runs times per binary, the binaries interleaved run by run so that they
share the machine's load:

- `1 spp`: the built-in shader ball at 256², 1 spp, EXR;
- `sphere 64 spp`: the built-in sphere's g-buffer at 256², polished gold (the metallic material
  of compare_mitsuba.py, roughness 0.25), the studio map with --env-clamp, 64 spp, seed 1, EXR.

Prints the median and the range of each binary's wall-clock times, and `uptime` before and
after. Caches are warm: one untimed run of each case per binary comes first. See
benches/README.md.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
METAL = "[[object]]\n[[object.layer]]\n[object.layer.set]\nbase_color = [0.9626, 0.8276, 0.4082]\nmetallic = 1.0\nroughness = 0.25\n"


def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def run(args):
    start = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"failed: {' '.join(args)}\n{done.stderr}")
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--lookdev", action="append", help="a binary to time (repeatable; default target/release/lookdev)")
    parser.add_argument("--runs", type=int, default=7)
    options = parser.parse_args()
    binaries = options.lookdev or [str(REPO / "target/release/lookdev")]
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        sphere, look = folder / "sphere.exr", folder / "metal.toml"
        look.write_text(METAL)
        subprocess.run([binaries[-1], "gbuffer", "--builtin", "sphere", "--size", "256", "256", "--out", str(sphere)], check=True)
        env = str(REPO / "src/environment/studio.exr")
        cases = {
            "1 spp": ["render", "--size", "256", "256", "--spp", "1", "--quiet"],
            "sphere 64 spp": ["render", "--gbuffer", str(sphere), "--look", str(look), "--env", env, "--env-clamp",
                              "--spp", "64", "--seed", "1", "--quiet"],
        }
        print(f"before: {uptime()}")
        for name, args in cases.items():
            times = {binary: [] for binary in binaries}
            for warm in [True] + [False] * options.runs:
                for k, binary in enumerate(binaries):
                    seconds = run([binary, *args, "--out", str(folder / f"out{k}.exr")])
                    if not warm:
                        times[binary].append(seconds)
            for binary, values in times.items():
                print(f"{name:>14}  {binary}: median {statistics.median(values):.3f} s "
                      f"(min {min(values):.3f}, max {max(values):.3f}, {len(values)} runs)")
        print(f"after: {uptime()}")


if __name__ == "__main__":
    main()
