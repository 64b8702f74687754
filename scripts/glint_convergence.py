#!/usr/bin/env python3
"""Does the glint image converge to its brute-force reference? (docs/glints.md)

Renders `scenes/glint-scratched-sphere.toml` with `evaluation = "reference"` (the
interpolated normal map at each hit as one sigma_eps lobe: the brute force) at a high
sample count as ground truth, then the glint material (the P-BRDF of each sample's
footprint) at several sample counts and seed subdivisions, and the reference itself at the
same counts, and prints the linear RMSE of each against the ground truth: over all pixels,
over the 99 % below the brightest 1 % of the ground truth, and over that brightest 1 %
(the highlight). The glint image converges when its RMSE falls with the sample count
like the reference's own does; CCM19's one lobe per texel (`seed_subdivision = 1`) stops
at a bias.

Usage (from the repository root, after `cargo build --release`):

    python3 scripts/glint_convergence.py [--spp 16 64 256] [--truth-spp 2048]
        [--subdivisions 1 2 4] [--masking approx] [--footprint ray|pixel] [--no-reference]
        [--out /tmp/glint-convergence]
        [--figure docs/figures/glint-convergence.png]

Needs numpy and the `mitsuba` Python package (for reading and writing EXR/PNG only).
"""

import argparse
import os
import re
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "glint-scratched-sphere.toml")
FACETTE = os.path.join(ROOT, "target", "release", "facette")


def scene_with(material_extra, masking):
    """The scratched-sphere scene with its material's keys changed."""
    text = open(SCENE).read()
    pattern = r'(scratched = \{[^}]*?)masking = "exact"'
    new = r'\1masking = "%s"%s' % (masking, material_extra)
    out, n = re.subn(pattern, new, text)
    if n != 1:
        sys.exit("glint_convergence: cannot find the material line in " + SCENE)
    return out


def render(text, spp, path, workdir):
    toml = path + ".toml"
    with open(toml, "w") as f:
        f.write(text)
    t0 = time.time()
    r = subprocess.run(
        [FACETTE, "render", toml, "--spp", str(spp), "-o", path],
        cwd=workdir,
        capture_output=True,
        text=True,
    )
    if r.returncode != 0:
        sys.exit(r.stderr)
    m = re.search(r"rendered in ([0-9.]+) s", r.stdout + r.stderr)
    return float(m.group(1)) if m else time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, nargs="+", default=[16, 64, 256])
    ap.add_argument("--truth-spp", type=int, default=2048)
    ap.add_argument("--subdivisions", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--masking", default="approx", choices=["approx", "exact"])
    ap.add_argument("--footprint", default="ray", choices=["ray", "pixel"],
                    help="the glint material's footprint at camera hits (docs/materials.md)")
    ap.add_argument("--no-reference", action="store_true",
                    help="skip the reference's own rows (only the ground truth is rendered)")
    ap.add_argument("--out", default="/tmp/glint-convergence")
    ap.add_argument("--figure", default=None, help="PNG: crops of the highlight at the largest spp")
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant("scalar_rgb")

    def load(p):
        b = mi.Bitmap(p).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
        return np.array(b)

    os.makedirs(args.out, exist_ok=True)
    ref_text = scene_with(', evaluation = "reference"', args.masking)
    truth_path = os.path.join(args.out, "truth-%d.exr" % args.truth_spp)
    if not os.path.exists(truth_path):
        t = render(ref_text, args.truth_spp, truth_path, args.out)
        print("ground truth: reference at %d spp, %.1f s" % (args.truth_spp, t))
    truth = load(truth_path)
    lum = truth.mean(axis=2)
    top = lum >= np.quantile(lum, 0.99)

    def errors(img):
        d2 = ((img - truth) ** 2).mean(axis=2)
        return np.sqrt(d2.mean()), np.sqrt(d2[~top].mean()), np.sqrt(d2[top].mean())

    rows = [] if args.no_reference else [("reference (brute force)", ref_text)]
    for n in args.subdivisions:
        extra = ", seed_subdivision = %d, footprint = \"%s\"" % (n, args.footprint)
        rows.append(("glint, seed_subdivision = %d" % n, scene_with(extra, args.masking)))
    print("linear RMSE against the ground truth: all pixels / 99 %% below the brightest 1 %% / "
          "the brightest 1 %% (render time), masking %s, footprint %s"
          % (args.masking, args.footprint))
    print("| render | " + " | ".join("%d spp" % s for s in args.spp) + " |")
    print("|---|" + "---|" * len(args.spp))
    last = {}
    for name, text in rows:
        cells = []
        for spp in args.spp:
            tag = re.sub(r"[^a-z0-9]+", "_", name) + ("" if "reference" in name else args.footprint)
            path = os.path.join(args.out, "%s-%d.exr" % (tag, spp))
            t = render(text, spp, path, args.out)
            img = load(path)
            e = errors(img)
            cells.append("%.3f / %.3f / %.2f (%.1f s)" % (e[0], e[1], e[2], t))
            last[name] = img
        print("| %s | %s |" % (name, " | ".join(cells)))
        sys.stdout.flush()

    if args.figure:
        # Crops of 96 x 96 pixels around the highlight, shown 3x; top row divided by the
        # ground truth's 99.5th percentile (the scratches; the core clips), bottom row by
        # its maximum (the highlight's core, where the bias of one lobe per texel lies).
        iy, ix = np.unravel_index(np.argmax(lum), lum.shape)
        h = 48
        y0 = int(np.clip(iy - h, 0, lum.shape[0] - 2 * h))
        x0 = int(np.clip(ix - h, 0, lum.shape[1] - 2 * h))
        tiles = [truth] + [last[name] for name, _ in rows]
        gap = np.ones((2 * h * 3, 4, 3), dtype=np.float32)

        def strip(scale):
            parts = []
            for k, img in enumerate(tiles):
                crop = np.clip(img[y0 : y0 + 2 * h, x0 : x0 + 2 * h] * scale, 0.0, 1.0)
                crop = np.repeat(np.repeat(crop, 3, axis=0), 3, axis=1).astype(np.float32)
                if k:
                    parts.append(gap)
                parts.append(crop)
            return np.concatenate(parts, axis=1)

        top_row = strip(1.0 / np.quantile(lum, 0.995))
        bottom_row = strip(1.0 / lum.max())
        sep = np.ones((4, top_row.shape[1], 3), dtype=np.float32)
        image = np.ascontiguousarray(np.concatenate([top_row, sep, bottom_row], axis=0))
        bmp = mi.Bitmap(image, mi.Bitmap.PixelFormat.RGB)
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True)
        bmp.write(args.figure)
        print("figure: " + args.figure + " (left to right: ground truth, "
              + ", ".join(name for name, _ in rows) + ", at %d spp)" % args.spp[-1])


if __name__ == "__main__":
    main()
