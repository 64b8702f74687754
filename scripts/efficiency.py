#!/usr/bin/env python3
"""Equal-time efficiency of facette against Mitsuba 3 on the scenes of scenes/efficiency/.

Not a test and not a CI dependency: a measurement for docs/performance.md. Both renderers
read the very same Mitsuba 3 XML file (facette renders Mitsuba scenes directly), so the
scene, the camera, the lights, the materials, the box filter, the path depth (max_depth 8)
and the image size (256 × 256) are identical; only the renderers differ. The scenes (see
the comment at the top of each file): a diffuse, a rough gold (GGX α 0.2) and a rough
glass (GGX α 0.2) unit sphere on a diffuse ground under a spherical area light and a
constant sky; a rectangular light over a rough aluminium plane (α 0.15) with diffuse
objects, and the same with an elliptic disk light (sampled by area in both renderers); an
emissive 320-triangle torus; a lat-long sky with a 1° sun carrying most of the
power (torus.obj and sky-sun.exr are written by `--write-assets`, and when missing).

    python3 scripts/efficiency.py                  # ≈ 15 min on two idle cores the first
                                                   # time (references), ≈ 5 min after
    python3 scripts/efficiency.py --quick          # smoke test, ≈ 2–3 min
    python3 scripts/efficiency.py --spp 16 64 256 --repeats 5 --markdown eff.md
    python3 scripts/efficiency.py --only sphere-glass --refresh
    python3 scripts/efficiency.py --write-assets   # regenerate torus.obj and sky-sun.exr

Needs the Mitsuba 3 Python package (`pip install mitsuba==3.9.1`) with its LLVM variant
(`apt-get install libllvm19`; DRJIT_LIBLLVM_PATH defaults to
/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1) and a release build of facette
(`cargo build --release -p facette`). Without LLVM the script falls back to Mitsuba's
scalar_rgb variant with a loud warning: the images are right but Mitsuba's timings are then
those of its scalar renderer, not of its fast one.

What is measured, per scene:

- A converged **reference per renderer**, cached under target/efficiency/ (reused when the
  scene file, its assets, the size and the sample count are unchanged; `--refresh`
  recomputes them; a facette binary newer than its reference is only reported). Each
  reference is rendered as two independent halves A and B (different seeds) and is their
  mean; (A − B)²/4 estimates its own squared error, so its own relMSE is printed, with its
  share of each tested image's relMSE (it adds to it). facette's reference uses its Sobol
  sampler (the lowest noise per second; with the `--sampler` flag), Mitsuba's its
  independent sampler (the XML's), in passes of at most 256 spp. The **relMSE between
  the two references** minus what their noise explains is the bias between the
  renderers; the relative difference of the image means is printed too, with its
  standard error (σ, from the halves, treating pixels as independent), and the absolute
  difference of the references is written to target/efficiency/<scene>/ref-difference.exr
  for inspection.
- **Test renders at equal spp** (`--spp`, default 64): facette `--sampler independent`,
  facette `--sampler sobol` (facette's default sampler) and Mitsuba (independent sampler),
  each repeated `--repeats` times (default 3) with different seeds, the three interleaved
  within each repeat so that a change in machine load affects them alike. facette is timed
  as a whole process (wall clock of `facette render`, scene loading and image writing
  included); Mitsuba with warm kernels (one untimed render first, then
  `mi.render(scene, spp=N, seed=S)` + `dr.eval` + `dr.sync_thread`, i.e. without JIT
  compilation, scene loading or file output). Both use `--threads` threads (default: all
  cores; `dr.set_thread_count` for Mitsuba).
- **relMSE** = mean over pixels and channels of (a − b)² / (b² + 0.01), against the
  renderer's own reference (the primary number: noise) and against the other renderer's
  reference (secondary: noise plus the bias between the renderers), averaged over the
  repeats, as are the times.
- Printed per scene: spp, seconds and relMSE of each, the relMSE ratio facette / Mitsuba at
  equal spp, and the **efficiency ratio** (relMSE × seconds, Mitsuba's over facette's: > 1
  means facette reaches a given error sooner). A final Markdown table (`--markdown FILE`
  writes it to a file too) is meant for docs/performance.md.

Known difference: in envmap-sun facette's image mean is about 0.3 % below Mitsuba's. Both
read the same 512 × 256 map, but Mitsuba places its first and last rows on the poles and
facette puts texel centres at (y + ½)/H (docs/scene-format.md), which puts facette's sun
0.13° lower: about 0.5 % less sun irradiance on the ground.

If `facette render --help` has no `--sampler` flag, facette is rendered once per repeat
without it (the XML's independent sampler) and its rows say "sampler flag unavailable".
The machine's load average is printed before and after: timings taken while other jobs
run are only comparable within one run.
"""

