#!/usr/bin/env python3
"""Render speed of facette against Mitsuba 3, side by side, on the scenes of scenes/bench/.

Not a test and not a CI dependency: the measurement behind issue 16's targets and the
render-speed figures of docs/performance.md. The bench scenes are Mitsuba 3 XML files that
both renderers read (facette renders Mitsuba scenes directly), so the scene, camera, light,
material, Gaussian filter, path depth (max_depth 8, the camera ray counting as segment 1 in
both) and Russian roulette (from depth 5) are identical; only the renderers differ. Each is
a unit sphere at the origin seen from (0, 0, 4) with a 40° field of view in a constant white
environment, 512 × 512, the material of one family Mitsuba also has:

    bench-sphere               scenes/bench-sphere.toml (facette's own format, the issue's
                               named target, ≥ 2×) against Mitsuba's sphere-dielectric.xml
    sphere-dielectric          roughdielectric GGX α 0.3, ior 1.5 (= bench-sphere.toml)
    sphere-conductor-beckmann  roughconductor Beckmann α 0.3, Au
    sphere-conductor-ggx       roughconductor GGX α 0.3, Au
    sphere-diffuse             diffuse 0.8
    sphere-plastic             roughplastic GGX α 0.3 (facette reads it as its interfaced
                               Lambertian: a different model, brighter; see the XML)
    showcase, mesh             (--showcase, --mesh) scenes/showcase.toml and scenes/mesh.toml
                               (1 M triangles), facette only, at their own spp by default

The sphere scenes' target is ≥ 1.5× Mitsuba (≥ 2× for bench-sphere), in Msamples/s.

    python3 scripts/bench_render.py                     # ≈ 7 min on two idle cores while
                                                        # facette renders ≈ 2 Msamples/s
    python3 scripts/bench_render.py --spp 4 --repeats 1 # smoke test, ≈ 1 min
    python3 scripts/bench_render.py --only bench-sphere --spp 256 --repeats 5
    python3 scripts/bench_render.py --showcase --mesh --markdown bench.md
    python3 scripts/bench_render.py --facette /tmp/old/facette   # an older build

Needs the Mitsuba 3 Python package (`pip install mitsuba==3.9.1`) with its LLVM variant
(`apt-get install libllvm19`; DRJIT_LIBLLVM_PATH defaults to
/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1) and a release build of facette
(`cargo build --release -p facette`). Without LLVM the script falls back to Mitsuba's
scalar_rgb variant with a loud warning: the images are right but Mitsuba's timings are then
those of its scalar renderer, not of its fast one, and the ratios say nothing about the
targets.

What is measured, per scene and repeat (`--repeats`, default 3; seed 1 + repeat):

- **facette** as a whole process: the wall clock of `facette render SCENE -o out.exr --spp N
  --seed S --threads T` (start-up, scene loading, BVH build, rendering and writing the EXR
  included), with `--sampler independent` and with `--sampler sobol` (facette's default),
  and the user + system CPU seconds of that child process (`os.wait4`). facette's own
  summary line (scene load time, render time) is printed beside it. One untimed render
  first (independent sampler, full spp, its own seed) brings the binary and the scene's
  files into the page cache and gives a second image for the noise estimate below.
- **Mitsuba** with warm kernels: the scene loaded once, one untimed `mi.render` (JIT tracing
  and compilation, or the kernel-cache lookup), then `mi.render(scene, spp=N, seed=S)` +
  `dr.eval` + `dr.sync_thread` timed with `time.perf_counter` (wall) and
  `time.process_time` (CPU seconds of all of this process's threads), with
  `dr.set_thread_count(T)`. Scene loading and image output are not included.
- The renders of one repeat are interleaved (facette independent, facette sobol, Mitsuba)
  so that a change of machine load hits all of them alike.

Printed per scene: Msamples/s = width · height · spp / wall seconds, Msamples per CPU-second
(the same over user + system seconds: less sensitive to other jobs on the machine, though
not immune), each renderer's median over the repeats, and the ratios facette / Mitsuba
(computed per repeat, the median printed, with the range). As a sanity check that both
render the same image, the mean pixel value of each (averaged over the repeats) and the
relative difference facette / Mitsuba − 1 with σ, its standard error: each renderer's from
two of its own images with different seeds (the warm-up and the first repeat), through 16 ×
16-pixel block means of their difference (blocks much wider than the filter, so nearly
independent); for the Sobol rows the independent sampler's σ is used (an upper bound). A
difference beyond 5 σ and 0.2 % is reported as a failure (exit status 3) unless the scene
has a documented model difference (sphere-plastic: facette's interfaced Lambertian is
brighter than Mitsuba's rough plastic, docs/scene-format.md). The final table (`--markdown
FILE` writes it to a file too) is meant for docs/performance.md.

A renderer that fails (facette's exit status, an unreadable image, a Mitsuba exception)
stops the script with its message and a non-zero status. If `facette render --help` has no
`--sampler` flag (an older `--facette`), facette is rendered once per repeat without it
(the XML's independent sampler; the TOML's own) and its rows say so. The machine's load
average is printed before, at each scene and after: timings taken while other jobs run are
only comparable within one run, and then only roughly.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np

from host import cpu_description, load_average

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FACETTE = os.path.join(ROOT, "target", "release", "facette")
BENCH_DIR = os.path.join(ROOT, "scenes", "bench")

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

try:
    mi.set_variant("llvm_ad_rgb")
except Exception as e:  # noqa: BLE001
    mi.set_variant("scalar_rgb")
    LLVM_ERROR = str(e)
else:
    LLVM_ERROR = None


def bench(name):
    return os.path.join(BENCH_DIR, name + ".xml")


PLASTIC_NOTE = (
    "model difference: facette reads roughplastic as its interfaced Lambertian, brighter"
    " than Mitsuba's rough plastic (docs/scene-format.md)"
)

# name → (facette's scene file, Mitsuba's scene file or None, target ratio or None,
#         documented reason why the image means differ, or None)
SCENES = {
    "bench-sphere": (
        os.path.join(ROOT, "scenes", "bench-sphere.toml"),
        bench("sphere-dielectric"),
        2.0,
        None,
    ),
    "sphere-dielectric": (bench("sphere-dielectric"), bench("sphere-dielectric"), 1.5, None),
    "sphere-conductor-beckmann": (
        bench("sphere-conductor-beckmann"),
        bench("sphere-conductor-beckmann"),
        1.5,
        None,
    ),
    "sphere-conductor-ggx": (
        bench("sphere-conductor-ggx"),
        bench("sphere-conductor-ggx"),
        1.5,
        None,
    ),
    "sphere-diffuse": (bench("sphere-diffuse"), bench("sphere-diffuse"), 1.5, None),
    "sphere-plastic": (bench("sphere-plastic"), bench("sphere-plastic"), 1.5, PLASTIC_NOTE),
}
# facette only (Mitsuba has no IL material, no procedural sky and no torus knot).
EXTRAS = {
    "showcase": (os.path.join(ROOT, "scenes", "showcase.toml"), None, None, None),
    "mesh": (os.path.join(ROOT, "scenes", "mesh.toml"), None, None, None),
}
ALL = {**SCENES, **EXTRAS}

WARMUP_SEED = 999_999
BLOCK = 16  # pixels per side of the blocks of the noise estimate
FAIL_SIGMAS = 5.0
FAIL_FLOOR = 0.002  # relative; below this a difference is never a failure


# --------------------------------------------------------------------------------------
# Rendering


def read_image(path, who):
    try:
        return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]
    except Exception as e:  # noqa: BLE001
        sys.exit(f"error: cannot read {who}'s image {path}: {e}")


def facette_help():
    p = subprocess.run([FACETTE, "render", "--help"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"error: `{FACETTE} render --help` failed:\n{p.stderr}")
    return p.stdout


def run_facette(scene, spp, seed, threads, extra, out):
    """Renders with facette as one process. Returns a dict: image, wall and CPU seconds of
    the whole process, facette's own load and render seconds (from its summary line, or
    None), and the other lines it printed (warnings)."""
    args = [FACETTE, "render", scene, "-o", out, "--spp", str(spp), "--seed", str(seed)]
    args += ["--threads", str(threads)] + list(extra)
    if os.path.exists(out):
        os.remove(out)
    with tempfile.TemporaryFile() as err:
        t = time.perf_counter()
        p = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=err, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        text = err.read().decode(errors="replace")
    if p.returncode != 0:
        sys.exit(f"error: facette failed (exit status {p.returncode}): {' '.join(args)}\n{text}")
    if not os.path.exists(out):
        sys.exit(f"error: facette wrote no image: {' '.join(args)}\n{text}")
    load = re.search(r"scene loaded in ([0-9.]+) s", text)
    render = re.search(r"rendered in ([0-9.]+) s", text)
    discarded = re.search(r"([0-9]+) discarded samples", text)
    notes = [l for l in text.splitlines() if l.strip() and "rendered in" not in l]
    if discarded and int(discarded.group(1)) > 0:
        notes.append(f"{discarded.group(1)} discarded samples")
    return {
        "img": read_image(out, "facette"),
        "wall": wall,
        "cpu": usage.ru_utime + usage.ru_stime,
        "load": float(load.group(1)) if load else None,
        "render": float(render.group(1)) if render else None,
        "notes": notes,
    }


class MitsubaScene:
    """A Mitsuba scene loaded once; its kernels warmed up (untimed) once per spp."""

    def __init__(self, path, spp):
        try:
            self.scene = mi.load_file(path, spp=str(spp))
        except Exception as e:  # noqa: BLE001
            sys.exit(f"error: Mitsuba cannot load {path}: {e}")
        self.path = path
        self.warm = {}

    def _render(self, spp, seed):
        try:
            t, c = time.perf_counter(), time.process_time()
            img = mi.render(self.scene, spp=spp, seed=seed)
            dr.eval(img)
            dr.sync_thread()
            wall, cpu = time.perf_counter() - t, time.process_time() - c
            return np.array(img, dtype=np.float64)[..., :3], wall, cpu
        except Exception as e:  # noqa: BLE001
            sys.exit(f"error: Mitsuba failed to render {self.path}: {e}")

    def warm_up(self, spp):
        """The untimed first render (JIT); returns its image."""
        if spp not in self.warm:
            img, wall, _ = self._render(spp, WARMUP_SEED)
            print(f"  Mitsuba warm-up (JIT, untimed): {wall:.2f} s")
            self.warm[spp] = img
        return self.warm[spp]

    def render(self, spp, seed):
        self.warm_up(spp)
        img, wall, cpu = self._render(spp, seed)
        return {"img": img, "wall": wall, "cpu": cpu}


def mean_sigma(a, b):
    """Standard error of one image's mean, from two images of the same renderer with
    different seeds: the mean over channels of a − b in BLOCK × BLOCK pixel blocks, whose
    block means are nearly independent (the filter is far narrower than a block)."""
    d = (a - b).mean(-1)
    h, w = (d.shape[0] // BLOCK) * BLOCK, (d.shape[1] // BLOCK) * BLOCK
    blocks = d[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean((1, 3))
    # Var(mean(a − b)) = 2 Var(mean(a)) = E[block²] / number of blocks.
    return float(np.sqrt(np.mean(blocks**2) / blocks.size / 2))


def toml_spp(path):
    with open(path, "rb") as f:
        return int(tomllib.load(f).get("film", {}).get("spp", 64))


# --------------------------------------------------------------------------------------
# The benchmark


def median(xs):
    return float(statistics.median(xs))


def msps(r, spp):
    h, w = r["img"].shape[:2]
    n = w * h * spp / 1e6
    return n / r["wall"], n / r["cpu"] if r["cpu"] > 0 else float("nan")


def bench_scene(name, args, variants):
    f_scene, m_scene, target, known = ALL[name]
    spp = args.spp
    if m_scene is None and name in EXTRAS:
        spp = args.extras_spp or toml_spp(f_scene)
    rel = os.path.relpath(f_scene, ROOT)
    vs = ""
    if m_scene and m_scene != f_scene:
        vs = f" against Mitsuba's {os.path.relpath(m_scene, ROOT)}"
    print(f"\n## {name}: {rel}{vs}, {spp} spp (load average {load_average()})")

    mts = None
    if m_scene:
        mts = args.mitsuba_scenes.get(m_scene)
        if mts is None:
            mts = args.mitsuba_scenes[m_scene] = MitsubaScene(m_scene, spp)

    results = {label: [] for label, _ in variants}
    if mts:
        results["Mitsuba"] = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        # Untimed: page cache, assets generated on first use, a second image for σ.
        warm_extra = variants[0][1] if m_scene else variants[-1][1]
        warm = run_facette(
            f_scene, spp if m_scene else 1, WARMUP_SEED, args.threads, warm_extra, out
        )
        print(f"  facette warm-up (untimed): {warm['wall']:.2f} s")
        for line in dict.fromkeys(warm["notes"]):
            print(f"  facette says: {line}")
        if mts:
            m_warm = mts.warm_up(spp)
        for rep in range(args.repeats):
            seed = 1 + rep
            line = []
            for label, extra in variants:
                r = run_facette(f_scene, spp, seed, args.threads, extra, out)
                results[label].append(r)
                w, c = msps(r, spp)
                inner = ""
                if r["render"] is not None:
                    inner = f", own: load {r['load']:.2f} s + render {r['render']:.2f} s"
                line.append(f"{label} {r['wall']:.2f} s ({r['cpu']:.2f} CPU-s{inner})")
            if mts:
                r = mts.render(spp, seed)
                results["Mitsuba"].append(r)
                line.append(f"Mitsuba {r['wall']:.2f} s ({r['cpu']:.2f} CPU-s)")
            print(f"  repeat {rep + 1}: " + "; ".join(line))

    # Aggregate.
    rows = []
    m_res = results.get("Mitsuba")
    sig_f = mean_sigma(results[variants[0][0]][0]["img"], warm["img"]) if m_scene else None
    sig_m = mean_sigma(m_res[0]["img"], m_warm) if m_res else None
    m_mean = float(np.mean([r["img"].mean() for r in m_res])) if m_res else None
    for label in results:
        rs = results[label]
        sp = [msps(r, spp) for r in rs]
        row = {
            "scene": name,
            "who": label,
            "spp": spp,
            "size": "×".join(str(x) for x in rs[0]["img"].shape[1::-1]),
            "wall": median([r["wall"] for r in rs]),
            "msps": median([s[0] for s in sp]),
            "msps_cpu": median([s[1] for s in sp]),
            "mean": float(np.mean([r["img"].mean() for r in rs])),
            "target": target,
            "known": known,
        }
        if label != "Mitsuba":
            loads = [r["load"] for r in rs if r["load"] is not None]
            renders = [r["render"] for r in rs if r["render"] is not None]
            row["own_load"] = median(loads) if loads else None
            row["own_msps"] = (
                median([msps(r, spp)[0] * r["wall"] / r["render"] for r in rs])
                if len(renders) == len(rs)
                else None
            )
        if m_res and label != "Mitsuba":
            ms = [msps(r, spp) for r in m_res]
            ratio = [a[0] / b[0] for a, b in zip(sp, ms)]
            ratio_cpu = [a[1] / b[1] for a, b in zip(sp, ms)]
            row["ratio"] = median(ratio)
            row["ratio_range"] = (min(ratio), max(ratio))
            row["ratio_cpu"] = median(ratio_cpu)
            row["ratio_cpu_range"] = (min(ratio_cpu), max(ratio_cpu))
            diff = row["mean"] / m_mean - 1
            sigma = np.hypot(sig_f, sig_m) / np.sqrt(len(rs)) / m_mean
            row["diff"], row["diff_sigma"] = float(diff), float(sigma)
            row["differs"] = abs(diff) > max(FAIL_SIGMAS * sigma, FAIL_FLOOR)
        rows.append(row)
    print_rows(rows)
    return rows


def fmt_ratio(r, key):
    if key not in r:
        return "-"
    lo, hi = r[key + "_range"]
    return f"{r[key]:.2f} ({lo:.2f}–{hi:.2f})" if hi > lo else f"{r[key]:.2f}"


def verdict(r):
    if "diff" not in r:
        return ""
    s = f"{100 * r['diff']:+.3f} % (σ {100 * r['diff_sigma']:.3f} %)"
    if r["differs"]:
        s += " expected: model difference" if r["known"] else " DIFFER"
    return s


def print_rows(rows):
    print(
        f"  {'renderer':<26} {'wall s':>7} {'Msamples/s':>10} {'per CPU-s':>9}"
        f" {'f/M Msamples/s':>17} {'f/M per CPU-s':>17} {'image mean':>10}  vs Mitsuba"
    )
    for r in rows:
        print(
            f"  {r['who']:<26} {r['wall']:>7.2f} {r['msps']:>10.3f} {r['msps_cpu']:>9.3f}"
            f" {fmt_ratio(r, 'ratio'):>17} {fmt_ratio(r, 'ratio_cpu'):>17}"
            f" {r['mean']:>10.5f}  {verdict(r)}"
        )
    for r in rows:
        if r.get("own_msps"):
            print(
                f"  {r['who']}: facette's own summary: load {r['own_load']:.2f} s,"
                f" {r['own_msps']:.3f} Msamples/s over its render time alone"
            )
    target = rows[0]["target"]
    if target:
        met = [f"{r['who']} {'yes' if r['ratio'] >= target else 'no'} ({r['ratio']:.2f}×)"
               for r in rows if "ratio" in r]
        print(f"  target ≥ {target:g}× Mitsuba in Msamples/s: " + ", ".join(met))


def markdown(rows, args, info):
    lines = [
        f"**Render speed against Mitsuba 3** ({info}; `python3 scripts/bench_render.py"
        f"{''.join(' ' + a for a in sys.argv[1:])}`, {args.spp} spp, {args.repeats} repeat{'s' if args.repeats > 1 else ''};"
        " median over the repeats; facette"
        " timed as a whole process, Mitsuba with warm kernels)",
        "",
        "| scene | renderer | spp | Msamples/s | Msamples/CPU-s | facette/Mitsuba,"
        " Msamples/s | per CPU-s | target | image mean vs Mitsuba |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        target = ""
        if r["target"] and "ratio" in r:
            target = f"≥ {r['target']:g}×: {'met' if r['ratio'] >= r['target'] else 'not met'}"
        lines.append(
            f"| {r['scene']} | {r['who']} | {r['spp']} | {r['msps']:.3f} |"
            f" {r['msps_cpu']:.3f} | {fmt_ratio(r, 'ratio')} | {fmt_ratio(r, 'ratio_cpu')} |"
            f" {target} | {verdict(r)} |"
        )
    lines += [
        "",
        "Msamples/s = width · height · spp / wall seconds (512 × 512 except `mesh`, 512 × 384):"
        " facette's whole `facette render` process (start-up, loading, BVH build, EXR output"
        " included), Mitsuba's `mi.render` + `dr.eval` with warm kernels. Msamples/CPU-s: the"
        " same over user + system CPU seconds. Ratios are per repeat (interleaved renders),"
        " median (range). Image mean vs Mitsuba: facette / Mitsuba − 1 of the mean pixel"
        " value, with its standard error. bench-sphere is facette's"
        " `scenes/bench-sphere.toml` against Mitsuba's `scenes/bench/sphere-dielectric.xml`.",
    ]
    return "\n".join(lines) + "\n"


def out_of_line_intrinsics(binary):
    """Calls of `core::arch` intrinsics in `binary` (objdump), or None without objdump.

    The AVX2 kernel's register lanes are only fast inlined: a closure or a std helper such
    as `array::from_fn` in generic code is compiled with that code's instruction set, not
    the kernel's, and its lane operations become calls (docs/performance.md, 2026-12-05).
    A healthy build has one: the CPU feature test's `xgetbv`.
    """
    try:
        asm = subprocess.run(["objdump", "-d", "--no-show-raw-insn", binary],
                             capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return sorted({m for m in re.findall(r"call\s+\S+\s+<([^>]*core_arch[^>]*)>", asm)
                   if "xgetbv" not in m})


def main():
    global FACETTE
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel (default 64)")
    ap.add_argument("--repeats", type=int, default=3, help="timed renders per renderer and"
                    " scene (default 3)")
    ap.add_argument("--only", nargs="+", choices=list(ALL), metavar="NAME",
                    help=f"scenes to run, among: {', '.join(ALL)}")
    ap.add_argument("--showcase", action="store_true",
                    help="also scenes/showcase.toml (facette only)")
    ap.add_argument("--mesh", action="store_true",
                    help="also scenes/mesh.toml, 1 M triangles (facette only)")
    ap.add_argument("--extras-spp", type=int, metavar="N",
                    help="spp of showcase and mesh (default: each scene's own, 64 and 32)")
    ap.add_argument("--threads", type=int, default=os.cpu_count(),
                    help="threads for both renderers (default: all cores)")
    ap.add_argument("--markdown", metavar="FILE", help="also write the Markdown table here")
    ap.add_argument("--kernel", nargs="+", default=["scalar"], choices=["scalar", "packet"],
                    help="facette's render kernels to time (default: scalar)")
    ap.add_argument("--facette", metavar="BINARY", default=FACETTE,
                    help="the facette binary (default: target/release/facette of the repo)")
    args = ap.parse_args()
    FACETTE = os.path.abspath(args.facette)
    if not os.path.exists(FACETTE):
        sys.exit(f"error: {FACETTE} not found: cargo build --release -p facette")
    if args.spp < 1 or args.repeats < 1:
        sys.exit("error: --spp and --repeats must be at least 1")
    calls = out_of_line_intrinsics(FACETTE)
    if calls is None:
        print("note: no objdump: the binary's inlining of the lane intrinsics is not checked")
    elif calls:
        bar = "!" * 78
        print(f"{bar}\nWARNING: {FACETTE} calls {len(calls)} distinct lane intrinsic(s) out of line"
              f" ({', '.join(calls[:4])}{', …' if len(calls) > 4 else ''}): a closure or std"
              " helper in lane code\nwas compiled without AVX2 (docs/performance.md). Its"
              f" timings are not the kernel's.\n{bar}", file=sys.stderr)
    names = args.only or (
        list(SCENES) + (["showcase"] if args.showcase else []) + (["mesh"] if args.mesh else [])
    )

    if LLVM_ERROR:
        bar = "!" * 78
        print(
            f"{bar}\nWARNING: Mitsuba's llvm_ad_rgb variant is unavailable ({LLVM_ERROR}).\n"
            "Falling back to scalar_rgb: the images are right, but Mitsuba's TIMINGS ARE"
            " MEANINGLESS\n(its scalar renderer, not its vectorized one). Install libllvm19"
            " and set DRJIT_LIBLLVM_PATH.\n" + bar,
            file=sys.stderr,
        )
    dr.set_thread_count(args.threads)
    args.mitsuba_scenes = {}

    if "--sampler" in facette_help():
        variants = [
            ("facette independent", ["--sampler", "independent"]),
            ("facette sobol", ["--sampler", "sobol"]),
        ]
    else:
        print("note: `facette render` has no --sampler flag: facette renders with the scene's"
              " own sampler")
        variants = [("facette (scene's sampler)", [])]
    if args.kernel != ["scalar"]:
        if "--kernel" not in facette_help():
            sys.exit("error: this facette has no --kernel flag")
        variants = [
            (f"{name} {k}" if k != "scalar" else name, flags + ["--kernel", k])
            for k in args.kernel
            for name, flags in variants
        ]

    info = (
        f"Mitsuba {mi.__version__} {mi.variant()}, {args.threads} threads,"
        f" {os.cpu_count()} cores ({cpu_description()})"
    )
    load_before = load_average()
    shown = os.path.relpath(FACETTE, ROOT) if FACETTE.startswith(ROOT + os.sep) else FACETTE
    print(f"{info}; facette: {shown}; load average before: {load_before}")
    t0 = time.perf_counter()
    rows = []
    for name in names:
        rows += bench_scene(name, args, variants)
    load_after = load_average()
    print(f"\nload average after: {load_after}; total {time.perf_counter() - t0:.0f} s\n")
    info += f", load average {load_before.split()[0]} before, {load_after.split()[0]} after"
    md = markdown(rows, args, info)
    print(md)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(md)
        print(f"wrote {args.markdown}")

    bad = [r for r in rows if r.get("differs") and not r["known"]]
    if bad:
        print(
            "\nERROR: the image means differ beyond noise (the timings compare different"
            " images):\n" + "\n".join(f"  {r['scene']}, {r['who']}: {verdict(r)}" for r in bad),
            file=sys.stderr,
        )
        sys.exit(3)


if __name__ == "__main__":
    main()
