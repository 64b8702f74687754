#!/usr/bin/env python3
"""Renders Mitsuba XML scenes in facette and in Mitsuba 3 and compares the images.

Not a test and not a CI dependency: a second opinion on the conventions of facette's
Mitsuba reader (camera, film orientation, uv, environment-map orientation, units) and on
its materials, with the numbers quoted in docs/scene-format.md ("Mitsuba scenes").

    python3 scripts/compare_mitsuba.py [--width 240 --height 135 --spp 256]

Needs the Mitsuba 3 Python package (variant llvm_ad_rgb, else scalar_rgb) and a release
build of facette (`cargo build --release -p facette`). The scenes:

- `spheres`: scenes/mitsuba/spheres.xml, with facette's own `il` BSDF (which Mitsuba does
  not have) replaced by a `diffuse` of the same colour in both renderers;
- `conventions`: written here: a lat-long environment map (rotated), bitmap textures on a
  rotated sphere and a rectangle, an anisotropic rough conductor, a rough dielectric and a
  point light, seen through a camera with fov_axis y. A convention that differs between the
  two renderers (mirrored film, uv flipped, environment map turned) shows up as a large
  difference in some region.

For each scene: the mean of each image, the relative RMSE over the image, and per region
(what the pixel centre sees, from Mitsuba's `aov` integrator: each shape by its BSDF id, and
the background) the mean of each image, their relative difference, and σ, the standard error
of one render's region mean (estimated from two facette renders with different seeds; the
difference of two independent renders has a standard deviation of about √2 σ). The noise
floor of the RMSE is the same RMSE between the two facette renders.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FACETTE = os.path.join(ROOT, "target", "release", "facette")

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

try:
    mi.set_variant("llvm_ad_rgb")
except Exception:  # no LLVM: the scalar variant gives the same images, slower
    mi.set_variant("scalar_rgb")


CONVENTIONS_XML = """<scene version="3.0.0">
    <default name="width" value="240"/>
    <default name="height" value="135"/>
    <default name="spp" value="64"/>
    <integrator type="path"><integer name="max_depth" value="6"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="35"/>
        <string name="fov_axis" value="y"/>
        <transform name="to_world"><lookat origin="1.0, 2.2, 7.0" target="0, 0.6, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/><integer name="height" value="$height"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="envmap">
        <string name="filename" value="env.exr"/>
        <float name="scale" value="0.8"/>
        <transform name="to_world"><rotate y="1" angle="70"/></transform>
    </emitter>
    <emitter type="point">
        <point name="position" x="2" y="4" z="3"/>
        <rgb name="intensity" value="20, 18, 15"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="-90"/><scale x="3" y="1" z="2"/><translate x="0.3"/></transform>
        <bsdf type="diffuse" id="floor-texture">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="quadrants.png"/>
                <transform name="to_uv"><scale value="2"/></transform>
            </texture>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="-1.6" y="0.7" z="0"/><float name="radius" value="0.7"/>
        <transform name="to_world"><rotate x="1" angle="40"/><rotate y="1" angle="-25"/></transform>
        <bsdf type="diffuse" id="sphere-texture">
            <texture type="bitmap" name="reflectance"><string name="filename" value="quadrants.png"/></texture>
        </bsdf>
    </shape>
    <shape type="sphere">
        <transform name="to_world"><rotate z="1" angle="30"/><scale value="0.7"/><translate x="0" y="0.7" z="0.2"/></transform>
        <bsdf type="roughconductor" id="anisotropic-copper">
            <string name="material" value="Cu"/>
            <string name="distribution" value="ggx"/>
            <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.4"/>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="1.6" y="0.7" z="0"/><float name="radius" value="0.7"/>
        <bsdf type="roughdielectric" id="rough-glass">
            <string name="distribution" value="beckmann"/>
            <float name="alpha" value="0.1"/>
            <float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.7" y="0.3" z="1.4"/><float name="radius" value="0.3"/>
        <bsdf type="twosided" id="green-diffuse"><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.6, 0.3"/></bsdf></bsdf>
    </shape>
