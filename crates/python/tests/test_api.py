"""The Python-facing surface: broadcasting, numpy values, Material as a value, scene
forms, argument order, and no panic reaching Python for any bad input."""

import pickle

import numpy as np
import pytest

import facette

CONDUCTOR = {"type": "conductor", "material": "Au", "distribution": "ggx", "alpha_u": 0.2, "alpha_v": 0.4}


def spherical(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def hemisphere(shape, seed):
    v = np.random.default_rng(seed).normal(size=shape + (3,))
    v[..., 2] = np.abs(v[..., 2]) + 0.05
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.mark.parametrize(
    "wi_shape, wo_shape, out",
    [((3,), (5, 3), (5,)), ((1, 3), (5, 3), (5,)), ((4, 6, 3), (3,), (4, 6)), ((4, 1, 3), (1, 6, 3), (4, 6)),
     ((3,), (3,), ())],
)
def test_eval_and_pdf_broadcast_like_numpy(wi_shape, wo_shape, out):
    m = facette.Material(CONDUCTOR)
    wi, wo = hemisphere(wi_shape[:-1], 1), hemisphere(wo_shape[:-1], 2)
    f = m.eval(wi, wo)
    p = m.pdf(wi, wo)
    assert f.shape == out + (3,) and p.shape == out
    # Each entry is the value of its own pair, evaluated as one row.
    bi, bo = np.broadcast_arrays(wi, wo)
    rows_f = m.eval(bi.reshape(-1, 3), bo.reshape(-1, 3))
    np.testing.assert_array_equal(f.reshape(-1, 3), rows_f)
    np.testing.assert_array_equal(p.reshape(-1), m.pdf(bi.reshape(-1, 3), bo.reshape(-1, 3)))
    with pytest.raises(ValueError, match="do not broadcast"):
        m.eval(hemisphere((4,), 1), hemisphere((5,), 2))


def test_sample_keeps_the_leading_shape_and_u_per_direction():
    m = facette.Material(CONDUCTOR)
    wo = hemisphere((3, 4), 5)
    wi, weight, pdf, lobes = m.sample(wo, seed=3)
    assert wi.shape == (3, 4, 3) and weight.shape == (3, 4, 3) and pdf.shape == (3, 4) and len(lobes) == 12
    flat = m.sample(wo.reshape(-1, 3), seed=3)
    np.testing.assert_array_equal(flat[0], wi.reshape(-1, 3))
    u = np.random.default_rng(0).random((3, 4, 2))
    np.testing.assert_array_equal(m.sample(wo, u=u)[0].reshape(-1, 3), m.sample(wo.reshape(-1, 3), u=u.reshape(-1, 2))[0])


def test_threads_do_not_change_results():
    m = facette.Material(CONDUCTOR)
    wi, wo = hemisphere((3000,), 1), hemisphere((3000,), 2)
    np.testing.assert_array_equal(m.eval(wi, wo, threads=1), m.eval(wi, wo, threads=2))
    np.testing.assert_array_equal(m.pdf(wi, wo, threads=1), m.pdf(wi, wo, threads=2))
    a, b = m.sample(wo, seed=4, threads=1), m.sample(wo, seed=4, threads=2)
    np.testing.assert_array_equal(a[0], b[0])
    assert a[3] == b[3]
    d = facette.Material('{type = "dielectric", distribution = "ggx", alpha = 0.3}')
    x, y = d.albedo([0, 40, 120], samples=5000, threads=1), d.albedo([0, 40, 120], samples=5000, threads=3)
    np.testing.assert_array_equal(x["transmittance"], y["transmittance"])


def test_pdf_takes_wi_then_wo_like_eval():
    m = facette.Material(CONDUCTOR)
    wo = np.broadcast_to(spherical(35.0, 10.0), (500, 3))
    wi, _, pdf, _ = m.sample(wo, seed=7)
    ok = pdf > 0
    # The density of the sampled wi given wo, in eval's order, positionally and by keyword.
    np.testing.assert_allclose(m.pdf(wi[ok], wo[ok]), pdf[ok], rtol=1e-9)
    np.testing.assert_allclose(m.pdf(wo=wo[ok], wi=wi[ok]), pdf[ok], rtol=1e-9)
    # The reverse order is another number: the order matters, so this test would see a swap.
    assert not np.allclose(m.pdf(wo[ok], wi[ok]), pdf[ok], rtol=1e-3)


def test_eval_cosine_is_mitsubas_value():
    m = facette.Material(CONDUCTOR)
    wi, wo = hemisphere((10,), 1) * 3.0, hemisphere((10,), 2)  # wi not normalized on purpose
    f = m.eval(wi, wo)
    np.testing.assert_allclose(m.eval(wi, wo, cosine=True), f * np.abs(wi[:, 2:3]) / 3.0, rtol=1e-12)


def test_numpy_values_in_dict_specs():
    a = facette.Material({"type": "il", "kd": np.array([0.8, 0.4, 0.2], dtype=np.float32), "ni": np.float64(1.5),
                          "alpha": 0.3})
    b = facette.Material('{type = "il", kd = [0.800000011920929, 0.4000000059604645, 0.20000000298023224], ni = 1.5, alpha = 0.3}')
    assert a == b
    wi, wo = hemisphere((3,), 1), hemisphere((3,), 2)
    np.testing.assert_array_equal(a.eval(wi, wo, samples=50), b.eval(wi, wo, samples=50))
    with pytest.raises(ValueError, match="material.kd: unsupported value of type object"):
        facette.Material({"type": "il", "kd": object()})


def test_material_is_a_value():
    m = facette.Material(CONDUCTOR)
    assert pickle.loads(pickle.dumps(m)) == m
    assert facette.Material(m.spec) == m == facette.Material(m.toml) == facette.Material(m)
    assert m.spec == CONDUCTOR
    assert m != facette.Material(dict(CONDUCTOR, alpha_u=0.25))
    assert len({m, facette.Material(m.toml)}) == 1
    # Accepted where a spec is.
    il = facette.Material({"type": "il", "ni": 1.4, "distribution": "beckmann", "alpha": 0.5})
    assert facette.tabulate(il, step=30, samples=64) == facette.tabulate(il.toml, step=30, samples=64)


def tiny_dict(material):
    return {
        "camera": {"position": [0, 0, 4], "target": [0, 0, 0], "fov": 40},
        "film": {"width": 24, "height": 16, "spp": 8},
        "objects": [{"shape": "sphere", "radius": 1, "material": material}],
        "lights": [{"type": "point", "position": [2, 2, 3], "intensity": 10}, {"type": "constant", "radiance": 0.5}],
    }


def test_dict_scene_renders_like_its_toml(tiny_scene):
    il = {"type": "il", "kd": [0.8, 0.4, 0.2], "ni": 1.5, "alpha": 0.3}
    ref = facette.render(tiny_scene, seed=5)
    np.testing.assert_array_equal(facette.render(tiny_dict(il), seed=5), ref)
    np.testing.assert_array_equal(facette.render(tiny_dict(facette.Material(il)), seed=5), ref)
    # Overrides.
    assert facette.render(tiny_dict(il), spp=1, width=12, height=9).shape == (9, 12, 3)


def test_one_line_toml_text_is_text_not_a_path():
    one_line = 'camera = {position = [0, 0, 4], target = [0, 0, 0]}'
    img = facette.render(one_line, spp=1, width=8, height=8)
    assert img.shape == (8, 8, 3) and np.all(img == 0)  # no lights: black, but rendered
    with pytest.raises(OSError, match="no such file"):
        facette.render("missing-scene.toml")


def test_xml_text_and_defines(tmp_path):
    xml = """<scene version="3.0.0">
    <default name="res" value="12"/>
    <sensor type="perspective"><float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    </sensor>
    <shape type="sphere"><bsdf type="diffuse"/></shape>
    <emitter type="constant"/>
</scene>"""
    path = tmp_path / "s.xml"
    path.write_text(xml)
    from_text = facette.render(xml, seed=2, defines={"res": 10})
    assert from_text.shape == (10, 10, 3) and from_text.mean() > 0
    np.testing.assert_array_equal(from_text, facette.render(path, seed=2, defines={"res": 10}))
    assert facette.render(str(path), spp=1).shape == (12, 12, 3)
    with pytest.raises(ValueError, match="width"):
        facette.render(path, width=5)
    with pytest.raises(ValueError, match="Mitsuba XML scenes only"):
        facette.render('camera = {position = [0, 0, 4], target = [0, 0, 0]}', defines={"a": 1})


def test_negative_and_wrong_counts_name_the_argument(tiny_scene):
    m = facette.Material('{type = "lambert"}')
    for call, name in [
        (lambda: m.eval([0, 0, 1], [0, 0, 1], samples=-1), "samples"),
        (lambda: m.eval([0, 0, 1], [0, 0, 1], seed=-1), "seed"),
        (lambda: m.albedo(30, samples=-5), "samples"),
        (lambda: m.validate(samples=-1), "samples"),
        (lambda: m.sample([0, 0, 1], seed=-2), "seed"),
        (lambda: facette.render(tiny_scene, spp=-1), "spp"),
        (lambda: facette.render(tiny_scene, threads=-1), "threads"),
        (lambda: facette.render(tiny_scene, width=-3), "width"),
        (lambda: facette.render_part(tiny_scene, -1, 4), "part"),
        (lambda: facette.tabulate('{type = "il", alpha = 0.3}', samples=-1), "samples"),
        (lambda: facette.fit("x.binary", samples=-1), "samples"),
    ]:
        with pytest.raises(ValueError, match=f"`{name}`"):
            call()
    with pytest.raises(TypeError, match="`spp`"):
        facette.render(tiny_scene, spp=2.5)


BAD_FILES = {
    "tiny.toml": b'[camera]\nposition = [0, 0, 4]\n',
    "empty": b"",
    "zeros": b"\x00" * 64,
    "huge-dims": b"\xff\xff\xff\x7f" * 3 + b"\x00" * 32,
    "text": "é😀 not a file format\n".encode(),
    "random": bytes(np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8)),
}


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_no_panic_reaches_python_for_bad_files(name, tmp_path):
    data = BAD_FILES[name]
    for suffix in ("", ".binary", ".exr", ".png", ".hdr", ".toml", ".xml"):
        (tmp_path / (name + suffix)).write_bytes(data)
    path = tmp_path / name
    calls = [
        lambda: facette.fit(path, samples=100),
        lambda: facette.fit(path.with_name(name + ".binary"), model="kelemen", samples=100),
        lambda: facette.read_image(path.with_name(name + ".exr")),
        lambda: facette.read_image(path.with_name(name + ".png")),
        lambda: facette.read_image(path.with_name(name + ".hdr")),
        lambda: facette.render(path.with_name(name + ".toml"), spp=1),
        lambda: facette.render(path.with_name(name + ".xml"), spp=1),
        lambda: facette.merge_render_parts([BAD_FILES[name]]),
        lambda: facette.merge_table_parts([BAD_FILES[name]]),
        lambda: facette.Material(BAD_FILES[name].decode("utf-8", "replace")),
    ]
    for k, call in enumerate(calls):
        try:
            call()
        except (ValueError, OSError, RuntimeError, TypeError) as e:
            # A user error, or a bug reported as a RuntimeError naming the call — never
            # pyo3's PanicException (a BaseException that `except Exception` misses).
            assert type(e).__name__ != "PanicException", (k, e)
            if isinstance(e, RuntimeError):
                assert str(e).startswith("facette."), (k, e)