import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

from host import cpu_description, load_average

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FACETTE = os.path.join(ROOT, "target", "release", "facette")
SCENE_DIR = os.path.join(ROOT, "scenes", "efficiency")
CACHE = os.path.join(ROOT, "target", "efficiency")

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

# name → (facette reference spp, Mitsuba reference spp). At 256² facette renders about
# 2 Msamples/s on two idle cores with its independent sampler, about 1.5× slower with
# Sobol (1024 spp ≈ 1 min on the simple scenes); Mitsuba's LLVM variant several times
# that. A reference of N independent samples adds about 64/N to a 64-spp independent
# test render's relMSE; facette's Sobol reference adds less. The per-scene output prints
# each reference's own relMSE and its share of each row's relMSE.
SCENES = {
    "sphere-diffuse": (1024, 2048),
    "sphere-conductor": (1024, 2048),
    "sphere-glass": (1024, 2048),
    "rect-glossy": (1024, 2048),
    "disk-glossy": (1024, 2048),
    "mesh-light": (1024, 2048),
    "envmap-sun": (1024, 2048),
}
QUICK_REF_SPP = (64, 128)
EPS = 0.01  # relMSE's denominator offset
MITSUBA_PASS_SPP = 256
REF_SEEDS = (1_000_001, 1_000_002)  # the two halves of a reference
WARMUP_SEED = 999_999


# --------------------------------------------------------------------------------------
# Assets


def write_assets(directory=SCENE_DIR):
    """torus.obj (the emitter of mesh-light.xml) and sky-sun.exr (envmap-sun.xml)."""
    write_torus(os.path.join(directory, "torus.obj"))
    write_sky(os.path.join(directory, "sky-sun.exr"))


def write_torus(path, major=0.4, minor=0.12, n_major=16, n_minor=10):
    """A torus in the xz plane around the origin: n_major × n_minor quads split into
    2 · 16 · 10 = 320 triangles, counter-clockwise seen from outside (front faces out)."""
    lines = [
        "# Torus for scenes/efficiency/mesh-light.xml, written by scripts/efficiency.py",
        f"# major radius {major}, minor radius {minor}, {n_major} x {n_minor} quads,"
        f" {2 * n_major * n_minor} triangles",
    ]
    for i in range(n_major):
        phi = 2 * np.pi * i / n_major
        for j in range(n_minor):
            theta = 2 * np.pi * j / n_minor
            r = major + minor * np.cos(theta)
            lines.append(
                f"v {r * np.cos(phi):.6f} {minor * np.sin(theta):.6f} {r * np.sin(phi):.6f}"
            )

    def idx(i, j):
        return (i % n_major) * n_minor + (j % n_minor) + 1

    for i in range(n_major):
        for j in range(n_minor):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            lines.append(f"f {a} {d} {c}")
            lines.append(f"f {a} {c} {b}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    # Orientation check: the outward normal at (i, j) = (0, 0) is +x.
    v = np.array([[float(t) for t in l.split()[1:]] for l in lines if l.startswith("v ")])
    f0 = [int(t) - 1 for t in lines[2 + len(v)].split()[1:]]
    n = np.cross(v[f0[1]] - v[f0[0]], v[f0[2]] - v[f0[0]])
    centroid = v[f0].mean(0)
    ring = major * np.array([centroid[0], 0, centroid[2]]) / np.hypot(centroid[0], centroid[2])
    assert np.dot(n, centroid - ring) > 0, "torus faces point inward"


def sun_direction():
    """The sun's direction (toward the sun) in the map's frame: elevation 35°, azimuth 50°
    from +z toward +x, i.e. from the camera's right-front, casting shadows back-left."""
    el, az = np.radians(35.0), np.radians(50.0)
    return np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])


