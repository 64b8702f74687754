"""Distributed runs on a local Ray instance: exact merges, retried failures."""

import numpy as np
import pytest

import facette

ray = pytest.importorskip("ray", reason="the distributed tests need Ray (.ci/run installs it)")
from facette import distributed  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_render_in_8_parts_equals_the_single_process_parts(tiny_scene, tmp_path):
    out = tmp_path / "dist.exr"
    img = distributed.render(tiny_scene, 8, output=out, seed=3, progress=False)
    np.testing.assert_array_equal(img, facette.render_in_parts(tiny_scene, 8, seed=3))
    np.testing.assert_array_equal(facette.read_image(out), img)


def test_a_failed_task_is_retried_and_the_result_is_identical(tiny_scene, tmp_path):
    faults = tmp_path / "faults"
    faults.mkdir()
    img = distributed.render(tiny_scene, 8, seed=3, progress=False, _fault_dir=str(faults))
    assert len(list(faults.iterdir())) == 8, "every part failed once"
    np.testing.assert_array_equal(img, facette.render_in_parts(tiny_scene, 8, seed=3))


def test_distributed_table_equals_the_single_process_table(tmp_path):
    m = '{type = "il", ni = 1.4, distribution = "beckmann", alpha = 0.5}'
    faults = tmp_path / "faults"
    faults.mkdir()
    out = tmp_path / "t.fctab"
    table = distributed.tabulate(m, 4, output=out, step=10, samples=256, progress=False, _fault_dir=str(faults))
    assert table == facette.tabulate(m, step=10, samples=256)
    assert out.read_bytes() == table
    assert len(list(faults.iterdir())) == 4


def test_a_bad_scene_fails_in_the_driver_before_any_task(tmp_path):
    # Checked in the driver: one OSError at once, naming the file, no task submitted.
    with pytest.raises(OSError, match="nope.toml: cannot read the scene file"):
        distributed.render(tmp_path / "nope.toml", 2, progress=False)
    with pytest.raises(ValueError, match="interfaced-Lambertian"):
        distributed.tabulate('{type = "lambert"}', 2, progress=False)


def test_a_user_error_in_a_task_is_not_retried_and_is_one_line(tiny_scene, tmp_path):
    faults = tmp_path / "faults"
    faults.mkdir()
    (faults / "user-error").write_text("")
    with pytest.raises(ValueError) as e:
        distributed.render(tiny_scene, 2, seed=3, progress=False, max_retries=3, _fault_dir=str(faults))
    assert "\n" not in str(e.value) and "injected user error" in str(e.value)
    # Each part ran at most once (a retried part would leave a second attempt file).
    attempts = [p.name for p in faults.iterdir() if p.name.startswith("attempt-")]
    for part in range(2):
        assert sum(a.startswith(f"attempt-render-{part}-") for a in attempts) <= 1, attempts


def test_dict_scenes_and_materials_travel_to_the_workers(tiny_scene):
    m = facette.Material({"type": "il", "kd": [0.8, 0.4, 0.2], "ni": 1.5, "alpha": 0.3})
    scene = {
        "camera": {"position": [0, 0, 4], "target": [0, 0, 0], "fov": 40},
        "film": {"width": 24, "height": 16, "spp": 8},
        "objects": [{"shape": "sphere", "radius": 1, "material": m}],
        "lights": [{"type": "point", "position": [2, 2, 3], "intensity": 10}, {"type": "constant", "radiance": 0.5}],
    }
    np.testing.assert_array_equal(distributed.render(scene, 2, seed=1, progress=False),
                                  facette.render_in_parts(scene, 2, seed=1))
    il = facette.Material({"type": "il", "ni": 1.4, "distribution": "beckmann", "alpha": 0.5})
    assert distributed.tabulate(il, 2, step=30, samples=64, progress=False) == facette.tabulate(il, step=30, samples=64)
    assert distributed.tabulate(il, 2, step=30, tolerance=1e-3, progress=False) == facette.tabulate(
        il, step=30, tolerance=1e-3
    )
