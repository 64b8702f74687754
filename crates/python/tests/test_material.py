"""facette.Material against the command line, and its errors."""

import subprocess
import threading
import time

import numpy as np
import pytest

import facette


def spherical(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


ROWS = np.array([[0, 0, 30, 180], [30, 0, 60, 180], [45, 90, 10, 0], [70, 0, 70, 180], [20, 0, 150, 30]], float)


def cli_eval(facette_bin, spec, samples, *flags):
    """`facette eval` of ROWS with seed 4: the columns after the four angles."""
    csv = "\n".join(",".join(f"{v:g}" for v in r) for r in ROWS)
    out = subprocess.run(
        [facette_bin, "eval", "--material", spec, "--samples", str(samples), "--seed", "4", *flags],
        input=csv, capture_output=True, text=True, check=True,
    ).stdout
    return np.array([[float(x) for x in line.split(",")[4:]] for line in out.strip().splitlines()[1:]])


@pytest.mark.parametrize(
    "spec, samples",
    [
        ('{type = "conductor", material = "Au", distribution = "ggx", alpha = 0.3}', 1),
        ('{type = "dielectric", distribution = "beckmann", alpha = 0.2, ior = 1.5}', 1),
        ('{type = "kelemen", alpha = 0.3, kd = 0.4}', 1),
        ('{type = "il", kd = [0.8, 0.4, 0.2], ni = 1.5, alpha = 0.3}', 200),
    ],
)
def test_eval_equals_the_cli(facette_bin, spec, samples):
    cli = cli_eval(facette_bin, spec, samples)
    m = facette.Material(spec)
    wi = spherical(ROWS[:, 0], ROWS[:, 1])
    wo = spherical(ROWS[:, 2], ROWS[:, 3])
    py = m.eval(wi, wo, samples=samples, seed=4)
    assert py.shape == (len(ROWS), 3)
    # The CLI prints 10 significant digits.
    np.testing.assert_allclose(py, cli, rtol=1e-9, atol=1e-300)


@pytest.mark.parametrize(
    "spec, samples",
    [
        # Adaptive quadrature: the error column is its error estimate.
        ('{type = "il", kd = 0.7, ni = 1.5, alpha = 0.4, evaluation = "quadrature", tolerance = 1e-4}', 1),
        # IL_∞ wholly by quadrature: deterministic (rows on all threads) though stochastic
        # as a model (its sampling weights carry a walk).
        ('{type = "il", kd = 0.7, ni = 1.5, alpha = 0.4, evaluation = "quadrature", tolerance = 1e-3, '
         'scattering = "multiple", multiple_evaluation = "quadrature"}', 1),
        # Stochastic: the standard error of the mean.
        ('{type = "il", kd = 0.7, ni = 1.5, alpha = 0.4}', 300),
        # Closed form: zero.
        ('{type = "conductor", material = "Au", distribution = "ggx", alpha = 0.3}', 1),
    ],
)
def test_eval_with_error_equals_the_cli(facette_bin, spec, samples):
    cli = cli_eval(facette_bin, spec, samples, "--with-error")
    m = facette.Material(spec)
    wi = spherical(ROWS[:, 0], ROWS[:, 1])
    wo = spherical(ROWS[:, 2], ROWS[:, 3])
    f, err = m.eval(wi, wo, samples=samples, seed=4, with_error=True)
    assert f.shape == err.shape == (len(ROWS), 3)
    np.testing.assert_allclose(f, cli[:, :3], rtol=1e-9, atol=1e-300)
    # The CLI prints errors with 4 significant digits.
    np.testing.assert_allclose(err, cli[:, 3:], rtol=1e-3, atol=1e-300)
    np.testing.assert_array_equal(m.eval(wi, wo, samples=samples, seed=4), f)
    if "multiple_evaluation" in spec:
        assert m.is_stochastic
        np.testing.assert_array_equal(m.eval(wi, wo, seed=9, threads=1), f)
    if "conductor" in spec:
        assert (err == 0).all()
    else:
        assert (err[f[:, 0] > 0] > 0).all()
        assert (err < 0.05 * np.maximum(f, 1e-3)).all()


def test_dict_specs_equal_toml_specs():
    a = facette.Material({"type": "conductor", "material": "Cu", "distribution": "ggx", "alpha_u": 0.1, "alpha_v": 0.4})
    b = facette.Material('{type = "conductor", material = "Cu", distribution = "ggx", alpha_u = 0.1, alpha_v = 0.4}')
    wi, wo = spherical([10, 40], [0, 30]), spherical([50, 20], [180, 200])
    np.testing.assert_array_equal(a.eval(wi, wo), b.eval(wi, wo))
    assert a.description == b.description


def test_sample_pdf_and_eval_are_consistent():
    m = facette.Material('{type = "conductor", distribution = "ggx", alpha = 0.4}')
    wo = np.repeat(spherical([35.0], [10.0]), 2000, axis=0)
    wi, weight, pdf, lobes = m.sample(wo, seed=7)
    ok = pdf > 0
    assert ok.mean() > 0.8 and set(lobes) <= {"glossy+reflection", "none"}
    np.testing.assert_allclose(m.pdf(wi[ok], wo[ok]), pdf[ok], rtol=1e-9)
    f = m.eval(wi[ok], wo[ok])
    np.testing.assert_allclose(weight[ok], f * np.abs(wi[ok, 2:3]) / pdf[ok, None], rtol=1e-9)
    # Given uniforms replay exactly; a different seed only matters past them.
    u = np.random.default_rng(0).random((5, 2))
    a = m.sample(wo[:5], u=u, seed=1)[0]
    b = m.sample(wo[:5], u=u, seed=2)[0]
    np.testing.assert_array_equal(a, b)


def test_albedo_and_validate():
    m = facette.Material('{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5}')
    a = m.albedo([0, 60, 150], samples=20_000)
    total = a["reflectance"] + a["transmittance"]
    assert a["reflectance"].shape == (3, 3)
    assert np.all(total < 1 + 4 * (a["reflectance_stderr"] + a["transmittance_stderr"]))
    assert np.all(total > 0.85)
    r = facette.Material('{type = "lambert", reflectance = 0.5}').validate(samples=20_000)
    assert r.passed and len(r.checks) > 5
    assert all(c.passed in (True, None) for c in r.checks)
    assert "passed, 0 failed" in r.summary


def test_bad_arguments_raise_documented_exceptions():
    with pytest.raises(ValueError, match="unknown material type `lambrt`; valid values: lambert"):
        facette.Material('{type = "lambrt"}')
    with pytest.raises(ValueError, match="unknown key `alpah`.*valid keys:"):
        facette.Material({"type": "conductor", "alpah": 0.3})
    with pytest.raises(ValueError, match="out of range"):
        facette.Material({"type": "lambert", "reflectance": 2.0})
    with pytest.raises(ValueError, match="finite"):
        facette.Material({"type": "conductor", "alpha": float("nan")})
    m = facette.Material('{type = "lambert"}')
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        m.eval(np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="not a finite non-zero vector"):
        m.eval([[0, 0, 1], [np.nan, 0, 1]], [[0, 0, 1], [0, 0, 1]])
    with pytest.raises(ValueError, match="do not broadcast"):
        m.eval(np.ones((3, 3)), np.ones((2, 3)))
    with pytest.raises(ValueError, match="unknown mode"):
        m.eval([0, 0, 1], [0, 0, 1], mode="photons")
    with pytest.raises(ValueError, match=r"\[0, 1\)"):
        m.sample([[0, 0, 1]], u=[[1.5, 0.2]])
    with pytest.raises(ValueError):
        facette.Material(42)


def test_heavy_calls_release_the_gil():
    """While a long evaluation runs in a thread, Python code keeps running."""
    m = facette.Material('{type = "il", kd = 0.5, ni = 1.5, alpha = 0.5, masking = "v-cavity", scattering = "multiple"}')
    wi = np.repeat(spherical([30.0], [0.0]), 40, axis=0)
    wo = np.repeat(spherical([45.0], [180.0]), 40, axis=0)
    done = threading.Event()
    result = {}

    def work():
        t = time.perf_counter()
        result["f"] = m.eval(wi, wo, samples=4000)
        result["seconds"] = time.perf_counter() - t
        done.set()

    th = threading.Thread(target=work)
    ticks = 0
    th.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    th.join()
    assert result["seconds"] > 0.2, "the workload is too small to show anything"
    # With the GIL held, the loop would not run at all during the call.
    assert ticks > 0.3 * result["seconds"] / 0.001 * 0.2, (ticks, result["seconds"])
    assert np.all(np.isfinite(result["f"]))