def write_sky(path, width=512, height=256, sun_radius_deg=1.0, sun_radiance=6000.0):
    """A 512 × 256 float32 lat-long map in Mitsuba's (and facette's) convention: direction
    d ↔ u = atan2(d.x, −d.z)/2π, v = acos(d.y)/π, pixel centres at ((x+½)/W, (y+½)/H).
    A smooth sky (bright horizon, blue zenith, dark ground below the horizon) plus a sun
    disk of 1° radius (its edge pixels weighted by their coverage, 16 × 16 subsamples) with
    radiance 6000 × (1, 0.93, 0.82): the sun carries about 80 % of the map's power (printed)
    and about 80 % of the irradiance on the ground."""
    sub = 16
    ys = (np.arange(height * sub) + 0.5) / (height * sub)
    xs = (np.arange(width * sub) + 0.5) / (width * sub)
    # Sky: a function of elevation only, evaluated at pixel centres.
    v = (np.arange(height) + 0.5) / height
    elev = np.pi / 2 - v * np.pi  # +π/2 at the top row
    s = np.clip(np.sin(elev), 0, 1)[:, None]
    zenith = np.array([0.05, 0.10, 0.22])
    horizon = np.array([0.28, 0.30, 0.33])
    sky = horizon + (zenith - horizon) * np.sqrt(s)
    ground = np.array([0.03, 0.028, 0.025])
    sky = np.where((elev > 0)[:, None], sky, ground[None, :])
    img = np.repeat(sky[:, None, :], width, axis=1)
    # Sun: coverage of the disk, by subsampling only the rows near it.
    sd = sun_direction()
    u0 = np.arctan2(sd[0], -sd[2]) / (2 * np.pi) % 1.0
    v0 = np.arccos(sd[1]) / np.pi
    cos_r = np.cos(np.radians(sun_radius_deg))
    y_lo = max(int((v0 - 0.02) * height), 0)
    y_hi = min(int((v0 + 0.02) * height) + 1, height)
    x_lo = max(int((u0 - 0.03) * width), 0)
    x_hi = min(int((u0 + 0.03) * width) + 1, width)
    vv, uu = np.meshgrid(
        ys[y_lo * sub : y_hi * sub], xs[x_lo * sub : x_hi * sub], indexing="ij"
    )
    th, ph = vv * np.pi, uu * 2 * np.pi
    d = np.stack([np.sin(th) * np.sin(ph), np.cos(th), -np.sin(th) * np.cos(ph)], -1)
    inside = (d @ sd) > cos_r
    cover = inside.reshape(y_hi - y_lo, sub, x_hi - x_lo, sub).mean((1, 3))
    sun = sun_radiance * np.array([1.0, 0.93, 0.82])
    img[y_lo:y_hi, x_lo:x_hi] += cover[..., None] * sun
    mi.Bitmap(img.astype(np.float32)).write(path)
    # Power fractions (solid angle per pixel: sin θ dθ dφ).
    w = np.sin((np.arange(height) + 0.5) / height * np.pi)[:, None] * (np.pi / height) * (
        2 * np.pi / width
    )
    lum = img.mean(-1)
    sun_part = np.zeros_like(lum)
    sun_part[y_lo:y_hi, x_lo:x_hi] = cover * sun.mean()
    frac = (sun_part * w).sum() / (lum * w).sum()
    print(f"wrote {os.path.relpath(path, ROOT)}: sun {100 * frac:.0f} % of the map's power")


