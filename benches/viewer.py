#!/usr/bin/env python3
"""The viewer against `lookdev render` on the built-in scene: how long the viewer, left alone,
takes to reach a target, how its frames keep up while the light turns, and whether adaptive
sampling turns fewer samples into less time.

- converge: whole-process wall time of `lookdev view --exit-after-spp N` (no script, no input:
  the window opens, the image converges, the last frame is saved) against `lookdev render` of
  the same size and spp, each --runs times, interleaved. Prints the medians and their ratio.
- drag: `lookdev view` with a script that turns the light a step each frame (a drag), then
  lets the image converge; prints the viewer's report of its frames while rendering: median,
  95th percentile and longest frame time, and the spp they showed.
- adaptive: `lookdev render --noise-threshold T` against uniform sampling to the same most
  samples, at 256², by the render's own time (start-up set aside): the time ratio against the
  ratio of mean samples. Then the same in the viewer, by wall time less the viewer's start-up
  (a 1 spp run).

Runs the real viewer: under the X display in DISPLAY, or a virtual one (Xvfb) it starts.
See benches/README.md.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def run(args, env=None):
    """Runs a command; returns (wall seconds, stderr)."""
    start = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"failed: {' '.join(args)}\n{done.stderr}")
    return seconds, done.stderr


def report_line(stderr):
    return next(line for line in stderr.splitlines() if line.startswith("lookdev: viewer:"))


def converge(lookdev, sizes, spp, runs, folder):
    print(f"converge: the built-in scene to {spp} spp, median of {runs} whole-process runs")
    for size in sizes:
        s = str(size)
        render = [lookdev, "render", "--size", s, s, "--spp", str(spp), "--quiet", "--out", str(folder / "r.exr")]
        view = [lookdev, "view", "--size", s, s, "--spp", str(spp), "--exit-after-spp", str(spp)]
        run(render), run(view)  # warm the caches
        times = {"render": [], "view": []}
        reports = []
        for _ in range(runs):
            times["render"].append(run(render)[0])
            seconds, stderr = run(view)
            times["view"].append(seconds)
            reports.append(report_line(stderr))
        r, v = statistics.median(times["render"]), statistics.median(times["view"])
        print(f"  {size}²: render {r:.2f} s, view {v:.2f} s: {v / r:.2f}× render")
        drawn = re.search(r"(\d+) frames drawn, (\d+) relighting slices", reports[-1])
        print(f"    the viewer drew {drawn.group(1)} frames, with {drawn.group(2)} relighting slices between them")


def drag(lookdev, sizes, spp, steps, folder):
    script = folder / "drag.script"
    script.write_text("".join(f"rotate {3 * i}\n" for i in range(steps)))
    print(f"drag: the light turns 3° a frame for {steps} frames, then the image converges to {spp} spp")
    for size in sizes:
        s = str(size)
        _, stderr = run([lookdev, "view", "--size", s, s, "--spp", str(spp), "--script", str(script),
                         "--exit-after-spp", str(spp)])
        line = report_line(stderr)
        frames = re.search(r"frame time while rendering ([^;]*);", line).group(1)
        preview = re.search(r"preview after the last change ([^;]*);", line).group(1)
        print(f"  {size}²: {frames}; preview {preview}")


def adaptive(lookdev, threshold, spp, folder):
    s = "256"
    base = [lookdev, "render", "--size", s, s, "--spp", str(spp), "--out", str(folder / "a.exr")]

    def render_time(args):
        stderr = run(args)[1]
        seconds = float(re.search(r"([\d.]+) s on", stderr).group(1))
        mean = re.search(r"([\d.]+) spp on average", stderr)
        return seconds, float(mean.group(1)) if mean else float(spp)

    noise = ["--noise-threshold", str(threshold)]
    render_time(base + noise)  # warm
    a = [render_time(base + noise) for _ in range(3)]
    u = [render_time(base) for _ in range(3)]
    ta, tu = statistics.median(x[0] for x in a), statistics.median(x[0] for x in u)
    mean = a[0][1]  # the same every run: the same seed stops the same pixels
    share = mean / spp
    print(f"adaptive: 256², at most {spp} spp, --noise-threshold {threshold}")
    print(f"  render: {mean:.1f} spp on average ({share:.0%} of uniform) in {ta:.3f} s; uniform {tu:.3f} s; "
          f"time {ta / tu:.0%} of uniform, {ta / tu / share:.2f}× proportional")
    view = [lookdev, "view", "--size", s, s, "--spp", str(spp), "--exit-after-spp"]
    startup = statistics.median(run(view + ["1"])[0] for _ in range(3))
    va = statistics.median(run(view + [str(spp)] + noise)[0] for _ in range(3))
    vu = statistics.median(run(view + [str(spp)])[0] for _ in range(3))
    ratio = (va - startup) / (vu - startup)
    print(f"  view: start-up {startup:.2f} s; adaptive {va:.2f} s, uniform {vu:.2f} s; past start-up, "
          f"time {ratio:.0%} of uniform, {ratio / share:.2f}× proportional")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--lookdev", default=str(REPO / "target/release/lookdev"))
    parser.add_argument("--sizes", default="512,1024")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--drag-steps", type=int, default=60)
    parser.add_argument("--threshold", type=float, default=0.05)
    parser.add_argument("--adaptive-spp", type=int, default=256)
    options = parser.parse_args()
    sizes = [int(s) for s in options.sizes.split(",")]
    xvfb = None
    if not os.environ.get("DISPLAY"):
        os.environ["DISPLAY"] = ":93"
        xvfb = subprocess.Popen(["Xvfb", ":93", "-screen", "0", "1600x1000x24"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(1)
    try:
        print(f"load before: {os.getloadavg()[0]:.2f}")
        with tempfile.TemporaryDirectory() as folder:
            folder = Path(folder)
            converge(options.lookdev, sizes, options.spp, options.runs, folder)
            drag(options.lookdev, sizes, options.spp, options.drag_steps, folder)
            adaptive(options.lookdev, options.threshold, options.adaptive_spp, folder)
        print(f"load after: {os.getloadavg()[0]:.2f}")
    finally:
        if xvfb:
            xvfb.terminate()


if __name__ == "__main__":
    main()
