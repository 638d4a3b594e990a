#!/usr/bin/env python3
"""Memory of `lookdev render` on large inputs: peak host and device memory, and bytes a pixel.

    cargo build --release && python3 benches/memory.py [--sizes 1024,2048] [--lookdev PATH]
        [--binary OTHER] [--no-env]

Cases, each one run of `lookdev render` with LOOKDEV_TIMINGS=1, which reports the device
memory the buffers and images held at their peak and the process's peak resident memory
(VmHWM, which on a CPU driver such as lavapipe holds the device memory too):

- the built-in shader ball (with its visibility) at each size, 1 spp, EXR beauty;
- the same with --aov all;
- an environment at the documented maximum, 16384x8192 (a flat Radiance .hdr this script
  writes, 8 MB), lighting a 16x16 render.

--binary adds a column of another build's host peak (measured with /usr/bin/time, as it may not
report its own), to compare before and after a change. See benches/README.md.
"""

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
MIB = 1 << 20


def write_flat_hdr(path, width=16384, height=8192):
    """A Radiance .hdr of radiance 1 everywhere, run-length encoded."""
    line = bytearray([2, 2, width >> 8, width & 255])
    for component in (128, 128, 128, 129):
        left = width
        while left > 0:
            run = min(127, left)
            line += bytes([128 + run, component])
            left -= run
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
        f.write(bytes(line) * height)


def measure(binary, args, folder):
    """(host peak MiB, device peak MiB or None) of one render."""
    done = subprocess.run(
        ["/usr/bin/time", "-f", "maxrss %M", binary, "render", "--quiet", *args],
        capture_output=True,
        text=True,
        cwd=folder,
        env={"LOOKDEV_TIMINGS": "1", "PATH": "/usr/bin:/bin", "HOME": str(folder)},
    )
    if done.returncode != 0:
        sys.exit(f"failed: {binary} render {' '.join(args)}\n{done.stderr}")
    host = int(re.search(r"maxrss (\d+)", done.stderr).group(1)) * 1024 / MIB
    device = re.search(r"device memory: peak ([\d.]+) MiB", done.stderr)
    return host, float(device.group(1)) if device else None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="1024,2048")
    parser.add_argument("--lookdev", default=str(REPO / "target/release/lookdev"))
    parser.add_argument("--binary", help="another build, for its host peak beside this one's")
    parser.add_argument("--no-env", action="store_true", help="leave out the 16384x8192 environment")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        cases = []
        for size in [int(s) for s in args.sizes.split(",")]:
            base = ["--size", str(size), str(size), "--spp", "1", "--out", "out.exr"]
            cases.append((f"shader ball {size}², beauty", size * size, base))
            cases.append((f"shader ball {size}², --aov all", size * size, base + ["--aov", "all"]))
        if not args.no_env:
            write_flat_hdr(folder / "max.hdr")
            cases.append(("16384x8192 environment, 16x16", 16384 * 8192, ["--env", "max.hdr", "--size", "16", "16", "--spp", "1", "--out", "out.exr"]))
        header = "| case | host peak | device peak | host B/pixel | device B/pixel |"
        if args.binary:
            header += " other build's host peak |"
        print(header)
        print("|" + "---|" * (header.count("|") - 1))
        for name, pixels, case in cases:
            host, device = measure(args.lookdev, case, folder)
            row = f"| {name} | {host:.0f} MiB | {device:.0f} MiB | {host * MIB / pixels:.0f} | {device * MIB / pixels:.0f} |"
            if args.binary:
                other, _ = measure(args.binary, case, folder)
                row += f" {other:.0f} MiB |"
            print(row, flush=True)
        print("(bytes a pixel: of the image's pixels, or of the environment's texels for the last case)")


if __name__ == "__main__":
    main()