</scene>
"""


def write_assets(directory):
    """A lat-long map whose four longitude quarters and two hemispheres all differ, and a
    2×2 texture whose quadrants differ, so that any flip or turn changes the image."""
    h, w = 512, 1024
    env = np.zeros((h, w, 3), dtype=np.float32)
    v, u = np.meshgrid(np.arange(h) / h, np.arange(w) / w, indexing="ij")
    quarter = (u * 4).astype(int)
    colours = np.array([[1.0, 0.3, 0.1], [0.2, 1.0, 0.2], [0.1, 0.3, 1.0], [1.0, 1.0, 0.3]])
    env[:] = colours[quarter]
    env *= np.where(v < 0.5, 1.0, 0.25)[..., None] * (0.5 + v[..., None])
    mi.Bitmap(env).write(os.path.join(directory, "env.exr"))
    tex = np.array(
        [[[0.8, 0.1, 0.1], [0.1, 0.8, 0.1]], [[0.1, 0.1, 0.8], [0.8, 0.8, 0.8]]], dtype=np.float32
    )
    tex = np.repeat(np.repeat(tex, 16, axis=0), 16, axis=1)
    # 8-bit sRGB, as a texture file usually is; both renderers decode it the same way.
    srgb = np.where(tex <= 0.0031308, 12.92 * tex, 1.055 * tex ** (1 / 2.4) - 0.055)
    mi.util.write_bitmap(
        os.path.join(directory, "quadrants.png"), srgb.astype(np.float32), write_async=False
    )


def spheres_scene(directory):
    """scenes/mitsuba/spheres.xml with its `il` material as a diffuse of the same colour."""
    shutil.copytree(os.path.join(ROOT, "scenes", "mitsuba"), directory, dirs_exist_ok=True)
    materials = os.path.join(directory, "parts", "materials.xml")
    text = open(materials).read()
    text, n = re.subn(
        r'<bsdf type="il" id="clay">.*?</bsdf>',
        '<bsdf type="diffuse" id="clay"><rgb name="reflectance" value="0.7, 0.3, 0.1"/></bsdf>',
        text,
        flags=re.S,
    )
    assert n == 1, "the il material of spheres.xml was not found"
    open(materials, "w").write(text)
    return os.path.join(directory, "spheres.xml")


def render_facette(scene, params, spp, seed, out):
    args = [FACETTE, "render", scene, "-o", out, "-q", "--spp", str(spp), "--seed", str(seed)]
    for k, v in params.items():
        args += ["-D", f"{k}={v}"]
    subprocess.run(args, check=True)
    return np.array(mi.Bitmap(out), dtype=np.float64)[..., :3]


def render_mitsuba(scene, params, spp, seed):
    s = mi.load_file(scene, **{k: str(v) for k, v in params.items()})
    return np.array(mi.render(s, spp=spp, seed=seed), dtype=np.float64)[..., :3], s


def regions(scene_path, params):
    """Per pixel: the index of the shape its centre sees (−1: background), from Mitsuba's
    aov integrator at 16 spp with a box filter; pixels whose 3×3 neighbourhood sees more
    than one thing (edges) are left out (−2)."""
    s = mi.load_file(scene_path, **{k: str(v) for k, v in params.items()})
    sensor = s.sensors()[0]
    film = sensor.film()
    w, h = film.size()
    aov = mi.load_dict({"type": "aov", "aovs": "depth:depth,index:shape_index"})
    box = mi.load_dict(
        {
            "type": "perspective",
            "to_world": mi.ScalarTransform4f(
                np.array(sensor.world_transform().matrix, dtype=np.float64).reshape(4, 4)
            ),
            "fov": float(mi.traverse(sensor)["x_fov"][0]),
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}},
        }
    )
    img = np.array(mi.render(s, sensor=box, integrator=aov, spp=16), dtype=np.float64)
    depth, index = img[..., -2], img[..., -1]
    label = np.where(depth > 0, np.round(index), -1).astype(int)
    pure = np.abs(index - np.round(index)) < 1e-4
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            pure &= np.roll(np.roll(label, dy, 0), dx, 1) == label
    pure[0, :] = pure[-1, :] = pure[:, 0] = pure[:, -1] = False
    label = np.where(pure, label, -2)
    # The aov's shape index is the shape's registry id, not its place in s.shapes().
    names = {-1: "background"}
    for shape in s.shapes():
        key = int(np.array(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(shape))).ravel()[0])
        names[key] = "area light" if shape.is_emitter() else (shape.bsdf().id() or shape.id())
    return label, names


def rel_rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.mean(b))


def compare(name, scene, params, spp):
    print(f"\n## {name}: {params['width']}×{params['height']}, {spp} spp ({mi.variant()})")
    with tempfile.TemporaryDirectory() as tmp:
        f0 = render_facette(scene, params, spp, 0, os.path.join(tmp, "a.exr"))
        f1 = render_facette(scene, params, spp, 1, os.path.join(tmp, "b.exr"))
    m, _ = render_mitsuba(scene, params, spp, 0)
    assert m.shape == f0.shape, (m.shape, f0.shape)
    label, names = regions(scene, params)
    print(f"image mean (R, G, B): facette {fmt(f0.mean((0, 1)))}, Mitsuba {fmt(m.mean((0, 1)))}")
    print(
        f"relative RMSE: facette vs Mitsuba {rel_rmse(f0, m):.4f};"
        f" noise floor (facette seed 0 vs 1) {rel_rmse(f0, f1):.4f}"
    )
    print("| region | pixels | facette mean (R, G, B) | Mitsuba mean | difference | σ |")
    print("|---|---|---|---|---|---|")
    for i in sorted(set(np.unique(label)) - {-2}):
        mask = label == i
        a, b = f0[mask].mean(0), m[mask].mean(0)
        diff = (a.sum() - b.sum()) / b.sum()
        # Standard error of a render's region mean (R + G + B), from the per-pixel
        # differences of the two facette renders: Var(pixel) ≈ mean((f0 − f1)²)/2.
        d = (f0[mask] - f1[mask]).sum(1)
        sigma = np.sqrt(np.mean(d**2) / 2 / mask.sum()) / b.sum()
        print(
            f"| {names.get(i, i)} | {mask.sum()} | {fmt(a)} | {fmt(b)} | {100 * diff:+.2f} % |"
            f" {100 * sigma:.2f} % |"
        )


def fmt(v):
    return "(" + ", ".join(f"{x:.4f}" for x in v) + ")"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--width", type=int, default=240)
    ap.add_argument("--height", type=int, default=135)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--only", choices=["spheres", "conventions"])
    args = ap.parse_args()
    if not os.path.exists(FACETTE):
        sys.exit(f"{FACETTE} not found: cargo build --release -p facette")
    params = {"width": args.width, "height": args.height, "spp": args.spp}
    with tempfile.TemporaryDirectory() as tmp:
        if args.only in (None, "spheres"):
            compare("spheres.xml", spheres_scene(os.path.join(tmp, "spheres")), params, args.spp)
        if args.only in (None, "conventions"):
            d = os.path.join(tmp, "conventions")
            os.makedirs(d)
            write_assets(d)
            path = os.path.join(d, "conventions.xml")
            open(path, "w").write(CONVENTIONS_XML)
            compare("conventions", path, params, args.spp)


if __name__ == "__main__":
    main()
