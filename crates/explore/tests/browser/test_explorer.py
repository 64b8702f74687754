"""End-to-end tests of `facette explore` in a real headless Chromium (selenium).

Run by scripts/test.sh, which installs Debian's chromium and chromium-driver and builds the
binary: FACETTE_BIN names it, FACETTE_ARTEFACTS the folder for the screenshots and the
latency figures. The numbers the page draws are checked against `facette eval` for the
same material, and a bad value must show the grammar's own error message.
"""

import json
import math
import os
import re
import select
import subprocess
import time
from pathlib import Path

import pytest

os.environ.setdefault("SE_OFFLINE", "true")  # never let selenium fetch a driver
from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402

ROOT = Path(__file__).resolve().parents[4]
BIN = Path(os.environ.get("FACETTE_BIN", ROOT / "target" / "optimized-tests" / "facette"))
ARTEFACTS = Path(os.environ.get("FACETTE_ARTEFACTS", ROOT / "target" / "explore-artefacts"))
GOLD = '{type = "conductor", distribution = "ggx", alpha = 0.2, material = "Au"}'
PLASTIC = '{type = "il", kd = 0.5, ni = 1.5, distribution = "beckmann", alpha = 0.3, evaluation = "approx"}'


@pytest.fixture(scope="module")
def server():
    proc = subprocess.Popen(
        [str(BIN), "explore", "--port", "0", "--material", GOLD, "--material", PLASTIC],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    ready, _, _ = select.select([proc.stdout], [], [], 60)
    line = proc.stdout.readline() if ready else ""
    m = re.search(r"http://\S+/", line)
    assert m, f"no URL in {line!r}; stderr: {proc.stderr.read() if proc.poll() is not None else ''}"
    yield m.group(0)
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture(scope="module")
def driver():
    o = webdriver.ChromeOptions()
    o.binary_location = "/usr/bin/chromium"
    for a in [
        "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
        "--no-first-run", "--disable-background-networking", "--disable-component-update",
        "--disable-sync", "--enable-unsafe-swiftshader", "--window-size=1500,2600",
    ]:
        o.add_argument(a)
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)
    yield d
    d.quit()


def settle(d, timeout=30.0):
    """Waits until the page has no debounce pending and no request in flight."""
    end = time.time() + timeout
    while time.time() < end:
        if d.execute_script("return !!(window.explorer && window.explorer.materials.length && window.explorer.settled())"):
            return
        time.sleep(0.02)
    raise AssertionError("the page did not settle")


def eval_rows(material, rows):
    """`facette eval` of (theta_i, phi_i, theta_o, phi_o) rows: (r, g, b) per row."""
    csv = "".join(f"{a},{b},{c},{e}\n" for a, b, c, e in rows)
    out = subprocess.run([str(BIN), "eval", "--material", material], input=csv,
                         capture_output=True, text=True, check=True).stdout
    return [tuple(float(x) for x in line.split(",")[4:7]) for line in out.splitlines()[1:]]


def plane_rows(theta_i, angles):
    """The lab's signed incidence-plane angle as eval's (theta_o, phi_o): + is the mirror side."""
    return [(theta_i, 0.0, abs(t), 180.0 if t > 0 else 0.0) for t in angles]


def close(a, b):
    return abs(a - b) <= 1e-8 * max(abs(a), abs(b)) + 1e-12


def slice_of(d, k):
    return d.execute_script(
        "const m = window.explorer.materials[arguments[0]]; const f = window.explorer.data.slice[m.id];"
        "return {text: f.material, theta: Array.from(f.data.theta_o), g: Array.from(f.data.reflect_g),"
        " r: Array.from(f.data.reflect_r), b: Array.from(f.data.reflect_b),"
        " drawn: window.explorer.drawn.slice.filter(s => s.material === m.id && s.side === 'reflect')[0].y};", k)


def check_slice_against_eval(d, k, theta_i):
    s = slice_of(d, k)
    picks = [i for i, t in enumerate(s["theta"]) if abs(t) < 89.0][::24]
    ref = eval_rows(s["text"], plane_rows(theta_i, [s["theta"][i] for i in picks]))
    for i, (r, g, b) in zip(picks, ref):
        assert close(s["g"][i], g), (s["theta"][i], s["g"][i], g)
    return s


