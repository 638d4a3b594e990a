#!/usr/bin/env python3
"""lookdev against Mitsuba 3 on the built-in orthographic sphere: time, relative MSE, efficiency.

For each material, both renderers draw the same scene: the unit sphere of
`lookdev gbuffer --builtin sphere` under an orthographic camera, lit by the same lat-long
environment in the same orientation, direct light only, with the Disney principled parameters.
Each is measured at --spp against its own --reference-spp render (a different seed):

- lookdev: the whole `lookdev render` process, start-up included, by wall clock;
- Mitsuba 3 (`llvm_ad_rgb`, the `direct` integrator: one emitter and one BSDF sample per
  sample, combined by MIS, as lookdev does): warm and in-process, a render after one that
  compiled the kernels.

relMSE is the mean, over the pixels lookdev's g-buffer covers wholly and over R, G and B, of
(x - r)^2 / (r^2 + 1e-2); efficiency is 1 / (time x relMSE). See benches/README.md.

Only the Python standard library is needed for lookdev's half (--lookdev-only);
Mitsuba's needs `pip install mitsuba numpy`.
"""

import argparse
import importlib.util
import json
import os
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from array import array
from pathlib import Path

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, str(Path(__file__).resolve().parent))
import exr_read  # noqa: E402

REPO = Path(__file__).resolve().parent.parent

# Half the width of the frame in world units: must match SPHERE_FRAME_HALF_EXTENT in
# src/gbuffer/sphere.rs.
FRAME_HALF_EXTENT = 1.1

# The materials, as Disney principled parameters (lookdev's names); Mitsuba's `principled`
# takes the same, spec_tint for specular_tint. Unset parameters keep both renderers' defaults
# (no sheen, no anisotropy, no transmission).
MATERIALS = {
    # Polished gold (the preset's F0 and roughness).
    "metallic": {"base_color": [0.9626, 0.8276, 0.4082], "metallic": 1.0, "roughness": 0.25},
    # A rough orange plastic: diffuse and a broad specular lobe.
    "rough-dielectric": {"base_color": [0.8, 0.25, 0.1], "metallic": 0.0, "roughness": 0.7, "specular": 0.5},
    # Car paint (the preset): a dark red base under a glossy clear coat.
    "clearcoat": {
        "base_color": [0.3, 0.01, 0.015],
        "metallic": 0.0,
        "roughness": 0.35,
        "specular": 1.0,
        "specular_tint": 0.5,
        "clearcoat": 1.0,
        "clearcoat_gloss": 0.95,
    },
}
# A mirror, for --check-orientation.
MIRROR = {"base_color": [1.0, 1.0, 1.0], "metallic": 1.0, "roughness": 0.0}

PIP_HINT = "pip install mitsuba numpy"
LLVM_HINT = (
    "Dr.Jit's LLVM backend needs a recent LLVM: if the worker died with 'LLVM ERROR: Cannot select', "
    "point DRJIT_LIBLLVM_PATH at a newer libLLVM.so (for example Debian's libllvm19: "
    "DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1)"
)


def rel_mse(image, reference, mask):
    """Mean over the masked pixels and their R, G and B of (x - r)^2 / (r^2 + 1e-2).

    `image` and `reference` are flat [r, g, b, r, g, b, ...] sequences; `mask` one bool a pixel.
    """
    total = 0.0
    count = 0
    for p, keep in enumerate(mask):
        if not keep:
            continue
        for k in range(3 * p, 3 * p + 3):
            r = reference[k]
            d = image[k] - r
            total += d * d / (r * r + 1e-2)
        count += 3
    if count == 0:
        raise ValueError("no pixel is wholly covered")
    return total / count


def mean_radiance(image, mask):
    """The mean of R + G + B over the masked pixels."""
    covered = [p for p, keep in enumerate(mask) if keep]
    return sum(sum(image[3 * p : 3 * p + 3]) for p in covered) / max(len(covered), 1)


def efficiency(seconds, error):
    return 1.0 / (seconds * error) if seconds > 0 and error > 0 else float("inf")


# --- lookdev -------------------------------------------------------------------------------


def toml_value(value):
    if isinstance(value, list):
        return "[" + ", ".join(repr(float(v)) for v in value) + "]"
    return repr(float(value))


def write_look(path, params):
    lines = ["[[object]]", "[[object.layer]]", "[object.layer.set]"]
    lines += [f"{name} = {toml_value(value)}" for name, value in params.items()]
    path.write_text("\n".join(lines) + "\n")