def ensure_assets():
    if not all(
        os.path.exists(os.path.join(SCENE_DIR, f)) for f in ("torus.obj", "sky-sun.exr")
    ):
        write_assets()


# --------------------------------------------------------------------------------------
# Rendering


def scene_path(name):
    return os.path.join(SCENE_DIR, name + ".xml")


def scene_hash(name):
    """SHA-256 of the XML and of the files it names (meshes, maps)."""
    path = scene_path(name)
    text = open(path, "rb").read()
    h = hashlib.sha256(text)
    for f in sorted(set(re.findall(rb'name="filename" value="([^"]+)"', text))):
        h.update(open(os.path.join(SCENE_DIR, f.decode()), "rb").read())
    return h.hexdigest()[:16]


def facette_help():
    out = subprocess.run(
        [FACETTE, "render", "--help"], capture_output=True, text=True, check=True
    ).stdout
    return out


def render_facette(name, params, spp, seed, threads, extra, out):
    """Renders with facette; returns (image, wall-clock seconds of the whole process,
    facette's own render seconds from its summary line or None)."""
    args = [FACETTE, "render", scene_path(name), "-o", out, "--spp", str(spp)]
    args += ["--seed", str(seed), "--threads", str(threads)] + list(extra)
    for k, v in params.items():
        args += ["-D", f"{k}={v}"]
    t = time.perf_counter()
    p = subprocess.run(args, capture_output=True, text=True)
    secs = time.perf_counter() - t
    if p.returncode != 0:
        sys.exit(f"facette failed ({' '.join(args)}):\n{p.stderr}")
    m = re.search(r"rendered in ([0-9.]+) s", p.stderr)
    img = np.array(mi.Bitmap(out), dtype=np.float64)[..., :3]
    return img, secs, (float(m.group(1)) if m else None)