def move(d, selector, value, event="input"):
    d.execute_script(
        "const e = document.querySelector(arguments[0]); e.focus(); e.value = arguments[1];"
        "e.dispatchEvent(new Event(arguments[2], {bubbles: true}));", selector, str(value), event)


def test_the_views_show_what_eval_computes_and_follow_the_controls(server, driver):
    d = driver
    d.get(server)
    settle(d)
    assert d.execute_script("return window.explorer.errors") == []
    texts = d.execute_script("return window.explorer.materials.map(m => m.type)")
    assert texts == ["conductor", "il"]

    before = check_slice_against_eval(d, 0, 30.0)
    check_slice_against_eval(d, 1, 30.0)

    # A slider moves alpha: the material's text and every number follow.
    move(d, 'input[data-material="0"][data-key="alpha"][data-role="slider"]', 0.4)
    settle(d)
    after = check_slice_against_eval(d, 0, 30.0)
    assert "alpha = 0.4" in after["text"], after["text"]
    assert max(after["g"]) < 0.5 * max(before["g"]), "a wider lobe has a lower peak"
    # The curve drawn is the channel mean of the numbers received.
    mean = [(r + g + b) / 3 for r, g, b in zip(after["r"], after["g"], after["b"])]
    assert len(after["drawn"]) == len(mean) and all(close(a, b) for a, b in zip(after["drawn"], mean))

    # The light moves: slice and hemisphere map are recomputed for the new angle.
    move(d, "#theta-i", 60)
    settle(d)
    check_slice_against_eval(d, 0, 60.0)
    hemi = d.execute_script(
        "const f = window.explorer.data.hemisphere; return {n: f.n, text: f.material, theta: f.theta_i,"
        " g: Array.from(f.data.value_g)};")
    n = hemi["n"]
    cells = [(r, c) for r, c in [(n // 2, n // 4), (n // 3, n // 2), (n // 2 + 7, n // 2 + 9)]]
    rows = []
    for r, c in cells:
        x, y = -1 + (c + 0.5) * 2 / n, -1 + (r + 0.5) * 2 / n
        z = math.sqrt(1 - x * x - y * y)
        rows.append((hemi["theta"], 0.0, math.degrees(math.acos(z)), math.degrees(math.atan2(y, x))))
    for (r, c), (_, g, _) in zip(cells, eval_rows(hemi["text"], rows)):
        assert abs(hemi["g"][r * n + c] - g) <= 1e-6 * abs(g) + 1e-12, (r, c, hemi["g"][r * n + c], g)

    # Albedo: estimates from the sampler, in [0, 1] within their error.
    alb = d.execute_script(
        "const m = window.explorer.materials[1]; const f = window.explorer.data.albedo[m.id];"
        "return {r: Array.from(f.data.reflect), e: Array.from(f.data.reflect_err)};")
    assert len(alb["r"]) == 19
    assert all(0 < r < 1 + 3 * e for r, e in zip(alb["r"], alb["e"]))


def test_a_bad_value_shows_the_grammars_error(server, driver):
    d = driver
    d.get(server)
    settle(d)
    move(d, 'input[data-material="0"][data-key="alpha"][data-role="input"]', "-1", "change")
    settle(d)
    shown = d.execute_script("return document.querySelector('.error[data-material=\"0\"]').textContent")
    bad = '{type = "conductor", distribution = "ggx", alpha = -1, material = "Au"}'
    cli = subprocess.run([str(BIN), "eval", "--material", bad], input="", capture_output=True, text=True)
    assert cli.returncode != 0
    grammar = cli.stderr.strip().split("--material: ", 1)[1]
    assert grammar in shown, (grammar, shown)
    # The other material still shows its curves.
    assert d.execute_script("return window.explorer.materials[1].error") is None


def test_a_bad_starting_material_is_an_error_before_serving():
    out = subprocess.run([str(BIN), "explore", "--port", "0", "--material", '{type = "conductor", alphaa = 1}'],
                         capture_output=True, text=True, timeout=30)
    assert out.returncode != 0
    assert "unknown key `alphaa`" in out.stderr and "alpha_u" in out.stderr, out.stderr


def test_screenshots_and_latency(server, driver):
    d = driver
    d.get(server)
    settle(d)
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    d.save_screenshot(str(ARTEFACTS / "explorer.png"))
    for view in ["slice", "polar", "hemisphere", "albedo"]:
        d.find_element("id", f"{view}-plot").find_element("xpath", "..").screenshot(str(ARTEFACTS / f"explorer-{view}.png"))
    # Latency of a slider move, from the input event to the view drawn (the page's own
    # clock): the light (θ_i), and a material's width (alpha: the material is rebuilt).
    # The preview is paused so that its passes do not share the cores with the views.
    d.execute_script("window.explorer.preview.maxPasses = 0;")
    figures = {}
    for what, selector, values in [
        ("theta_i", "#theta-i", [10, 20, 35, 50, 65, 75, 15, 45]),
        ("alpha", 'input[data-material="0"][data-key="alpha"][data-role="slider"]', [0.1, 0.15, 0.25, 0.3, 0.12, 0.35, 0.2, 0.28]),
    ]:
        samples = {"slice": [], "hemisphere": []}
        for value in values:
            move(d, selector, value)
            settle(d)
            lat = d.execute_script("return window.explorer.latency")
            for v in samples:
                samples[v].append(lat[v])
        figures[what] = {v: {"median_ms": sorted(s)[len(s) // 2], "max_ms": max(s)} for v, s in samples.items()}
        assert all(len(s) == len(values) and all(x > 0 for x in s) for s in samples.values())
    (ARTEFACTS / "latency.json").write_text(json.dumps(figures, indent=2))
    print("latency of a slider move (ms):", figures)


def test_requests_naming_another_host_are_refused(server):
    import urllib.error
    import urllib.request

    req = urllib.request.Request(server + "api/schema", headers={"Host": "attacker.example"})
    with pytest.raises(urllib.error.HTTPError) as e:
        urllib.request.urlopen(req, timeout=10)
    assert e.value.code == 403
    with urllib.request.urlopen(server + "api/schema", timeout=10) as ok:
        assert json.loads(ok.read())["types"][0]["name"] == "lambert"


def wait_for(d, script, timeout=60.0, what="condition"):
    end = time.time() + timeout
    while time.time() < end:
        v = d.execute_script(script)
        if v:
            return v
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}: {script}")


def test_preview_lobe_and_validation(server, driver):
    d = driver
    d.get(server)
    settle(d)
    # The live preview refines pass after pass (the path tracer, a few samples each).
    passes = wait_for(d, "const p = window.explorer.preview; return p.passes >= 4 && p.passes;", what="preview passes")
    lit = d.execute_script("const p = window.explorer.preview; let s = 0; for (const v of p.sum) s += v; return s / p.passes;")
    assert passes >= 4 and lit > 0
    # The 3D lobe is a mesh of the hemisphere map.
    assert d.execute_script("return window.explorer.drawn.lobe.triangles") > 1000
    # Validation: the selected material's checks, every one passing.
    assert d.execute_script("return document.getElementById('validate-samples').value") == '100000'
    d.find_element("id", "validate-run").click()
    wait_for(d, "return window.explorer.data.validation && !window.explorer.validating", what="validation")
    v = d.execute_script("return window.explorer.data.validation")
    assert v["failed"] == 0 and len(v["lines"]) >= 6, v
    rows = d.find_elements("css selector", "#validate-lines tr")
    assert len(rows) == len(v["lines"])
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    for view in ["preview", "lobe"]:
        d.find_element("id", f"{view}-plot").find_element("xpath", "..").screenshot(str(ARTEFACTS / f"explorer-{view}.png"))
    d.find_element("id", "validate-figure").screenshot(str(ARTEFACTS / "explorer-validation.png"))


def test_a_glint_shows_its_patch_ndf(server, driver):
    d = driver
    d.get(server)
    settle(d)
    d.execute_script("window.explorer.addMaterialFromText(arguments[0])",
                     '{type = "glint", generate = "bumpy", resolution = 128, footprint_size = 8.0}')
    wait_for(d, "return window.explorer.data.patchNdf && window.explorer.materials.length === 3", what="patch NDF")
    settle(d)
    f = d.execute_script("const f = window.explorer.data.patchNdf; return {n: f.n, integral: f.integral};")
    assert f["n"] == 128 and abs(f["integral"] - 1) < 0.05, f
    assert d.execute_script("return document.getElementById('patch-ndf-figure').hidden") is False
    d.find_element("id", "patch-ndf-figure").screenshot(str(ARTEFACTS / "explorer-patch-ndf.png"))


def test_a_measured_file_is_shown_and_fitted(server, driver, tmp_path):
    d = driver
    source = '{type = "il", kd = [0.55, 0.3, 0.12], ni = 1.5, distribution = "beckmann", alpha = 0.35, evaluation = "approx"}'
    merl = tmp_path / "synthetic-il.binary"
    subprocess.run([str(BIN), "measure", "--material", source, "-o", str(merl)], check=True, capture_output=True)
    d.get(server)
    settle(d)
    d.find_element("id", "measured-file").send_keys(str(merl))
    wait_for(d, "return window.explorer.materials.some(m => m.kind === 'measured')", what="the upload")
    settle(d)
    m = d.execute_script("const m = window.explorer.materials.find(m => m.kind === 'measured'); return {name: m.name, error: m.error, text: m.text};")
    assert m["name"] == "synthetic-il.binary" and m["error"] is None, m
    # Its slice is the file's nearest-bin values: compare a few with the source model's eval.
    s = d.execute_script(
        "const m = window.explorer.materials.find(m => m.kind === 'measured'); const f = window.explorer.data.slice[m.id];"
        "return {theta: Array.from(f.data.theta_o), g: Array.from(f.data.reflect_g)};")
    # Nearest-bin values against the source model at the same directions: the bins are
    # 1° (θ_h near the peak) to 2° wide, so a smooth lobe agrees within a few percent.
    picks = [i for i, t in enumerate(s["theta"]) if abs(t) < 60][::20]
    ref = eval_rows(source, plane_rows(30.0, [s["theta"][i] for i in picks]))
    for i, (_, g, _) in zip(picks, ref):
        assert abs(s["g"][i] - g) <= 0.1 * g, (s["theta"][i], s["g"][i], g)
    # Fit the IL model (closed-form body) and check the parameters come back.
    assert d.execute_script("return document.getElementById('fit-figure').hidden") is False
    d.execute_script("document.getElementById('fit-model').value = 'il'; document.getElementById('fit-model').dispatchEvent(new Event('change'));"
                     "document.getElementById('fit-il-evaluation').value = 'approx';")
    d.find_element("id", "fit-run").click()
    wait_for(d, "return !window.explorer.fitting && (window.explorer.data.fit || document.getElementById('fit-info').textContent.startsWith('error'))",
             timeout=120, what="the fit")
    assert not d.execute_script("return document.getElementById('fit-info').textContent").startswith("error")
    fit = d.execute_script("const f = window.explorer.data.fit; return {p: f.parameters, material: f.material, rel: f.rms_relative_error};")
    values = {p["name"]: p["value"] for p in fit["p"]}
    assert abs(values["ni"] - 1.5) < 0.05, values
    assert fit["material"].startswith('{type = "il"'), fit
    assert fit["rel"] < 0.05, fit
    d.find_element("id", "fit-figure").screenshot(str(ARTEFACTS / "explorer-fit.png"))
    d.find_element("id", "validate-run").click()
    wait_for(d, "return window.explorer.data.validation && !window.explorer.validating", what="validation")
    d.save_screenshot(str(ARTEFACTS / "explorer.png"))
    # The fitted material joins the others.
    n = d.execute_script("return window.explorer.materials.length")
    d.find_element("id", "fit-add").click()
    wait_for(d, f"return window.explorer.materials.length === {n + 1}", what="the fitted material")
    settle(d)


def test_a_corrupt_measured_file_is_an_error(server, driver, tmp_path):
    d = driver
    bad = tmp_path / "truncated.binary"
    bad.write_bytes(b"\x5a\x00\x00\x00\x5a\x00\x00\x00\xb4\x00\x00\x00" + b"\x00" * 100)
    d.get(server)
    settle(d)
    d.find_element("id", "measured-file").send_keys(str(bad))
    info = wait_for(d, "const t = document.getElementById('measured-info').textContent; return t.startsWith('error') && t;", what="the error")
    assert "truncated.binary" in info, info