def run_lookdev(lookdev, args):
    """Runs lookdev; returns the wall time in seconds. Fails with its stderr on an error."""
    start = time.perf_counter()
    done = subprocess.run([str(lookdev), *args], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"compare_mitsuba: lookdev {' '.join(args)} failed ({done.returncode}):\n{done.stderr}")
    return seconds


def read_rgb(path):
    width, height, planes = exr_read.read(path)
    rgb = [0.0] * (3 * width * height)
    for k, name in enumerate("RGB"):
        rgb[k::3] = planes[name]
    return width, height, rgb


def lookdev_side(opts, work, gbuffer, name, params):
    """lookdev's reference, then its timed renders: (seconds, image, reference)."""
    look = work / f"{name}.toml"
    write_look(look, params)
    common = ["render", "--gbuffer", str(gbuffer), "--look", str(look), "--env", str(opts.env), "--env-clamp"]
    common += ["--quiet"]
    reference = work / f"{name}_lookdev_ref.exr"
    run_lookdev(opts.lookdev, [*common, "--spp", str(opts.reference_spp), "--seed", "1000", "--out", str(reference)])
    image = work / f"{name}_lookdev.exr"
    times = [
        run_lookdev(opts.lookdev, [*common, "--spp", str(opts.spp), "--seed", "1", "--out", str(image)])
        for _ in range(opts.repeats)
    ]
    return statistics.median(times), read_rgb(image)[2], read_rgb(reference)[2]


# --- Mitsuba (run in a worker process, so that a crash of its JIT cannot lose lookdev's figures)


def rgb_to_xyz(chromaticities):
    """OpenEXR's RGB-to-XYZ matrix (white at Y = 1) for the file's primaries and white point."""
    (rx, ry), (gx, gy), (bx, by), (wx, wy) = chromaticities
    primaries = [[rx / ry, gx / gy, bx / by], [1.0, 1.0, 1.0], [(1 - rx - ry) / ry, (1 - gx - gy) / gy, (1 - bx - by) / by]]
    white = [wx / wy, 1.0, (1 - wx - wy) / wy]
    import numpy as np

    p = np.array(primaries)
    return p * np.linalg.solve(p, np.array(white))


REC709 = ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06), (0.3127, 0.3290))


def file_chromaticities(path):
    """The EXR header's `chromaticities` (four xy pairs), or None."""
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    attributes, _ = exr_read._header(data, path)
    if "chromaticities" not in attributes:
        return None
    values = struct.unpack("<8f", attributes["chromaticities"][1][:32])
    return tuple((values[2 * i], values[2 * i + 1]) for i in range(4))


def environment_for_mitsuba(path):
    """The environment's texels as lookdev reads them, for Mitsuba's envmap.

    Mitsuba's Bitmap converts an EXR whose header declares other primaries or white point
    (Blender's studio lights declare a D50 white) into Rec.709, without chromatic adaptation;
    lookdev takes the numbers as they are. The conversion is undone here, and negative texels
    (lossy DWA ringing) are zeroed as lookdev's --env-clamp does.
    """
    import mitsuba as mi
    import numpy as np

    texels = np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]
    chroma = file_chromaticities(path)
    if chroma is not None and not all(abs(a - b) < 1e-4 for pa, pb in zip(chroma, REC709) for a, b in zip(pa, pb)):
        converted = np.linalg.inv(rgb_to_xyz(REC709)) @ rgb_to_xyz(chroma)
        texels = texels @ np.linalg.inv(converted).T
    texels = np.nan_to_num(texels, nan=0.0, posinf=0.0)
    return mi.Bitmap(np.ascontiguousarray(np.maximum(texels, 0.0), dtype=np.float32))