def test_bad_arguments_never_panic(tiny_scene):
    m = facette.Material(CONDUCTOR)
    bad = [
        lambda: m.eval(np.zeros((0, 3)), np.zeros((0, 3))),
        lambda: m.eval([[np.inf, 0, 1]], [0, 0, 1]),
        lambda: m.eval("x", [0, 0, 1]),
        lambda: m.sample(np.zeros((2, 3)) + [0, 0, 1], u=np.full((2, 3), 0.999999)),
        lambda: m.albedo([90]),
        lambda: m.albedo([]),
        lambda: facette.render(tiny_scene, exposure=float("nan")),
        lambda: facette.render(tiny_scene, seed=2**64),
        lambda: m.eval([0, 0, 1], [0, 0, 1], seed=2**70),
        lambda: facette.render_part(tiny_scene, 5, 4),
        lambda: facette.render_in_parts(tiny_scene, 0),
        lambda: facette.render({"camera": 3}),
        lambda: facette.render({"camera": {"position": [0, 0, 4], "target": [0, 0, 0]}, "film": {"width": 2**40}}),
        lambda: facette.tabulate_part('{type = "il", alpha = 0.3}', 3, 2, step=30, samples=8),
        lambda: facette.tabulate('{type = "il", alpha = 0.3}', step=0.0, samples=8),
        lambda: facette.write_image("/nonexistent-dir/x.png", np.zeros((2, 2, 3))),
        lambda: facette.Material({"type": "il", "ni": 10**30}),
        lambda: facette.Material({"type": {"nested": 1}}),
    ]
    for k, call in enumerate(bad):
        try:
            call()
        except (ValueError, OSError, RuntimeError, TypeError, OverflowError) as e:
            assert type(e).__name__ != "PanicException", (k, e)


def test_limits_are_raised_and_refused_like_the_cli():
    limits = facette.limits()
    value, default, ceiling, what = limits["xml-includes"]
    assert (value, default) == (256, 256) and ceiling > default
    facette.set_limit("xml-includes", 1000)
    try:
        assert facette.limits()["xml-includes"][0] == 1000
    finally:
        facette.set_limit("xml-includes", default)
    with pytest.raises(ValueError, match="is fixed at 64"):
        facette.set_limit("xml-depth", 100)
    with pytest.raises(ValueError, match="unknown limit `nope`"):
        facette.set_limit("nope", 1)
    with pytest.raises(ValueError, match="must be an integer"):
        facette.set_limit("xml-includes", 1.5)
