"""facette.fit and facette.measure: the `facette fit` / `facette measure` commands from Python."""

import subprocess

import numpy as np
import pytest

import facette


def test_measure_then_fit_recovers_kelemen_parameters(tmp_path):
    path = tmp_path / "k.binary"
    truth = facette.Material('{type = "kelemen", alpha = 0.2, ior = 1.5, kd = [0.5, 0.3, 0.2]}')
    valid = truth.to_merl(path, noise=0.05, seed=3)
    assert valid > 1_000_000
    png = tmp_path / "k.png"
    r = facette.fit(path, model="kelemen", samples=2000, output=png)
    for name, expected in [("kd_r", 0.5), ("kd_g", 0.3), ("kd_b", 0.2), ("alpha", 0.2), ("ior", 1.5)]:
        assert abs(r["parameters"][name] / expected - 1) < 0.03, (name, r["parameters"])
    assert r["model"].startswith("KSK01") or "kelemen" in r["model"].lower(), r["model"]
    assert r["samples"] == 2000 and r["valid_bins"] == valid
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The fitted material is a material: it evaluates close to the truth.
    fitted = facette.Material(r["material"])
    wi = np.array([[0.3, 0.1, 0.9]])
    wo = np.array([[-0.2, 0.4, 0.8]])
    assert np.allclose(fitted.eval(wi, wo), truth.eval(wi, wo), rtol=0.05)


def test_fit_equals_the_cli(facette_bin, tmp_path):
    path = tmp_path / "l.binary"
    facette.measure('{type = "lambert", reflectance = [0.6, 0.4, 0.2]}', path)
    out = subprocess.run(
        [facette_bin, "fit", str(path), "--model", "plastic", "--samples", "500"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    r = facette.fit(path, model="plastic", samples=500)
    for name, value in r["parameters"].items():
        line = next(l for l in out.splitlines() if l.startswith(f"{name} = "))
        assert float(line.split()[2]) == pytest.approx(value, rel=1e-5, abs=1e-6), (name, out)


def test_bad_fit_arguments_raise_documented_exceptions(tmp_path):
    with pytest.raises(OSError, match="missing.binary"):
        facette.fit(tmp_path / "missing.binary")
    bad = tmp_path / "bad.binary"
    bad.write_bytes(b"\x01\x00\x00\x00" * 5)
    with pytest.raises(ValueError, match="not a MERL BRDF file"):
        facette.fit(bad)
    with pytest.raises(ValueError, match="il, plastic, kelemen"):
        facette.fit(bad, model="phong")
    with pytest.raises(ValueError, match="log, cosine"):
        facette.fit(bad, error="l2")
    with pytest.raises(ValueError, match="at least 10"):
        facette.fit(bad, samples=3)
    with pytest.raises(ValueError, match="noise"):
        facette.measure('{type = "lambert"}', tmp_path / "x.binary", noise=float("nan"))
