"""facette.render against the EXR the command line writes; parts and merges."""

import subprocess

import numpy as np
import pytest

import facette


def test_render_equals_the_cli_exr(facette_bin, tiny_scene, tmp_path):
    out = tmp_path / "cli.exr"
    subprocess.run([facette_bin, "render", str(tiny_scene), "-o", str(out), "--seed", "5", "-q"], check=True)
    cli = facette.read_image(out)
    py = facette.render(tiny_scene, seed=5)
    assert py.shape == (16, 24, 3) and py.dtype == np.float32
    np.testing.assert_array_equal(py, cli)
    # TOML text renders the same as the file.
    np.testing.assert_array_equal(facette.render(tiny_scene.read_text(), seed=5), py)
    # Threads do not change the image.
    np.testing.assert_array_equal(facette.render(tiny_scene, seed=5, threads=1), py)


def test_parts_merge_exactly(tiny_scene):
    parts = [facette.render_part(tiny_scene, k, 4, seed=2) for k in range(4)]
    merged = facette.merge_render_parts(parts[::-1])
    np.testing.assert_array_equal(merged, facette.render_in_parts(tiny_scene, 4, seed=2))
    with pytest.raises(ValueError, match="missing part"):
        facette.merge_render_parts(parts[:3])
    with pytest.raises(ValueError, match="given twice"):
        facette.merge_render_parts([parts[0]] + parts[:3])
    with pytest.raises(ValueError, match="the seed"):
        facette.merge_render_parts(parts[:3] + [facette.render_part(tiny_scene, 3, 4, seed=3)])
    with pytest.raises(ValueError, match="checksum|truncated|magic"):
        facette.merge_render_parts([parts[0][:-10]])


def test_tables_split_and_merge_to_the_same_bytes(tmp_path):
    m = '{type = "il", ni = 1.4, distribution = "beckmann", alpha = 0.5}'
    full = facette.tabulate(m, step=10, samples=256, output=tmp_path / "t.fctab")
    assert (tmp_path / "t.fctab").read_bytes() == full
    parts = [facette.tabulate_part(m, k, 3, step=10, samples=256) for k in range(3)]
    assert facette.merge_table_parts(parts) == full
    with pytest.raises(ValueError, match="interfaced-Lambertian"):
        facette.tabulate('{type = "lambert"}')


def test_adaptive_tables_split_and_merge_and_check_their_tolerance(tmp_path):
    # `tolerance`: deterministic adaptive entries (`facette tabulate --tolerance`), written in
    # the header; parts merge into the same bytes; the table agrees with the sampled one
    # within the sampled one's standard errors.
    m = '{type = "il", ni = 1.4, distribution = "beckmann", alpha = 0.5}'
    full = facette.tabulate(m, step=30, tolerance=1e-4)
    assert b"tolerance = 1e-4" in full and full == facette.tabulate(m, step=30, tolerance=1e-4)
    parts = [facette.tabulate_part(m, k, 2, step=30, tolerance=1e-4) for k in range(2)]
    assert facette.merge_table_parts(parts) == full
    with pytest.raises(ValueError, match="exclusive"):
        facette.tabulate(m, step=30, samples=64, tolerance=1e-4)
    for bad in (-1.0, 0.5, float("nan")):
        with pytest.raises(ValueError, match="tolerance"):
            facette.tabulate(m, step=30, tolerance=bad)
    with pytest.raises(ValueError, match="tolerance"):
        facette.tabulate(m, step=30, tolerance="1e-4")


def test_render_errors(tmp_path):
    with pytest.raises(OSError, match="cannot read the scene file"):
        facette.render(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text('[camera]\nposition = [0, 0, 4]\ntarget = [0, 0, 0]\n[[objects]]\nshape = "sphere"\nmaterial = "nope"\n')
    with pytest.raises(ValueError, match=r"bad.toml:6: .*unknown material `nope`"):
        facette.render(bad)
    with pytest.raises(ValueError, match="spp"):
        facette.render(bad, spp=0)
    with pytest.raises(ValueError, match=r"shape \(H, W, 3\)"):
        facette.write_image(tmp_path / "x.png", np.zeros((4, 4)))
    with pytest.raises(ValueError, match="unsupported"):
        facette.write_image(tmp_path / "x.jpg", np.zeros((4, 4, 3)))
    with pytest.raises(OSError):
        facette.read_image(tmp_path / "none.exr")