class MitsubaScene:
    def __init__(self, name, params):
        self.scene = mi.load_file(scene_path(name), **{k: str(v) for k, v in params.items()})
        self.warm = set()

    def render(self, spp, seed):
        """(image, seconds): kernels warmed up first (untimed) for each spp."""
        if spp not in self.warm:
            img = mi.render(self.scene, spp=spp, seed=WARMUP_SEED)
            dr.eval(img)
            dr.sync_thread()
            self.warm.add(spp)
        t = time.perf_counter()
        img = mi.render(self.scene, spp=spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        secs = time.perf_counter() - t
        return np.array(img, dtype=np.float64)[..., :3], secs


def rel_mse(a, b):
    return float(np.mean((a - b) ** 2 / (b**2 + EPS)))


def read_exr(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def write_exr(path, img):
    mi.Bitmap(img.astype(np.float32)).write(path)


class Reference:
    """A reference image as the mean of two independent halves."""

    def __init__(self, a, b, meta):
        self.a, self.b, self.meta = a, b, meta
        self.img = 0.5 * (a + b)
        # E[(A − B)²] = 4 Var(reference): the reference's own relMSE.
        self.own_rel_mse = float(np.mean((a - b) ** 2 / 4 / (self.img**2 + EPS)))
        # Standard error of the image mean, treating pixels as independent.
        d = (a - b).mean(-1)
        self.mean_sigma = float(np.sqrt(np.mean(d**2 / 4) / d.size))


def load_or_render_reference(renderer, name, params, spp, args, sampler_flag, mts):
    d = os.path.join(args.cache, name)
    os.makedirs(d, exist_ok=True)
    # A facette without --sampler (an older build, --facette) renders its reference with
    # the XML's sampler: cached apart, so that it never replaces the Sobol reference.
    tag = renderer if renderer != "facette" or sampler_flag else "facette-default"
    meta_path = os.path.join(d, f"{tag}.json")
    files = [os.path.join(d, f"{tag}-{h}.exr") for h in "ab"]
    want = {
        "scene": scene_hash(name),
        "spp": spp,
        "width": params["width"],
        "height": params["height"],
    }
    if renderer == "facette":
        want["sampler"] = "sobol" if sampler_flag else "default"
    else:
        want["variant"] = mi.variant()
        want["mitsuba"] = mi.__version__
    if not args.refresh and os.path.exists(meta_path) and all(map(os.path.exists, files)):
        meta = json.load(open(meta_path))
        if all(meta.get(k) == v for k, v in want.items()):
            if renderer == "facette" and os.path.getmtime(FACETTE) > meta["made"]:
                print(
                    f"  note: facette's reference for {name} predates the facette binary"
                    " (--refresh to re-render it)"
                )
            return Reference(read_exr(files[0]), read_exr(files[1]), meta)
    half = spp // 2
    t0 = time.perf_counter()
    halves = []
    if renderer == "facette":
        extra = ["--sampler", "sobol"] if sampler_flag else []
        with tempfile.TemporaryDirectory() as tmp:
            for seed in REF_SEEDS:
                img, _, _ = render_facette(
                    name, params, half, seed, args.threads, extra, os.path.join(tmp, "r.exr")
                )
                halves.append(img)
    else:
        for k, seed in enumerate(REF_SEEDS):
            acc, done, p = 0.0, 0, 0
            while done < half:
                n = min(MITSUBA_PASS_SPP, half - done)
                img = mi.render(mts.scene, spp=n, seed=seed * 1000 + p)
                acc = acc + np.array(img, dtype=np.float64)[..., :3] * n
                done += n
                p += 1
            halves.append(acc / half)
    secs = time.perf_counter() - t0
    for f, img in zip(files, halves):
        write_exr(f, img)
    meta = dict(want, seconds=round(secs, 1), made=time.time())
    json.dump(meta, open(meta_path, "w"), indent=1)
    print(f"  {renderer} reference: {spp} spp in {secs:.0f} s")
    return Reference(halves[0], halves[1], meta)


# --------------------------------------------------------------------------------------
# The benchmark


def bench_scene(name, args, variants, sampler_flag):
    params = {"width": args.width, "height": args.height}
    f_spp, m_spp = QUICK_REF_SPP if args.quick else SCENES[name]
    if args.ref_spp:
        f_spp, m_spp = args.ref_spp
    print(f"\n## {name} ({args.width}×{args.height}, max_depth 8)")
    mts = MitsubaScene(name, params)
    refs = {
        "facette": load_or_render_reference(
            "facette", name, params, f_spp, args, sampler_flag, mts
        ),
        "mitsuba": load_or_render_reference(
            "mitsuba", name, params, m_spp, args, sampler_flag, mts
        ),
    }
    rf, rm = refs["facette"], refs["mitsuba"]
    between = rel_mse(rf.img, rm.img)
    expected = rf.own_rel_mse + rm.own_rel_mse
    mean_diff = float(rf.img.mean() / rm.img.mean() - 1)
    mean_sigma = float(np.hypot(rf.mean_sigma, rm.mean_sigma) / rm.img.mean())
    diff_path = os.path.join(args.cache, name, "ref-difference.exr")
    write_exr(diff_path, np.abs(rf.img - rm.img))
    bias = {
        "f_spp": rf.meta["spp"],
        "m_spp": rm.meta["spp"],
        "f_own": rf.own_rel_mse,
        "m_own": rm.own_rel_mse,
        "between": between,
        "expected": expected,
        "mean_diff": mean_diff,
        "mean_sigma": mean_sigma,
    }
    print(
        f"references: facette {rf.meta['spp']} spp (own relMSE {rf.own_rel_mse:.2e}),"
        f" Mitsuba {rm.meta['spp']} spp (own relMSE {rm.own_rel_mse:.2e})"
    )
    print(
        f"facette ref vs Mitsuba ref: relMSE {between:.2e} (noise alone: {expected:.2e};"
        f" bias ≈ {between - expected:.2e}), image mean {100 * mean_diff:+.3f} %"
        f" (σ {100 * mean_sigma:.3f} %)"
    )

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "t.exr")
        for spp in args.spp:
            acc = {v[0]: {"s": [], "own": [], "other": [], "inner": []} for v in variants}
            acc["Mitsuba"] = {"s": [], "own": [], "other": [], "inner": []}
            for r in range(args.repeats):
                seed = 1 + r
                for label, extra in variants:
                    img, secs, inner = render_facette(
                        name, params, spp, seed, args.threads, extra, out
                    )
                    a = acc[label]
                    a["s"].append(secs)
                    a["inner"].append(inner)
                    a["own"].append(rel_mse(img, rf.img))
                    a["other"].append(rel_mse(img, rm.img))
                img, secs = mts.render(spp, seed)
                a = acc["Mitsuba"]
                a["s"].append(secs)
                a["own"].append(rel_mse(img, rm.img))
                a["other"].append(rel_mse(img, rf.img))
            m = {k: float(np.mean(v)) for k, v in acc["Mitsuba"].items() if k != "inner"}
            for label in list(acc):
                a = acc[label]
                s, own, other = (float(np.mean(a[k])) for k in ("s", "own", "other"))
                inner = [x for x in a["inner"] if x is not None]
                rows.append(
                    {
                        "scene": name,
                        "who": label,
                        "spp": spp,
                        "s": s,
                        "inner": float(np.mean(inner)) if inner else None,
                        "own": own,
                        "other": other,
                        "ratio": own / m["own"],
                        "share": (rm if label == "Mitsuba" else rf).own_rel_mse / own,
                        "eff": (m["own"] * m["s"]) / (own * s),
                    }
                )
    print(
        f"{'renderer':<36} {'spp':>5} {'seconds':>8} {'(render)':>8} {'relMSE own ref':>15}"
        f" {'(ref share)':>11} {'other ref':>10} {'relMSE/M':>9} {'efficiency M/f':>15}"
    )
    for r in rows:
        inner = f"{r['inner']:.3f}" if r["inner"] is not None else "-"
        print(
            f"{r['who']:<36} {r['spp']:>5} {r['s']:>8.3f} {inner:>8} {r['own']:>15.4e}"
            f" {100 * r['share']:>10.1f}% {r['other']:>10.4e} {r['ratio']:>9.3f}"
            f" {r['eff']:>15.3f}"
        )
    print(
        "  (render) = facette's own render time from its summary line; ref share = the"
        " own reference's relMSE / the row's relMSE"
    )
    return rows, bias


def markdown(all_rows, biases, args, sampler_flag, info):
    lines = [
        f"**Equal-time efficiency against Mitsuba 3** ({info}; `python3 scripts/efficiency.py"
        f"{' --quick' if args.quick else ''}`; {args.width}×{args.height}, max_depth 8, box"
        f" filter; mean of {args.repeats} renders with different seeds; facette timed as a"
        " whole process, Mitsuba with warm kernels)",
        "",
        "| scene | renderer, sampler | spp | seconds | relMSE (own ref) | relMSE (other ref)"
        " | relMSE / Mitsuba's | efficiency vs Mitsuba |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in all_rows:
        lines.append(
            f"| {r['scene']} | {r['who']} | {r['spp']} | {r['s']:.2f} | {r['own']:.3e} |"
            f" {r['other']:.3e} | {r['ratio']:.2f} | {r['eff']:.2f} |"
        )
    lines += [
        "",
        "seconds: facette's whole `facette render` process (wall clock); Mitsuba's"
        " `mi.render` with warm kernels. relMSE = mean of (a − b)²/(b² + 0.01) against the"
        " renderer's own reference (noise) and the other renderer's (noise + bias).",
    ]
    lines += [
        "",
        "efficiency = (relMSE × seconds) of Mitsuba over that of the row: > 1 means the row"
        " reaches a given error in less time than Mitsuba.",
        "",
        "**Reference against reference** (the bias between the renderers; facette's"
        f" references {'with its Sobol sampler' if sampler_flag else 'without --sampler'},"
        " Mitsuba's with its independent sampler):",
        "",
        "| scene | facette ref spp (own relMSE) | Mitsuba ref spp (own relMSE) |"
        " relMSE between | expected from noise | image mean, facette vs Mitsuba (σ) |",
        "|---|---|---|---|---|---|",
    ]
    for name, b in biases.items():
        lines.append(
            f"| {name} | {b['f_spp']} ({b['f_own']:.1e}) | {b['m_spp']} ({b['m_own']:.1e}) |"
            f" {b['between']:.2e} | {b['expected']:.2e} | {100 * b['mean_diff']:+.3f} %"
            f" ({100 * b['mean_sigma']:.3f} %) |"
        )
    return "\n".join(lines) + "\n"


def main():
    global FACETTE
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, nargs="+", help="test sample counts (default 64)")
    ap.add_argument("--repeats", type=int, help="renders per test (default 3)")
    ap.add_argument("--only", nargs="+", choices=list(SCENES), help="scenes to run")
    ap.add_argument("--quick", action="store_true", help="smoke test: small references,"
                    " 16 spp, 1 repeat, cached apart (target/efficiency/quick)")
    ap.add_argument("--refresh", action="store_true", help="re-render the references")
    ap.add_argument("--ref-spp", type=int, nargs=2, metavar=("FACETTE", "MITSUBA"),
                    help="reference sample counts for every scene")
    ap.add_argument("--threads", type=int, default=os.cpu_count(),
                    help="threads for both renderers (default: all cores)")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--markdown", metavar="FILE", help="also write the Markdown table here")
    ap.add_argument("--write-assets", action="store_true",
                    help="regenerate scenes/efficiency/torus.obj and sky-sun.exr and exit")
    ap.add_argument("--facette", metavar="BINARY", default=FACETTE,
                    help="the facette binary to test (default: target/release/facette), e.g."
                    " an older build to measure a change; its cached references are reused,"
                    " or cached apart when it has no --sampler flag")
    args = ap.parse_args()
    FACETTE = os.path.abspath(args.facette)
    if args.write_assets:
        write_assets()
        return
    args.spp = args.spp or ([16] if args.quick else [64])
    args.repeats = args.repeats or (1 if args.quick else 3)
    args.cache = os.path.join(CACHE, "quick") if args.quick else CACHE
    if (args.width, args.height) != (256, 256):
        args.cache = os.path.join(args.cache, f"{args.width}x{args.height}")
    if not os.path.exists(FACETTE):
        sys.exit(f"{FACETTE} not found: cargo build --release -p facette")
    ensure_assets()

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

    sampler_flag = "--sampler" in facette_help()
    if sampler_flag:
        variants = [
            ("facette independent", ["--sampler", "independent"]),
            ("facette sobol", ["--sampler", "sobol"]),
        ]
    else:
        print("note: `facette render` has no --sampler flag: facette renders with the XML's"
              " sampler (independent); rows marked 'sampler flag unavailable'")
        variants = [("facette (sampler flag unavailable)", [])]
    info = (
        f"Mitsuba {mi.__version__} {mi.variant()}, {args.threads} threads,"
        f" {os.cpu_count()} cores ({cpu_description()})"
    )
    load_before = load_average()
    print(f"{info}; load average before: {load_before}")
    t0 = time.perf_counter()
    all_rows, biases = [], {}
    for name in args.only or SCENES:
        rows, bias = bench_scene(name, args, variants, sampler_flag)
        all_rows += rows
        biases[name] = bias
    load_after = load_average()
    print(f"\nload average after: {load_after}; total {time.perf_counter() - t0:.0f} s\n")
    info += f", load average {load_before.split()[0]} before, {load_after.split()[0]} after"
    md = markdown(all_rows, biases, args, sampler_flag, info)
    print(md)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(md)
        print(f"wrote {args.markdown}")


if __name__ == "__main__":
    main()