def mitsuba_worker(job):
    """Renders one material in Mitsuba: its reference, a warm-up render, then the timed ones.

    Writes the images as raw float32 RGB and prints a JSON line with the times.
    """
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant("llvm_ad_rgb")
    params = job["params"]
    bsdf = {"type": "principled"}
    for name, value in params.items():
        key = {"specular_tint": "spec_tint"}.get(name, name)
        bsdf[key] = {"type": "rgb", "value": value} if isinstance(value, list) else value
    T = mi.ScalarTransform4f
    size = job["size"]
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "direct"},
            "sensor": {
                "type": "orthographic",
                # Looking toward -Z with +Y up, as lookdev's camera; the film spans +-1.1.
                "to_world": T().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
                @ T().scale([FRAME_HALF_EXTENT, FRAME_HALF_EXTENT, 1]),
                "film": {
                    "type": "hdrfilm",
                    "width": size,
                    "height": size,
                    "pixel_format": "rgb",
                    "rfilter": {"type": "box"},
                },
                "sampler": {"type": "independent", "sample_count": job["spp"]},
            },
            "sphere": {"type": "sphere", "bsdf": bsdf},
            # Mitsuba maps a direction d to u = atan2(d.x, -d.z)/2pi, lookdev to 0.5 plus that:
            # a half turn about +Y makes them agree (checked by --check-orientation).
            "environment": {
                "type": "envmap",
                "bitmap": environment_for_mitsuba(job["env"]),
                "to_world": T().rotate([0, 1, 0], 180),
            },
        }
    )

    def render(spp, seed):
        image = mi.render(scene, spp=spp, seed=seed)
        dr.eval(image)
        dr.sync_thread()
        return image

    reference = np.zeros((size, size, 3))
    passes = max(1, (job["reference_spp"] + 127) // 128)
    for k in range(passes):
        spp = job["reference_spp"] // passes + (1 if k < job["reference_spp"] % passes else 0)
        reference += np.array(render(spp, 1000 + k)) * (spp / job["reference_spp"])
    render(job["spp"], 1)  # compiles the kernels
    times = []
    for _ in range(job["repeats"]):
        start = time.perf_counter()
        image = render(job["spp"], 1)
        times.append(time.perf_counter() - start)
    np.asarray(image, dtype=np.float32).tofile(job["out"] + ".image.f32")
    reference.astype(np.float32).tofile(job["out"] + ".reference.f32")
    threads = dr.thread_count() if hasattr(dr, "thread_count") else None
    print(json.dumps({"seconds": statistics.median(times), "threads": threads, "version": mi.__version__}))


def mitsuba_side(opts, work, name, params):
    """Runs the worker for one material: (seconds, image, reference, info), or None on failure."""
    out = str(work / f"{name}_mitsuba")
    job = {
        "params": params,
        "size": opts.size,
        "spp": opts.spp,
        "reference_spp": opts.reference_spp,
        "repeats": opts.repeats,
        "env": str(opts.env),
        "out": out,
    }
    done = subprocess.run(
        [sys.executable, __file__, "--mitsuba-worker", json.dumps(job)], capture_output=True, text=True
    )
    if done.returncode != 0:
        tail = "\n".join((done.stderr or done.stdout).strip().splitlines()[-12:])
        print(f"compare_mitsuba: the Mitsuba render of {name} failed ({done.returncode}):\n{tail}\n{LLVM_HINT}")
        return None
    info = json.loads(done.stdout.strip().splitlines()[-1])

    def load(suffix):
        values = array("f")
        with open(out + suffix, "rb") as f:
            values.frombytes(f.read())
        return values

    return info["seconds"], load(".image.f32"), load(".reference.f32"), info


# --- the comparison --------------------------------------------------------------------------


def fmt(x):
    return f"{x:.3g}"


def print_table(rows):
    header = ["material", "renderer", "time (s)", "relMSE", "efficiency"]
    table = [header] + [[m, r, fmt(t), fmt(e), fmt(efficiency(t, e))] for m, r, t, e in rows]
    widths = [max(len(row[i]) for row in table) for i in range(len(header))]
    for row in table:
        print("  ".join(cell.ljust(widths[i]) for i, cell in enumerate(row)).rstrip())


def check_orientation(opts, work, gbuffer, coverage):
    """Renders a mirror sphere in both and compares them pixel by pixel."""
    _, image, _ = lookdev_side(opts, work, gbuffer, "mirror", MIRROR)
    result = mitsuba_side(opts, work, "mirror", MIRROR)
    if result is None:
        return 1
    _, other, _, _ = result
    pixels = [p for p, c in enumerate(coverage) if c]
    medians = []
    for k in range(3):
        ratios = sorted((other[3 * p + k] + 1e-3) / (image[3 * p + k] + 1e-3) for p in pixels)
        medians.append(ratios[len(ratios) // 2])
    ratios = [(sum(other[3 * p : 3 * p + 3]) + 1e-3) / (sum(image[3 * p : 3 * p + 3]) + 1e-3) for p in pixels]
    within = sum(1 for r in ratios if abs(r - 1) < 0.1) / len(ratios)
    print(
        "mirror sphere, Mitsuba / lookdev per pixel: median "
        + ", ".join(f"{c} {m:.4f}" for c, m in zip("RGB", medians))
        + f"; {within:.1%} of pixels within 10%"
    )
    agree = all(abs(m - 1) < 0.02 for m in medians) and within > 0.5
    print("the environments agree in orientation and colour" if agree else "the environments DISAGREE")
    return 0 if agree else 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lookdev", type=Path, default=REPO / "target" / "release" / "lookdev")
    parser.add_argument("--env", type=Path, default=REPO / "src" / "environment" / "studio.exr")
    parser.add_argument("--size", type=int, default=256, help="image width and height (default 256)")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--repeats", type=int, default=3, help="timed renders per side; the median is shown")
    parser.add_argument("--materials", default=",".join(MATERIALS), help="a comma-separated list of " + ", ".join(MATERIALS))
    parser.add_argument("--lookdev-only", action="store_true", help="measure lookdev alone")
    parser.add_argument("--check-orientation", action="store_true", help="compare a mirror sphere in both renderers")
    parser.add_argument("--keep", type=Path, help="keep the looks and images in this folder")
    parser.add_argument("--mitsuba-worker", help=argparse.SUPPRESS)
    opts = parser.parse_args()
    if opts.mitsuba_worker:
        mitsuba_worker(json.loads(opts.mitsuba_worker))
        return 0

    if not opts.lookdev.is_file():
        raise SystemExit(f"compare_mitsuba: {opts.lookdev}: no lookdev binary (build it with cargo build --release)")
    if not opts.env.is_file():
        raise SystemExit(f"compare_mitsuba: {opts.env}: no such environment file")
    if min(opts.size, opts.spp, opts.reference_spp, opts.repeats) < 1:
        raise SystemExit("compare_mitsuba: --size, --spp, --reference-spp and --repeats must be at least 1")
    names = [m for m in opts.materials.split(",") if m]
    unknown = [m for m in names if m not in MATERIALS]
    if unknown:
        raise SystemExit(f"compare_mitsuba: unknown material {unknown[0]!r}; choose from {', '.join(MATERIALS)}")
    with_mitsuba = not opts.lookdev_only
    if with_mitsuba and importlib.util.find_spec("mitsuba") is None:
        print(f"compare_mitsuba: Mitsuba 3 is not importable by {sys.executable}: `{PIP_HINT}`. Measuring lookdev alone.")
        with_mitsuba = False
    if opts.check_orientation and not with_mitsuba:
        raise SystemExit("compare_mitsuba: --check-orientation needs Mitsuba")

    with tempfile.TemporaryDirectory(prefix="compare_mitsuba_") as temp:
        work = opts.keep or Path(temp)
        work.mkdir(parents=True, exist_ok=True)
        gbuffer = work / "sphere.exr"
        size = str(opts.size)
        run_lookdev(opts.lookdev, ["gbuffer", "--builtin", "sphere", "--size", size, size, "--out", str(gbuffer)])
        _, _, planes = exr_read.read(gbuffer)
        coverage = [a == 1.0 for a in planes["A"]]
        if opts.check_orientation:
            return check_orientation(opts, work, gbuffer, coverage)

        print(
            f"{opts.size}x{opts.size}, {opts.spp} spp against {opts.reference_spp} spp (seeds 1 and 1000+), "
            f"environment {opts.env.name}, {sum(coverage)} wholly covered pixels; "
            f"times are medians of {opts.repeats}; load average {os.getloadavg()[0]:.2f}",
            flush=True,
        )
        rows = []
        ratios = []
        for name in names:
            params = MATERIALS[name]
            seconds, image, reference = lookdev_side(opts, work, gbuffer, name, params)
            ours = (seconds, rel_mse(image, reference, coverage))
            rows.append((name, "lookdev (process)", *ours))
            if with_mitsuba:
                result = mitsuba_side(opts, work, name, params)
                if result is None:
                    with_mitsuba = False
                else:
                    m_seconds, m_image, m_reference, info = result
                    theirs = (m_seconds, rel_mse(m_image, m_reference, coverage))
                    threads = f", {info['threads']} threads" if info["threads"] else ""
                    rows.append((name, f"Mitsuba {info['version']} (warm{threads})", *theirs))
                    agreement = mean_radiance(m_reference, coverage) / mean_radiance(reference, coverage)
                    ratios.append((name, ours, theirs, agreement))
            print(f"  {name}: measured", flush=True)
        print()
        print_table(rows)
        print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} (1, 5, 15 minutes) at the end")
        if ratios:
            print()
            print("lookdev / Mitsuba:")
            for name, (t, e), (mt, me), agreement in ratios:
                print(
                    f"  {name}: time {t / mt:.2f}x, relMSE {e / me:.3g}x, "
                    f"efficiency {efficiency(t, e) / efficiency(mt, me):.3g}x "
                    f"(the references' mean radiance, Mitsuba / lookdev: {agreement:.3f})"
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
